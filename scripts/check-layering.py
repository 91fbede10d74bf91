#!/usr/bin/env python3
"""Checks that no folder of cpp/ includes a folder later in the pipeline's order.

Data flows one way (docs/architecture.md): a stage may use the stages before it, never one
after it. Every `#include "x/..."` under cpp/ names the folder x it uses; an include of a
folder later in the order below than the including file's own folder is an error. Folders of
one rank may include each other. Exit status 1 naming each offending file and include, 0 when
there are none. Tests and benchmarks (tests/, bench/) may use anything and are not checked."""

import pathlib
import re
import sys

# The order, lowest first; folders on one line share a rank. cli and python are the top.
# element/ (shapes, bases, node sets, the element's map and measure) serves every stage.
# quality/ sits below optimise/ although the pipeline runs the optimiser first: the optimiser
# keeps and focuses its states by the certified quality (quality/bezier_jacobian.hpp), while
# quality measures any mesh without knowing what made it. boundary_layer/ (the macro layer grown
# on the linear mesh, blended and split on the curved one) shares curving/'s rank: elevation asks
# which cells are layer cells, and the split places its nodes on the CAD's curves as elevation does.
ORDER = [
    ["core"],
    ["element"],
    ["cad"],
    ["sizing"],
    ["linear"],
    ["curving", "boundary_layer"],
    ["quality"],
    ["optimise"],
    ["io"],
    ["pipeline"],
    ["cli", "python"],
]

RANK = {folder: rank for rank, folders in enumerate(ORDER) for folder in folders}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"/]+)/[^"]*"')


def violations(root):
    """(file, line number, include, why) for every include against the order."""
    found = []
    for path in sorted(root.rglob("*")):
        if path.suffix not in (".cpp", ".hpp", ".h") or not path.is_file():
            continue
        folder = path.relative_to(root).parts[0]
        if folder not in RANK:
            found.append((path, 0, "", "folder %r is not in the order" % folder))
            continue
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
            match = INCLUDE.match(line)
            if not match:
                continue
            used = match.group(1)
            if used not in RANK:
                found.append((path, number, line.strip(),
                              "folder %r is not in the order" % used))
            elif RANK[used] > RANK[folder]:
                found.append((path, number, line.strip(),
                              "%s/ sits below %s/" % (folder, used)))
    return found


def main():
    repo = pathlib.Path(__file__).resolve().parent.parent
    found = violations(repo / "cpp")
    for path, number, include, why in found:
        print("%s:%d: %s: %s" % (path.relative_to(repo), number, include, why))
    if found:
        print("%d include(s) against the layering order" % len(found), file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
