#!/usr/bin/env bash
# CI job: build the tests with AddressSanitizer + UndefinedBehaviorSanitizer in a second build
# directory and run the whole suite; any sanitizer report fails the run.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${PARRENDER_ASAN_BUILD_DIR:-$root/build-asan}

bash "$root/tools/setup.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARRENDER_SANITIZE=address,undefined >/dev/null
cmake --build "$build" -j"$(nproc)" --target parrender parrender_tests
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$root/tools/ci/lsan.supp
cd "$build"
ctest --output-on-failure -j"$(nproc)"
