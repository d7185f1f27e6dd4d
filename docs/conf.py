"""Sphinx configuration of OnTime's documentation site (built by scripts/docs.sh).

The guides and references are the Markdown documents of this folder (MyST), the C++ API comes
from Doxygen's XML through Breathe, the Python API from the package's docstrings (autodoc, so
the extension must be importable: scripts/docs.sh puts build/python on PYTHONPATH) and the
tutorial notebook is executed on every build (nbsphinx), so a broken API breaks the build.
Everything is local: no theme, script or font is fetched at build time or by the browser.
"""

from __future__ import annotations

import os
import pathlib
import re

DOCS = pathlib.Path(__file__).resolve().parent
ROOT = DOCS.parent

project = "OnTime"
author = "OnTime's authors"
copyright = "OnTime's authors"
release = version = "0.1.0"

extensions = [
    "myst_parser",
    "breathe",
    "nbsphinx",
    "sphinx.ext.autodoc",
    "sphinx.ext.napoleon",
    "sphinx_copybutton",
]

source_suffix = {".md": "markdown", ".rst": "restructuredtext"}
root_doc = "index"
exclude_patterns = ["_build", "**.ipynb_checkpoints", "api/undocumented.txt"]
html_theme = "furo"
html_title = "OnTime"
html_static_path = ["_static"]
html_css_files = ["ontime.css"]
pygments_style = "friendly"
# Every warning fails the build (scripts/docs.sh passes -W); the site is never published with a
# broken reference, image or page.
nitpicky = False

# MyST: GitHub-style Markdown stays readable as plain files, with anchors for `#section` links.
myst_enable_extensions = ["colon_fence", "dollarmath", "deflist"]
myst_heading_anchors = 4

# Breathe: the XML written by Doxygen (docs/api/Doxyfile) into build/docs/doxygen/xml.
breathe_projects = {"ontime": os.environ.get("ONTIME_DOXYGEN_XML", str(ROOT / "build/docs/doxygen/xml"))}
breathe_default_project = "ontime"
breathe_default_members = ("members",)
breathe_show_include = True

# autodoc: signatures come from the docstrings pybind11 writes (the first line of each).
autodoc_default_options = {"members": True, "undoc-members": False, "show-inheritance": True}
autodoc_docstring_signature = True
autodoc_typehints = "signature"
autodoc_member_order = "bysource"

# nbsphinx: the tutorial runs on every build; an error in a cell fails it.
nbsphinx_execute = "always"
nbsphinx_allow_errors = False
nbsphinx_timeout = 300
nbsphinx_kernel_name = "python3"

# Copy buttons leave out shell prompts and the `# ...` remarks after a command.
copybutton_prompt_text = r"\$ |>>> "
copybutton_prompt_is_regexp = True

suppress_warnings = [
    # MyST's anchors for headings that repeat in one document ("Examples" under each command).
    "myst.duplicate_def",
]


# Links from the Markdown documents to the repository's own files (data, scripts, headers) work on
# a code host. In the site MyST copies each linked file into _downloads/; a link to a folder
# (`../scripts/cluster`) cannot be copied, so it points at the folder of the checkout the site was
# built from (file://), which works offline and which the link checker follows.
myst_url_schemes = ["http", "https", "mailto", "ftp", "file"]
FOLDER_LINK = re.compile(r"\]\(((?:\.\./)+(?:data|scripts|include|domains|apps|tests|python|bench|fuzz|cmake)(?:/[^)#\s]*)?)\)")


def _link_folders(app, docname, source):
    base = (DOCS / docname).parent

    def replace(match):
        target = (base / match.group(1)).resolve()
        return f"]({target.as_uri()})" if target.is_dir() else match.group(0)

    source[0] = FOLDER_LINK.sub(replace, source[0])


# The C++ reference: one page a layer (docs/api/cpp/LAYER.md, written here on every build, so that
# a header added to include/ontime/ or domains/include/ appears without anyone listing it), each
# with a section per header: its leading comment, then every documented declaration.
LAYERS = {
    "util": ("Utilities", "include/ontime/util",
             "Errors, random numbers, parallel loops, MPI ranks, statistics, file output: the bottom "
             "layer, knowing nothing of planning."),
    "model": ("Model", "include/ontime/model",
              "The problem: actions and their planning and execution distributions, skeletons, "
              "rewards, exogenous chains, and the instance, log and skeleton file formats."),
    "mdp": ("MDP", "include/ontime/mdp", "The effort-allocation MDP of SPEC §2: its states and transitions."),
    "solve": ("Exact solvers", "include/ontime/solve",
              "The exact optimum and certified bounds: the layered, memoised and branch-and-bound "
              "solvers, Eq. (1)'s tables and Theorem 1's knapsack reduction."),
    "allocators": ("Allocators", "include/ontime/allocators",
                   "The effort allocators (one decision per step of effort) and the registry that "
                   "names and builds them."),
    "run": ("Running", "include/ontime/run",
            "Sessions, worlds, clocks, simulation, episodes and their evaluation, tables and studies."),
    "learn": ("Learning", "include/ontime/learn",
              "Fitting distributions to planner logs, conditional time models of unseen worlds, "
              "online updates, chain fitting and ppo training."),
    "report": ("Reports", "include/ontime/report", "The text and JSON reports the command-line tool prints."),
    "domains": ("TAMP domains", "domains/include/ontime/domains",
                "The navigation and manipulation domains on OMPL, FCL and KDL (library "
                "`ontime::domains`): the Domain/Refinement interface, worlds, collection and the TAMP loop."),
}


