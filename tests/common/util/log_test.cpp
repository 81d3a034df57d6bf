#include <doctest/doctest.h>

#include "common/util/log.h"

TEST_CASE("Log: quiet mode is a switch that reads back") {
  pr::setQuiet(true);
  CHECK(pr::quiet());
  pr::setQuiet(false);
  CHECK_FALSE(pr::quiet());
}
