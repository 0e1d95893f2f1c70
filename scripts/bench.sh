#!/usr/bin/env bash
# make bench: runs every Google Benchmark of tailor (load, topology, orientation, mapping, export,
# end to end, tiling, interactive edits (EditSession::apply against the full map); export_as/load_output:
# PLY and .glb with each --compress, sizes in MB) and
# prints one line per benchmark with its throughput counters.
# Without extra flags it then prints the tiling size table of docs/tiling.md (every shared texture
# at its size, 2048 and 4096 px: time, peak memory, the five targets; scripts/bench_tile_sizes.sh),
# the browser edit bench, and python3 -m tailor.tiles on 1 and 2 Dask workers (when Dask is installed).
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
  # python3 -m tailor.tiles on a 6.2 M-face mesh (the horse subdivided three times, written once into
  # the build folder): Dask's 1 and 2 workers against the same tiles mapped in one process, and
  # tailor map --chunks on (docs/scale.md, "Measured").
  python=$(sed -n 's/^Python_EXECUTABLE:FILEPATH=//p' "$build/CMakeCache.txt")
  if [[ -d $build/python/tailor ]] && "$python" -c 'import distributed' 2>/dev/null; then
    echo
    echo "bench: python3 -m tailor.tiles, 1 and 2 Dask workers (6.2 M faces; a few minutes)"
    mesh="$build/bench_horse_x64.ply"
    [[ -f $mesh ]] || PYTHONPATH="$build/python" "$python" "$(dirname "$0")/../bench/tiles_scale.py" mesh "$mesh"
    PYTHONPATH="$build/python" "$python" "$(dirname "$0")/../bench/tiles_scale.py" time "$mesh" "$build/tailor"
  fi
fi
