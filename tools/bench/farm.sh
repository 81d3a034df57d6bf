#!/usr/bin/env bash
# The render farm (render --farm) on this machine (issue-level benchmark, not part of the test
# suite): the hot-spot scene with the photon map, rendered by a master and 1 server and by a
# master and S servers (default 2) of one PE each, then at S servers with the seed paper's two
# job sizes, 32x24 and 40x30; each the fastest of --rounds rounds. Figures from the farm's run
# record: the jobs stage's wall (the part that servers share) and the whole farm's (with the
# pre-passes every server runs itself, which do not shrink with S). Speed-up: 1 server's jobs
# wall over S servers'. On a machine of C cores, S + 1 processes share them. Beside them, the
# simulator's prediction from the S-server record (parrender simulate on a farm record): the
# jobs stage at S servers (against the measured one) and at 30 servers on a 100 Mbit network,
# the seed paper's farm.
# Usage: tools/bench/farm.sh [build-dir] [servers] [rounds]
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
servers="${2:-2}"
rounds="${3:-3}"
parrender="$build/tools/parrender"
[ -x "$parrender" ] || { echo "farm: build parrender first ($parrender)" >&2; exit 2; }
command -v mpirun >/dev/null || { echo "farm: mpirun not found (bash tools/setup.sh installs Open MPI)" >&2; exit 2; }
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
scene="$root/scenes/hotspot.gltf"
common=(render "$scene" --integrator photonmap --width "${FARM_WIDTH:-320}" --height "${FARM_HEIGHT:-240}" --farm --quiet)

# run SERVERS JOB -> "jobs_wall farm_wall" of the fastest round (by jobs wall)
run() {
  local best="" line
  for _ in $(seq "$rounds"); do
    mpirun --oversubscribe --enable-recovery -np $(($1 + 1)) "$parrender" "${common[@]}" --farm-job "$2" \
      -o "$out/image.png" --metrics "$out/run.json" --farm-status "$out/status" >/dev/null 2>&1 || true
    [ "$(cat "$out/status" 2>/dev/null)" = 0 ] || { echo "farm: the run with $1 server(s), jobs $2, failed" >&2; exit 1; }
    line="$(python3 -c "
import json, sys
r = json.load(open(sys.argv[1]))
print('%.3f %.3f' % (r['stages'][1]['wallSeconds'], r['farm']['wallSeconds']))" "$out/run.json")"
    if [ -z "$best" ] || python3 -c "import sys; sys.exit(0 if float(sys.argv[1]) < float(sys.argv[2]) else 1)" "${line%% *}" "${best%% *}"; then
      best="$line"
      cp "$out/run.json" "$out/best_$1_$2.json"
    fi
  done
  echo "$best"
}

printf "%-8s %-7s %12s %12s\n" servers job "jobs_wall_s" "farm_wall_s"
one="$(run 1 32x24)"
printf "%-8s %-7s %12s %12s\n" 1 32x24 $one
for job in 32x24 40x30; do
  many="$(run "$servers" "$job")"
  printf "%-8s %-7s %12s %12s\n" "$servers" "$job" $many
  [ "$job" = 32x24 ] && speedup="$(python3 -c "import sys; print('%.2f' % (float(sys.argv[1]) / float(sys.argv[2])))" "${one%% *}" "${many%% *}")"
done
echo "speed-up of $servers servers over 1 (jobs stage, 32x24): $speedup"
echo "simulator, from the $servers-server record (32x24), network 100mbit:"
"$parrender" simulate "$out/best_${servers}_32x24.json" --pes "1,$servers,30" --network 100mbit | sed -n '3p;5,9p'

