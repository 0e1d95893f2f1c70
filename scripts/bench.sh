#!/usr/bin/env bash
# make bench: runs every Google Benchmark of tailor (load, topology, orientation, mapping, export,
# end to end, tiling, interactive edits (EditSession::apply against the full map); export_as/load_output:
# PLY and .glb with each --compress, sizes in MB) and
# prints one line per benchmark with its throughput counters.
# Without extra flags it then prints the tiling size table of docs/tiling.md (every shared texture
# at its size, 2048 and 4096 px: time, peak memory, the five targets; scripts/bench_tile_sizes.sh).
# Usage: scripts/bench.sh BUILD_DIR [extra Google Benchmark flags, e.g. --benchmark_filter=Load]
set -euo pipefail
build=${1:-build}
shift || true
bin="$build/tailor_bench"
[[ -x $bin ]] || { echo "bench: $bin not built (configure with -DTAILOR_BUILD_BENCH=ON)" >&2; exit 1; }
echo "bench: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
"$bin" --benchmark_counters_tabular=false "$@"
# The Python module's overhead over its C++ calls (1M faces), when the module is built.
if [[ -d $build/python/tailor ]]; then
  PYTHONPATH="$build/python" "$(sed -n 's/^Python_EXECUTABLE:FILEPATH=//p' "$build/CMakeCache.txt")" \
    "$(dirname "$0")/../bench/python_overhead.py" "$build"
fi
if (($# == 0)); then
  echo
  echo "bench: tiling sizes (tailor tile under /usr/bin/time -v)"
  bash "$(dirname "$0")/bench_tile_sizes.sh" "$build"
  echo
  echo "bench: tailor edit in the browser, end of a brush stroke to its frame (100k and 1.55M faces)"
  bash "$(dirname "$0")/bench_edit_browser.sh" "$build"
fi
