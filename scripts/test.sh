#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-2.0-or-later
# Sets everything up, builds, and runs every test through ctest (unit, integration, robustness, install,
# browser). With --sanitize, does the same in build-asan with AddressSanitizer and UBSan.
set -euo pipefail
cd "$(dirname "$0")/.."
build_dir=build
extra=()
if [ "${1:-}" = "--sanitize" ]; then
  build_dir=build-asan
  extra=(-DRFBSIM_SANITIZE=ON -DCMAKE_BUILD_TYPE=Debug -DRFBSIM_BUILD_BENCH=OFF)
  export ASAN_OPTIONS="detect_leaks=1:abort_on_error=1"
  export LSAN_OPTIONS="suppressions=$PWD/tests/sanitizers/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1"
fi
scripts/setup.sh --with-browser --build-dir "$build_dir" "${extra[@]}"
cd "$build_dir"
# Floods of thousands of connections (label flood) run on demand: `ctest -L flood` (docs/security.md).
ctest --output-on-failure --timeout 300 -j 2 -LE flood
