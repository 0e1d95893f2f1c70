#!/usr/bin/env bash
# Every installed public header compiles alone: run by ctest from the repo root as
#   bash tests/headers_test.sh <build-dir>/tailor
# Installs the `library` component of that build into a temporary prefix, then compiles one
# translation unit per installed include/tailor/*.h, the header on its first line and nothing else,
# with only the prefix's include folder, in C++20 with -Wall -Wextra -Werror (the build's compiler).
# A header that leans on something its includer happened to include first (size_t without
# <cstddef>, printf without <cstdio>...) fails here.
set -uo pipefail
tailor=${1:?usage: headers_test.sh <build-dir>/tailor}
build=$(cd "$(dirname "$tailor")" && pwd)
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"

tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
prefix=$tmp/prefix
compiler=$(sed -n 's/^CMAKE_CXX_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
compiler=${compiler:-c++}

if ! cmake --install "$build" --component library --prefix "$prefix" >"$tmp/install.log" 2>&1; then
  echo "FAIL: cmake --install --component library: $(tail -20 "$tmp/install.log")"
  exit 1
fi
include=$(find "$prefix" -type d -path '*/include/tailor' | head -1)
if [[ -z $include ]]; then
  echo "FAIL: no include/tailor under the prefix"
  exit 1
fi
mapfile -t headers < <(cd "$include" && ls -- *.h | sort)
# The installed set is the source tree's include/tailor/*.h (version.h among them).
expected=$( (cd include/tailor && ls -- *.h) | sort -u)
if [[ $(printf '%s\n' "${headers[@]}") != "$expected" ]]; then
  echo "FAIL: installed headers differ from include/tailor/*.h:" \
    "$(diff <(echo "$expected") <(printf '%s\n' "${headers[@]}") | grep '^[<>]' | tr '\n' ' ')"
  exit 1
fi

mkdir -p "$tmp/tu"
for h in "${headers[@]}"; do
  printf '#include "tailor/%s"\n' "$h" >"$tmp/tu/${h%.h}.cpp"
done
# One compiler per header, two at a time; each writes NAME.log, kept when it fails.
include_root=$(dirname "$include")
export compiler include_root
# shellcheck disable=SC2016
printf '%s\n' "${headers[@]}" | xargs -P 2 -I{} bash -c '
  h={}; tu=${0}/tu/${h%.h}
  if "$compiler" -std=c++20 -Wall -Wextra -Werror -fsyntax-only -I"$include_root" "$tu.cpp" >"$tu.log" 2>&1; then
    rm -f "$tu.log"
  fi' "$tmp"

failed=0
for h in "${headers[@]}"; do
  log=$tmp/tu/${h%.h}.log
  if [[ -f $log ]]; then
    failed=$((failed + 1))
    echo "FAIL: tailor/$h does not compile alone:"
    head -15 "$log"
  fi
done
echo "${#headers[@]} installed headers, $failed failed to compile alone"
[[ $failed -eq 0 ]]
