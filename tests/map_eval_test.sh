#!/usr/bin/env bash
# `tailor eval` of a file `tailor map` wrote reports the figures `map` printed for it: the patch
# count, seams (visible and invisible share), dangling ends and the rest of the metrics, on several
# meshes, textures of several sizes (128, 300 and 512 px: the .obj's size comes from its .mtl), a
# 4-fold map (the symmetry from the .glb's material and the .mtl), and a mesh with vertices at
# identical positions (a split .ply, mapped again). Both .glb and .obj.
# Usage: bash tests/map_eval_test.sh path/to/tailor   (ctest passes the built binary)
set -uo pipefail
tailor=${1:?usage: map_eval_test.sh TAILOR_BINARY}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0
ok() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }
meshes=tests/data/meshes
textures=tests/data/textures

# agree NAME OUTPUT: map's --stats metrics and its summary line against eval of OUTPUT (--json and
# its summary line). Every figure both report must be equal (the same bits); eval sizes the texture
# from the file (never the default) and measures as many faces.
agree() {
  local name=$1 out=$2
  if ! "$tailor" eval "$out" --json >"$tmp/$name.eval.json" 2>"$tmp/$name.eval.err" ||
    ! "$tailor" eval "$out" >"$tmp/$name.eval.txt" 2>>"$tmp/$name.eval.err"; then
    fail "$name: eval failed: $(cat "$tmp/$name.eval.err")"
    return
  fi
  if python3 - "$tmp/$name.stats.json" "$tmp/$name.eval.json" "$tmp/$name.map.txt" "$tmp/$name.eval.txt" <<'PY'; then ok; else fail "$name: map and eval disagree"; fi
import json, re, sys
stats = json.load(open(sys.argv[1]))
m, e = stats["metrics"], json.load(open(sys.argv[2]))
bad = [f"{k}: map {m[k]!r}, eval {e[k]!r}" for k in m if k != "uv_scale" and m[k] != e.get(k)]
if e["faces"] != stats["mesh"]["faces"]:
    bad.append(f"faces: map {stats['mesh']['faces']}, eval {e['faces']}")
if e["texture_size_from"] == "default" or [e["texture_width"], e["texture_height"]] != stats["texture_size"]:
    bad.append(f"texture: map {stats['texture_size']}, eval {e['texture_width']}x{e['texture_height']} "
               f"({e['texture_size_from']})")
if e["symmetry"] != stats["options"]["symmetry"]:
    bad.append(f"symmetry: map {stats['options']['symmetry']}, eval {e['symmetry']}")
# The printed lines: patches, visible seams, invisible share, dangling ends.
map_line, eval_line = open(sys.argv[3]).read(), open(sys.argv[4]).read()
def figures(line, patterns):
    return [re.search(p, line).group(1) if re.search(p, line) else None for p in patterns]
got_map = figures(map_line, [r"(\d+) patch", r"visible seams ([\d.]+)%", r"\((\d+)% of seam length invisible",
                             r"(\d+) dangling end"])
got_eval = figures(eval_line, [r"(\d+) patch", r"visible seams ([\d.]+)%", r"([\d.]+)% invisible",
                               r"(\d+) dangling end"])
if None in got_map or None in got_eval:
    bad.append(f"unparsed summary lines: {map_line!r} {eval_line!r}")
else:
    got_eval[2] = "%.0f" % (100 * e["seam_invisible_ratio"])  # map prints it to 1 %, eval to 0.1 %
    if got_map != got_eval:
        bad.append(f"printed: map {got_map}, eval {got_eval}")
for line in bad:
    print("   ", line)
sys.exit(1 if bad else 0)
PY
}

# map_both NAME MESH ARGS...: maps MESH to NAME.glb and NAME.obj (its own folder each) and checks both.
map_both() {
  local name=$1 mesh=$2
  shift 2
  local ext
  for ext in glb obj; do
    mkdir -p "$tmp/$name-$ext"
    local out="$tmp/$name-$ext/$name.$ext"
    if ! "$tailor" map "$mesh" -o "$out" --stats "$tmp/$name-$ext.stats.json" "$@" \
      >"$tmp/$name-$ext.map.txt" 2>"$tmp/$name-$ext.map.err"; then
      fail "$name.$ext: map failed: $(cat "$tmp/$name-$ext.map.err")"
      continue
    fi
    agree "$name-$ext" "$out"
  done
}

map_both spot-bark "$meshes/spot.obj" -t "$textures/vistex-bark11-128.png"
map_both fertility-water "$meshes/fertility.off" -t "$textures/water-caustics-300.jpg"
map_both blobby-brick "$meshes/blobby-3cc.off" -t "$textures/brick-gray-512.png"
map_both fandisk-grass "$meshes/fandisk.off" -t "$textures/grass-gray-512.png" --scale 1500
map_both spot-tile4 "$meshes/spot.obj" -t "$textures/vistex-tile04-128.png" --symmetry 4
# A mesh whose vertices repeat positions: a split .ply (tailor's own output), mapped again. Readers
# of the output join them, and so does map's report.
"$tailor" map "$meshes/spot.obj" -t "$textures/vistex-sand05-128.png" -o "$tmp/split.ply" -q ||
  fail "map to .ply failed"
map_both split-sand "$tmp/split.ply" -t "$textures/vistex-sand05-128.png"
if grep -q '"welded_vertices": 0,' "$tmp/split-sand-obj.eval.json"; then
  fail "split-sand.obj: eval joined no vertices (the input has none at identical positions?)"
else
  ok
fi

# The .obj output moved elsewhere keeps its texture's size (the texture lies beside the .mtl).
mv "$tmp/fertility-water-obj" "$tmp/moved" &&
  "$tailor" eval "$tmp/moved/fertility-water.obj" | grep -q "texture 300x300 px, texture file)" && ok ||
  fail "a moved .obj output lost its texture's size: $("$tailor" eval "$tmp/moved/fertility-water.obj" 2>&1)"
# Without its .mtl, eval falls back to the default size and says so; --texture-size still wins.
rm "$tmp/moved/fertility-water.mtl" &&
  "$tailor" eval "$tmp/moved/fertility-water.obj" | grep -q "texture 512x512 px, default)" &&
  "$tailor" eval "$tmp/spot-bark-obj/spot-bark.obj" --texture-size 64 | grep -q "texture 64x64 px, option)" && ok ||
  fail "eval of an .obj without its .mtl, or with --texture-size, did not size the texture as documented"

# A texture the .mtl names but that cannot be read: the default size, and a warning that says why.
rm "$tmp/spot-bark-obj/"*.png &&
  "$tailor" eval "$tmp/spot-bark-obj/spot-bark.obj" 2>"$tmp/named.err" | grep -q "texture 512x512 px, default)" &&
  grep -q "^tailor: warning: .*spot-bark.obj: the texture it names (.*) could not be read: measured at 512x512 px" \
    "$tmp/named.err" && ok || fail "eval of an .obj whose texture is missing: no warning: $(cat "$tmp/named.err")"

# --threads: the same figures for any count (the large-mesh parallel paths are tests/metrics_test.cpp's).
if "$tailor" eval "$tmp/spot-bark-glb/spot-bark.glb" --json --threads 3 >"$tmp/threads3.json" &&
  python3 - "$tmp/spot-bark-glb.eval.json" "$tmp/threads3.json" <<'PY'; then ok; else fail "eval --threads 3 changed the figures"; fi
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:])
for d in (a, b):
    d.pop("seconds", None)
sys.exit(0 if a == b else 1)
PY
echo "map_eval_test: $passed passed, $failed failed"
[[ $failed -eq 0 ]]
