#!/usr/bin/env bash
# make blender-addon: zips blender/tailor_addon into OUT (default out/tailor_addon.zip), with the
# Python module of BUILD_DIR (build/python/tailor) bundled in tailor_addon/_bundled/ when it was
# built: Blender's Python imports it when it is the same Python version (Debian's Blender 3.4 uses
# the system's python3.11); otherwise the add-on uses the tailor command.
# Usage: scripts/blender_addon.sh [BUILD_DIR] [OUT.zip]
set -euo pipefail
repo=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-build}
out=${2:-out/tailor_addon.zip}
mkdir -p "$(dirname "$out")"
out=$(cd "$(dirname "$out")" && pwd)/$(basename "$out")
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
cp -r "$repo/blender/tailor_addon" "$stage/"
find "$stage" -name __pycache__ -prune -exec rm -rf {} +
if [[ -f $build/python/tailor/__init__.py ]]; then
  mkdir -p "$stage/tailor_addon/_bundled/tailor"
  cp "$build"/python/tailor/{__init__.py,__init__.pyi,py.typed} "$build"/python/tailor/_tailor.*.so \
    "$stage/tailor_addon/_bundled/tailor/"
  bundled="with the Python module of $build"
else
  bundled="without the Python module (not built): the add-on will use the tailor command"
fi
rm -f "$out"
(cd "$stage" && python3 -c "
import os, sys, zipfile
with zipfile.ZipFile(sys.argv[1], 'w', zipfile.ZIP_DEFLATED) as z:
    for root, dirs, files in os.walk('tailor_addon'):
        dirs.sort()
        for name in sorted(files):
            z.write(os.path.join(root, name))
" "$out")
echo "blender-addon: $out ($bundled)"
