#!/usr/bin/env bash
# The tilesets of `python3 -m tailor.tiles` against the 3D Tiles 1.1 JSON schema, run by ctest from
# the repo root as
#   bash tests/tiles_schema_test.sh <tailor-binary>
# 1. three tilesets of the horse (no Dask: --workers 0): a texture with levels of detail; a PBR
#    material (colour, normal, roughness, occlusion) with --up z; a texture-size run without levels
#    of detail;
# 2. each tileset.json passes tests/tools/validate_tileset.py (the specification's JSON schema,
#    tests/data/3d-tiles-schema, with Debian's python3-jsonschema; every content URI a file) and
#    every tile, leaves and parents, passes the Khronos glTF validator without a warning, the images
#    they name read beside them;
# 3. the check can fail: a copy of a tileset broken on purpose is rejected.
# Never skips: a missing python3-jsonschema, node_modules or Python module is a failure.
set -euo pipefail

tailor="${1:?usage: bash tests/tiles_schema_test.sh <tailor-binary>}"
tailor="$(cd "$(dirname "$tailor")" && pwd)/$(basename "$tailor")"
repo="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$repo"

fail() { echo "FAIL: $*" >&2; exit 1; }

python=/usr/bin/python3
"$python" -c "import jsonschema" 2>/dev/null || fail "python3-jsonschema is missing (apt-get install python3-jsonschema)"
command -v node >/dev/null || fail "node is missing"
[ -d web/node_modules/gltf-validator ] || fail "web/node_modules/gltf-validator is missing (run 'npm install' in web/)"
python_dir="$(dirname "$tailor")/python"
[ -d "$python_dir/tailor" ] || fail "the Python module is not built beside $tailor"

tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT

tiles() {
  PYTHONPATH="$python_dir" timeout 300 "$python" -m tailor.tiles tests/data/meshes/horse.ply --chunk-cell -4 \
    --workers 0 -q "$@" || fail "python3 -m tailor.tiles $* failed"
}

# --- 1. the tilesets -------------------------------------------------------------------------------
tiles -o "$tmp/texture" --texture examples/gravel.png
# A material: the Flemish bond bricks as colour; a normal map, roughness and occlusion derived from
# one height field.
PYTHONPATH="$python_dir" "$python" - "$tmp/material" <<'PY'
import json, pathlib, struct, sys, zlib
import numpy as np
folder = pathlib.Path(sys.argv[1])
folder.mkdir()

def png(path, pixels):
    pixels = np.ascontiguousarray(pixels, np.uint8)
    h, w = pixels.shape[:2]
    raw = b"".join(b"\0" + pixels[y].tobytes() for y in range(h))
    chunk = lambda kind, body: struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    head = struct.pack(">IIBBBBB", w, h, 8, {2: 0, 3: 2}[pixels.ndim], 0, 0, 0)
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", head) + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))

y, x = np.mgrid[0:256, 0:256] / 256.0 * 2 * np.pi
height = np.sin(4 * x) * np.cos(6 * y)
n = np.stack([-np.gradient(height, axis=1) * 20, np.gradient(height, axis=0) * 20, np.ones_like(height)], -1)
n /= np.linalg.norm(n, axis=-1, keepdims=True)
png(folder / "bumps.png", np.round((n * 0.5 + 0.5) * 255))
png(folder / "rough.png", np.round(127 + 100 * height))
png(folder / "ao.png", np.round(200 + 50 * height))
colour = pathlib.Path("tests/data/textures/flemish-bond-256.png").resolve()
(folder / "material.json").write_text(json.dumps({"maps": [
    {"file": str(colour), "role": "color"}, {"file": "bumps.png", "normal": True},
    {"file": "rough.png", "role": "roughness"}, {"file": "ao.png", "role": "occlusion"}]}))
PY
tiles -o "$tmp/material_tiles" --material "$tmp/material/material.json" --up z
tiles -o "$tmp/plain" --texture-size 256 --no-lod --tile-size 0.125

# --- 2. the schema and the glTF validator ----------------------------------------------------------
for set in texture material_tiles plain; do
  "$python" tests/tools/validate_tileset.py "$tmp/$set/tileset.json" >"$tmp/schema.log" 2>&1 \
    || fail "$set: $(head -5 "$tmp/schema.log")"
  timeout 300 node tests/tools/validate_gltf.mjs --strict --allow-external "$tmp/$set"/tiles/*.glb >"$tmp/validate.log" \
    || fail "$set: glTF validator: $(grep -v 'errors 0 warnings 0' "$tmp/validate.log" | head -5)"
done
for image in material_color.png material_normal.png material_orm.png; do
  [ -s "$tmp/material_tiles/tiles/$image" ] || fail "no $image beside the material's tiles"
done

# --- 3. the check can fail -------------------------------------------------------------------------
"$python" - "$tmp/texture/tileset.json" "$tmp/texture/broken.json" <<'PY'
import json, sys
tileset = json.load(open(sys.argv[1]))
tileset["asset"]["version"] = 1.1                                    # a number, not a string
tileset["root"]["children"][0]["boundingVolume"]["box"].pop()        # 11 numbers
tileset["root"]["children"][0]["geometricError"] = -1                # negative
json.dump(tileset, open(sys.argv[2], "w"))
PY
set +e
"$python" tests/tools/validate_tileset.py "$tmp/texture/broken.json" >"$tmp/broken.log" 2>&1; rc=$?
set -e
[ "$rc" -eq 1 ] || fail "a broken tileset was not rejected (exit $rc): $(cat "$tmp/broken.log")"
[ "$(grep -c 'broken.json: root\|broken.json: asset' "$tmp/broken.log")" -eq 3 ] \
  || fail "the broken tileset's three problems were not all found: $(cat "$tmp/broken.log")"
echo "tiles schema test: ok"
