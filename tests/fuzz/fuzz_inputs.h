// What each fuzz target does with one input, shared by the libFuzzer targets (fuzz_*.cpp) and
// the regression test that replays the committed corpus (fuzz_regression_test.cpp) in the
// normal build. Each returns normally for good and bad input alike (bad input ends as the
// InputError the CLI turns into exit 2) and aborts on a broken invariant: a crash is a bug.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

namespace pr::fuzz {

// The memory a fuzzed load may take: well under libFuzzer's -rss_limit_mb, so that the limit
// refuses a huge file rather than the fuzzer killing the process.
inline constexpr uint64_t kLoadMemoryBytes = uint64_t(256) << 20;

// glTF or GLB bytes through the loader; a loaded scene is checked for the invariants the
// renderers rely on (indices in range, finite positions, unit normals). True when it loaded.
bool loadInput(std::span<const uint8_t> bytes);

// The loaded scene (up to 4096 triangles) through sort-middle and the image-space path tracer
// at 16 x 16; every pixel must be finite. True when it rendered.
bool renderInput(std::span<const uint8_t> bytes);

// A JSON run record or a cost table through the reader, the workload builder and the
// simulator at P = 1, 3 and 64. True when it was read.
bool simulateInput(std::span<const uint8_t> bytes);

}  // namespace pr::fuzz
