#!/usr/bin/env bash
# Builds the libFuzzer targets (tests/fuzz: clang, coverage, AddressSanitizer + UBSan) in
# build-fuzz and runs each for a bounded time or number of executions, then prints one line
# per target: executions, coverage, corpus, and the crashes, hangs, out-of-memory and leak
# reports found (their inputs are kept under build-fuzz/artifacts/TARGET/, the previous run's
# under TARGET.previous/). Exit status 1 when any target found one.
#   tools/fuzz.sh                        every target for 60 s (the CI job)
#   tools/fuzz.sh --seconds 600 render   one target for 10 minutes
#   tools/fuzz.sh --runs 10000000 gltf_loader   a campaign of 10 million executions
# The corpus grows in build-fuzz/corpus/TARGET from the seeds: tests/fuzz/corpus, the bundled
# scenes/, the shared sample models of up to 1 MiB (when ../shared/scenes is there) and the
# committed regression inputs tests/fuzz/regressions/TARGET.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${PARRENDER_FUZZ_BUILD_DIR:-$root/build-fuzz}
seconds=60
runs=-1
targets=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) seconds=$2; shift 2 ;;
    --runs) runs=$2; seconds=0; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    gltf_loader|render|run_record) targets+=("$1"); shift ;;
    *) echo "fuzz: unknown argument '$1' (targets: gltf_loader, render, run_record; options: --seconds N, --runs N)" >&2; exit 2 ;;
  esac
done
[ ${#targets[@]} -gt 0 ] || targets=(gltf_loader render run_record)

bash "$root/tools/setup.sh" --fuzz
CC=clang CXX=clang++ cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARRENDER_FUZZ=ON >/dev/null
cmake --build "$build" -j"$(nproc)" --target fuzzers

# Seeds outside the repository's own corpus: the bundled scenes and the small shared models.
seeds="$build/seeds"
rm -rf "$seeds"
mkdir -p "$seeds/gltf"
cp "$root"/tests/fuzz/corpus/gltf/* "$root"/scenes/*.gltf "$seeds/gltf/"
shared=${PARRENDER_SCENES:-$root/../shared/scenes}
if [ -d "$shared" ]; then
  find "$shared" -type f \( -name '*.gltf' -o -name '*.glb' \) -size -1024k -print0 |
    while IFS= read -r -d '' f; do cp "$f" "$seeds/gltf/$(echo "${f#"$shared"/}" | tr '/ ' '__')"; done
fi

status=0
for target in "${targets[@]}"; do
  corpus="$build/corpus/$target" artifacts="$build/artifacts/$target"
  # Each run reports its own findings: an earlier run's are moved aside, not counted again.
  if [ -d "$artifacts" ] && [ -n "$(ls -A "$artifacts")" ]; then
    rm -rf "$artifacts.previous" && mv "$artifacts" "$artifacts.previous"
  fi
  mkdir -p "$corpus" "$artifacts"
  inputs=("$corpus")
  case "$target" in
    run_record) inputs+=("$root/tests/fuzz/corpus/run_record"); dict=(); max_len=65536 ;;
    # Inputs up to 16 KiB: five times the executions per second of 128 KiB ones; the larger
    # seeds are read truncated (and replayed whole by the normal suite).
    *) inputs+=("$seeds/gltf"); dict=(-dict="$root/tests/fuzz/gltf.dict"); max_len=16384 ;;
  esac
  [ -d "$root/tests/fuzz/regressions/$target" ] && inputs+=("$root/tests/fuzz/regressions/$target")
  limit=(-max_total_time="$seconds")
  [ "$runs" -ge 0 ] && limit=(-runs="$runs")
  log="$build/fuzz_$target.log"
  echo "== fuzz_$target: ${limit[*]}, corpus $corpus"
  set +e
  # -timeout: an input running 20 s is a hang; -rss_limit_mb: over 2 GiB is out of memory
  # (the targets load under a 256 MiB --max-memory); leaks are reported as well.
  ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    "$build/tests/fuzz/fuzz_$target" "${inputs[@]}" "${dict[@]}" "${limit[@]}" -max_len=$max_len -timeout=20 \
    -rss_limit_mb=2048 -print_final_stats=1 -artifact_prefix="$artifacts/" >"$log" 2>&1
  rc=$?
  set -e
  found=$(find "$artifacts" -type f | wc -l)
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || echo 0)
  per_second=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$log" | tail -1 | grep -o '[0-9]*$' || echo 0)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  cov=$(echo "$last" | grep -o 'cov: [0-9]*' | grep -o '[0-9]*' || echo 0)
  ft=$(echo "$last" | grep -o 'ft: [0-9]*' | grep -o '[0-9]*' || echo 0)
  corp=$(echo "$last" | grep -o 'corp: [0-9]*' | grep -o '[0-9]*' || echo 0)
  count() { find "$artifacts" -type f -name "$1-*" | wc -l; }
  echo "fuzz_$target: $execs executions ($per_second/s), coverage $cov edges, $ft features, corpus $corp;" \
       "crashes $(count crash), hangs $(count timeout), out-of-memory $(count oom), leaks $(count leak) (log $log)"
  if [ "$rc" -ne 0 ] || [ "$found" -ne 0 ]; then
    status=1
    grep -E 'ERROR|SUMMARY|broken invariant|internal check' "$log" | head -5 || true
  fi
done
exit $status
