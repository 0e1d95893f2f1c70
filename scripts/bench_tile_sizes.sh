#!/usr/bin/env bash
# The tiling size benchmark (docs/tiling.md, "Sizes"): every shared texture at its own size and
# resampled (bicubic) to 2048 and 4096 px, tiled by `tailor tile IMG -o OUT --json J` (metrics
# included, as a user runs it) under /usr/bin/time -v. Prints one Markdown table row per run:
# wall time, peak resident memory and the five targets (tile / exemplar where both apply).
# Usage: scripts/bench_tile_sizes.sh BUILD_DIR [SIZES...]   (sizes default: own 2048 4096)
set -euo pipefail
build=${1:-build}
shift || true
sizes=("$@")
((${#sizes[@]})) || sizes=(own 2048 4096)
here=$(cd "$(dirname "$0")/.." && pwd)
textures="$here/../shared/data/textures"
tailor="$build/tailor"
upsample="$build/upsample_texture"
for tool in "$tailor" "$upsample"; do
  [[ -x $tool ]] || { echo "bench_tile_sizes: $tool not built (make build, TAILOR_BUILD_BENCH=ON)" >&2; exit 1; }
done
[[ -x /usr/bin/time ]] || { echo "bench_tile_sizes: /usr/bin/time (Debian package time) is needed" >&2; exit 1; }
[[ -d $textures ]] || { echo "bench_tile_sizes: no shared textures in $textures; skipped" >&2; exit 0; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
echo "| texture | size | time (s) | peak memory (MB) | wrap x / y | worst seam (exemplar) | hist L1 | gradient ratio | coherence (exemplar) | targets |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for src in "$textures"/*.png "$textures"/*.jpg; do
  name=$(basename "$src")
  for size in "${sizes[@]}"; do
    input=$src
    if [[ $size != own ]]; then
      input="$tmp/in.png"
      "$upsample" "$src" "$size" "$input"
    fi
    /usr/bin/time -v "$tailor" tile "$input" -o "$tmp/out.png" --json "$tmp/out.json" -q --allow-misses 2>"$tmp/time.txt"
    wall=$(grep 'Elapsed (wall clock)' "$tmp/time.txt" | awk '{print $NF}' |
      awk -F: '{ if (NF == 3) print $1 * 3600 + $2 * 60 + $3; else print $1 * 60 + $2 }')
    rss=$(grep 'Maximum resident set size' "$tmp/time.txt" | awk '{printf "%.0f", $NF / 1024}')
    python3 - "$tmp/out.json" "$name" "$size" "$wall" "$rss" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
t = j["tiles"][0]
met = "met" if t["targets_met"] else "NOT met"
size = f'{j["width"]}x{j["height"]}'
print(f'| {sys.argv[2]} | {size} | {float(sys.argv[4]):.2f} | {sys.argv[5]} | '
      f'{t["wrap_ratio_x"]:.2f} / {t["wrap_ratio_y"]:.2f} | {t["worst_seam_ratio"]:.2f} ({t["exemplar_worst_seam_ratio"]:.2f}) | '
      f'{t["histogram_l1"]:.3f} | {t["gradient_ratio"]:.3f} | '
      f'{t["patch_coherence"]:.4f} ({t["exemplar_patch_coherence"]:.4f}) | {met} |')
PY
  done
done
