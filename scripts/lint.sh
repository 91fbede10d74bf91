#!/bin/sh
# The layering check (scripts/check-layering.py), clang-format check, clang-tidy and the size
# limits (scripts/check-sizes.py) on our C++ (needs a configured ./build for compile_commands.json).
# Exit status 1 if any reports anything.
set -eu
cd "$(dirname "$0")/.."
[ -f build/compile_commands.json ] || scripts/build.sh build
files=$(git ls-files 'cpp/*.cpp' 'cpp/*.hpp' 'tests/cpp/*.cpp' 'tests/cpp/*.hpp' 'bench/*.cpp' 'bench/*.hpp')
status=0
python3 scripts/check-layering.py || status=1
clang-format --dry-run --Werror $files || status=1
# shellcheck disable=SC2086
# Only diagnostics located in our files count (the analyser also walks into Eigen's headers).
clang-tidy -p build --quiet $(echo "$files" | grep '\.cpp$') 2>/dev/null |
  grep -E "^$(pwd)/(cpp|tests|bench)/.*(warning|error):" && status=1
# The size limits: no file under cpp/ over 900 lines, no function over 120.
python3 scripts/check-sizes.py || status=1
exit $status
