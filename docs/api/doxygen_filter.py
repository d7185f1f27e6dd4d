#!/usr/bin/python3
"""Doxygen INPUT_FILTER: reads OnTime's plain `//` header comments as documentation.

OnTime's headers document every declaration with an ordinary `//` comment block directly above
it, and each header's purpose (what it computes, its guarantees and cost) in the block that
follows `#pragma once`. Doxygen reads only `///`-style comments, so this filter rewrites a header
on the fly, line for line (so that Doxygen's warnings keep the header's line numbers):

- the header's leading block becomes the file's documentation (`\\file`);
- a block directly above a declaration (no blank line between) becomes that declaration's
  documentation; when several declarations follow one block without a blank line or another
  comment between them (`report_not_yet`, `report_refined`, `report`), each gets the block;
- a `//` comment after a member on the same line (`int skeleton = -1;  // ...`) documents that
  member;
- lines indented further than the block's text (code examples, formulas) become code blocks.

Comments inside function bodies and blocks followed by a blank line are left alone: they
explain code, not an interface. The header files themselves are never modified.
"""

from __future__ import annotations

import re
import sys

COMMENT = re.compile(r"^(\s*)//(?![/!])(.*)$")
TRAILING = re.compile(r"^(.*?[;,{]|.*?\))(\s*)//(?![/!])\s?(.*)$")
SCOPE_OPENER = re.compile(r"\b(namespace|class|struct|union|enum)\b")
# Characters Doxygen would read as commands or HTML in the prose of a comment.
ESCAPES = [("\\", "\\\\"), ("@", "\\@"), ("<", "\\<"), (">", "\\>"), ("#", "\\#"), ("%", "\\%"),
           ("&", "\\&"), ("$", "\\$")]


def strip_code(line: str) -> str:
    """The line without string and character literals and without a trailing comment."""
    line = re.sub(r'"(\\.|[^"\\])*"', '""', line)
    line = re.sub(r"'(\\.|[^'\\])*'", "''", line)
    return line.split("//", 1)[0]


def escape(text: str) -> str:
    # Backticks keep their Markdown meaning (code) and their content is left as written.
    parts = text.split("`")
    for i in range(0, len(parts), 2):
        for old, new in ESCAPES:
            parts[i] = parts[i].replace(old, new)
    return "`".join(parts)


def doc_lines(block: list[tuple[str, str]], file_doc: bool) -> list[str]:
    """The Doxygen form of one comment block (a list of (indent, text)), as many lines."""
    texts = [text[1:] if text.startswith(" ") else text for _, text in block]
    prose_indent = min((len(t) - len(t.lstrip()) for t in texts if t.strip()), default=0)
    deeper = [bool(t.strip()) and len(t) - len(t.lstrip()) >= prose_indent + 2 for t in texts]
    # Each run of code lines loses its common indentation (Doxygen keeps the rest as written).
    code_indent = [0] * len(texts)
    i = 0
    while i < len(texts):
        if deeper[i]:
            j = i
            while j < len(texts) and (deeper[j] or not texts[j].strip()):
                j += 1
            common = min(len(t) - len(t.lstrip()) for t in texts[i:j] if t.strip())
            code_indent[i:j] = [common] * (j - i)
            i = j
        else:
            i += 1
    out = []
    in_code = False
    for i, text in enumerate(texts):
        indent = block[i][0]
        body = text[code_indent[i]:] if deeper[i] else text
        if deeper[i] and not in_code:
            body = "@code{.unparsed}" + body
            in_code = True
        elif not deeper[i] and in_code and text.strip():
            # Close the code block at the end of the previous line.
            out[-1] += " @endcode"
            in_code = False
            body = escape(text)
        elif not in_code:
            body = escape(text)
        out.append(f"{indent}/// {body}")
    if in_code:
        out[-1] += " @endcode"
    if file_doc:
        out[-1] += " @file"
    return out


def filter_header(source: str) -> str:
    lines = source.split("\n")
    out: list[str] = []
    depth_body = 0          # braces of function bodies and initialisers
    scopes: list[bool] = []  # for each open brace: is it a namespace/class scope?
    statement = ""          # the declaration read so far (for a brace's kind)
    seen_file_doc = False
    seen_code = False
    pending_doc: list[str] | None = None  # a block waiting for its declaration(s)
    run_doc: list[str] | None = None       # the block of the run of declarations being read
    i = 0
    while i < len(lines):
        line = lines[i]
        match = COMMENT.match(line)
        if match and depth_body == 0:
            block = []
            while i < len(lines) and (m := COMMENT.match(lines[i])):
                block.append((m.group(1), m.group(2)))
                i += 1
            following = lines[i] if i < len(lines) else ""
            if not seen_file_doc and not seen_code:
                seen_file_doc = True
                out.extend(doc_lines(block, file_doc=True))
                run_doc = None
                continue
            if following.strip() and not following.lstrip().startswith("#"):
                converted = doc_lines(block, file_doc=False)
                out.extend(converted)
                pending_doc = converted
                run_doc = None
            else:
                out.extend(f"{indent}//{text}" for indent, text in block)
                pending_doc = run_doc = None
            continue
        stripped = line.strip()
        if stripped and not stripped.startswith("#"):
            seen_code = True
        if not stripped:
            pending_doc = run_doc = None
        code = strip_code(line)
        starts_statement = (depth_body == 0 and statement.strip() == "" and code.strip() != ""
                            and not code.strip().startswith("}")
                            and not re.match(r"(public|private|protected)\s*:", code.strip()))
        if starts_statement and pending_doc is None and run_doc is not None and not TRAILING.match(line):
            # A further declaration under the same block: it shares the block's documentation,
            # flattened onto its own line so that the header's line numbers are kept.
            shared = " ".join(d.strip()[3:].strip() for d in run_doc)
            indent = line[: len(line) - len(line.lstrip())]
            line = f"{indent}/** {shared} */ {line.lstrip()}"
        if starts_statement and pending_doc is not None:
            run_doc = pending_doc
            pending_doc = None
        # Digit separators (10'000'000): Doxygen copies them into signatures with spaces, which
        # Sphinx's C++ parser then rejects.
        if "'" in code:
            line = re.sub(r"(?<=[0-9])'(?=[0-9])", "", line)
        # Same-line member comments.
        if depth_body == 0 and (t := TRAILING.match(line)) and "/**" not in line:
            line = f"{t.group(1)}{t.group(2)}///< {escape(t.group(3))}"
        out.append(line)
        for ch in code:
            if ch == "{":
                is_scope = depth_body == 0 and bool(SCOPE_OPENER.search(statement)) and "(" not in statement.split("{")[0].replace("alignas(", "")
                scopes.append(is_scope)
                if not is_scope:
                    depth_body += 1
                else:
                    run_doc = None  # a block above a class documents the class, not its members
                statement = ""
            elif ch == "}":
                if scopes and not scopes.pop():
                    depth_body -= 1
                elif depth_body == 0:
                    run_doc = None
                statement = ""
            elif ch == ";":
                statement = ""
            else:
                statement += ch
        if depth_body == 0 and code.strip().endswith(":") and not code.strip().endswith("::"):
            statement = ""  # public: / private:
        statement += " "
        i += 1
    return "\n".join(out)


def main() -> None:
    with open(sys.argv[1], encoding="utf-8") as f:
        sys.stdout.write(filter_header(f.read()))


if __name__ == "__main__":
    main()
