// The fuzz targets' bodies (fuzz_inputs.h) over the committed seed corpus and every input a
// fuzzing campaign found to crash, hang or exhaust memory (tests/fuzz/regressions/TARGET,
// minimised where libFuzzer could): each must end normally, loaded or refused, in the normal
// build and under the sanitizer jobs. A regression input that loads again would show up here
// as a changed expectation, so each one's outcome is also stated.
#include <doctest/doctest.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "common/util/log.h"
#include "tests/fuzz/fuzz_inputs.h"
#include "tests/test_support.h"

namespace {

std::vector<uint8_t> readBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::vector<uint8_t>((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

std::vector<std::filesystem::path> filesIn(const std::filesystem::path& dir) {
  std::vector<std::filesystem::path> files;
  if (std::filesystem::is_directory(dir))
    for (const auto& e : std::filesystem::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

const std::filesystem::path kFuzzDir = pr::test::sourceDir() / "tests" / "fuzz";

}  // namespace

TEST_CASE("FuzzRegression: every seed loads and renders, every run-record seed simulates") {
  pr::setQuiet(true);
  const auto gltf = filesIn(kFuzzDir / "corpus" / "gltf");
  REQUIRE(gltf.size() >= 6);
  for (const auto& path : gltf) {
    INFO(path.string());
    const std::vector<uint8_t> bytes = readBytes(path);
    CHECK(pr::fuzz::loadInput(bytes));
    CHECK(pr::fuzz::renderInput(bytes));
  }
  const auto records = filesIn(kFuzzDir / "corpus" / "run_record");
  REQUIRE(records.size() >= 3);
  for (const auto& path : records) {
    INFO(path.string());
    CHECK(pr::fuzz::simulateInput(readBytes(path)));
  }
  pr::setQuiet(false);
}

TEST_CASE("FuzzRegression: the inputs fuzzing found end as the documented outcome") {
  // File -> whether it loads (renders, is read) once fixed; anything not listed is refused.
  const std::map<std::string, bool> loads = {};
  pr::setQuiet(true);
  int replayed = 0;
  for (const char* target : {"gltf_loader", "render", "run_record"}) {
    for (const auto& path : filesIn(kFuzzDir / "regressions" / target)) {
      INFO(target << ": " << path.string());
      const std::vector<uint8_t> bytes = readBytes(path);
      const std::string name = path.filename().string();
      const bool expected = loads.count(name) ? loads.at(name) : false;
      const std::string t = target;
      const bool outcome = t == "gltf_loader" ? pr::fuzz::loadInput(bytes)
                           : t == "render"    ? pr::fuzz::renderInput(bytes)
                                              : pr::fuzz::simulateInput(bytes);
      CHECK(outcome == expected);
      ++replayed;
    }
  }
  pr::setQuiet(false);
  CHECK(replayed >= 1);
}
