#!/bin/sh
# Quick start, step 2: runs the whole test suite (C++ unit tests, Python and command-line tests,
# headless FreeCAD tests and the GUI smoke test under Xvfb) in ./build.
set -eu
cd "$(dirname "$0")/.."

scripts/install-deps.sh
scripts/build.sh build
ctest --test-dir build --output-on-failure -j "$(nproc)"
