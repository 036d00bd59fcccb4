#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Builds the libFuzzer targets of tests/fuzz with clang (ASan + UBSan + libFuzzer) in build-fuzz, runs each
# on a copy of its seed corpus, one target at a time, and prints a table. Exits non-zero on any crash, leak,
# timeout or out-of-memory; what failed is kept under build-fuzz/fuzz-work/<target>/ (see docs/fuzzing.md).
#   scripts/fuzz.sh [--seconds N | --runs N] [--build-only | --no-build] [target...]
# Default: 30 seconds per target, every target. The on-demand long run is --runs 1000000.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build_dir=${RFBSIM_FUZZ_BUILD_DIR:-$root/build-fuzz}

limit=(-max_total_time=30)
build=1
run=1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) limit=(-max_total_time="${2:?--seconds needs a number}"); shift ;;
    --runs) limit=(-runs="${2:?--runs needs a number}"); shift ;;
    --build-only) run=0 ;;
    --no-build) build=0 ;;
    -h|--help) sed -n '3,7p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "fuzz.sh: unknown option '$1'" >&2; exit 2 ;;
    *) targets+=("$1") ;;
  esac
  shift
done

# Every target is a tests/fuzz/<name>_fuzz.cpp with its seeds in tests/fuzz/corpus/<name>/.
known=()
for source in tests/fuzz/*_fuzz.cpp; do
  name=$(basename "$source" _fuzz.cpp)
  known+=("$name")
done
[ ${#targets[@]} -eq 0 ] && targets=("${known[@]}")
for target in "${targets[@]}"; do
  if [[ ! " ${known[*]} " == *" $target "* ]]; then
    echo "fuzz.sh: no target '$target' (known: ${known[*]})" >&2
    exit 2
  fi
done

if [ "$build" = 1 ]; then
  command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang libclang-rt-14-dev)" >&2; exit 2; }
  # Everything compiled with coverage instrumentation (fuzzer-no-link) and ASan + UBSan (RFBSIM_SANITIZE,
  # whose UBSan findings abort); only the fuzz executables link libFuzzer itself.
  if [ ! -f "$build_dir/CMakeCache.txt" ]; then
    CC=clang CXX=clang++ cmake -S "$root" -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DRFBSIM_FUZZ=ON -DRFBSIM_SANITIZE=ON -DRFBSIM_BUILD_BENCH=OFF \
      -DBUILD_SHARED_LIBS=OFF -DCMAKE_C_FLAGS=-fsanitize=fuzzer-no-link -DCMAKE_CXX_FLAGS=-fsanitize=fuzzer-no-link
  fi
  cmake --build "$build_dir" --target "${targets[@]/#/fuzz_}"
fi
[ "$run" = 1 ] || exit 0
for target in "${targets[@]}"; do
  [ -x "$build_dir/tests/fuzz/fuzz_$target" ] || { echo "fuzz.sh: $build_dir has no fuzz_$target; build it first" >&2; exit 2; }
done

# A 16 MB quarantine instead of 256 MB: the loaders allocate and free a lot, and the bigger one spends
# most of its time faulting pages in (the scenario target runs 2x faster) for little extra use-after-free reach.
export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1:quarantine_size_mb=16:${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1:${UBSAN_OPTIONS:-}"

failed=0
rows=()
for target in "${targets[@]}"; do
  # A fresh copy of the seeds: what the fuzzer adds stays in build-fuzz, never in the source tree.
  work=$build_dir/fuzz-work/$target
  rm -rf "$work"
  mkdir -p "$work/corpus" "$work/artifacts"
  cp -r "tests/fuzz/corpus/$target/." "$work/corpus/"
  echo "fuzz.sh: $target ${limit[*]} (log: $work/log)" >&2
  start=$(date +%s)
  status=0
  "$build_dir/tests/fuzz/fuzz_$target" "$work/corpus" "${limit[@]}" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$work/artifacts/" >"$work/log" 2>&1 || status=$?
  seconds=$(( $(date +%s) - start ))
  runs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$work/log" | tail -1)
  speed=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$work/log" | tail -1)
  if [ "$status" = 0 ]; then
    result=ok
  else
    failed=1
    if grep -q "ERROR: libFuzzer: timeout" "$work/log"; then result=timeout
    elif grep -q "ERROR: LeakSanitizer" "$work/log"; then result=leak
    elif grep -q "ERROR: libFuzzer: out-of-memory" "$work/log"; then result=out-of-memory
    else result=crash
    fi
    artifact=$(sed -n 's/.*Test unit written to \(.*\)$/\1/p' "$work/log" | tail -1)
    result="$result (exit $status; input: ${artifact:-none}; log: $work/log)"
  fi
  rows+=("$(printf '%-20s %10s %10s %8s  %s' "$target" "${runs:-?}" "${speed:-?}" "$seconds" "$result")")
done

printf '%-20s %10s %10s %8s  %s\n' target runs exec/s seconds result
printf '%s\n' "${rows[@]}"
exit "$failed"
