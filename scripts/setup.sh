#!/bin/sh
# Quick start, step 1: installs the Debian packages, builds HOMesh, installs the `homesh`
# command (and the Python package) under /usr/local, registers the FreeCAD workbench for the
# current user, and meshes the bundled example, printing its report.
set -eu
cd "$(dirname "$0")/.."

scripts/install-deps.sh
scripts/build.sh build
cmake --install build --prefix /usr/local >/dev/null

# FreeCAD 0.20 loads user workbenches from ~/.local/share/FreeCAD/Mod.
mods="${HOME}/.local/share/FreeCAD/Mod"
mkdir -p "$mods"
ln -sfn /usr/local/share/homesh/Mod/HOMesh "$mods/HOMesh"
echo "homesh: workbench registered in $mods/HOMesh"

mkdir -p out
homesh mesh examples/bracket.step --order 4 --size 2.5 \
  -o out/bracket.msh -o out/bracket.vtu -o out/bracket.xml --report out/bracket.json
cat out/bracket.json
echo "homesh: wrote out/bracket.msh (Gmsh), out/bracket.vtu (ParaView), out/bracket.xml (Nektar++)"
