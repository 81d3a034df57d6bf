#!/usr/bin/env bash
# ThreadSanitizer job for the parallel runtime (common/parallel): configures its own build
# directory with -DPARRENDER_SANITIZE=thread, builds parrender_tests, and runs the runtime's
# test cases only. Any ThreadSanitizer report stops the run with a non-zero status
# (halt_on_error=1), so CI fails on the first data race.
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

cmake -S "$source_dir" -B "$build_dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARRENDER_SANITIZE=thread
cmake --build "$build_dir" -j"$jobs" --target parrender_tests

export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 ${TSAN_OPTIONS:-}"
"$build_dir/tests/parrender_tests" -tc="$runtime_tests"
echo "tsan: runtime tests passed with no ThreadSanitizer report"
