#!/usr/bin/env bash
# ThreadSanitizer job for the parallel runtime (common/parallel): configures its own build
# directory with -DPARRENDER_SANITIZE=thread, builds parrender_tests from the test files that
# hold the runtime's test cases (below), and runs those cases only. Any ThreadSanitizer report
# stops the run with a non-zero status (halt_on_error=1), so CI fails on the first data race.
# Usage: tools/ci/tsan.sh [build-dir]   (default: build-tsan next to the sources; JOBS=2)
set -euo pipefail

source_dir="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build_dir="${1:-$source_dir/build-tsan}"
jobs="${JOBS:-2}"

# Every runtime test case starts with one of these concept names (tests/common/parallel), plus
# RayBatches and CachedImageSpace (raytrace/partition): the partitioned tracers with batched
# rays, the data-managed tracer with latency hiding; TilePull
# (raster/sort): PEs waiting on each other's messages inside a task, and the abort;
# GatherToRoot and PhotonPass (photonmap): per-PE results written during a pre-pass program
# in every tracer and merged on PE 0; TileAffinity (raytrace/partition): probe hits sent to PE 0
# in the build stage; ObjectSpace (raytrace/partition): owners building their BVHs as the trace
# stage's set-up while the other PEs already trace and send them rays; RankStage
# (common/parallel): ranks in one process, their controlling threads passing messages;
# SortFirst (raster/sort): PEs installing what they receive into their own copies of the scene;
# Farm (common/parallel): a farm's master and servers on threads, passing messages.
runtime_tests="Scheduler*,DemandPool*,DataDriven*,DemandDriven*,Hybrid*,TaskManager*,Distributed*,PreferredBias*,Runtime*,Channel*,BatchedChannel*,RayBatches*,CachedImageSpace*,Termination*,Simulator*,Metrics*,RunRecord*,DataManager*,RunOptions*,TilePull*,GatherToRoot*,PhotonPass*,TileAffinity*,ObjectSpace*,RankStage*,SortFirst*,Farm*"

# The test program is built from the files that hold those cases alone (PARRENDER_TEST_FILES),
# not from the whole suite and the parrender program: a case that needs the program is left out.
# doctest's -tc is case-insensitive: so is the search.
pattern="^[[:space:]]*TEST_CASE[A-Z_]*\\([[:space:]]*\"($(echo "$runtime_tests" | sed 's/\*//g; s/,/|/g'))"
files=$(cd "$source_dir/tests" && grep -rliE --include='*_test.cpp' "$pattern" . | sed 's|^\./||' | sort | paste -sd';') || files=
[ -n "$files" ] || { echo "tsan: no test file holds the runtime's cases" >&2; exit 1; }
without_program="Simulator: parrender simulate*"

cmake -S "$source_dir" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARRENDER_SANITIZE=thread \
  "-DPARRENDER_TEST_FILES=$files"
cmake --build "$build_dir" -j"$jobs" --target parrender_tests

export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 ${TSAN_OPTIONS:-}"
# Every concept name must name at least one case of the program, or its file was not found.
IFS=, read -ra concepts <<<"$runtime_tests"
for concept in "${concepts[@]}"; do
  listed=$("$build_dir/tests/parrender_tests" -ltc -tc="$concept")
  grep -q "^${concept%\*}" <<<"$listed" ||
    { echo "tsan: no test case '$concept' in the program built from: $files" >&2; exit 1; }
done
"$build_dir/tests/parrender_tests" -tc="$runtime_tests" -tce="$without_program"
echo "tsan: runtime tests passed with no ThreadSanitizer report"
