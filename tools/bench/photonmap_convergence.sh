#!/usr/bin/env bash
# The photon map converging to the path-traced reference on glossy light (issue-level
# benchmark, not part of the test suite): on scenes/cornell-rough.gltf (a rough metal block and
# a frosted, partly transmissive sphere), 256x256, P = 2, 64 spp (so the eye samples' own noise
# stays below the maps'), against a 4096-spp path trace rendered in the run (cached):
#   1. the error as the photons grow, at the default cache accuracy (0.25) and precomputed-
#      irradiance stride (4), and again with both tightened (0.1, an estimate per gather hit):
#      the first curve flattens at the bias those two settings leave, the second goes lower;
#   2. the error as the gather rays grow;
#   3. the error as each of the two settings is tightened alone.
# Usage: tools/bench/photonmap_convergence.sh [build-dir]
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
build="${1:-$root/build}"
parrender="$build/tools/parrender"
scene="$root/scenes/cornell-rough.gltf"
out="$build/bench-photonmap-convergence"
mkdir -p "$out"
[ -x "$parrender" ] || { echo "photonmap_convergence: build parrender first ($parrender not found)" >&2; exit 2; }
common=(--width 256 --height 256 --threads 2 --integrator photonmap --spp 64 --reference-spp 4096
        --reference-dir "$build/bench-references")

sweep() {  # name, sweep options...
  local name="$1"
  shift
  echo "== $name"
  "$parrender" sweep "$scene" "${common[@]}" "$@" --csv "$out/$name.csv" --images "$out/$name" 2>&1 |
    grep -E '^(integrator|photonmap) '
}
sweep photons --vary photons --values 25000,50000,100000,200000,400000,800000
sweep photons-tight --vary photons --values 25000,50000,100000,200000,400000,800000 --cache-accuracy 0.1 --irradiance-stride 0
sweep gather --vary gather --values 32,64,128,256,512
sweep cache-accuracy --vary cache-accuracy --values 0.5,0.25,0.125,0.0625
sweep irradiance-stride --vary irradiance-stride --values 16,4,1,0
