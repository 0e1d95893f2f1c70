#!/usr/bin/env bash
# The Makefile's two user commands, as `make -n` prints them (nothing is run): `make run` builds only
# the tailor command before mapping the example (a fresh clone must not wait for every test binary,
# benchmark and tool), `make test` builds everything, then runs the tests.
#   bash tests/makefile_test.sh <build-dir>/tailor   (ctest; the argument is not used)
set -uo pipefail
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$repo"
passed=0
failed=0
ok() { passed=$((passed + 1)); }
fail() { failed=$((failed + 1)); echo "FAIL: $*"; }

build=/nonexistent-build-dir
run=$(make -n run BUILD_DIR=$build JOBS=2 2>&1) || fail "make -n run failed: $run"
builds=$(grep -E '^cmake --build ' <<<"$run")
[[ $builds == "cmake --build $build -j 2 --target tailor" ]] && ok ||
  fail "make run does not build only the tailor target: '$builds'"
grep -q "$build/tailor map examples/" <<<"$run" && ok || fail "make run does not map the example: $run"
test=$(make -n test BUILD_DIR=$build JOBS=2 2>&1) || fail "make -n test failed: $test"
builds=$(grep -E '^cmake --build ' <<<"$test")
[[ $builds == "cmake --build $build -j 2" ]] && ok || fail "make test does not build every target: '$builds'"
grep -q "ctest" <<<"$test" && ok || fail "make test runs no ctest: $test"

echo "$passed passed, $failed failed"
[[ $failed -eq 0 ]]
