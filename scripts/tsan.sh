#!/usr/bin/env bash
# The threaded stages under ThreadSanitizer: the crack closing (bands of seed distance zipped at
# once, which must never touch the same vertex), the metrics' and the orientation's chunked
# passes, the integer-grid map's field and relaxation (symmetry 4), the export's second thread,
# the chunked engine (one chunk per thread, progress from every worker) and the edit session's
# chunk updates (the touched chunks on parallel threads), and the topology's slices of vertices
# and faces.
#
#   scripts/tsan.sh   # make tsan
#
# Configures build-tsan (-DTAILOR_TSAN=ON: -fsanitize=thread on the scalar paths), builds the
# tests that run those stages on several threads and the tailor binary, runs the thread-count
# tests, then maps three shared meshes with 4 threads. Any race report fails the run (exit 1).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
build="$root/build-tsan"
jobs="${JOBS:-2}"
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1"

# Line tables only (-g1): a race report names files and lines; full debug information made the
# build ~20 % longer.
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -g1 -DNDEBUG" \
  -DTAILOR_TSAN=ON -DTAILOR_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$jobs" --target tailor mapping_test metrics_test orientation_test chunks_test edit_session_test topology_test >/dev/null

"$build/mapping_test" --gtest_brief=1 --gtest_filter='Mapping.CrackClosingIsTheSameOnAnyThreadCount:Mapping.RelaxationLowersAngleDistortion:Mapping.ProgressCanCancel:Mapping.SymmetryFourGivesInvisibleSeams'
"$build/metrics_test" --gtest_brief=1 --gtest_filter='Metrics.ThreadCountDoesNotChangeAnyFigure:Metrics.LargeMeshesGiveTheSameFiguresOnAnyThreadCount'
"$build/orientation_test" --gtest_brief=1
"$build/chunks_test" --gtest_brief=1 --gtest_filter='ChunkPlan.SameForAnyThreadCountWithTheExactMedian:ChunkedMapping.SameBitsForAnyThreadCountAndQualityKept:ChunkedMapping.CancelsAndRefusesWhatNeedsTheWholeMesh'
"$build/edit_session_test" --gtest_brief=1 --gtest_filter='EditSession.ChunkedLocalUpdatesAreTheSameForAnyThreadCount'
"$build/topology_test" --gtest_brief=1
tmp="$(mktemp -d "${TMPDIR:-/tmp}/tailor-tsan.XXXXXX")"
trap 'rm -rf "$tmp"' EXIT
for mesh in horse.ply fertility.off blobby-3cc.off; do
  "$build/tailor" map "$root/tests/data/meshes/$mesh" -o "$tmp/out.glb" --threads 4 --quiet
  echo "tsan: map $mesh with 4 threads ok"
done
"$build/tailor" map "$root/tests/data/meshes/horse.ply" -o "$tmp/out.glb" --chunks on --chunk-cell -4 --threads 4 --quiet
echo "tsan: map horse.ply in chunks with 4 threads ok"
echo "tsan: no data race"
