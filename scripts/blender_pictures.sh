#!/usr/bin/env bash
# Renders the pictures of docs/blender.md headless (needs blender: make deps-blender) into
# docs/images/: the add-on's zip with the module of BUILD_DIR, then scripts/blender_pictures.py
# (Cycles renders), then, when xvfb-run is there (apt-get install xvfb), the operator's dialog in
# Blender's window under a virtual X server (scripts/blender_dialog_picture.py).
# Usage: scripts/blender_pictures.sh [BUILD_DIR]
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
bash "$repo/scripts/blender_addon.sh" "$build" "$tmp/tailor_addon.zip"
HOME=$tmp/home XDG_CONFIG_HOME=$tmp/config TMPDIR=$tmp PYTHONDONTWRITEBYTECODE=1 \
  blender -b --factory-startup --python-exit-code 1 --python "$repo/scripts/blender_pictures.py" -- \
  "$tmp/tailor_addon.zip" "$repo/examples/spot.obj" "$repo/examples/gravel.png" "$repo/docs/images" \
  "$tmp/scene.blend" | grep -E "^(Saved|Error|Info: tailor)"
if command -v xvfb-run >/dev/null 2>&1; then
  HOME=$tmp/home XDG_CONFIG_HOME=$tmp/config TMPDIR=$tmp PYTHONDONTWRITEBYTECODE=1 xvfb-run -a -s "-screen 0 1120x700x24" \
    blender "$tmp/scene.blend" --factory-startup --python "$repo/scripts/blender_dialog_picture.py" -- \
    "$tmp/tailor_addon.zip" "$tmp/dialog.png" >/dev/null 2>&1
  # Re-saved with the strongest PNG compression (Blender's screenshot uses a light one).
  blender -b --factory-startup --python-expr "import bpy; s = bpy.context.scene; \
s.render.image_settings.compression = 100; bpy.data.images.load('$tmp/dialog.png').save_render('$tmp/dialog.png', scene=s)" \
    >/dev/null 2>&1
  cp "$tmp/dialog.png" "$repo/docs/images/blender_dialog.png" && echo "Saved: docs/images/blender_dialog.png"
else
  echo "skipped: docs/images/blender_dialog.png (xvfb-run is missing: apt-get install xvfb)"
fi
