#!/usr/bin/env bash
# The SIMD paths of the mapping (SSE2, and GCC's AVX copies where the CPU has AVX) give the same
# bits as the scalar paths: `tailor map` and map_scalar (the same pipeline with the mapping built
# with TAILOR_NO_SIMD, tests/tools/map_scalar.cpp) must write byte-identical binary PLY files.
# Usage: bash tests/simd_test.sh path/to/tailor   (map_scalar is built next to it)
set -uo pipefail
tailor=${1:?usage: simd_test.sh TAILOR_BINARY}
scalar="$(dirname "$tailor")/map_scalar"
[[ -x $scalar ]] || { echo "FAIL: $scalar not built"; exit 1; }
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
passed=0
failed=0
compare() {  # compare NAME MESH [options...]
  local name=$1 mesh=$2
  shift 2
  if ! "$tailor" map "$mesh" -o "$tmp/simd.ply" --quiet "$@" || ! "$scalar" "$mesh" "$tmp/scalar.ply" "$@"; then
    failed=$((failed + 1)); echo "FAIL: $name: a run failed"; return
  fi
  if cmp -s "$tmp/simd.ply" "$tmp/scalar.ply"; then passed=$((passed + 1))
  else failed=$((failed + 1)); echo "FAIL: $name: SIMD and scalar outputs differ"; fi
}
for mesh in tests/data/meshes/*.{ply,obj,off,stl}; do compare "$(basename "$mesh")" "$mesh"; done
compare "fertility unfolded" tests/data/meshes/fertility.off --field-following 0
compare "spot 32 rings" tests/data/meshes/spot.obj --crack-rings 32
echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
