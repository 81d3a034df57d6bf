// libFuzzer target: the glTF/GLB loader and scene builder (tests/fuzz/fuzz_inputs.h).
#include "common/util/log.h"
#include "tests/fuzz/fuzz_inputs.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  pr::setQuiet(true);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pr::fuzz::loadInput(std::span(data, size));
  return 0;
}
