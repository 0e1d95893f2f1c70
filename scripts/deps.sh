#!/usr/bin/env bash
# Installs what tailor needs on Debian 12, and nothing when everything is there already.
# Idempotent: checks each package with dpkg-query and only calls apt-get for missing ones.
set -euo pipefail

# Build tools and libraries (all Debian packages; see docs/ARCHITECTURE.md for why each is used).
packages=(
  g++ cmake make pkg-config ccache
  libeigen3-dev libstb-dev zlib1g-dev libcli11-dev nlohmann-json3-dev libfast-float-dev
  libmeshoptimizer-dev libdraco-dev
  libopencv-core-dev libopencv-imgproc-dev libosmesa6-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  clang-format python3 time
  pybind11-dev python3-dev python3-numpy python3-pytest python3-distributed python3-jsonschema
  libcgal-dev
  chromium
)
# ccache: the Makefile compiles through it (rebuilds, and the install test's shared libraries).
# pybind11, Python's headers, numpy and pytest: the Python module and its tests (/usr/bin/python3).
# python3-distributed (Dask): python3 -m tailor.tiles maps tiles as Dask tasks on a cluster.
# python3-jsonschema: tests/tiles_schema_test.sh checks the tilesets against the 3D Tiles 1.1 schema.
# libcgal-dev (header-only in Debian 12's CGAL 5.5, with GMP/MPFR and Boost headers): --axis skeleton.
# clang + its fuzzer runtime are optional: the fuzz step skips cleanly without them.
# Blender only on request (TAILOR_BLENDER=1, make deps-blender): the add-on's test skips without it.
if [[ ${TAILOR_BLENDER:-0} == 1 ]]; then
  packages+=(blender)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Node.js and npm: any install will do (Debian's or another), only add Debian's when absent.
command -v node >/dev/null 2>&1 || missing+=(nodejs)
command -v npm >/dev/null 2>&1 || missing+=(npm)

if ((${#missing[@]})); then
  echo "deps: installing ${missing[*]}"
  if [[ $(id -u) -eq 0 ]]; then
    sudo_cmd=()
  elif command -v sudo >/dev/null 2>&1; then
    sudo_cmd=(sudo)
  else
    echo "deps: error: missing packages (${missing[*]}) and not root, and sudo is not available;" \
         "install them as root: apt-get install ${missing[*]}" >&2
    exit 1
  fi
  export DEBIAN_FRONTEND=noninteractive
  "${sudo_cmd[@]}" apt-get update -qq
  "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# JavaScript packages of the web viewer and its tests (three.js, playwright-core, gltf-validator).
here=$(cd "$(dirname "$0")/.." && pwd)
if [[ -f "$here/web/package.json" ]]; then
  if [[ ! -d "$here/web/node_modules" || "$here/web/package.json" -nt "$here/web/node_modules" ]]; then
    echo "deps: installing npm packages in web/"
    (cd "$here/web" && npm install --no-audit --no-fund --loglevel=error >/dev/null && touch node_modules)
  fi
fi
