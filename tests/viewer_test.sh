#!/usr/bin/env bash
# End-to-end test of `tailor view` and `tailor render`, run by ctest from the repo root as
#   bash tests/viewer_test.sh <tailor-binary>
# 0. unit-tests the viewer's mesh analysis (web/mesh_data.js) in node, with the seam figures of a
#    mapped horse against `tailor eval --json`;
# 1. makes a .glb with `tailor map` from the bundled example;
# 2. `tailor render`: every view writes a PNG, bad input gives one error line and exit 1;
# 3. `tailor view`: serves on 127.0.0.1, answers GET, refuses path traversal and POST, a foreign
#    Host header (tests/viewer_hardening.py), sends a CSP, survives 200 idle sockets;
# 4. a real browser (headless Chromium + playwright-core) opens the viewer, waits for the first
#    frame, checks for console errors, a non-blank canvas, that the views change the picture, red
#    seam lines in the seams view and the viewer's seam figures against `tailor eval --json`;
# 5. a stalled client holds up neither other requests nor Ctrl-C;
# 6. Ctrl-C (SIGINT) stops the server with exit status 0;
# 7. the browser test with tile variants from `tailor tile --variants 3`;
# 8. the seams view of a mapped horse (128 px texture): red and green seam lines, eval's figures;
# 9. `tailor map --compress meshopt` and `draco` outputs load in the browser (eval's figures too);
# 10. a `tailor map --material` output: its normal map and tangents change the texture view.
# 11. the output of a glTF scene (two meshes: a node each, Draco per primitive) loads too.
# Never skips: a missing Chromium or node_modules is a failure.
set -euo pipefail

tailor="${1:?usage: bash tests/viewer_test.sh <tailor-binary>}"
tailor="$(cd "$(dirname "$tailor")" && pwd)/$(basename "$tailor")"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"

fail() { echo "FAIL: $*" >&2; exit 1; }

[ -x /usr/bin/chromium ] || fail "/usr/bin/chromium is missing (apt-get install chromium)"
command -v node >/dev/null || fail "node is missing"
for pkg in three playwright-core; do
  [ -d "web/node_modules/$pkg" ] || fail "web/node_modules/$pkg is missing (run 'npm install' in web/)"
done

timeout 60 node web/test/mesh_data_test.mjs "$tailor" || fail "web/mesh_data.js unit test failed"

tmp="$(mktemp -d)"
server_pid=""
stop_server() {
  if [ -n "$server_pid" ]; then
    kill "$server_pid" 2>/dev/null || true
    wait "$server_pid" 2>/dev/null || true
    server_pid=""
  fi
}
cleanup() { stop_server; rm -rf "$tmp"; }
trap cleanup EXIT

# --- 1. a textured .glb from the bundled example -------------------------------------------------
timeout 60 "$tailor" map examples/spot.obj --texture examples/gravel.png -o "$tmp/spot.glb" -q \
  || fail "tailor map could not make the test .glb"
[ -s "$tmp/spot.glb" ] || fail "tailor map wrote no .glb"

# --- 2. tailor render ------------------------------------------------------------------------------
for view in texture patches distortion checker; do
  out="$(timeout 60 "$tailor" render "$tmp/spot.glb" -o "$tmp/spot_$view.png" --view "$view" --size 320x240)" \
    || fail "tailor render --view $view failed"
  [ -s "$tmp/spot_$view.png" ] || fail "tailor render --view $view wrote nothing"
  case "$out" in *"$tmp/spot_$view.png"*" s"*) ;; *) fail "tailor render did not print its output and time: $out" ;; esac
done
printf 'not a glb' > "$tmp/bad.glb"
set +e
err="$("$tailor" render "$tmp/bad.glb" -o "$tmp/bad.png" 2>&1 >/dev/null)"; rc=$?
set -e
[ "$rc" -eq 1 ] || fail "tailor render on a bad .glb exited $rc, expected 1"
[ "$(printf '%s\n' "$err" | wc -l)" -eq 1 ] || fail "tailor render on a bad .glb printed more than one line: $err"
case "$err" in "tailor: error: "*) ;; *) fail "unexpected error line: $err" ;; esac
[ ! -e "$tmp/bad.png" ] || fail "tailor render wrote a picture for a bad .glb"

