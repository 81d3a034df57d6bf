// Tests of the registry template (common/util/registry.h): lookup, the error message that
// lists the valid names, names(), describe() for --help, declared properties, add().
#include <string>

#include <doctest/doctest.h>

#include "common/parallel/schedulers/scheduler.h"
#include "common/util/error.h"
#include "common/util/registry.h"

namespace {

struct Shape {
  int corners = 0;
};
using ShapeRegistry = pr::Registry<int (*)(), Shape>;

int three() { return 3; }
int four() { return 4; }

ShapeRegistry shapes() {
  return ShapeRegistry("shape", {{"triangle", "three corners", three, {3}}, {"square", "four corners", four, {4}}});
}

}  // namespace

TEST_CASE("Registry: find returns the entry with its factory and properties") {
  const ShapeRegistry r = shapes();
  CHECK(r.size() == 2);
  CHECK(r.find("square").make() == 4);
  CHECK(r.find("triangle").properties.corners == 3);
  CHECK(r.contains("triangle"));
  CHECK_FALSE(r.contains("circle"));
  CHECK(r.tryFind("circle") == nullptr);
  CHECK(r.problem("square").empty());
}

TEST_CASE("Registry: an unknown name is an InputError listing the valid names in order") {
  const ShapeRegistry r = shapes();
  std::string message;
  try {
    r.find("circle");
  } catch (const pr::InputError& e) {
    message = e.what();
  }
  CHECK(message == "unknown shape 'circle' (expected one of: triangle, square)");
  CHECK(r.problem("circle") == message);
}

TEST_CASE("Registry: names, joinedNames and describe follow registration order") {
  ShapeRegistry r = shapes();
  r.add({"pentagon", "five corners", four, {5}});
  const std::vector<std::string_view> names = r.names();
  REQUIRE(names.size() == 3);
  CHECK(names[0] == "triangle");
  CHECK(names[2] == "pentagon");
  CHECK(r.joinedNames(" | ") == "triangle | square | pentagon");
  // Names padded to one column (at least 15 wide), one line each.
  CHECK(r.describe() ==
        "  triangle       three corners\n"
        "  square         four corners\n"
        "  pentagon       five corners\n");
}

TEST_CASE("Registry: schedules declare whether they need cost estimates") {
  CHECK(pr::par::scheduleNeedsCostEstimates("unbalanced"));
  CHECK(pr::par::scheduleNeedsCostEstimates("hot-spots"));
  CHECK_FALSE(pr::par::scheduleNeedsCostEstimates("balanced"));
  CHECK_FALSE(pr::par::scheduleNeedsCostEstimates("demand"));
  int declaring = 0;
  for (const pr::par::ScheduleInfo& s : pr::par::schedules()) declaring += s.properties.needsCostEstimates;
  CHECK(declaring == 2);
  CHECK_THROWS_WITH_AS(pr::par::scheduleNeedsCostEstimates("nope"),
                       doctest::Contains("unknown schedule 'nope' (expected one of: balanced, unbalanced"),
                       pr::InputError);
}
