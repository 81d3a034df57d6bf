#include <doctest/doctest.h>

#include "common/util/error.h"
#include "common/util/memory_limit.h"

using pr::InputError;

TEST_CASE("MemoryLimit: sizes parse with binary suffixes and bad ones are input errors") {
  CHECK(pr::parseByteSize("1000") == 1000);
  CHECK(pr::parseByteSize("512M") == uint64_t(512) << 20);
  CHECK(pr::parseByteSize("2g") == uint64_t(2) << 30);
  CHECK(pr::parseByteSize("1.5GiB") == uint64_t(3) << 29);
  CHECK(pr::parseByteSize("4KB") == 4096);
  CHECK(pr::parseByteSize("1T") == uint64_t(1) << 40);
  for (std::string bad : {"", "0", "-1G", "12Q", "G", "1.2.3M", "1e9", "99999999999T"}) {
    INFO(bad);
    CHECK_THROWS_WITH_AS(pr::parseByteSize(bad, "--max-memory"), doctest::Contains("--max-memory: '"), InputError);
  }
}

TEST_CASE("MemoryLimit: a budget refuses the charge that would pass the limit, and saturates") {
  pr::MemoryBudget budget(uint64_t(100) << 20);
  budget.charge(uint64_t(60) << 20, "first");
  CHECK(budget.used() == uint64_t(60) << 20);
  CHECK_THROWS_WITH_AS(budget.charge(uint64_t(50) << 20, "accessor 3"),
                       "accessor 3 needs 50.0 MiB, which with the 60.0 MiB already taken exceeds the memory limit of "
                       "100.0 MiB (--max-memory)",
                       InputError);
  CHECK(budget.used() == uint64_t(60) << 20);  // a refused charge takes nothing
  CHECK_THROWS_AS(budget.charge(UINT64_MAX, "everything"), InputError);
  budget.charge(uint64_t(40) << 20, "the rest");  // exactly up to the limit is allowed
  CHECK(pr::saturatingMul(uint64_t(1) << 40, uint64_t(1) << 40) == UINT64_MAX);
  CHECK(pr::saturatingMul(0, UINT64_MAX) == 0);
}

TEST_CASE("MemoryLimit: the default is three quarters of physical memory and the limit can be set") {
  const uint64_t physical = pr::physicalMemoryBytes();
  REQUIRE(physical > 0);
  CHECK(pr::defaultMemoryLimit() == physical / 4 * 3);
  const uint64_t before = pr::memoryLimit();
  pr::setMemoryLimit(uint64_t(1) << 30);
  CHECK(pr::memoryLimit() == uint64_t(1) << 30);
  pr::setMemoryLimit(before);
  CHECK(pr::formatBytes(17) == "17 bytes");
  CHECK(pr::formatBytes(uint64_t(3) << 29) == "1.5 GiB");
}
