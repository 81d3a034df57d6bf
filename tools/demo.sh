#!/usr/bin/env bash
# Quick start command 1: install, build, and run the main job on the bundled default scene:
# the classification report of every method on the Cornell box (parrender report), measured
# on every core at P = 1, 2, 4, ... and predicted by the simulator out to 1024 PEs.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${PARRENDER_BUILD_DIR:-$root/build}

bash "$root/tools/build.sh"
mkdir -p "$root/out"
"$build/tools/parrender" report "$root/scenes/cornell.gltf" -o "$root/out/report"
echo "report: $root/out/report/index.html (open it in a browser; it needs no network)"
