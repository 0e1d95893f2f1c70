#!/usr/bin/env bash
# The installed tailor, as a user or a packager gets it, run by ctest from the repo root as
#   bash tests/install_test.sh <build-dir>/tailor
# 1. cmake --install of that build into a temporary prefix: the layout, and no installed file (the
#    tailor binary and the libraries included) naming the source or build tree;
# 2. the installed `tailor` runs (--version, map); the installed Python module (when built) imports
#    from the prefix alone and writes the same .glb;
# 3. examples/consumer built against the prefix with find_package(tailor) and with pkg-config
#    (static libraries): both run, write valid .glb files (node + glTF-Validator, skipped without
#    node), byte-identical to the installed `tailor map`'s; a program whose only include is
#    "tailor/tailor.h" (on its first line) builds both ways with -Wall -Wextra -Werror and runs;
# 4. the installed `tailor view` serves the installed share/tailor/web (it says so in its startup
#    line): the page and every module it imports, following the imports from viewer.js, and no
#    installed module goes unused; share/ holds nothing else (the pages, the modules, three.js's
#    licence and Draco's decoder);
# 5. BUILD_SHARED_LIBS=ON: the three libraries alone (kept in <build-dir>/install-test-shared, so a
#    rerun rebuilds only what changed), installed with `--component library`; the consumer built
#    with find_package is dynamically linked to libtailor_core.so and gives the same .glb; a
#    program calling the texture and render libraries links with pkg-config.
set -uo pipefail
tailor=${1:?usage: install_test.sh <build-dir>/tailor}
build=$(cd "$(dirname "$tailor")" && pwd)
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"

tmp=$(mktemp -d)
server_pid=""
cleanup() {
  if [[ -n $server_pid ]]; then
    kill "$server_pid" 2>/dev/null
    wait "$server_pid" 2>/dev/null
  fi
  rm -rf "$tmp"
}
trap cleanup EXIT
passed=0
failed=0
ok() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }
# A step the rest depends on: report and stop.
fatal() {
  fail "$*"
  echo "$passed passed, $failed failed"
  exit 1
}

mesh=tests/data/meshes/horse.ply
texture=examples/gravel.png
prefix=$tmp/prefix
version=$(sed -n 's/^#define TAILOR_VERSION_STRING "\(.*\)"$/\1/p' include/tailor/version.h)
[[ -n $version ]] || fatal "no TAILOR_VERSION_STRING in include/tailor/version.h"
jobs=2

# Validates a .glb with the Khronos validator when node is there.
validate() {
  if ! command -v node >/dev/null; then
    echo "skipped: glTF validation of $(basename "$1") (node is missing)"
    return
  fi
  node tests/tools/validate_gltf.mjs --strict "$1" >"$tmp/validate.txt" 2>&1 && ok ||
    fail "$1 is not valid glTF: $(cat "$tmp/validate.txt")"
}

# --- 1. install into a temporary prefix ---
cmake --install "$build" --prefix "$prefix" >"$tmp/install.log" 2>&1 || fatal "cmake --install failed: $(cat "$tmp/install.log")"
for f in bin/tailor include/tailor/tailor.h include/tailor/api.h include/tailor/version.h \
  lib/libtailor_core.a lib/libtailor_texture.a lib/libtailor_render.a \
  lib/cmake/tailor/tailorConfig.cmake lib/cmake/tailor/tailorConfigVersion.cmake lib/cmake/tailor/tailorTargets.cmake \
  lib/pkgconfig/tailor.pc share/tailor/web/index.html share/tailor/web/node_modules/three/build/three.module.js; do
  [[ -f $prefix/$f ]] && ok || fail "not installed: $f"
done
# Binary files too: the tailor binary finds its viewer relative to itself, and nothing else names a path.
refs=$(grep -rlF -e "$repo" -e "$build" "$prefix")
[[ -z $refs ]] && ok || fail "installed files name the source or build tree: $refs"

# --- 2. the installed command ---
[[ $("$prefix/bin/tailor" --version) == "tailor $version" ]] && ok || fail "tailor --version: $("$prefix/bin/tailor" --version 2>&1)"
"$prefix/bin/tailor" map "$mesh" --texture "$texture" -o "$tmp/reference.glb" --quiet && [[ -s $tmp/reference.glb ]] ||
  fatal "the installed tailor map failed"
ok

