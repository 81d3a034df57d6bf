#!/usr/bin/env bash
# CI job: build the tests with AddressSanitizer + UndefinedBehaviorSanitizer in a second build
# directory and run the whole suite; any sanitizer report fails the run.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
build=${PARRENDER_ASAN_BUILD_DIR:-$root/build-asan}

bash "$root/tools/setup.sh"
cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPARRENDER_SANITIZE=address,undefined >/dev/null
cmake --build "$build" -j"$(nproc)" --target parrender parrender_tests
# intercept_tls_get_addr=0: with glibc 2.36, LeakSanitizer's record of a dlopen'd module's
# dynamic TLS (the image codec module) can hold a stale range, and its stop-the-world tracer then
# faults at exit ("Tracer caught signal 11", about one render in four of object-space at P = 2);
# leaks are still found, the TLS of modules opened at run time is no longer scanned as roots.
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:intercept_tls_get_addr=0
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$root/tools/ci/lsan.supp
cd "$build"
ctest --output-on-failure -j"$(nproc)"
