#!/usr/bin/env bash
# Quick start command 1: install, build, and run the main job on the bundled default scene —
# the Cornell box path traced by the image-space parallel ray tracer on every core.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${PARRENDER_BUILD_DIR:-$root/build}

bash "$root/tools/build.sh"
mkdir -p "$root/out"
"$build/tools/parrender" render "$root/scenes/cornell.gltf" -m image-space --integrator path \
  --threads "$(nproc)" --spp 16 --width 512 --height 512 \
  -o "$root/out/cornell.png" --metrics "$root/out/cornell_metrics.json"
echo "image: $root/out/cornell.png   run record: $root/out/cornell_metrics.json"
