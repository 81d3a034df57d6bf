#!/usr/bin/env bash
# Quick start command 1: install, build, and run the main job on the bundled default scene.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${PARRENDER_BUILD_DIR:-$root/build}

bash "$root/tools/build.sh"
"$build/tools/parrender" info "$root/scenes/cornell.gltf"
