// libFuzzer target: the run-record / cost-table reader and the simulator (tests/fuzz/fuzz_inputs.h).
#include "common/util/log.h"
#include "tests/fuzz/fuzz_inputs.h"

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  pr::setQuiet(true);
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  pr::fuzz::simulateInput(std::span(data, size));
  return 0;
}
