#!/usr/bin/env bash
# End-to-end test of `tailor edit` (the texturing tool) and its HTTP API (docs/edit-api.md), run by
# ctest from the repo root as
#   bash tests/edit_test.sh <tailor-binary>
# 1. bad input and options: one error line, exit 1 or 2, nothing written;
# 2. the API with curl on the bundled example: an edit answers {version, changed_faces, ms, settled}
#    and changes the UVs; undo gives the previous version's UVs bit for bit, redo the edit's; a
#    malformed request (bad JSON, unknown key, face out of range, bad stroke, bad option) gets 400
#    with one line and changes nothing; save writes the .glb, seam faces and strokes, and the
#    `tailor map` command it prints gives the same bytes, as does GET /api/model.glb;
# 3. the server's hardening for POST: Content-Type, cross-site Origin, foreign Host, body size;
# 4. the page in headless Chromium (web/test/edit_browser_test.mjs): paint, patches change, undo,
#    save and replay;
# 5. Ctrl-C stops it with exit status 0;
# 6. a session cut into chunks (--chunks on): an edit, the settle, save and replay agree.
# Never skips: a missing Chromium or node_modules is a failure.
set -euo pipefail

tailor="${1:?usage: bash tests/edit_test.sh <tailor-binary>}"
tailor="$(cd "$(dirname "$tailor")" && pwd)/$(basename "$tailor")"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"

fail() { echo "FAIL: $*" >&2; exit 1; }

[ -x /usr/bin/chromium ] || fail "/usr/bin/chromium is missing (apt-get install chromium)"
command -v node >/dev/null || fail "node is missing"
command -v curl >/dev/null || fail "curl is missing"
for pkg in three playwright-core; do
  [ -d "web/node_modules/$pkg" ] || fail "web/node_modules/$pkg is missing (run 'npm install' in web/)"
done

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

# --- 1. bad input ------------------------------------------------------------------------------------
expect_error() {  # expected exit code, then the command
  local want="$1"; shift
  set +e
  err="$("$@" 2>&1 >/dev/null)"; rc=$?
  set -e
  [ "$rc" -eq "$want" ] || fail "'$*' exited $rc, expected $want: $err"
  [ "$(printf '%s\n' "$err" | wc -l)" -eq 1 ] || fail "'$*' printed more than one line: $err"
  case "$err" in "tailor: error: "*) ;; *) fail "unexpected error line: $err" ;; esac
}
printf 'not a mesh' > "$tmp/bad.obj"
expect_error 1 "$tailor" edit "$tmp/bad.obj" -o "$tmp/bad.glb"
expect_error 2 "$tailor" edit examples/spot.obj -o "$tmp/bad.ply"
expect_error 2 "$tailor" edit examples/spot.obj -o "$tmp/no/such/dir/x.glb"
expect_error 2 "$tailor" edit examples/spot.obj -o examples/spot.obj
[ ! -e "$tmp/bad.glb" ] || fail "a refused tailor edit wrote a file"

# --- 2. the API -------------------------------------------------------------------------------------
start_server() {
  # The log is emptied here, not by the background redirection: that one runs in the child, so the
  # first grep below could still read the previous server's address.
  : >"$tmp/edit.log"
  "$tailor" edit "$@" >>"$tmp/edit.log" 2>&1 &
  server_pid=$!
  url=""
  for _ in $(seq 1 300); do
    url="$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$tmp/edit.log" || true)"
    [ -n "$url" ] && return 0
    kill -0 "$server_pid" 2>/dev/null || fail "tailor edit exited early: $(cat "$tmp/edit.log")"
    sleep 0.1
  done
  fail "tailor edit printed no URL within 30 s"
}
json_field() { python3 -c "import json,sys; print(json.load(sys.stdin)[sys.argv[1]])" "$1"; }
post() {  # path, JSON body -> the answer; the status code in $tmp/code
  curl -s --max-time 120 -o "$tmp/answer" -w '%{http_code}' -H 'Content-Type: application/json' \
    --data-binary "$2" "${url}api/$1" >"$tmp/code"
  cat "$tmp/answer"
}
code() { cat "$tmp/code"; }
uvs() { curl -s --max-time 30 -o "$2" -w '%{http_code}' "${url}api/uv?version=$1"; }
wait_settled() {
  for _ in $(seq 1 600); do
    [ "$(curl -s --max-time 10 "${url}api/status" | json_field settled)" = True ] && return 0
    sleep 0.1
  done
  fail "the session did not settle within 60 s"
}

