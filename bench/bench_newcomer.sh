#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# bench_newcomer: a newcomer's minutes, measured as the README's two commands run on fresh clones (issue 29).
# For each git ref, in clones of this repository made for the purpose (nothing here is touched):
#   demo    scripts/run-demo.sh --port P on a fresh clone until it prints its link, then the link must answer
#           302; then a second run-demo.sh in the same clone, to its link again (no rebuild expected)
#   tests   scripts/test.sh on another fresh clone: its whole time, its ctest time and its test count
# and, with --labels, each ctest label run alone in the last ref's test clone (`ctest -L <label>`).
# The Debian packages must be installed already (scripts/setup.sh --with-browser); npm ci runs in each clone,
# from npm's cache after the first. Prints one table row per ref and run; run it on an idle machine.
#   bench/bench_newcomer.sh [--runs N] [--labels] [--work DIR] REF...
#   e.g. bench/bench_newcomer.sh --runs 1 6a30a27 HEAD
set -euo pipefail
repo="$(cd "$(dirname "$0")/.." && pwd)"
runs=1
labels=0
work="${TMPDIR:-/tmp}/rfbsim-bench-newcomer"
refs=()
while [ $# -gt 0 ]; do
  case "$1" in
    --runs) runs="$2"; shift ;;
    --labels) labels=1 ;;
    --work) work="$2"; shift ;;
    -*) echo "bench_newcomer: unknown option '$1'" >&2; exit 2 ;;
    *) refs+=("$(git -C "$repo" rev-parse --short "$1")") ;;
  esac
  shift
done
[ ${#refs[@]} -gt 0 ] || { echo "usage: bench/bench_newcomer.sh [--runs N] [--labels] [--work DIR] REF..." >&2; exit 2; }
mkdir -p "$work"

now() { date +%s.%N; }
elapsed() { echo "$(now) - $1" | bc; }

# A fresh clone of `ref` at `dir`.
fresh_clone() {
  rm -rf "$2"
  git clone -q "$repo" "$2"
  git -C "$2" checkout -q "$1"
}

# A free loopback port.
free_port() { python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'; }

# Runs run-demo.sh in `dir` on `port` until the link shows (at most 1800 s); prints the seconds to the link
# and whether the link answered 302, then stops the demo.
demo_to_link() {
  local dir="$1" port="$2" log="$3"
  local start; start=$(now)
  (cd "$dir" && exec scripts/run-demo.sh --port "$port" --data-dir "$dir/demo-data-$port") > "$log" 2>&1 &
  local pid=$!
  local link=""
  for _ in $(seq 1 18000); do
    link=$(grep -o "http://127.0.0.1:$port/start?[^ ]*" "$log" | head -1 || true)
    [ -n "$link" ] && break
    kill -0 "$pid" 2>/dev/null || break
    sleep 0.1
  done
  local secs; secs=$(elapsed "$start")
  local code="none"
  [ -n "$link" ] && code=$(curl -s -o /dev/null -w '%{http_code}' "$link" || true)
  kill "$pid" 2>/dev/null || true
  wait "$pid" 2>/dev/null || true
  printf '%.1f %s\n' "$secs" "$code"
}

printf '| ref | run | demo: clone to link, s | link answers | second start to link, s | test.sh, s | of it ctest, s | tests | failed | skipped |\n'
printf '| --- | --: | --: | --- | --: | --: | --: | --: | --: | --: |\n'
for run in $(seq 1 "$runs"); do
  for ref in "${refs[@]}"; do
    demo_dir="$work/demo-$ref"
    fresh_clone "$ref" "$demo_dir"
    read -r first code < <(demo_to_link "$demo_dir" "$(free_port)" "$work/demo-$ref-$run.log")
    read -r second code2 < <(demo_to_link "$demo_dir" "$(free_port)" "$work/demo-$ref-$run-again.log")

    test_dir="$work/tests-$ref"
    fresh_clone "$ref" "$test_dir"
    start=$(now)
    status=0
    (cd "$test_dir" && scripts/test.sh) > "$work/tests-$ref-$run.log" 2>&1 || status=$?
    total=$(elapsed "$start")
    ctest_s=$(sed -n 's/^Total Test time (real) = *\([0-9.]*\) sec$/\1/p' "$work/tests-$ref-$run.log" | tail -1)
    count=$(sed -n 's/.*tests failed out of \([0-9]*\)$/\1/p' "$work/tests-$ref-$run.log" | tail -1)
    failed=$(sed -n 's/.*, \([0-9]*\) tests failed out of.*/\1/p' "$work/tests-$ref-$run.log" | tail -1)
    skipped=$(grep -c '(Skipped)$' "$work/tests-$ref-$run.log" || true)
    printf '| %s | %d | %s | %s, then %s | %s | %.1f | %s | %s | %s | %s |\n' "$ref" "$run" "$first" "$code" "$code2" \
      "$second" "$total" "${ctest_s:-?}" "${count:-?}" "${failed:-?}" "$skipped"
    [ "$status" -eq 0 ] || echo "(test.sh exited $status: $work/tests-$ref-$run.log)"
  done
done

if [ "$labels" = 1 ]; then
  ref="${refs[-1]}"
  build="$work/tests-$ref/build"
  printf '\n| label (%s, run alone) | tests | ctest, s |\n| --- | --: | --: |\n' "$ref"
  jobs=$((8 * $(nproc)))
  for label in $(cd "$build" && ctest --print-labels | sed -n 's/^  //p'); do
    [ "$label" = flood ] && continue
    out=$(cd "$build" && RFBSIM_NO_SKIP=1 ctest -L "^$label\$" -LE flood -j "$jobs" --timeout 300 2>&1 || true)
    secs=$(echo "$out" | sed -n 's/^Total Test time (real) = *\([0-9.]*\) sec$/\1/p')
    n=$(echo "$out" | sed -n 's/.*tests failed out of \([0-9]*\)$/\1/p')
    printf '| %s | %s | %s |\n' "$label" "${n:-?}" "${secs:-?}"
  done
fi
