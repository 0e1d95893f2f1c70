#!/usr/bin/env bash
# Renders the pictures of docs/blender.md headless (needs blender: make deps-blender) into
# docs/images/: the add-on's zip with the module of BUILD_DIR, then scripts/blender_pictures.py.
# Usage: scripts/blender_pictures.sh [BUILD_DIR]
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bash "$repo/scripts/blender_addon.sh" "$build" "$tmp/tailor_addon.zip"
HOME=$tmp/home XDG_CONFIG_HOME=$tmp/config PYTHONDONTWRITEBYTECODE=1 \
  blender -b --factory-startup --python-exit-code 1 --python "$repo/scripts/blender_pictures.py" -- \
  "$tmp/tailor_addon.zip" "$repo/examples/spot.obj" "$repo/examples/gravel.png" "$repo/docs/images" | grep -E "^(Saved|Error|Info: tailor)"
