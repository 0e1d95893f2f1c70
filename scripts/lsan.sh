#!/usr/bin/env bash
# The preview renderer under LeakSanitizer (make lsan): configures build-lsan with clang
# (-DTAILOR_SANITIZE=ON), builds render_test only, and runs it with leak detection on and the
# suppressions of tests/lsan.supp (leaks inside Mesa, each with its reason). Any other leak, or an
# ASan/UBSan report, fails the run (exit 1). Without clang it prints "lsan: skipped" and exits 0.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-lsan"
jobs="${JOBS:-2}"
command -v clang >/dev/null 2>&1 && command -v clang++ >/dev/null 2>&1 || { echo "lsan: skipped (clang not installed)"; exit 0; }

CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DTAILOR_SANITIZE=ON \
  -DTAILOR_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target render_test >/dev/null

export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=1"
export LSAN_OPTIONS="${LSAN_OPTIONS:+$LSAN_OPTIONS:}suppressions=$root/tests/lsan.supp:print_suppressions=0"
cd "$root"
"$build/render_test" --gtest_brief=1
echo "lsan: render_test has no leak"