# --- 3. tailor view: bad input, then a running server ----------------------------------------------
set +e
err="$("$tailor" view "$tmp/bad.glb" 2>&1 >/dev/null)"; rc=$?
set -e
[ "$rc" -eq 1 ] || fail "tailor view on a bad .glb exited $rc, expected 1"
case "$err" in "tailor: error: "*) ;; *) fail "unexpected error line from view: $err" ;; esac

# Starts `tailor view ARGS...` in the background and sets $url once it printed its address.
start_server() {
  # The log is emptied here, not by the background redirection: that one runs in the child, so the
  # first grep below could still read the previous server's address.
  : >"$tmp/view.log"
  "$tailor" view "$@" >>"$tmp/view.log" 2>&1 &
  server_pid=$!
  url=""
  for _ in $(seq 1 100); do
    url="$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$tmp/view.log" || true)"
    [ -n "$url" ] && return 0
    kill -0 "$server_pid" 2>/dev/null || fail "tailor view exited early: $(cat "$tmp/view.log")"
    sleep 0.1
  done
  fail "tailor view printed no URL within 10 s"
}

status_of() { curl -s -o /dev/null -w '%{http_code}' --max-time 10 "$@"; }

start_server "$tmp/spot.glb"
echo "viewer at $url"
[ "$(status_of "$url")" = 200 ] || fail "GET / is not 200"
[ "$(status_of "${url}config.json")" = 200 ] || fail "GET /config.json is not 200"
[ "$(status_of "${url}node_modules/three/build/three.module.js")" = 200 ] || fail "three.js is not served"
size="$(curl -s --max-time 10 "${url}files/model.glb" | wc -c)"
[ "$size" -eq "$(wc -c <"$tmp/spot.glb")" ] || fail "the served model has $size bytes, not the file's"
[ "$(status_of --path-as-is "${url}../CMakeLists.txt")" = 403 ] || fail "path traversal with .. was not refused"
[ "$(status_of "${url}%2e%2e/CMakeLists.txt")" = 403 ] || fail "path traversal with %2e%2e was not refused"
[ "$(status_of "${url}nothing-here.js")" = 404 ] || fail "a missing file is not 404"
[ "$(status_of -X POST "${url}")" = 405 ] || fail "POST is not refused"
# Host check (DNS rebinding), the CSP header, and 200 idle sockets not locking a real request out.
timeout 30 python3 tests/viewer_hardening.py "$(echo "$url" | sed 's|.*:\([0-9]*\)/$|\1|')" web/index.html \
  || fail "viewer hardening checks failed"

# --- 4. the browser ---------------------------------------------------------------------------------
timeout 60 "$tailor" eval "$tmp/spot.glb" --json -q >"$tmp/spot_eval.json" || fail "tailor eval of the test .glb failed"
timeout 120 node web/test/viewer_browser_test.mjs "$url" --eval "$tmp/spot_eval.json" || fail "browser test failed"

# --- 5. a client that never finishes its request holds up neither others nor Ctrl-C -----------------
port="${url#http://127.0.0.1:}"; port="${port%/}"
exec 3<>"/dev/tcp/127.0.0.1/$port"
printf 'GET / HTTP/1.1\r\nHost: x' >&3
[ "$(curl -s -o /dev/null -w '%{http_code}' --max-time 2 "$url")" = 200 ] || fail "a stalled client blocked other requests"

# --- 6. Ctrl-C stops the server cleanly and promptly, the stalled client still connected ---------------
kill -INT "$server_pid"
set +e
timeout 3 tail --pid="$server_pid" -f /dev/null || fail "tailor view took more than 3 s to stop after SIGINT"
exec 3<&-
wait "$server_pid"; rc=$?
set -e
server_pid=""
[ "$rc" -eq 0 ] || fail "tailor view exited $rc after SIGINT, expected 0"

# --- 7. tile variants (a small exemplar keeps `tailor tile` fast) ------------------------------------
timeout 60 "$tailor" tile tests/data/textures/vistex-tile04-128.png --variants 3 -o "$tmp/tile.png" -q --allow-misses \
  || fail "tailor tile --variants 3 failed"
[ -s "$tmp/tile.json" ] || fail "tailor tile wrote no variants .json"
start_server "$tmp/spot.glb" --texture "$tmp/tile.json"
timeout 120 node web/test/viewer_browser_test.mjs "$url" --variants || fail "browser test with tile variants failed"
stop_server

