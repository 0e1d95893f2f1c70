#!/usr/bin/env bash
# The texturing tool's latency in the real browser (issue 19 point 3): `tailor edit` on a mesh, and
# headless Chromium (the project's Playwright + Debian's chromium, software WebGL: no GPU) paints
# brush strokes of seam faces with real mouse events; for each stroke it prints the time from the
# end of the stroke (pointer up) to the frame showing its result, with the parts of the last request
# (round trip, server update, UV fetch, page update, frame). Meshes: the shared 100k-face nefertiti
# and the 1.55 M face horse (horse.ply subdivided twice, as tailor_bench's horse_x16).
# Usage: scripts/bench_edit_browser.sh BUILD_DIR [STROKES]
set -euo pipefail
build=${1:-build}
strokes=${2:-5}
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
tailor="$(cd "$build" && pwd)/tailor"
[[ -x $tailor && -x $build/write_bench_mesh ]] || { echo "bench: build tailor and write_bench_mesh first" >&2; exit 1; }
[[ -x /usr/bin/chromium && -d $repo/web/node_modules/playwright-core ]] || { echo "bench: chromium or web/node_modules missing (make deps)" >&2; exit 1; }
tmp="$(mktemp -d)"
pid=""
cleanup() { [[ -n $pid ]] && kill "$pid" 2>/dev/null && wait "$pid" 2>/dev/null; rm -rf "$tmp"; }
trap cleanup EXIT
"$build/write_bench_mesh" "$tmp/horse_x16.ply"
meshes=("$repo/../shared/data/meshes/nefertiti.obj" "$tmp/horse_x16.ply")
for mesh in "${meshes[@]}"; do
  [[ -f $mesh ]] || { echo "bench: $mesh missing, skipped"; continue; }
  start=$(date +%s.%N)
  "$tailor" edit "$mesh" --texture "$repo/examples/gravel.png" -o "$tmp/out.glb" >"$tmp/edit.log" 2>&1 &
  pid=$!
  url=""
  for _ in $(seq 1 1200); do
    url="$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$tmp/edit.log" || true)"
    [[ -n $url ]] && break
    kill -0 "$pid" 2>/dev/null || { cat "$tmp/edit.log"; exit 1; }
    sleep 0.1
  done
  echo "bench: $(head -1 "$tmp/edit.log")"
  (cd "$repo" && timeout 1200 node web/test/edit_browser_test.mjs "$url" "$tailor" --bench "$strokes")
  kill -INT "$pid"; wait "$pid" || true; pid=""
  echo "bench: $(basename "$mesh") done in $(echo "$(date +%s.%N) - $start" | bc) s"
done
