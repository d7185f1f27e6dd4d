#!/usr/bin/python3
"""Fails when a public function or class of OnTime's headers has no comment.

Reads Doxygen's XML (built from the headers through doxygen_filter.py) and lists every public
function, free or member, and every class whose documentation is empty. Exempt, because their
meaning is fixed by the language or by a documented declaration elsewhere:

- special members that are defaulted or deleted (`Session(Session&&) = default`);
- an override of a documented virtual function (Doxygen shows the base's comment, INHERIT_DOCS);
- a class in a header whose leading comment documents it: a header devoted to one class
  (`dp_rerun.hpp`: "`dp-rerun` (the paper's DP_Rerun, ...)") describes it there, and the site shows
  that comment at the top of the header's section.

Doxygen's own WARN_IF_UNDOCUMENTED is not used as the gate: it also asks for a comment on every
data member (`int seed`), which the headers document by their names and types.

Public functions that had no comment when this check was introduced are listed in
undocumented.txt; they are reported but do not fail the build. Anything else undocumented does,
so a new public function without its comment breaks `scripts/docs.sh`.

Usage: check_documented.py XML_DIR [--write-baseline]
"""

from __future__ import annotations

import pathlib
import sys
import xml.etree.ElementTree as ET

HERE = pathlib.Path(__file__).resolve().parent
BASELINE = HERE / "undocumented.txt"


def has_text(element: ET.Element | None) -> bool:
    return element is not None and "".join(element.itertext()).strip() != ""


def documented(member: ET.Element) -> bool:
    return has_text(member.find("briefdescription")) or has_text(member.find("detaileddescription"))


def main() -> int:
    xml_dir = pathlib.Path(sys.argv[1])
    write_baseline = "--write-baseline" in sys.argv[2:]
    members: dict[str, ET.Element] = {}
    files_documented: dict[str, bool] = {}
    compounds = []
    for path in sorted(xml_dir.glob("*.xml")):
        if path.name in ("index.xml", "Doxyfile.xml"):
            continue
        root = ET.parse(path).getroot()
        for compound in root.iter("compounddef"):
            compounds.append(compound)
            if compound.get("kind") == "file":
                location = compound.find("location").get("file")
                files_documented[location] = documented(compound)
            for member in compound.iter("memberdef"):
                members[member.get("id")] = member

    missing = []
    for compound in compounds:
        kind = compound.get("kind")
        name = compound.findtext("compoundname")
        if kind in ("class", "struct", "union") and compound.get("prot") == "public":
            location = compound.find("location").get("file")
            if not documented(compound) and not files_documented.get(location, False):
                missing.append(f"{kind} {name}")
        if kind not in ("class", "struct", "union", "namespace"):
            continue
        for member in compound.iter("memberdef"):
            if member.get("kind") != "function" or member.get("prot") != "public":
                continue
            args = (member.findtext("argsstring") or "").replace(" ", "")
            if args.endswith("=default") or args.endswith("=delete"):
                continue
            if documented(member):
                continue
            base = member.find("reimplements")
            if base is not None and base.get("refid") in members and documented(members[base.get("refid")]):
                continue
            scope = name if kind != "namespace" else name
            missing.append(f"function {scope}::{member.findtext('name')}{member.findtext('argsstring')}")

    missing = sorted(set(missing))
    if write_baseline:
        BASELINE.write_text(
            "# Public functions and classes without a comment in their header when the API reference\n"
            "# was introduced (docs/api/check_documented.py reports them; anything not listed here\n"
            "# fails the docs build). Remove a line once its declaration has its comment.\n"
            + "".join(line + "\n" for line in missing))
        print(f"check_documented: wrote {len(missing)} entries to {BASELINE}")
        return 0
    baseline = {line.strip() for line in BASELINE.read_text().splitlines()
                if line.strip() and not line.startswith("#")} if BASELINE.exists() else set()
    new = [item for item in missing if item not in baseline]
    known = [item for item in missing if item in baseline]
    fixed = sorted(baseline - set(missing))
    print(f"check_documented: {len(compounds)} compounds; {len(known)} known undocumented "
          f"(undocumented.txt), {len(new)} new")
    for item in new:
        print(f"check_documented: error: undocumented public {item}")
    for item in fixed:
        print(f"check_documented: note: '{item}' is documented or gone: remove it from undocumented.txt")
    return 1 if new else 0


if __name__ == "__main__":
    sys.exit(main())
