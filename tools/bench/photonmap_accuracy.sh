#!/usr/bin/env bash
# The photon map's accuracy target (issue-level benchmark, not part of the test suite): on the
# bundled Cornell box with a glass and a diffuse sphere (scenes/cornell-glass.gltf), 256x256,
# P = 2, against a 4096-spp path-traced reference rendered in the same run (cached), the CPU
# time the photon map needs to reach the RMSE of the path tracer's 64-spp image, as a fraction
# of the path tracer's own CPU time for that image (target: at most 1/3). Both curves come from
# one `parrender sweep`, the path tracer's 64-spp row being the baseline measured in the run.
# Usage: tools/bench/photonmap_accuracy.sh [build-dir] [extra sweep options...]
# PHOTONMAP_ACCURACY_SIZE=512 measures at 512x512, the default image size of `render`, instead.
# The reference (about 5 CPU minutes at 256x256, four times that at 512x512) is cached in
# <build-dir>/bench-references.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
shift || true
parrender="$build/tools/parrender"
scene="$root/scenes/cornell-glass.gltf"
size="${PHOTONMAP_ACCURACY_SIZE:-256}"
out="$build/bench-photonmap-accuracy-$size"
mkdir -p "$out"
[ -x "$parrender" ] || { echo "photonmap_accuracy: build parrender first ($parrender not found)" >&2; exit 2; }

# The photon map at its defaults, and with its pre-pass sized to this image (a quarter of the
# photons, a quarter of the gather rays: at 256x256 the image's own noise, not the maps',
# dominates its RMSE, which the default pre-pass leaves the same, see the README).
"$parrender" sweep "$scene" --width "$size" --height "$size" --threads 2 --integrator photonmap,path --vary spp \
  --values 4,8,16,32 --path-spp 16,64,256 --reference-spp 4096 --reference-dir "$build/bench-references" \
  --images "$out/images" --json "$out/sweep.json" --csv "$out/sweep.csv" "$@"
"$parrender" sweep "$scene" --width "$size" --height "$size" --threads 2 --integrator photonmap --vary spp \
  --values 4,8,16 --photons 50000 --caustic-photons 50000 --gather 64 --reference-spp 4096 \
  --reference-dir "$build/bench-references" --json "$out/sweep_sized.json" --csv "$out/sweep_sized.csv" "$@"
python3 - "$out/sweep.json" "$out/sweep_sized.json" <<'PY'
import json, math, sys
j = json.load(open(sys.argv[1]))
sized = json.load(open(sys.argv[2]))
def curve(rows, integrator):
    # by the varied setting (spp): CPU time and RMSE both follow it
    return sorted((r["value"], r["cpuSeconds"], r["rmse"]) for r in rows if r["integrator"] == integrator)
def cpu_to(points, target):
    # log-log interpolation between the two renders around the target RMSE
    if points and points[0][2] <= target:
        return points[0][1]
    for (_, t0, e0), (_, t1, e1) in zip(points, points[1:]):
        if e0 > target >= e1:
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return None
path64 = next(r for r in j["rows"] if r["integrator"] == "path" and r["value"] == 64)
print(f"path        64 spp: {path64['cpuSeconds']:6.2f} CPU s, RMSE {path64['rmse']:.4f} (the baseline)")
verdict = 1
for name, rows in (("defaults", j["rows"]), ("50k + 50k photons, 64 gather rays", sized["rows"])):
    pm = curve(rows, "photonmap")
    for v, t, e in pm:
        print(f"photonmap {int(v):>3} spp ({name}): {t:6.2f} CPU s, RMSE {e:.4f}")
    t = cpu_to(pm, path64["rmse"])
    if t is None:
        print(f"photon map ({name}) never reached the path tracer's 64-spp RMSE")
        continue
    ratio = t / path64["cpuSeconds"]
    ok = ratio <= 1 / 3
    verdict = 0 if ok else verdict
    print(f"photon map ({name}) to the path tracer's 64-spp RMSE: {t:.2f} CPU s, {ratio:.2f} of the path tracer's time "
          f"(target at most 0.33): {'PASS' if ok else 'FAIL'}")
sys.exit(verdict)
PY