mkdir -p "$tmp/out"
start_server examples/spot.obj --texture examples/gravel.png -o "$tmp/out/spot.glb"
echo "tailor edit at $url"
[ "$(curl -s -o /dev/null -w '%{http_code}' "$url")" = 200 ] || fail "GET / is not 200"
curl -s "$url" | grep -q 'edit.js' || fail "GET / is not the editing page"
v0="$(curl -s "${url}api/status" | json_field version)"
[ "$(uvs "$v0" "$tmp/uv0.bin")" = 200 ] || fail "GET /api/uv?version=$v0 failed"
faces="$(curl -s "${url}api/state" | json_field faces)"
[ "$(stat -c %s "$tmp/uv0.bin")" -eq $((faces * 24)) ] || fail "/api/uv is not 6 floats per face"

answer="$(post edit '{"add_seam_faces": [100, 101, 102, 103, 104, 105, 200, 201, 202]}')"
[ "$(code)" = 200 ] || fail "an edit answered $(code): $answer"
for key in version changed_faces ms settled; do
  echo "$answer" | python3 -c "import json,sys; j=json.load(sys.stdin); assert '$key' in j" \
    || fail "the edit's answer has no '$key': $answer"
done
v1="$(echo "$answer" | json_field version)"
[ "$v1" -gt "$v0" ] || fail "the edit made no new version: $answer"
[ "$(uvs "$v1" "$tmp/uv1.bin")" = 200 ] || fail "GET /api/uv?version=$v1 failed"
cmp -s "$tmp/uv0.bin" "$tmp/uv1.bin" && fail "the edit did not change the UVs"
wait_settled

# Malformed requests: 400, one line, nothing changed.
before="$(curl -s "${url}api/status" | json_field version)"
for body in 'not json' '[1, 2]' '{"bogus": 1}' '{"add_seam_faces": [99999999]}' '{"add_seam_faces": [-1]}' \
    '{"add_seam_faces": "1"}' '{"strokes": [{"points": [[0, 0, 0]], "radius": 0.1}]}' \
    '{"strokes": [{"points": [[0, 0, 0], [1, 1, 1]], "radius": -1}]}' '{"options": {"axis": "w"}}' \
    '{"options": {"scale": -3}}' '{"options": {"crack_rings": 99}}' '{"options": {"bogus": 1}}' \
    '{"add_seam_faces": [1], "options": {"mode": "none"}}' '{"options": {"mode": "thesis", "max_stretch": 0.3}}' \
    '{"options": {"mode": "thesis", "crack_rings": 8}}' '{"options": {"threshold_px": 2}}'; do
  answer="$(post edit "$body")"
  [ "$(code)" = 400 ] || fail "the malformed edit '$body' answered $(code): $answer"
  [ "$(printf '%s\n' "$answer" | wc -l)" -eq 1 ] || fail "the 400 answer to '$body' is not one line: $answer"
done
post edit '{"options": {"scale": "x"}}' | grep -qF "options.scale must be a number of pixels per unit, 0.001 to 1e7" ||
  fail "a scale that is no number was not refused with its range"
post edit '{"options": {"max_stretch": 9}}' | grep -qF "options.max_stretch must be a number in [0.01, 4]" ||
  fail "a max_stretch out of range was not refused with its range"
