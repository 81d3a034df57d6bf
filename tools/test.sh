#!/usr/bin/env bash
# Quick start command 2: install, build, and run the whole test suite (CTest prints the summary).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
build=${PARRENDER_BUILD_DIR:-$root/build}

bash "$root/tools/build.sh"
cd "$build"
ctest --output-on-failure -j"$(nproc)"
