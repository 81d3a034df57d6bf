// Tests of the stored photon (photonmap/photon.h): its size, and the round-trip error of the
// packed power (RGBE) and the packed incoming direction (octahedral 2 x 8 bits).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "photonmap/photon.h"
#include "photonmap/photon_test_support.h"

using pr::pm::Photon;
using pr::pm::PhotonMapKind;

TEST_CASE("Photon: a stored photon takes 20 bytes") {
  CHECK(sizeof(Photon) == 20);
  CHECK(alignof(Photon) == 4);
}

TEST_CASE("Photon: RGBE power round trip is within 1/255.5 of the largest channel") {
  // Analytic bound (photon.h): each channel off by at most half a mantissa step, the largest
  // channel at least 127.75 steps: error <= 1/255.5 (0.39 %) of the largest channel.
  pr::test::TestRng rng(7);
  float worst = 0.0f;
  for (int i = 0; i < 100000; ++i) {
    const float scale = std::ldexp(1.0f, static_cast<int>(rng.uniform(-100.0f, 100.0f)));
    const glm::vec3 power(rng.uniform() * scale, rng.uniform() * scale, rng.uniform() * scale);
    const glm::vec3 back = pr::pm::unpackRgbe(pr::pm::packRgbe(power));
    const float largest = std::max(power.x, std::max(power.y, power.z));
    if (largest == 0.0f) continue;
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(back[c] - power[c]) / largest);
  }
  MESSAGE("largest RGBE error relative to the largest channel: " << worst);
  CHECK(worst <= 1.0f / 255.5f);
  CHECK(worst < 0.01f);  // the bound, 1 %
}

TEST_CASE("Photon: RGBE keeps zero exactly, stores negative and NaN as zero, saturates") {
  using pr::pm::packRgbe;
  using pr::pm::unpackRgbe;
  CHECK(unpackRgbe(packRgbe(glm::vec3(0.0f))) == glm::vec3(0.0f));
  // A zero channel stays zero (no energy added to it).
  const glm::vec3 red = unpackRgbe(packRgbe(glm::vec3(3.0f, 0.0f, 0.0f)));
  CHECK(red.x == doctest::Approx(3.0f).epsilon(0.004));
  CHECK(red.y == 0.0f);
  CHECK(red.z == 0.0f);
  const glm::vec3 bad = unpackRgbe(packRgbe(glm::vec3(-1.0f, std::numeric_limits<float>::quiet_NaN(), 2.0f)));
  CHECK(bad.x == 0.0f);
  CHECK(bad.y == 0.0f);
  CHECK(bad.z == doctest::Approx(2.0f).epsilon(0.004));
  // Powers of two and the mantissa round-up at the top of an octave are exact or near.
  CHECK(unpackRgbe(packRgbe(glm::vec3(1.0f))).x == 1.0f);
  CHECK(unpackRgbe(packRgbe(glm::vec3(0.99999f))).x == doctest::Approx(1.0f).epsilon(0.004));
  const glm::vec3 huge = unpackRgbe(packRgbe(glm::vec3(std::numeric_limits<float>::infinity())));
  CHECK(std::isfinite(huge.x));
  CHECK(huge.x > 1e38f);
  CHECK(unpackRgbe(packRgbe(glm::vec3(1e-39f))) == glm::vec3(0.0f));  // below 2^-128: zero
}

namespace {
float angleDegrees(const glm::vec3& a, const glm::vec3& b) {
  return glm::degrees(std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f)));
}
}  // namespace

TEST_CASE("Photon: octahedral direction round trip is within 1 degree") {
  pr::test::TestRng rng(11);
  float worst = 0.0f;
  auto check = [&](const glm::vec3& d) {
    const glm::vec3 back = pr::pm::unpackDirection(pr::pm::packDirection(d));
    CHECK(std::abs(glm::length(back) - 1.0f) < 1e-5f);
    worst = std::max(worst, angleDegrees(d, back));
  };
  for (int i = 0; i < 200000; ++i) {
    glm::vec3 d;
    do d = rng.inBox(-1.0f, 1.0f);
    while (glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-6f);
    check(d);
  }
  // The axes, the folded seam (z = 0) and the octahedron's edges.
  for (const glm::vec3& d : {glm::vec3(1, 0, 0), glm::vec3(-1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, -1, 0),
                             glm::vec3(0, 0, 1), glm::vec3(0, 0, -1), glm::vec3(1, 1, 0), glm::vec3(-1, 1, 0),
                             glm::vec3(1, -1, 0), glm::vec3(-1, -1, 0), glm::vec3(1, 0, -1e-7f), glm::vec3(1, 1, -1)})
    check(d);
  MESSAGE("largest octahedral direction error: " << worst << " degrees");
  CHECK(worst < 1.0f);
  // A degenerate direction is stored as +z (to the grid's precision), not NaN.
  CHECK(angleDegrees(pr::pm::unpackDirection(pr::pm::packDirection(glm::vec3(0.0f))), {0, 0, 1}) < 1.0f);
}

TEST_CASE("Photon: split axis, map kind and bounces are independent fields") {
  Photon p = Photon::make({1, 2, 3}, {0.5f, 0.25f, 0.125f}, {0, 1, 0}, PhotonMapKind::Caustic, 300);
  CHECK(p.kind() == PhotonMapKind::Caustic);
  CHECK(p.bounces == 255);  // saturating
  for (int axis = 0; axis < 3; ++axis) {
    p.setSplitAxis(axis);
    CHECK(p.splitAxis() == axis);
    CHECK(p.kind() == PhotonMapKind::Caustic);
  }
  p.setKind(PhotonMapKind::Global);
  CHECK(p.kind() == PhotonMapKind::Global);
  CHECK(p.splitAxis() == 2);
  CHECK(p.powerRgb() == glm::vec3(0.5f, 0.25f, 0.125f));  // powers of two are exact
  CHECK(angleDegrees(p.incoming(), {0, 1, 0}) < 1.0f);
}