# Undo, redo and save take nothing: a body asking for something is refused, not ignored.
for request in undo redo save; do
  answer="$(post "$request" '{"add_seam_faces": [1]}')"
  [ "$(code)" = 400 ] && echo "$answer" | grep -qF "POST /api/$request takes no body (or {})" ||
    fail "POST /api/$request with a body answered $(code): $answer"
done
[ "$(curl -s "${url}api/status" | json_field version)" = "$before" ] || fail "a malformed edit changed the version"
[ "$(uvs 999999 /dev/null)" = 404 ] || fail "an unknown version is not 404"
[ "$(uvs abc /dev/null)" = 400 ] || fail "a malformed version is not 400"

# Undo: the previous UVs bit for bit; redo: the edit's.
answer="$(post undo '')"
[ "$(code)" = 200 ] || fail "undo answered $(code): $answer"
wait_settled
vu="$(curl -s "${url}api/status" | json_field version)"
uvs "$vu" "$tmp/uv_undo.bin" >/dev/null
cmp -s "$tmp/uv0.bin" "$tmp/uv_undo.bin" || fail "undo did not restore version $v0's UVs bit for bit"
answer="$(post undo '')"
[ "$(code)" = 409 ] || fail "undo with nothing to undo answered $(code), expected 409"
post redo '' >/dev/null
[ "$(code)" = 200 ] || fail "redo answered $(code)"
wait_settled
vr="$(curl -s "${url}api/status" | json_field version)"
[ "$(curl -s "${url}api/state" | python3 -c 'import json,sys; print(len(json.load(sys.stdin)["seam_faces"]))')" = 9 ] \
  || fail "redo did not bring the 9 seam faces back"

# A stroke and an option, then save and replay.
answer="$(post edit '{"strokes": [{"points": [[-0.3, 0.2, 0.1], [0.0, 0.25, 0.1], [0.3, 0.2, 0.1]], "radius": 0.3}], "options": {"smooth_passes": 2, "axis": "1,0.37,0"}}')"
[ "$(code)" = 200 ] || fail "a stroke edit answered $(code): $answer"
answer="$(post save '{}')"
[ "$(code)" = 200 ] || fail "save answered $(code): $answer"
for f in spot.glb spot_seam_faces.txt spot_strokes.json; do [ -s "$tmp/out/$f" ] || fail "save did not write $f"; done
[ "$(grep -cv '^#' "$tmp/out/spot_seam_faces.txt")" -eq 9 ] || fail "the saved seam faces are not the 9 marked ones"
command="$(echo "$answer" | json_field command)"
case "$command" in "tailor map "*" --seam-faces "*" --strokes "*" -o "*) ;; *) fail "unexpected replay command: $command" ;; esac
case "$command" in *" --max-stretch 0.25 "*" --hop-age 0.02 "*" --axis 1,0.37,0 "*) ;;
  *) fail "the replay command does not name the options as given (--max-stretch 0.25, --hop-age 0.02, --axis 1,0.37,0): $command" ;; esac
replay="${command/#tailor /\'$tailor\' }"
replay="${replay% -o *} -o '$tmp/replay.glb' -q"
bash -c "$replay" || fail "the replay command failed: $replay"
cmp -s "$tmp/replay.glb" "$tmp/out/spot.glb" || fail "tailor map with the saved seam faces and strokes gave other bytes"
curl -s -o "$tmp/model.glb" "${url}api/model.glb"
cmp -s "$tmp/model.glb" "$tmp/out/spot.glb" || fail "GET /api/model.glb differs from the saved .glb"
echo "save + replay: identical ($(stat -c %s "$tmp/replay.glb") bytes)"

# --- 3. hardening of POST ---------------------------------------------------------------------------
port="${url#http://127.0.0.1:}"; port="${port%/}"
status_of() { curl -s -o /dev/null -w '%{http_code}' --max-time 10 "$@"; }
[ "$(status_of -d '{}' "${url}api/edit")" = 415 ] || fail "a POST without Content-Type: application/json is not 415"
[ "$(status_of -H 'Content-Type: application/json' -H 'Origin: http://evil.example' -d '{}' "${url}api/edit")" = 403 ] \
  || fail "a cross-site Origin is not refused"
