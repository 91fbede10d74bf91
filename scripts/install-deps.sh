#!/bin/sh
# Installs the Debian 12 packages HOMesh needs to build, run and test (idempotent: does nothing
# when all are present). Needs root, or sudo. occt-misc is OpenCASCADE's sample data: the CAD
# corpus benchmark and a repair-round test mesh its files. man-db: `man homesh`. python3-netgen:
# a test curves a mesh Netgen itself made (Debian's FreeCAD has no FEM Netgen mesher).
# cgns-convert: cgnscheck, the CGNS library's own checker, which tests run on written files.
set -eu

PACKAGES="
  g++ make cmake pkg-config
  freecad
  libocct-modeling-algorithms-dev libocct-data-exchange-dev libocct-foundation-dev libtbb-dev
  libeigen3-dev libgmsh-dev gmsh zlib1g-dev libcgns-dev cgns-convert
  libboost-python-dev libboost-numpy-dev python3-dev python3-numpy
  libgtest-dev python3-pytest python3-meshio python3-vtk9 python3-netgen
  xvfb xauth ccache man-db
  occt-misc
"

missing=""
for p in $PACKAGES; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
    missing="$missing $p"
done
[ -z "$missing" ] && exit 0

echo "homesh: installing Debian packages:$missing"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null 2>&1 || { echo "homesh: run as root (or install sudo)" >&2; exit 1; }
  SUDO=sudo
fi
$SUDO apt-get update -qq
# shellcheck disable=SC2086  # word splitting of the package list is intended
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
