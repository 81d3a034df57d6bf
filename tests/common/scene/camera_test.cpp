// Tests of cameras (common/scene/camera.cpp, camera_select.cpp): projection for the image
// aspect, selection by default, index and name, and the automatic framing camera.
#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "common/util/error.h"
#include "common/util/log.h"
#include "test_support.h"

using pr::scene::Camera;
using pr::scene::Projection;

TEST_CASE("Camera: perspective projection follows the image aspect, not the file's") {
  Camera c;
  c.yfov = 1.0f;
  c.znear = 0.1f;
  c.fileAspectRatio = 1.0f;
  glm::mat4 p = c.projectionMatrix(2.0f);
  // A point on the top edge of the vertical fov maps to NDC y = 1; x scale is y scale / aspect.
  float t = std::tan(0.5f);
  glm::vec4 top = p * glm::vec4(0.0f, t, -1.0f, 1.0f);
  CHECK(top.y / top.w == doctest::Approx(1.0f));
  CHECK(p[0][0] == doctest::Approx(p[1][1] / 2.0f));
}

TEST_CASE("Camera: orthographic keeps ymag and widens x with the aspect") {
  Camera c;
  c.projection = Projection::Orthographic;
  c.xmag = 1.0f;
  c.ymag = 2.0f;
  c.znear = 0.0f;
  c.zfar = 10.0f;
  glm::mat4 p = c.projectionMatrix(1.5f);
  glm::vec4 corner = p * glm::vec4(3.0f, 2.0f, -5.0f, 1.0f);  // x half extent = 2 * 1.5
  CHECK(corner.x == doctest::Approx(1.0f));
  CHECK(corner.y == doctest::Approx(1.0f));
}

TEST_CASE("Camera: selectCamera by default, index, name, auto, and bad selectors") {
  pr::scene::Scene s;
  s.bounds.extend(glm::vec3(-1.0f));
  s.bounds.extend(glm::vec3(1.0f));
  // No cameras: the framing camera.
  CHECK(pr::scene::selectCamera(s, "", 1.0f).automatic);
  CHECK_THROWS_AS(pr::scene::selectCamera(s, "0", 1.0f), pr::InputError);
  Camera a, b;
  a.name = "front";
  b.name = "side";
  b.projection = Projection::Orthographic;
  s.cameras = {a, b};
  CHECK(pr::scene::selectCamera(s, "", 1.0f).name == "front");
  CHECK(pr::scene::selectCamera(s, "1", 1.0f).name == "side");
  CHECK((pr::scene::selectCamera(s, "side", 1.0f).projection == Projection::Orthographic));
  CHECK(pr::scene::selectCamera(s, "auto", 1.0f).automatic);
  CHECK_THROWS_WITH_AS(pr::scene::selectCamera(s, "2", 1.0f), doctest::Contains("valid indices are 0..1"), pr::InputError);
  CHECK_THROWS_WITH_AS(pr::scene::selectCamera(s, "top", 1.0f), doctest::Contains("\"top\""), pr::InputError);
}

TEST_CASE("Camera: the framing camera sees every corner of the bounds") {
  pr::scene::Bounds b;
  b.extend(glm::vec3(-3.0f, 0.0f, -1.0f));
  b.extend(glm::vec3(5.0f, 2.0f, 1.0f));
  for (float aspect : {0.5f, 1.0f, 2.0f}) {
    Camera c = pr::scene::framingCamera(b, aspect);
    glm::mat4 vp = c.projectionMatrix(aspect) * c.view();
    for (int i = 0; i < 8; ++i) {
      glm::vec3 corner((i & 1) ? b.max.x : b.min.x, (i & 2) ? b.max.y : b.min.y, (i & 4) ? b.max.z : b.min.z);
      glm::vec4 clip = vp * glm::vec4(corner, 1.0f);
      REQUIRE(clip.w > 0.0f);
      CHECK(std::abs(clip.x / clip.w) <= 1.0f);
      CHECK(std::abs(clip.y / clip.w) <= 1.0f);
      CHECK(std::abs(clip.z / clip.w) <= 1.0f);
    }
  }
}

TEST_CASE("Camera: the Cameras model has a perspective and an orthographic camera") {
  if (!pr::test::haveSharedScenes()) return;
  pr::setQuiet(true);
  auto s = pr::scene::loadGltf(pr::test::sharedScenes() / "Cameras/glTF/Cameras.gltf");
  pr::setQuiet(false);
  REQUIRE(s.cameras.size() == 2);
  CHECK((s.cameras[0].projection == Projection::Perspective));
  CHECK((s.cameras[1].projection == Projection::Orthographic));
  // Both sit in front of the quad (+Z) looking at it down -Z.
  for (const auto& c : s.cameras) CHECK(c.position().z > 0.0f);
}