# --- 8. the seams view on a mesh with invisible seams too (the horse: ~3% of its seam length) ------
timeout 60 "$tailor" map tests/data/meshes/horse.ply --texture tests/data/textures/vistex-tile04-128.png -o "$tmp/horse.glb" -q \
  || fail "tailor map could not make the horse .glb"
timeout 60 "$tailor" eval "$tmp/horse.glb" --json -q >"$tmp/horse_eval.json" || fail "tailor eval of the horse .glb failed"
start_server "$tmp/horse.glb"
timeout 120 node web/test/viewer_browser_test.mjs "$url" --eval "$tmp/horse_eval.json" --expect-invisible \
  || fail "browser test of the seams view (horse) failed"
stop_server

# --- 8b. a 4-fold map (tailor map --symmetry 4): its .glb says so, and the viewer counts quarter-turn
# seams as invisible as eval does (its figures against eval's, which reads the same record) ---------
timeout 60 "$tailor" tile tests/data/textures/vistex-tile04-128.png --symmetry 4 -o "$tmp/tile4.png" -q --allow-misses \
  || fail "tailor tile --symmetry 4 failed"
timeout 60 "$tailor" map examples/spot.obj --texture "$tmp/tile4.png" --symmetry 4 -o "$tmp/spot4.glb" -q \
  || fail "tailor map --symmetry 4 failed"
timeout 60 "$tailor" eval "$tmp/spot4.glb" --json -q >"$tmp/spot4_eval.json" || fail "tailor eval of the 4-fold .glb failed"
grep -q '"symmetry": 4' "$tmp/spot4_eval.json" || fail "eval did not read the 4-fold map's record"
start_server "$tmp/spot4.glb"
timeout 120 node web/test/viewer_browser_test.mjs "$url" --eval "$tmp/spot4_eval.json" --expect-invisible \
  || fail "browser test of the seams view (4-fold map) failed"
stop_server

# --- 9. compressed outputs (three.js's meshopt and Draco decoders, WebAssembly under the CSP) -------
for method in meshopt draco; do
  timeout 60 "$tailor" map examples/spot.obj --texture examples/gravel.png --compress "$method" \
    -o "$tmp/spot_$method.glb" -q || fail "tailor map --compress $method failed"
  timeout 60 "$tailor" eval "$tmp/spot_$method.glb" --json -q >"$tmp/spot_${method}_eval.json" \
    || fail "tailor eval of the $method .glb failed"
  start_server "$tmp/spot_$method.glb"
  timeout 120 node web/test/viewer_browser_test.mjs "$url" --eval "$tmp/spot_${method}_eval.json" \
    || fail "browser test of the --compress $method .glb failed"
  stop_server
done

# --- 10. a PBR material: colour + normal map (tangents in the file) -----------------------------
mkdir -p "$tmp/material"
cp tests/data/textures/vistex-bark11-128.png "$tmp/material/bark_color.png"
cp tests/data/textures/vistex-fabric02-128.png "$tmp/material/bark_normal.png"  # any RGB bumps do
timeout 60 "$tailor" map examples/spot.obj --material "$tmp/material" -o "$tmp/spot_material.glb" -q \
  || fail "tailor map --material failed"
start_server "$tmp/spot_material.glb"
timeout 120 node web/test/viewer_browser_test.mjs "$url" --normal-map || fail "browser test of the material .glb failed"
stop_server

# --- 11. a glTF scene (two meshes merged by glTF-Transform): one node per mesh, primitives per
#          material, each its own Draco stream (issue 18: names and materials kept) ----------------
gltf_transform=web/node_modules/.bin/gltf-transform
if [ -x "$gltf_transform" ]; then
  timeout 120 "$gltf_transform" merge "$tmp/spot.glb" "$tmp/horse.glb" "$tmp/scene.glb" --merge-scenes >/dev/null 2>&1 \
    || fail "gltf-transform merge failed"
  timeout 60 "$tailor" map "$tmp/scene.glb" --texture examples/gravel.png --compress draco -o "$tmp/scene_out.glb" -q \
    || fail "tailor map of a merged scene failed"
  timeout 60 "$tailor" eval "$tmp/scene_out.glb" --json -q >"$tmp/scene_eval.json" || fail "tailor eval of the scene failed"
  start_server "$tmp/scene_out.glb"
  timeout 120 node web/test/viewer_browser_test.mjs "$url" --eval "$tmp/scene_eval.json" \
    || fail "browser test of the scene .glb failed"
  stop_server
fi

echo "PASS: tailor render and tailor view (browser) work"