def _classes_by_header(xml_dir: pathlib.Path) -> dict[str, list[tuple[str, str]]]:
    """For each header (`ontime/...`, as included), its top-level classes and structs as
    (kind, qualified name), from Doxygen's XML."""
    import xml.etree.ElementTree as ET
    kinds = {}
    for path in xml_dir.glob("*.xml"):
        if path.name.startswith(("class", "struct", "union")):
            compound = ET.parse(path).getroot().find("compounddef")
            kinds[compound.findtext("compoundname")] = compound.get("kind")
    result = {}
    for path in xml_dir.glob("*_8hpp.xml"):
        compound = ET.parse(path).getroot().find("compounddef")
        header = compound.find("location").get("file")  # relative to include/ (STRIP_FROM_PATH)
        classes = []
        for inner in compound.findall("innerclass"):
            name = inner.text
            # Nested classes are rendered inside their enclosing class.
            if name.rsplit("::", 1)[0] in kinds or inner.get("prot") != "public":
                continue
            classes.append((kinds.get(name, "class"), name))
        result[header] = classes
    return result


def _write_cpp_pages(app):
    xml_dir = pathlib.Path(breathe_projects["ontime"])
    classes = _classes_by_header(xml_dir)
    covered = set()
    for layer, (title, folder, text) in LAYERS.items():
        include_root = ROOT / folder.split("/ontime")[0]
        headers = sorted((ROOT / folder).rglob("*.hpp"))
        lines = [f"# {title}", "", text, "",
                 f"The headers of `{folder}/`; each section opens with the header's own description.", ""]
        for header in headers:
            name = header.relative_to(include_root).as_posix()
            covered.add(header)
            # The file's description and its free functions, types and constants; its classes
            # one by one (a whole doxygenfile would declare the namespace again on every page).
            lines += [f"## `{name}`", "", f"```{{doxygenfile}} {name}", ":project: ontime",
                      ":sections: briefdescription detaileddescription typedef enum func var", "```", ""]
            for kind, qualified in classes.get(name, []):
                lines += [f"```{{doxygen{kind}}} {qualified}", ":project: ontime", ":members:", "```", ""]
        page = DOCS / "api/cpp" / f"{layer}.md"
        content = "\n".join(lines)
        # Rewritten only when it changes, so that an incremental build does not redo every page.
        if not page.exists() or page.read_text() != content:
            page.write_text(content)
    everything = set((ROOT / "include/ontime").rglob("*.hpp")) | set((ROOT / "domains/include").rglob("*.hpp"))
    uncovered = sorted(str(h.relative_to(ROOT)) for h in everything - covered
                       if h != ROOT / "include/ontime/ontime.hpp")
    if uncovered:
        from sphinx.errors import ConfigError
        raise ConfigError("headers outside the C++ reference's layers (docs/conf.py LAYERS): " + ", ".join(uncovered))


INDENTED = re.compile(r"^( {4,})\S")


def _literal_blocks_in_docstrings(app, what, name, obj, options, lines):
    """Indented examples in the package's docstrings (written for help()) become code blocks.

    The docstrings of `ontime` and of its C++ bindings show code by indenting it under a line of
    prose, as Python's help() reads well; reStructuredText would read that as a block quote
    without its blank line. A block of lines indented by four spaces or more is marked as code.
    """
    out = []
    in_block = False
    for line in lines:
        if not in_block and INDENTED.match(line) and not (out and out[-1].rstrip().endswith("::")):
            if out and out[-1].strip():
                out.append("")
            out += [".. code-block:: python", ""]
            in_block = True
        elif in_block and line.strip() and not line.startswith("    "):
            out.append("")
            in_block = False
        if in_block:
            out.append(("   " + line) if line.strip() else line)
        else:
            # A star in prose is a product ("D * step_seconds") or a signature's `*, ` and
            # `**kwargs` (pybind11's list of overloads), never emphasis: the docstrings use none.
            parts = line.split("`")
            parts[::2] = [part.replace("*", r"\*") for part in parts[::2]]
            out.append("`".join(parts))
    lines[:] = out


# Debian's furo imports normalize.css from the web server's /javascript/ folder (Debian's shared
# JavaScript, which only a server set up with javascript-common has). The site carries its own
# copy instead, from the same package (node-normalize.css), next to furo.css.
NORMALIZE = pathlib.Path("/usr/share/javascript/normalize.css/normalize.css")


def _bundle_normalize_css(app, exception):
    if exception is not None or app.builder.format != "html":
        return
    styles = pathlib.Path(app.outdir) / "_static/styles"
    furo_css = styles / "furo.css"
    text = furo_css.read_text()
    if "@import url(/javascript/normalize.css/normalize.css);" in text:
        (styles / "normalize.css").write_text(NORMALIZE.read_text())
        furo_css.write_text(text.replace("@import url(/javascript/normalize.css/normalize.css);",
                                         "@import url(normalize.css);"))


def _check_every_python_name_is_documented(app, exception):
    """The Python reference lists every name of `ontime.__all__` (autodoc skips silently what it
    cannot document, e.g. a constant without a docstring)."""
    if exception is not None:
        return
    import ontime
    documented = set(app.env.get_domain("py").objects)
    missing = [name for name in ontime.__all__ if f"ontime.{name}" not in documented]
    if missing:
        from sphinx.errors import ExtensionError
        raise ExtensionError("names of ontime.__all__ missing from docs/api/python.md: " + ", ".join(missing))


def setup(app):
    app.connect("builder-inited", _write_cpp_pages)
    app.connect("source-read", _link_folders)
    app.connect("autodoc-process-docstring", _literal_blocks_in_docstrings)
    app.connect("build-finished", _bundle_normalize_css)
    app.connect("build-finished", _check_every_python_name_is_documented)
