#!/usr/bin/python3
"""Checks that every figure and command of an earlier README is in the documentation site.

    scripts/check-readme-facts.py [REVISION]   (default: the README of 82bfda1, before the site)

When the README was shortened to a front door, everything it said moved into the site's pages
(docs/**/*.md and the tutorial). This reads the README of REVISION from git and looks up, in the
site's sources and the current README, every line of its command blocks, every inline code span
and every number with a decimal point, a thousands separator or two digits or more. Whitespace is
normalised; a line of a command block is checked as a whole, its trailing `# remark` included
(the remarks carry the figures). Prints what is missing and exits 1 when anything is.
"""

import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def normalise(text: str) -> str:
    return re.sub(r"\s+", " ", text).strip()


def main() -> int:
    revision = sys.argv[1] if len(sys.argv) > 1 else "82bfda1"
    old = subprocess.run(["git", "show", f"{revision}:README.md"], cwd=ROOT, check=True,
                         capture_output=True, text=True).stdout
    pages = sorted((ROOT / "docs").rglob("*.md")) + [ROOT / "docs/tutorial.ipynb", ROOT / "README.md"]
    site = normalise("\n".join(p.read_text(encoding="utf-8") for p in pages))
    # Links are rewritten between the README and the pages (docs/x.md -> ../x.md): compare the text.
    site_text = re.sub(r"\]\([^)]*\)", "]", site)

    facts = []
    in_block = False
    for line in old.splitlines():
        if line.startswith("```"):
            in_block = not in_block
            continue
        if in_block:
            if line.strip():
                facts.append(("line", normalise(line)))
            continue
        for span in re.findall(r"`([^`]+)`", line):
            facts.append(("code", normalise(span)))
        prose = re.sub(r"`[^`]+`", " ", re.sub(r"\]\([^)]*\)", "]", line))
        for number in re.findall(r"(?<![\w.])[−+-]?\d[\d,]*(?:\.\d+)?(?:e-?\d+)?", prose):
            if re.search(r"[.,]", number) or len(number.lstrip("−+-")) >= 2:
                facts.append(("number", number))
    missing = [(kind, fact) for kind, fact in dict.fromkeys(facts) if fact not in site and fact not in site_text]
    for kind, fact in missing:
        print(f"check-readme-facts: missing {kind}: {fact}")
    print(f"check-readme-facts: {len(dict.fromkeys(facts))} facts of {revision}:README.md, {len(missing)} missing")
    return 1 if missing else 0


if __name__ == "__main__":
    sys.exit(main())