# --- 2b. the Python module (when the build has it): imported from the prefix alone, same .glb ---
python=$(sed -n 's/^Python_EXECUTABLE:FILEPATH=//p' "$build/CMakeCache.txt")
if [[ -d $build/python/tailor && -x $python ]]; then
  module_dir=$(dirname "$(find "$prefix" -path '*-packages/tailor/__init__.py' | head -1)")
  for f in __init__.py __init__.pyi py.typed; do [[ -f $module_dir/$f ]] && ok || fail "python: not installed: tailor/$f"; done
  (cd "$tmp" && PYTHONPATH=$(dirname "$module_dir") PYTHONDONTWRITEBYTECODE=1 "$python" -c "
import sys, tailor
assert tailor.__file__.startswith('$prefix'), tailor.__file__
mesh = tailor.load('$repo/$mesh')
tailor.save('$tmp/python.glb', mesh, tailor.map(mesh, texture='$repo/$texture'))
") && cmp -s "$tmp/python.glb" "$tmp/reference.glb" && ok || fail "python: the installed module does not give the installed tailor's .glb"
else
  echo "skipped: the Python module (not built)"
fi

# --- 3. examples/consumer with find_package and with pkg-config ---
# run_consumer NAME BINARY: maps the test mesh, validates the .glb and compares it with tailor map's.
run_consumer() {
  local name=$1 binary=$2
  if "$binary" "$mesh" "$tmp/$name.glb" "$texture" >"$tmp/$name.txt" 2>&1; then ok
  else fail "$name: the consumer failed: $(cat "$tmp/$name.txt")"; return; fi
  grep -q "faces in [0-9]* patches" "$tmp/$name.txt" && ok || fail "$name: unexpected output: $(cat "$tmp/$name.txt")"
  validate "$tmp/$name.glb"
  cmp -s "$tmp/$name.glb" "$tmp/reference.glb" && ok ||
    fail "$name: the consumer's .glb differs from tailor map's (the same default options)"
}
if cmake -S examples/consumer -B "$tmp/consumer-cmake" -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/cmake.log" 2>&1 &&
  cmake --build "$tmp/consumer-cmake" -j "$jobs" >>"$tmp/cmake.log" 2>&1; then
  ok
  run_consumer consumer-cmake "$tmp/consumer-cmake/consumer"
else
  fail "examples/consumer does not build with find_package: $(tail -20 "$tmp/cmake.log")"
fi
export PKG_CONFIG_PATH=$prefix/lib/pkgconfig
[[ $(pkg-config --modversion tailor 2>&1) == "$version" ]] && ok || fail "pkg-config --modversion tailor: $(pkg-config --modversion tailor 2>&1)"
if g++ -std=c++20 -O2 examples/consumer/main.cpp $(pkg-config --cflags --libs --static tailor) \
  -o "$tmp/consumer-pkg-config" >"$tmp/g++.log" 2>&1; then
  ok
  run_consumer consumer-pkg-config "$tmp/consumer-pkg-config"
else
  fail "examples/consumer does not build with pkg-config: $(tail -20 "$tmp/g++.log")"
fi

# A program whose only include is tailor/tailor.h, on line 1: every header includes what it uses.
# It calls the three libraries (core, texture, render).
mkdir -p "$tmp/only-tailor-h"
cat >"$tmp/only-tailor-h/main.cpp" <<'EOF'
#include "tailor/tailor.h"
int main() {
  tailor::Image image{64, 32, 1, std::vector<uint8_t>(64 * 32, 7)};
  const tailor::Image swapped = tailor::swap_quadrants(image);  // tailor::texture
  tailor::PreviewView view;
  const bool parsed = tailor::preview_view_from_name("patches", view);  // tailor::render
  const tailor::Atlas atlas;
  if (!parsed || swapped.width != 64 || atlas.face_count() != 0) return 1;
  return tailor::check_image(swapped).is_ok() ? 0 : 1;  // tailor::core
}
EOF
cat >"$tmp/only-tailor-h/CMakeLists.txt" <<'EOF'
cmake_minimum_required(VERSION 3.20)
project(only_tailor_h CXX)
find_package(tailor 0.1 CONFIG REQUIRED)
add_executable(only_tailor_h main.cpp)
target_compile_options(only_tailor_h PRIVATE -Wall -Wextra -Werror)
target_link_libraries(only_tailor_h PRIVATE tailor::core tailor::texture tailor::render)
EOF
if cmake -S "$tmp/only-tailor-h" -B "$tmp/only-tailor-h/build" -DCMAKE_PREFIX_PATH="$prefix" >"$tmp/only.log" 2>&1 &&
  cmake --build "$tmp/only-tailor-h/build" >>"$tmp/only.log" 2>&1; then
  "$tmp/only-tailor-h/build/only_tailor_h" && ok || fail "the find_package program including only tailor/tailor.h failed"
else
  fail "a program including only tailor/tailor.h does not build with find_package: $(tail -20 "$tmp/only.log")"
fi
if g++ -std=c++20 -Wall -Wextra -Werror "$tmp/only-tailor-h/main.cpp" $(pkg-config --cflags --libs --static tailor) \
  -o "$tmp/only-tailor-h/pkg-config" >"$tmp/only-pc.log" 2>&1; then
  "$tmp/only-tailor-h/pkg-config" && ok || fail "the pkg-config program including only tailor/tailor.h failed"
else
  fail "a program including only tailor/tailor.h does not build with pkg-config: $(tail -20 "$tmp/only-pc.log")"
fi

# --- 4. the installed tailor view serves the installed viewer ---
"$prefix/bin/tailor" view "$tmp/reference.glb" >"$tmp/view.log" 2>&1 &
server_pid=$!
url=""
for _ in $(seq 1 100); do
  url=$(grep -o 'http://127\.0\.0\.1:[0-9]*/' "$tmp/view.log")
  [[ -n $url ]] && break
  kill -0 "$server_pid" 2>/dev/null || break
  sleep 0.1
done
web=$(cd "$prefix/share/tailor/web" && pwd -P)
if [[ -z $url ]]; then
  fail "the installed tailor view printed no URL: $(cat "$tmp/view.log")"
else
  ok
  grep -qF "viewer in $web;" "$tmp/view.log" && ok || fail "tailor view does not serve $web: $(cat "$tmp/view.log")"
  fetch() { curl -sf --max-time 10 -o "$2" "$url${1#/}"; }
  fetch / "$tmp/index.html" && cmp -s "$tmp/index.html" "$web/index.html" && ok || fail "GET / is not the installed index.html"
  # Follow the imports from the pages' module scripts (the viewer's and tailor edit's), the importmap's
  # way ('three' and 'three/addons/').
  declare -A seen=()
  queue=($(grep -oh '<script type="module" src="[^"]*"' "$web/index.html" "$web/edit.html" | sed 's/.*src="//; s/"$//'))
  [[ ${#queue[@]} -gt 1 ]] && ok || fail "index.html or edit.html has no module script"
  while [[ ${#queue[@]} -gt 0 ]]; do
    path=${queue[0]}
    queue=("${queue[@]:1}")
    [[ -n ${seen[$path]:-} ]] && continue
    seen[$path]=1
    if ! fetch "$path" "$tmp/module.js"; then
      fail "GET $path (imported by the viewer) failed"
      continue
    fi
    while read -r spec; do
      case $spec in
        three) target=/node_modules/three/build/three.module.js ;;
        three/addons/*) target=/node_modules/three/examples/jsm/${spec#three/addons/} ;;
        /node_modules/*) target=$spec ;;
        ./* | ../*)
          target=${path%/*}/$spec
          while [[ $target == */./* ]]; do target=${target/\/.\//\/}; done
          while [[ $target =~ ^(.*)/[^/.][^/]*/\.\./(.*)$ ]]; do target=${BASH_REMATCH[1]}/${BASH_REMATCH[2]}; done ;;
        *) fail "$path imports '$spec', which the page cannot resolve"; continue ;;
      esac
      queue+=("$target")
    done < <({
      grep -E "^[[:space:]]*(import|export|\})[^'\"]*['\"][^'\"]+['\"];?[[:space:]]*$" "$tmp/module.js" |
        grep -oE "(from|import)[[:space:]]+['\"][^'\"]+['\"]"
      # A package's bundle (3d-tiles-renderer) puts its imports anywhere on a line; dynamic import('./x.js').
      [[ $path == /node_modules/3d-tiles-renderer/* ]] && grep -oE "from ?\"[^\"]+\"" "$tmp/module.js" | sed -E 's/^from ?/from /'
      grep -oE "import\((['\"])\./[^'\"]+['\"]\)" "$tmp/module.js" | sed -E "s/^import\(/import /; s/\)$//"
    } | sed -E "s/^(from|import)[[:space:]]*['\"]//; s/['\"]$//" | sort -u)
  done
  # libs/draco/ holds Draco's decoder, which DRACOLoader fetches at run time (not an import).
  installed=$(cd "$web" && find . -name '*.js' -not -path './node_modules/three/examples/jsm/libs/draco/*' |
    sed 's/^\.//' | sort)
  for f in draco_wasm_wrapper.js draco_decoder.wasm; do
    fetch "/node_modules/three/examples/jsm/libs/draco/gltf/$f" "$tmp/decoder" && ok || fail "GET Draco's $f failed"
  done
  imported=$(printf '%s\n' "${!seen[@]}" | sort)
  [[ $installed == "$imported" ]] && ok ||
    fail "installed modules and imported ones differ: $(diff <(echo "$installed") <(echo "$imported") | grep '^[<>]' | tr '\n' ' ')"
  # Nothing else under share/: the two pages, the licences of three.js and 3d-tiles-renderer and
  # Draco's decoder (fetched above).
  others=$(cd "$web" && find . -type f -not -name '*.js' | sed 's/^\.//' | sort | tr '\n' ' ')
  [[ $others == "/edit.html /index.html /node_modules/3d-tiles-renderer/LICENSE /node_modules/three/LICENSE /node_modules/three/examples/jsm/libs/draco/gltf/draco_decoder.wasm " ]] &&
    ok || fail "share/tailor/web holds other files than the pages, the modules and the licence: $others"
  echo "tailor view served the installed viewer: ${#seen[@]} modules"
fi
kill -INT "$server_pid" 2>/dev/null
wait "$server_pid" 2>/dev/null
server_pid=""

# --- 5. shared libraries ---
shared_build=$build/install-test-shared
shared=$tmp/shared
# The build's compiler, launcher, unity batches and warning flags (the Makefile's build sets no
# other): with ccache (the Makefile's default) the libraries' objects, the same in both builds,
# come from its cache.
cached() { sed -n "s/^$1:[A-Z]*=//p" "$build/CMakeCache.txt"; }
start=$SECONDS
if cmake -S "$repo" -B "$shared_build" -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=ON \
  -DTAILOR_BUILD_TESTS=OFF -DTAILOR_BUILD_BENCH=OFF -DCMAKE_CXX_COMPILER="$(cached CMAKE_CXX_COMPILER)" \
  -DCMAKE_CXX_COMPILER_LAUNCHER="$(cached CMAKE_CXX_COMPILER_LAUNCHER)" \
  -DTAILOR_UNITY_BUILD="$(unity=$(cached TAILOR_UNITY_BUILD); echo "${unity:-ON}")" \
  -DTAILOR_WERROR="$(werror=$(cached TAILOR_WERROR); echo "${werror:-OFF}")" >"$tmp/shared.log" 2>&1 &&
  cmake --build "$shared_build" -j "$jobs" --target tailor_core tailor_texture tailor_render >>"$tmp/shared.log" 2>&1 &&
  cmake --install "$shared_build" --component library --prefix "$shared" >>"$tmp/shared.log" 2>&1; then
  ok
  echo "shared libraries built and installed in $((SECONDS - start)) s"
else
  fatal "the shared libraries do not build or install: $(tail -20 "$tmp/shared.log")"
fi
for lib in core texture render; do
  [[ -f $shared/lib/libtailor_$lib.so ]] && ok || fail "not installed: lib/libtailor_$lib.so"
done
[[ ! -e $shared/bin/tailor ]] && ok || fail "--component library installed the tailor command"
if cmake -S examples/consumer -B "$tmp/consumer-shared" -DCMAKE_PREFIX_PATH="$shared" >"$tmp/cmake-shared.log" 2>&1 &&
  cmake --build "$tmp/consumer-shared" -j "$jobs" >>"$tmp/cmake-shared.log" 2>&1; then
  ok
  # ldd's output is read whole first: with pipefail, grep -q stopping early would make ldd fail
  # with SIGPIPE now and then.
  linked=$(ldd "$tmp/consumer-shared/consumer")
  grep -q "libtailor_core\.so.* => $shared/lib/" <<<"$linked" && ok ||
    fail "the consumer is not linked to $shared/lib/libtailor_core.so: $linked"
  run_consumer consumer-shared "$tmp/consumer-shared/consumer"
else
  fail "examples/consumer does not build with the shared libraries: $(tail -20 "$tmp/cmake-shared.log")"
fi
# The texture and render libraries export their API too (pkg-config, shared: no --static).
cat >"$tmp/all_libs.cpp" <<'EOF'
#include <cstdio>
#include "tailor/tailor.h"
int main() {
  tailor::Image image{64, 32, 1, std::vector<uint8_t>(64 * 32, 7)};
  const tailor::Image swapped = tailor::swap_quadrants(image);  // tailor::texture
  tailor::PreviewView view;
  const bool parsed = tailor::preview_view_from_name("patches", view);  // tailor::render
  std::printf("%d %d %s\n", swapped.width, parsed, tailor::preview_view_name(view));
  return tailor::check_image(swapped).is_ok() ? 0 : 1;  // tailor::core
}
EOF
if PKG_CONFIG_PATH=$shared/lib/pkgconfig g++ -std=c++20 "$tmp/all_libs.cpp" \
  $(PKG_CONFIG_PATH=$shared/lib/pkgconfig pkg-config --cflags --libs tailor) -Wl,-rpath,"$shared/lib" \
  -o "$tmp/all_libs" >"$tmp/all_libs.log" 2>&1; then
  [[ $("$tmp/all_libs") == "64 1 patches" ]] && ok || fail "the program using all three shared libraries: $("$tmp/all_libs" 2>&1)"
  [[ $(ldd "$tmp/all_libs" | grep -c "libtailor_[a-z]*\.so.* => $shared/lib/") -eq 3 ]] && ok ||
    fail "not linked to the three shared libraries: $(ldd "$tmp/all_libs")"
else
  fail "a program using all three shared libraries does not link: $(tail -20 "$tmp/all_libs.log")"
fi

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
