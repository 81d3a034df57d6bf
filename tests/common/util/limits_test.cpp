// Tests of the count limits of packed indices (common/util/limits.h). The checks built on them
// are tested beside their code (bvh_build_test, geometry_test, the loader's bad inputs).
#include <string>

#include <doctest/doctest.h>

#include "common/scene/scene.h"
#include "common/util/error.h"
#include "common/util/limits.h"

TEST_CASE("Limits: a count up to the limit passes, one more names the count and the limit") {
  CHECK(pr::countLimitProblem("scene a.gltf", "vertices", 10, 10, "why").empty());
  CHECK(pr::countLimitProblem("scene a.gltf", "vertices", 11, 10, "indices are 32 bits") ==
        "scene a.gltf: 11 vertices exceed the limit of 10 (indices are 32 bits)");
  CHECK_THROWS_AS(pr::checkCountLimit("x", "y", 11, 10, "z"), pr::InputError);
  CHECK_NOTHROW(pr::checkCountLimit("x", "y", 10, 10, "z"));
}

TEST_CASE("Limits: a scene holds at most 2^32 - 2 vertices and triangles (32-bit indices)") {
  CHECK(pr::scene::kMaxVertices == 4294967294ull);
  CHECK(pr::scene::kMaxTriangles == 4294967294ull);
}
