#!/bin/sh
# Configures and builds HOMesh in ./build (Release). Usage: scripts/build.sh [BUILD_DIR]
# Uses ccache when it is installed (scripts/install-deps.sh installs it): a fresh clone on a
# machine that built HOMesh before then compiles only what changed.
set -eu
cd "$(dirname "$0")/.."
build=${1:-build}
launcher=""
if command -v ccache >/dev/null 2>&1; then
  # Paths relative to the source tree, so clones in other folders share the cache.
  export CCACHE_BASEDIR="$(pwd)" CCACHE_NOHASHDIR=1
  launcher="-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"
fi
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release $launcher >/dev/null
cmake --build "$build" -j "$(nproc)"
