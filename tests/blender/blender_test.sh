#!/usr/bin/env bash
# The Blender add-on headless: makes its zip (scripts/blender_addon.sh, with the module of the build)
# in a temporary folder and runs tests/blender/test_addon.py inside Blender. Blender is optional
# (make deps-blender installs it): without it this exits 77, which ctest reports as skipped.
# Usage: bash tests/blender/blender_test.sh <build-dir>/tailor
set -uo pipefail
tailor=${1:?usage: blender_test.sh <build-dir>/tailor}
if ! command -v blender >/dev/null 2>&1; then
  echo "skipped: blender is not installed (make deps-blender)"
  exit 77
fi
build=$(cd "$(dirname "$tailor")" && pwd)
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bash "$repo/scripts/blender_addon.sh" "$build" "$tmp/tailor_addon.zip" || exit 1
# Blender writes its user settings under HOME (the add-on install too) and its temporary files in
# TMPDIR: keep both in the temp folder.
HOME=$tmp/home XDG_CONFIG_HOME=$tmp/config TMPDIR=$tmp PYTHONDONTWRITEBYTECODE=1 \
  blender -b --factory-startup --python-exit-code 1 --python "$repo/tests/blender/test_addon.py" -- \
  "$tmp/tailor_addon.zip" "$repo/examples/spot.obj" "$repo/examples/gravel.png" "$tailor" "$tmp" \
  "$([[ -f $build/python/tailor/__init__.py ]] && echo 1 || echo 0)" 2>&1 |
  grep -v "^Read prefs\|^Blender quit$\|^$"
exit "${PIPESTATUS[0]}"