[ "$(status_of -H 'Content-Type: application/json' -H "Origin: http://127.0.0.1:$port" -d '{}' "${url}api/edit")" = 200 ] \
  || fail "the page's own Origin is refused"
[ "$(status_of -H 'Content-Type: application/json' -H "Host: evil.example:$port" -d '{}' "${url}api/edit")" = 403 ] \
  || fail "a foreign Host is not refused"
[ "$(status_of -H 'Content-Type: application/json' -H 'Transfer-Encoding: chunked' -d '{}' "${url}api/edit")" = 411 ] \
  || fail "a chunked body is not refused"
head -c $((17 * 1024 * 1024)) /dev/zero >"$tmp/big.json"
[ "$(status_of -H 'Content-Type: application/json' --data-binary "@$tmp/big.json" "${url}api/edit")" = 413 ] \
  || fail "a body over 16 MiB is not refused"
[ "$(status_of -H 'Content-Type: application/json' -H 'Content-Length: 99999999999999999999' -d '{}' "${url}api/edit")" = 413 ] \
  || fail "a Content-Length past 2^64 is not refused as too large"
# Two Content-Length headers (even equal ones) are refused: the body's end would depend on the reader.
python3 - "$port" <<'PY' || fail "two Content-Length headers are not refused"
import socket, sys
s = socket.create_connection(("127.0.0.1", int(sys.argv[1])), timeout=10)
s.sendall(b"POST /api/edit HTTP/1.1\r\nHost: 127.0.0.1:%s\r\nContent-Type: application/json\r\n"
          b"Content-Length: 2\r\nContent-Length: 2\r\n\r\n{}" % sys.argv[1].encode())
answer = b""
while True:  # the whole answer: the server closes the connection after it (its body may come apart)
    part = s.recv(4096)
    if not part:
        break
    answer += part
assert answer.startswith(b"HTTP/1.1 400 ") and b"more than one Content-Length" in answer, answer
PY
[ "$(status_of -H 'Content-Type: application/json' -d '{}' "${url}api/status")" = 405 ] || fail "POST to a GET route is not 405"
[ "$(status_of -X POST "${url}")" = 405 ] || fail "POST / is not 405"
# 70 POSTs whose bodies never finish (more than the server's 64 connections): a real request is
# still answered at once (the oldest unfinished one is dropped), not after the 30 s body deadline.
python3 - "$port" <<'EOF' || fail "slow POST bodies locked a real request out"
import socket, sys, time
port = int(sys.argv[1])
head = ("POST /api/edit HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nContent-Type: application/json\r\n"
        "Content-Length: 1000\r\n\r\n{" % port).encode()
slow = []
for _ in range(70):
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(head)
    slow.append(s)
time.sleep(0.3)
start = time.monotonic()
with socket.create_connection(("127.0.0.1", port), timeout=2) as s:
    s.sendall(("GET /api/status HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: close\r\n\r\n" % port).encode())
    answer = s.recv(100)
took = time.monotonic() - start
for s in slow:
    s.close()
if not (answer.startswith(b"HTTP/1.1 200") and took < 1.0):
    sys.exit("answer %r after %.2f s" % (answer[:40], took))
EOF
python3 - "$repo/web/index.html" "$repo/web/edit.html" <<'EOF' || fail "edit.html's importmap differs from index.html's (the CSP allows that one's hash)"
import re, sys
maps = [re.search(r'<script type="importmap">(.*?)</script>', open(p, encoding="utf-8").read(), re.S).group(1) for p in sys.argv[1:]]
sys.exit(0 if maps[0] == maps[1] else 1)
EOF

# --- 4. the page in the browser ---------------------------------------------------------------------
timeout 300 node web/test/edit_browser_test.mjs "$url" "$tailor" || fail "browser test of the editing page failed"

# --- 5. Ctrl-C ----------------------------------------------------------------------------------------
kill -INT "$server_pid"
set +e
timeout 5 tail --pid="$server_pid" -f /dev/null || fail "tailor edit took more than 5 s to stop after SIGINT"
wait "$server_pid"; rc=$?
set -e
server_pid=""
[ "$rc" -eq 0 ] || fail "tailor edit exited $rc after SIGINT, expected 0"

# --- 6. a session cut into chunks: edits go chunk by chunk, save and replay still agree ---------------
start_server examples/spot.obj --texture examples/gravel.png --chunks on --chunk-cell -1 -o "$tmp/out/spot_chunks.glb"
c0="$(curl -s "${url}api/status" | json_field version)"
uvs "$c0" "$tmp/c0.bin" >/dev/null
answer="$(post edit '{"add_seam_faces": [100, 101, 102, 103, 104, 105], "strokes": [{"points": [[-0.3, 0.2, 0.1], [0.0, 0.25, 0.1]], "radius": 0.1}]}')"
[ "$(code)" = 200 ] || fail "an edit of a chunked session answered $(code): $answer"
c1="$(echo "$answer" | json_field version)"
uvs "$c1" "$tmp/c1.bin" >/dev/null
cmp -s "$tmp/c0.bin" "$tmp/c1.bin" && fail "the chunked session's edit did not change the UVs"
wait_settled
answer="$(post save '{}')"
[ "$(code)" = 200 ] || fail "save of a chunked session answered $(code): $answer"
command="$(echo "$answer" | json_field command)"
case "$command" in *" --chunks on --chunk-cell -1"*) ;; *) fail "the replay command lost the chunk options: $command" ;; esac
replay="${command/#tailor /\'$tailor\' }"
replay="${replay% -o *} -o '$tmp/replay_chunks.glb' -q"
bash -c "$replay" || fail "the replay command failed: $replay"
cmp -s "$tmp/replay_chunks.glb" "$tmp/out/spot_chunks.glb" || fail "the chunked session's replay gave other bytes"
echo "chunked session: save + replay identical ($(stat -c %s "$tmp/replay_chunks.glb") bytes)"
stop_server

