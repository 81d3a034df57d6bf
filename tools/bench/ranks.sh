#!/usr/bin/env bash
# The transport's cost on whole renders (issue-level benchmark, not part of the test suite):
# every method on the hot-spot scene and, when it exists, the landscape, rendered by R = 2 ranks
# of one PE (mpirun on this machine) against the thread runtime at P = 2 in the same run, each
# the fastest of --rounds rounds taking turns. The figure is the run record's wall time (first
# stage start to last stage end: the render, not the processes' start-up). Target: within
# 1.25x for image-space and the sort points. The sort points render an orbit of RANKS_FRAMES
# frames (default 8; the first frame distributes the scene), as an animation would. A method
# that does not run across ranks says so.
# Usage: tools/bench/ranks.sh [build-dir] [rounds]   (RANKS_METHODS="m1 m2 ..." picks methods)
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
rounds="${2:-3}"
parrender="$build/tools/parrender"
[ -x "$parrender" ] || { echo "ranks: build parrender first ($parrender)" >&2; exit 2; }
command -v mpirun >/dev/null || { echo "ranks: mpirun not found (bash tools/setup.sh installs Open MPI)" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

scenes=("$root/scenes/hotspot.gltf")
[ -f "$build/scenes/landscape.glb" ] && scenes+=("$build/scenes/landscape.glb")

wall() {  # run-record JSON -> its wall seconds
  python3 -c "import json, sys; print(json.load(open(sys.argv[1]))['wallSeconds'])" "$1"
}

verdict=0
printf "%-14s %-20s %-9s %12s %12s %7s\n" scene method schedule "threads_s" "ranks_s" ratio
for scene in "${scenes[@]}"; do
  name="$(basename "$scene")"
  for method in ${RANKS_METHODS:-image-space image-space-cached object-space object sort-first sort-middle sort-last}; do
    for schedule in demand balanced; do
      args=(render "$scene" -m "$method" --width 512 --height 512 --schedule "$schedule" --quiet -o "$out/image.png")
      [[ "$method" == sort-* ]] && args+=(--frames "${RANKS_FRAMES:-8}" --orbit)
      best_threads=""
      best_ranks=""
      refused=""
      for ((round = 0; round < rounds; round++)); do
        "$parrender" "${args[@]}" --threads 2 --metrics "$out/threads.json" >/dev/null
        if ! mpirun --oversubscribe -np 2 "$parrender" "${args[@]}" --threads 1 --metrics "$out/ranks.json" \
            >"$out/ranks.txt" 2>&1; then
          refused="$(grep -o "does not run across processes" "$out/ranks.txt" | head -1 || true)"
          [ -n "$refused" ] || { cat "$out/ranks.txt" >&2; exit 1; }
          break
        fi
        t=$(wall "$out/threads.json")
        r=$(wall "$out/ranks.json")
        best_threads=$(python3 -c "print(min(float('$t'), float('${best_threads:-inf}')))")
        best_ranks=$(python3 -c "print(min(float('$r'), float('${best_ranks:-inf}')))")
      done
      if [ -n "$refused" ]; then
        printf "%-14s %-20s %-9s %s\n" "$name" "$method" "$schedule" "does not run across ranks"
        break
      fi
      ratio=$(python3 -c "print(f'{$best_ranks / $best_threads:.2f}')")
      note=""
      if [ "$method" = image-space ] || [[ "$method" == sort-* ]]; then
        if python3 -c "import sys; sys.exit(0 if $ratio <= 1.25 else 1)"; then note="PASS (<= 1.25)"; else note="FAIL (> 1.25)"; verdict=1; fi
      fi
      printf "%-14s %-20s %-9s %12.4f %12.4f %7s  %s\n" "$name" "$method" "$schedule" "$best_threads" "$best_ranks" "$ratio" "$note"
    done
  done
done
exit $verdict
