#!/bin/sh
# Builds the libFuzzer harnesses (Clang, AddressSanitizer, UndefinedBehaviorSanitizer) in
# build-fuzz/ and runs each for SECONDS (default 600) on the seeds in tests/data and
# ../shared/peer-cases. Findings land in build-fuzz/findings/TARGET/ (crash-*, leak-*, timeout-*);
# a finding fails the script. Not part of CI's default run.
#   scripts/fuzz.sh [SECONDS] [TARGET...]     TARGET: msh nektar mcf step unv vtk vtu (default:
#                                             all)
set -eu
cd "$(dirname "$0")/.."
seconds=${1:-600}
[ $# -gt 0 ] && shift
targets=${*:-msh nektar mcf step unv vtk vtu}
build=build-fuzz
if [ ! -f "$build/CMakeCache.txt" ]; then
  CXX=clang++ cmake -S . -B "$build" -DHOMESH_FUZZ=ON -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_COMPILER_LAUNCHER=ccache >/dev/null
fi
names=""
for t in $targets; do names="$names fuzz_$t"; done
# shellcheck disable=SC2086  # one word per target
cmake --build "$build" -j"$(nproc)" --target $names

shared=../shared/peer-cases
status=0
for t in $targets; do
  seeds="$build/seeds/$t"
  mkdir -p "$seeds" "$build/findings/$t" "$build/corpus-$t"
  case $t in
    msh) find tests/data "$shared" -name '*.msh' -size -2M -exec cp {} "$seeds" \; 2>/dev/null ;;
    nektar) find tests/data "$shared" -name '*.xml' -size -2M -exec cp {} "$seeds" \; 2>/dev/null ;;
    mcf) find tests/data "$shared" -name '*.mcf' -exec cp {} "$seeds" \; 2>/dev/null ;;
    unv | vtk | vtu) find tests/data -name "*.$t" -size -2M -exec cp {} "$seeds" \; 2>/dev/null ;;
    step) find tests/data "$shared" \( -name '*.step' -o -name '*.stp' \) -size -1M \
            -exec cp {} "$seeds" \; 2>/dev/null ;;
  esac
  echo "fuzz_$t: ${seconds} s"
  # -rss_limit_mb: the readers must refuse absurd sizes before allocating them. Leaks are not
  # checked in the STEP harness: OpenCASCADE's STEP reader keeps process-lifetime statics
  # (XSControl sessions, IFSelect editors) that LeakSanitizer reports at every exit.
  leaks=1
  [ "$t" = step ] && leaks=0
  if ! ASAN_OPTIONS="detect_leaks=$leaks" "$build/fuzz/fuzz_$t" -max_total_time="$seconds" \
      -rss_limit_mb=2048 -timeout=30 \
      -detect_leaks=$leaks \
      -max_len=65536 -artifact_prefix="$build/findings/$t/" -print_final_stats=1 \
      "$build/corpus-$t" "$seeds" 2>"$build/findings/$t.log"; then
    echo "fuzz_$t: FINDING, see $build/findings/$t/ and $build/findings/$t.log" >&2
    status=1
  fi
  tail -n 12 "$build/findings/$t.log" | grep -E "stat::|Done|ERROR" || true
done
exit $status
