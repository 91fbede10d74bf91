#!/bin/sh
# Does what a new user does, in a fresh clone of the current commit in a temporary folder with
# no ../shared beside it: runs the README's two commands (scripts/setup.sh, then
# scripts/test.sh) and prints the closing counts. Run it before every stop (docs/testing.md).
#
# usage: scripts/test-fresh-clone.sh [--with-shared] [--load] [--rounds N] [--two-clones] [--keep]
#   --with-shared  put the shared folder (../shared of this checkout, or $HOMESH_SHARED_DIR)
#                  beside the clone, as CI does; without it the peer-file tests must be skipped
#   --load         run the test command while two busy processes load the machine
#   --rounds N     run the test command N times in a row in the clone (default 1)
#   --two-clones   make two clones and run the test command in both at the same time
#   --keep         keep the temporary folder (its path is printed)
# Only committed work is tested: uncommitted changes in this checkout are not in the clone.
set -eu
here=$(cd "$(dirname "$0")/.." && pwd)
with_shared=0 load=0 rounds=1 clones=1 keep=0
while [ $# -gt 0 ]; do
  case $1 in
    --with-shared) with_shared=1 ;;
    --load) load=1 ;;
    --rounds) rounds=${2:?--rounds needs a number}; shift ;;
    --two-clones) clones=2 ;;
    --keep) keep=1 ;;
    *) echo "test-fresh-clone: unknown argument '$1' (see the usage at the top of $0)" >&2
       exit 2 ;;
  esac
  shift
done
case $rounds in ''|*[!0-9]*|0) echo "test-fresh-clone: --rounds must be a positive integer" >&2
  exit 2 ;; esac

shared=${HOMESH_SHARED_DIR:-$here/../shared}
if [ "$with_shared" -eq 1 ] && [ ! -d "$shared/peer-cases" ]; then
  echo "test-fresh-clone: --with-shared: no peer-cases in $shared" >&2
  exit 2
fi
if [ -n "$(git -C "$here" status --porcelain --untracked-files=no)" ]; then
  echo "test-fresh-clone: note: uncommitted changes in $here are not tested"
fi
commit=$(git -C "$here" rev-parse HEAD)

top=$(mktemp -d /tmp/homesh-fresh-XXXXXX)
busy=""
cleanup() {
  for pid in $busy; do kill "$pid" 2>/dev/null || true; done
  if [ "$keep" -eq 0 ]; then rm -rf "$top"; else echo "test-fresh-clone: kept $top"; fi
}
trap cleanup EXIT INT TERM

# Each clone sits in a folder of its own, so that its ../shared is either the link made here or
# nothing. HOMESH_SHARED_DIR is unset for the runs: the clone finds the peer files only where a
# new user's clone would.
unset HOMESH_SHARED_DIR
for k in $(seq 1 "$clones"); do
  mkdir -p "$top/$k"
  git clone -q "$here" "$top/$k/homesh"
  git -C "$top/$k/homesh" checkout -q "$commit"
  [ "$with_shared" -eq 1 ] && ln -s "$(cd "$shared" && pwd)" "$top/$k/shared"
done
echo "test-fresh-clone: commit $(git -C "$here" log -1 --format='%h %s' | cut -c1-70)"
echo "test-fresh-clone: $clones clone(s) in $top, ../shared $([ "$with_shared" -eq 1 ] &&
  echo "beside them" || echo "absent"), load $([ "$load" -eq 1 ] && echo "two busy processes" ||
  echo "none"), $rounds round(s)"

# The README's first command, in each clone in turn (both install into /usr/local).
for k in $(seq 1 "$clones"); do
  start=$(date +%s)
  if ! (cd "$top/$k/homesh" && ./scripts/setup.sh) >"$top/$k/setup.log" 2>&1; then
    tail -n 30 "$top/$k/setup.log"
    echo "test-fresh-clone: clone $k: scripts/setup.sh FAILED (log: $top/$k/setup.log)"
    keep=1
    exit 1
  fi
  echo "test-fresh-clone: clone $k: scripts/setup.sh passed in $(( $(date +%s) - start )) s"
done

if [ "$load" -eq 1 ]; then
  for _ in 1 2; do
    sh -c 'while :; do :; done' &
    busy="$busy $!"
  done
fi

# Prints a run's closing lines: CTest's counts and time, the tests it skipped, and the Python
# tests pytest skipped inside passing entries (CTest's LastTest.log keeps every test's output).
summarise() {
  log=$1 clone=$2
  grep -E "tests passed|Total Test time" "$log" || echo "(no closing line: see $log)"
  grep -E "\(Skipped\)|\(Failed\)|\(Timeout\)|\(Not Run\)" "$log" | sed 's/^/  /' || true
  last=$clone/build/Testing/Temporary/LastTest.log
  if [ -f "$last" ]; then
    echo "  pytest skips: $(grep -cE '^SKIPPED \[' "$last" || true)"
    grep -E '^SKIPPED \[' "$last" | sed 's/^/    /' | head -n 20 || true
    reason=$(grep -m1 -oE "NekMesh's peer files are not here: [^(]*" "$last" || true)
    [ -n "$reason" ] && echo "  reason: $reason"
  fi
  return 0
}

status=0
for r in $(seq 1 "$rounds"); do
  pids=""
  for k in $(seq 1 "$clones"); do
    (cd "$top/$k/homesh" && ./scripts/test.sh) >"$top/$k/test-$r.log" 2>&1 &
    pids="$pids $!"
  done
  k=0
  for pid in $pids; do
    k=$((k + 1))
    if wait "$pid"; then result=passed; else result=FAILED; status=1; keep=1; fi
    echo "test-fresh-clone: round $r, clone $k: scripts/test.sh $result" \
      "(load average $(cut -d' ' -f1 /proc/loadavg))"
    summarise "$top/$k/test-$r.log" "$top/$k/homesh"
  done
done
exit "$status"
