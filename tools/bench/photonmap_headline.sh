#!/usr/bin/env bash
# The seed's headline for the photon map (issue-level benchmark, not part of the test suite):
# on the bundled Cornell box with glass at 256x256,
#   1. the CPU time the photon-map integrator and the path tracer need to reach the same RMSE
#      against a long path-traced reference (parrender sweep, both curves in one run; bar 3x,
#      goal 5x), and the caustic region's error of each at about equal time;
#   2. the parallel efficiency of pass 1 (photon tracing, kd-trees, precomputed irradiance)
#      and pass 2 (irradiance cache and the render) at P = 2 against P = 1 in the same run;
#   3. the simulator's prediction out to 1024 PEs from the P = 2 run record, the maps' and the
#      cache's broadcast charged on the chosen network.
# Usage: tools/bench/photonmap_headline.sh [build-dir] [network]   (default: ./build, 10gbe)
# The reference (4096 spp, about 5 CPU minutes) is cached in <build-dir>/bench-references.
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
network="${2:-10gbe}"
parrender="$build/tools/parrender"
scene="$root/scenes/cornell.gltf"
out="$build/bench-photonmap"
mkdir -p "$out"
[ -x "$parrender" ] || { echo "photonmap_headline: build parrender first ($parrender not found)" >&2; exit 2; }

echo "== 1. accuracy against time (photonmap vs path, one sweep)"
"$parrender" sweep "$scene" --width 256 --height 256 --threads 2 --integrator photonmap,path --vary spp \
  --values 4,16,64 --path-spp 16,64,256,1024 --reference-spp 4096 --reference-dir "$build/bench-references" \
  --images "$out/images" --json "$out/sweep.json" --csv "$out/sweep.csv"
python3 - "$out/sweep.json" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
t = j["cpuSecondsToTarget"]
pm, path = t.get("photonmap"), t.get("path")
print(f"target RMSE {j['targetRmse']:.5f}: photonmap {pm:.2f} CPU s, path {path:.2f} CPU s" if pm and path else "target not reached by both")
if pm and path:
    ratio = path / pm
    print(f"speed-up of the photon map at equal RMSE: {ratio:.1f}x (bar 3x, goal 5x): {'PASS' if ratio >= 3 else 'FAIL'}")
rows = j["rows"]
def cpu_to(integrator, target):
    pts = sorted((r["cpuSeconds"], r["rmse"]) for r in rows if r["integrator"] == integrator)
    for (t0, e0), (t1, e1) in zip(pts, pts[1:]):
        if e0 > target >= e1:
            import math
            f = (math.log(target) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(t0) + f * (math.log(t1) - math.log(t0)))
    return pts[0][0] if pts and pts[0][1] <= target else None
path256 = next((r for r in rows if r["integrator"] == "path" and r["value"] == 256), None)
if path256:
    a, b = cpu_to("photonmap", path256["rmse"]), path256["cpuSeconds"]
    if a:
        print(f"at the path tracer's 256-spp RMSE {path256['rmse']:.5f}: photonmap {a:.2f} CPU s, path {b:.2f} CPU s, {b / a:.1f}x")
best = max((r for r in rows if r["integrator"] == "photonmap"), key=lambda r: r["cpuSeconds"])
near = min((r for r in rows if r["integrator"] == "path"), key=lambda r: abs(r["cpuSeconds"] - best["cpuSeconds"]))
print(f"caustic region ({j['causticPixels']} px) at about equal time: photonmap {best['causticRmse']:.4f} "
      f"({best['cpuSeconds']:.1f} s) vs path {near['causticRmse']:.4f} ({near['cpuSeconds']:.1f} s): "
      f"{near['causticRmse'] / max(best['causticRmse'], 1e-12):.1f}x lower")
PY

echo "== 2. parallel efficiency of both passes, P = 2 against P = 1"
for p in 1 2; do
  "$parrender" render "$scene" -m image-space --integrator photonmap --spp 16 --width 256 --height 256 \
    --threads "$p" --quiet -o "$out/pm_p$p.png" --metrics "$out/pm_p$p.json" > /dev/null
done
python3 - "$out/pm_p1.json" "$out/pm_p2.json" <<'PY'
import json, sys
def passes(path):
    stages = json.load(open(path))["stages"]
    one = sum(s["wallSeconds"] for s in stages if s["name"].startswith(("photon", "precompute", "build")))
    two = sum(s["wallSeconds"] for s in stages if s["name"].startswith("irradiance-cache") or s["name"] == "trace")
    return one, two
(a1, b1), (a2, b2) = passes(sys.argv[1]), passes(sys.argv[2])
print(f"pass 1: {a1:.3f} s at P=1, {a2:.3f} s at P=2, efficiency {a1 / (2 * a2):.2f}")
print(f"pass 2: {b1:.3f} s at P=1, {b2:.3f} s at P=2, efficiency {b1 / (2 * b2):.2f}")
PY

echo "== 3. the simulator's prediction from the P = 2 record ($network)"
"$parrender" simulate "$out/pm_p2.json" --pes 1,2,4,8,16,32,64,128,256,512,1024 --network "$network" | tail -15
