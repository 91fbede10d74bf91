#!/bin/sh
# Runs one test command with TMPDIR set to a fresh folder of its own under ROOT, so that no test
# sees another's temporary files (ctest -j runs them side by side, and some tests check that
# they leave nothing behind). The folder is removed when the command passes and kept for
# inspection when it fails.
#
# usage: own_tmpdir.sh ROOT COMMAND [ARGS...]
set -eu
root=$1
shift
mkdir -p "$root"
dir=$(mktemp -d "$root/tmp.XXXXXXXX")
TMPDIR=$dir
export TMPDIR
status=0
"$@" || status=$?
[ "$status" -eq 0 ] && rm -rf "$dir"
exit "$status"