# --- 7. what the input holds that is not read: said as tailor map says it --------------------------
printf 'OFF\n4 1 0\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n3 0 1 2\n3 1 3 2\n' >"$tmp/short.off"
start_server "$tmp/short.off" -o "$tmp/out/short.glb"
grep -qF "tailor: warning: $tmp/short.off: not read: 1 line after the 1 face the OFF header declares (from line 8)" \
  "$tmp/edit.log" || fail "tailor edit read past an OFF's undeclared face without a word: $(cat "$tmp/edit.log")"
# A mode change keeps the stored values; only what a request gives that its mode does not read is refused.
for body in '{"options": {"max_stretch": 0.3}}' '{"options": {"mode": "thesis"}}' \
    '{"options": {"field_following": "auto", "threshold_px": 2}}' '{"options": {"mode": "patches", "max_stretch": 0.2}}'; do
  answer="$(post edit "$body")"
  [ "$(code)" = 200 ] || fail "the edit '$body' answered $(code): $answer"
  wait_settled
done
post edit '{"options": {"mode": "thesis", "max_stretch": 0.3}}' | grep -qF "options.max_stretch has no effect in thesis mode" ||
  fail "a thesis request with max_stretch was not refused for it"
# The page greys what the state names as patches-only: the keys the server refuses in thesis mode.
[ "$(curl -s "${url}api/state" | json_field patches_only)" = "['max_stretch', 'field_following', 'min_patch_faces', 'hop_age', 'shorten_seams', 'close_cracks', 'crack_rings', 'relax_iterations']" ] ||
  fail "the state's patches_only is not the options the thesis mode refuses: $(curl -s "${url}api/state")"
stop_server

echo "PASS: tailor edit and its API work"
