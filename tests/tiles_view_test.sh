#!/usr/bin/env bash
# End-to-end test of a tileset in the viewer, run by ctest from the repo root as
#   bash tests/tiles_view_test.sh <tailor-binary>
# 1. `python3 -m tailor.tiles` (the Python module built beside the binary) maps the horse as tiles
#    with levels of detail (no Dask: --workers 0); every tile passes the glTF validator;
# 2. `tailor view OUTDIR/tileset.json` serves the tileset's folder; a file that is not a tileset
#    gives one error line and exit 1;
# 3. headless Chromium with 3d-tiles-renderer loads every leaf tile, shows the textured horse, and
#    loads only part of the tiles for a view of the whole model (web/test/tileset_browser_test.mjs).
# Never skips: a missing Chromium, node_modules or Python module is a failure.
set -euo pipefail

tailor="${1:?usage: bash tests/tiles_view_test.sh <tailor-binary>}"
tailor="$(cd "$(dirname "$tailor")" && pwd)/$(basename "$tailor")"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"

fail() { echo "FAIL: $*" >&2; exit 1; }

[ -x /usr/bin/chromium ] || fail "/usr/bin/chromium is missing (apt-get install chromium)"
command -v node >/dev/null || fail "node is missing"
for pkg in three playwright-core 3d-tiles-renderer; do
  [ -d "web/node_modules/$pkg" ] || fail "web/node_modules/$pkg is missing (run 'npm install' in web/)"
done
python_dir="$(dirname "$tailor")/python"
[ -d "$python_dir/tailor" ] || fail "the Python module is not built beside $tailor"

tmp="$(mktemp -d)"
server_pid=""
cleanup() {
  if [ -n "$server_pid" ]; then kill "$server_pid" 2>/dev/null || true; wait "$server_pid" 2>/dev/null || true; fi
  rm -rf "$tmp"
}
trap cleanup EXIT

# Starts `tailor view INPUT` (its log in LOG) and sets server_pid and url once it prints its URL.
start_view() {
  "$tailor" view "$1" >"$2" 2>&1 &
  server_pid=$!
  url=""
  for _ in $(seq 1 100); do
    url="$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$2" || true)"
    [ -n "$url" ] && return
    kill -0 "$server_pid" 2>/dev/null || fail "tailor view $1 exited early: $(cat "$2")"
    sleep 0.1
  done
  fail "tailor view $1 printed no URL within 10 s"
}

# --- 1. the tiles ----------------------------------------------------------------------------------
PYTHONPATH="$python_dir" timeout 120 /usr/bin/python3 -m tailor.tiles tests/data/meshes/horse.ply -o "$tmp/horse_tiles" \
  --chunk-cell -4 --texture examples/gravel.png --workers 0 -q || fail "python3 -m tailor.tiles failed"
[ -s "$tmp/horse_tiles/tileset.json" ] || fail "no tileset.json"
# Every tile, leaves and parents, passes the Khronos glTF validator without a warning (the shared
# texture read beside them).
timeout 120 node tests/tools/validate_gltf.mjs --strict --allow-external "$tmp"/horse_tiles/tiles/*.glb >"$tmp/validate.log" \
  || fail "glTF validator: $(grep -v 'errors 0 warnings 0' "$tmp/validate.log" | head -5)"

# --- 2. tailor view: not a tileset -----------------------------------------------------------------
echo '{"name": "not a tileset"}' >"$tmp/other.json"
set +e
err="$("$tailor" view "$tmp/other.json" 2>&1 >/dev/null)"; rc=$?
set -e
[ "$rc" -eq 1 ] || fail "tailor view of a JSON that is not a tileset exited $rc"
[ "$(printf '%s\n' "$err" | wc -l)" -eq 1 ] || fail "more than one error line: $err"
case "$err" in *"not a 3D Tiles tileset"*) ;; *) fail "unexpected error: $err" ;; esac

# --- 3. the browser --------------------------------------------------------------------------------
start_view "$tmp/horse_tiles/tileset.json" "$tmp/view.log"
curl -sf "${url}tileset/tileset.json" >/dev/null || fail "the tileset is not served at ${url}tileset/tileset.json"
curl -sf "${url}tileset/tiles/texture.png" >/dev/null || fail "the shared texture is not served"
timeout 240 node web/test/tileset_browser_test.mjs "$url" "$tmp/horse_tiles/tileset.json" \
  ${TAILOR_SCREENSHOT:+--screenshot "$TAILOR_SCREENSHOT"} || fail "the tileset browser test failed"
kill "$server_pid" 2>/dev/null || true
wait "$server_pid" 2>/dev/null || true

# --- 4. one tile alone: the texture it names beside it is served where the page asks for it -------
leaf="$(ls "$tmp"/horse_tiles/tiles/0_*.glb | head -1)"
start_view "$leaf" "$tmp/view1.log"
cmp <(curl -sf "${url}files/texture.png") "$tmp/horse_tiles/tiles/texture.png" ||
  fail "one tile's texture is not served at ${url}files/texture.png"
status="$(curl -s -o /dev/null -w '%{http_code}' "${url}files/tileset.json")"
[ "$status" = 404 ] || fail "a file the tile does not name was served ($status)"
echo "tiles view test: ok"
