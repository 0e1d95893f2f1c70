#!/usr/bin/env bash
# Fuzzes the mesh readers with libFuzzer under ASan + UBSan.
#
#   scripts/fuzz.sh short   # 10 s per reader (CI)
#   scripts/fuzz.sh long    # 120 s per reader
#
# Configures build-fuzz with clang (-DTAILOR_FUZZ=ON -DTAILOR_SANITIZE=ON), builds only the
# fuzz targets, seeds each from tests/data/meshes (copied to a temporary directory: nothing is
# written into the repository), and prints one line per target. Exits non-zero when a target
# crashes; the crashing input is kept in build-fuzz/artifacts/. Without clang or the libFuzzer
# runtime it prints "fuzz: skipped (clang/libFuzzer not installed)" and exits 0.
#
# Leak detection is on: a leak fails the target like a crash does. tests/lsan.supp lists the
# leaks of system libraries that are not ours (each with its reason).
set -euo pipefail

mode="${1:-short}"
case "$mode" in
  short) seconds=10 ;;
  long) seconds=120 ;;
  *) echo "usage: $0 short|long" >&2; exit 2 ;;
esac

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-fuzz"
jobs="${JOBS:-2}"
max_len=65536  # seeds are cut to this; larger inputs only slow the search down

skip() { echo "fuzz: skipped (clang/libFuzzer not installed)"; exit 0; }
command -v clang >/dev/null 2>&1 && command -v clang++ >/dev/null 2>&1 || skip

tmp="$(mktemp -d "${TMPDIR:-/tmp}/tailor-fuzz.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT

# The libFuzzer runtime ships separately from clang on some systems: probe it.
printf '#include <cstddef>\n#include <cstdint>\nextern "C" int LLVMFuzzerTestOneInput(const uint8_t*, size_t) { return 0; }\n' \
  > "$tmp/probe.cpp"
clang++ -fsanitize=fuzzer,address "$tmp/probe.cpp" -o "$tmp/probe" >/dev/null 2>&1 || skip

# Line tables only (-g1): a crash's stack names files and lines, for less build time than -g.
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" -DTAILOR_FUZZ=ON -DTAILOR_SANITIZE=ON -DTAILOR_BUILD_TESTS=OFF -DTAILOR_BUILD_BENCH=OFF >"$tmp/configure.log" 2>&1 ||
  { cat "$tmp/configure.log" >&2; echo "fuzz: configure failed" >&2; exit 1; }

targets=(ply_fuzz obj_fuzz off_fuzz stl_fuzz glb_fuzz)
cmake --build "$build" -j"$jobs" --target "${targets[@]}" >"$tmp/build.log" 2>&1 ||
  { tail -n 40 "$tmp/build.log" >&2; echo "fuzz: build failed" >&2; exit 1; }

# Any ASAN_OPTIONS/LSAN_OPTIONS of the caller are kept; ours come last and win.
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=1"
export LSAN_OPTIONS="${LSAN_OPTIONS:+$LSAN_OPTIONS:}suppressions=$root/tests/lsan.supp:print_suppressions=0"

mkdir -p "$build/artifacts"
status=0
for target in "${targets[@]}"; do
  ext="${target%_fuzz}"
  corpus="$tmp/corpus-$ext"
  mkdir -p "$corpus"
  # Seeds: every test mesh of this format, cut to max_len (a cut file is a fine seed too).
  while IFS= read -r -d '' f; do
    head -c "$max_len" "$f" >"$corpus/$(basename "$(dirname "$f")")-$(basename "$f")"
  done < <(find "$root/tests/data/meshes" -type f -iname "*.$ext" -print0)
  log="$tmp/$target.log"
  if "$build/$target" "$corpus" -max_total_time="$seconds" -max_len="$max_len" -timeout=10 \
      -rss_limit_mb=2048 -detect_leaks=1 -print_final_stats=1 -artifact_prefix="$build/artifacts/$target-" >"$log" 2>&1; then
    runs="$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)"
    echo "fuzz: $target ok (${runs:-?} inputs in ${seconds} s)"
  else
    status=1
    echo "fuzz: $target FAILED (artifacts in $build/artifacts/)"
    grep -E "ERROR|SUMMARY|Test unit written" "$log" | head -n 5 | sed 's/^/  /'
  fi
done
exit "$status"
