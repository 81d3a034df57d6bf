#!/usr/bin/env bash
# Start-up of a parrender process (issue-level benchmark, not part of the test suite): the
# median wall time of 21 runs of commands that touch no image (--help, info, simulate) and of
# a small render that writes a PNG, each run as built (the image codec module opened on first
# use, in the background while the render runs) and with the codec forced in at start
# (LD_PRELOAD of the module: what every process paid when OpenImageIO was linked in), the
# baseline measured in the same run. Target: under 50 ms for commands that touch no image.
# Usage: tools/bench/startup.sh [build-dir]
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
parrender="$build/tools/parrender"
codec="$build/lib/libparrender_image_codec.so"
[ -x "$parrender" ] && [ -f "$codec" ] || { echo "startup: build parrender first ($parrender, $codec)" >&2; exit 2; }
scene="$root/scenes/cornell.gltf"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
"$parrender" render "$scene" -m sort-middle --width 8 --height 8 --threads 1 --quiet -o "$out/warm.png" --metrics "$out/run.json" >/dev/null

median_ms() {  # command... -> median wall milliseconds of 21 runs
  python3 - "$@" <<'PY'
import subprocess, sys, time
times = []
for _ in range(21):
    t = time.perf_counter()
    subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    times.append((time.perf_counter() - t) * 1000.0)
print(f"{sorted(times)[len(times) // 2]:.1f}")
PY
}

verdict=0
printf "%-34s %10s %14s %7s\n" command "lazy_ms" "codec_at_start" ratio
for name in help info simulate render; do
  case "$name" in
    help) args=(--help) ;;
    info) args=(info "$scene") ;;
    simulate) args=(simulate "$out/run.json" --pes 1,2,4) ;;
    render) args=(render "$scene" -m sort-middle --width 64 --height 64 --threads 1 --quiet -o "$out/r.png") ;;
  esac
  lazy=$(median_ms "$parrender" "${args[@]}")
  eager=$(median_ms env LD_PRELOAD="$codec" "$parrender" "${args[@]}")
  ratio=$(python3 -c "print(f'{$lazy / $eager:.2f}')")
  note=""
  if [ "$name" != render ]; then
    if python3 -c "import sys; sys.exit(0 if $lazy < 50 else 1)"; then note="PASS (< 50 ms)"; else note="FAIL (>= 50 ms)"; verdict=1; fi
  fi
  printf "%-34s %10s %14s %7s  %s\n" "parrender $name" "$lazy" "$eager" "$ratio" "$note"
done
exit $verdict
