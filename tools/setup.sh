#!/usr/bin/env bash
# Installs every Debian package parrender needs to build, test and benchmark, and the plotting
# libraries of `parrender report` (vega, vega-lite, vega-embed from npm, pinned by
# tools/report/package-lock.json, into tools/report/node_modules).
# Idempotent: when everything is present it only checks and returns (no apt or npm traffic).
#   tools/setup.sh          build and test dependencies
#   tools/setup.sh --bench  also the benchmark anchors: Intel Embree 3, Mesa llvmpipe over EGL,
#                           nanoflann (kd-tree, header-only)
#   tools/setup.sh --fuzz   also clang and its libFuzzer runtime (tools/fuzz.sh)
set -euo pipefail

bench=0
fuzz=0
for arg in "$@"; do
  case "$arg" in
    --bench) bench=1 ;;
    --fuzz) fuzz=1 ;;
    *) echo "setup: unknown option '$arg' (expected --bench or --fuzz)" >&2; exit 2 ;;
  esac
done

packages=(
  build-essential cmake pkg-config
  libtinygltf-dev nlohmann-json3-dev libstb-dev  # glTF loading and writing
  libglm-dev                                     # vector math
  libopenimageio-dev                             # EXR / PNG images
  libcli11-dev                                   # command-line parsing
  doctest-dev                                    # unit tests
  libopenmpi-dev openmpi-bin                     # running across processes (mpirun)
  chromium                                       # the report's test opens it headless
)
# npm installs the report's plotting libraries; the Debian package only where no node is present
# (a node from elsewhere brings its own npm, and Debian's would conflict with it).
command -v npm >/dev/null 2>&1 || packages+=(npm)
if [ "$bench" -eq 1 ]; then
  packages+=(
    libembree-dev                                  # Embree 3 ray tracing anchor
    libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri  # llvmpipe raster anchor (EGL surfaceless)
    libnanoflann-dev                               # nanoflann kd-tree anchor (bench_photonmap)
  )
fi
if [ "$fuzz" -eq 1 ]; then
  packages+=(clang libclang-rt-dev)                # libFuzzer, ASan, UBSan runtimes for clang
fi

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
else
  echo "setup: installing ${missing[*]}"
  if [ "$(id -u)" -ne 0 ]; then SUDO=sudo; else SUDO=; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

report=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)/report
if [ -f "$report/node_modules/vega-embed/build/vega-embed.min.js" ] &&
   [ "$report/node_modules/.package-lock.json" -nt "$report/package-lock.json" ]; then
  echo "setup: report scripts present"
else
  echo "setup: installing the report's plotting libraries (npm ci)"
  (cd "$report" && npm ci --no-audit --no-fund --loglevel=error)
fi
