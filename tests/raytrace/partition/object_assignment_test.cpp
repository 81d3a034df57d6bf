// Tests of object partitioning's data split (raytrace/partition/object_assignment.cpp): every
// triangle has exactly one owner, large objects are split, PEs are balanced by triangle
// count in compact regions, and the owner directory lists every owner holding a triangle a ray
// hits (never skipped), no later than the hit.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstring>
#include <limits>
#include <random>
#include <set>
#include <vector>

#include "common/util/error.h"
#include "raytrace/core/bvh.h"
#include "raytrace/core/geometry_builders.h"
#include "raytrace/partition/object_assignment.h"
#include "raytrace/partition/owner_directory.h"
#include "raytrace/partition/partition_margin.h"

using pr::rt::ObjectAssignment;
using pr::rt::Ray;

namespace {

// A scene of `sizes.size()` objects, object i a random soup of sizes[i] triangles around its
// own centre, recorded in Scene::objects as the loader would.
pr::scene::Scene objectsScene(const std::vector<uint32_t>& sizes) {
  pr::scene::Scene s = pr::test::emptyScene();
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (size_t o = 0; o < sizes.size(); ++o) {
    pr::scene::Object obj;
    obj.name = "object" + std::to_string(o);
    obj.firstTriangle = uint32_t(s.triangles.size());
    obj.triangleCount = sizes[o];
    const glm::vec3 centre(3.0f * float(o), 0.0f, 0.0f);
    for (uint32_t i = 0; i < sizes[o]; ++i) {
      const glm::vec3 a = centre + glm::vec3(u(rng), u(rng), u(rng));
      pr::test::addTriangle(s, a, a + 0.1f * glm::vec3(u(rng), u(rng), u(rng)), a + 0.1f * glm::vec3(u(rng), u(rng), u(rng)));
    }
    for (uint32_t t = obj.firstTriangle; t < obj.firstTriangle + obj.triangleCount; ++t)
      for (uint32_t v : s.triangles[t].v) obj.bounds.extend(s.positions[v]);
    s.objects.push_back(obj);
  }
  return s;
}

// A floor of two triangles under every object of s, added as one more object.
pr::scene::Object addFloor(pr::scene::Scene& s) {
  pr::scene::Object floor;
  floor.firstTriangle = uint32_t(s.triangles.size());
  floor.triangleCount = 2;
  pr::test::addTriangle(s, {-50, -5, -50}, {50, -5, -50}, {50, -5, 50});
  pr::test::addTriangle(s, {-50, -5, -50}, {50, -5, 50}, {-50, -5, 50});
  s.objects.push_back(floor);
  return floor;
}

}  // namespace

TEST_CASE("ObjectAssignment: every triangle has exactly one owner and pieces stay within objects") {
  const pr::scene::Scene s = objectsScene({500, 40, 40, 10, 300});
  const ObjectAssignment a(s, {3, 100, 0.0f});
  REQUIRE(a.pes() == 3);
  std::vector<int> owner(s.triangles.size(), -1);
  for (int pe = 0; pe < 3; ++pe) {
    const auto tris = a.triangles(pe);
    CHECK(std::is_sorted(tris.begin(), tris.end()));
    for (uint32_t t : tris) {
      CHECK(owner[t] == -1);
      owner[t] = pe;
    }
  }
  CHECK(std::count(owner.begin(), owner.end(), -1) == 0);
  for (const auto& piece : a.pieces()) {
    CHECK(piece.triangles.size() <= 100);
    CHECK(!piece.triangles.empty());
    const auto& obj = s.objects[piece.object];
    for (uint32_t t : piece.triangles) {
      CHECK(t >= obj.firstTriangle);
      CHECK(t < obj.firstTriangle + obj.triangleCount);
      CHECK(owner[t] == piece.owner);
      for (uint32_t v : s.triangles[t].v) {
        CHECK(glm::all(glm::greaterThanEqual(s.positions[v], piece.bounds.min)));
        CHECK(glm::all(glm::lessThanEqual(s.positions[v], piece.bounds.max)));
      }
    }
  }
  // The 500-triangle object was split (into at least 5 pieces); the small ones were not.
  size_t piecesOfFirst = 0;
  for (const auto& piece : a.pieces()) piecesOfFirst += piece.object == 0 ? 1 : 0;
  CHECK(piecesOfFirst >= 5);
}

TEST_CASE("ObjectAssignment: PEs are balanced by triangle count") {
  // One object of 900 triangles and three of 100: without splitting, one PE would hold 75%.
  const pr::scene::Scene s = objectsScene({900, 100, 100, 100});
  const ObjectAssignment a(s, {4, 0, 0.0f});  // default piece size: ceil(1200 / 16) = 75 -> 75
  size_t lo = s.triangles.size(), hi = 0;
  for (int pe = 0; pe < 4; ++pe) {
    lo = std::min(lo, a.triangles(pe).size());
    hi = std::max(hi, a.triangles(pe).size());
  }
  // LPT with pieces of at most 75: the spread is at most one piece.
  CHECK(hi - lo <= 75);
  // One PE: everything, no splitting needed for correctness.
  const ObjectAssignment one(s, {1, 0, 0.0f});
  CHECK(one.triangles(0).size() == s.triangles.size());
  CHECK_THROWS_AS(ObjectAssignment(s, {0, 0, 0.0f}), pr::InputError);
}

TEST_CASE("ObjectAssignment: the small pieces rays reach most are replicated, within the budget") {
  // The soups of objectsScene and a floor of two triangles under all of them: per triangle the
  // floor's bounds are hundreds of times larger than a soup piece's, so it is replicated first;
  // a soup piece (75 triangles) does not fit the rest of a 1% budget (12 triangles).
  pr::scene::Scene s = objectsScene({900, 100, 100, 100});
  const pr::scene::Object floor = addFloor(s);
  const ObjectAssignment a(s, {4, 0, 0.0f, 0.01});
  REQUIRE(a.replicated().size() == 2);
  CHECK(a.replicated()[0] == floor.firstTriangle);
  CHECK(a.replicated()[1] == floor.firstTriangle + 1);
  size_t owned = 0;
  for (int pe = 0; pe < 4; ++pe) {
    owned += a.triangles(pe).size();
    for (uint32_t t : a.triangles(pe)) CHECK(t < floor.firstTriangle);
  }
  CHECK(owned == 1200);
  for (const auto& piece : a.pieces()) CHECK((piece.owner == pr::rt::kEveryPe) == (piece.object == 4));
  CHECK(a.curveOrder().size() == a.pieces().size() - 1);
  // The directory lists the replicated pieces as one owner, kEveryPe, where a ray meets them.
  const pr::rt::OwnerDirectory directory(a);
  std::vector<pr::rt::OwnerEntry> owners;
  std::vector<pr::rt::OwnerDirectory::NodeEntry> heap;
  directory.ownersNearestFirst(Ray{{20, 10, 20}, 0.0f, {0, -1, 0}, 100.0f}, -1, owners, heap);
  REQUIRE(owners.size() == 1);
  CHECK(owners[0].owner == pr::rt::kEveryPe);
  CHECK(owners[0].t == doctest::Approx(15.0f));
  // One PE, or no budget: nothing is replicated.
  CHECK(ObjectAssignment(s, {1, 0, 0.0f, 0.01}).replicated().empty());
  CHECK(ObjectAssignment(s, {4, 0, 0.0f, 0.0}).replicated().empty());
}

TEST_CASE("ObjectAssignment: triangles outside every object form one more object") {
  pr::scene::Scene s = pr::test::randomSoup(30);  // built in code: no Scene::objects
  const ObjectAssignment a(s, {2, 0, 0.0f});
  CHECK(a.triangles(0).size() + a.triangles(1).size() == 30);
  for (const auto& piece : a.pieces()) CHECK(piece.object == 0);
}

TEST_CASE("OwnerDirectory: a ray lists every owner of a triangle it hits, nearest first, no later than the hit") {
  const pr::scene::Scene s = objectsScene({200, 150, 120, 90, 60, 30});
  const glm::vec3 eye(7.0f, 0.5f, 6.0f);
  // 4 owners are tested one by one, 16 through the directory's tree.
  for (int pes : {4, 16}) {
    CAPTURE(pes);
    const ObjectAssignment a(s, {pes, 10, pr::rt::partitionMargin(s, eye)});
    const pr::rt::OwnerDirectory directory(a);
    CHECK(directory.bytes() > 0u);
    std::vector<pr::rt::Bvh> bvhs;
    for (int pe = 0; pe < pes; ++pe) bvhs.emplace_back(s.positions, s.triangles, a.triangles(pe));
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::vector<pr::rt::OwnerEntry> owners, others;
    std::vector<pr::rt::OwnerDirectory::NodeEntry> heap;
    size_t asked = 0, hits = 0;
    for (int i = 0; i < 400; ++i) {
      Ray ray;
      ray.origin = eye;
      // Aimed at a triangle's centroid (most rays hit), or anywhere near the objects.
      const auto& tri = s.triangles[size_t(i * 7) % s.triangles.size()];
      const glm::vec3 target = i % 3 == 0 ? glm::vec3(7.5f * u(rng) + 7.5f, u(rng), u(rng))
                                          : (s.positions[tri.v[0]] + s.positions[tri.v[1]] + s.positions[tri.v[2]]) / 3.0f;
      ray.direction = glm::normalize(target - eye);
      if (i % 4 == 0) ray.tMax = 3.0f;  // short segments skip far owners
      directory.ownersNearestFirst(ray, -1, owners, heap);
      CHECK(std::is_sorted(owners.begin(), owners.end(), [](const auto& x, const auto& y) { return x.t < y.t; }));
      std::set<int> distinct;
      for (const auto& e : owners) distinct.insert(e.owner);
      CHECK(distinct.size() == owners.size());
      asked += owners.size();
      // The same owners at the same entries as the walk through the directory's tree.
      std::vector<std::pair<float, int>> listed, walked;
      for (const auto& e : owners) listed.push_back({e.t, e.owner});
      pr::rt::OwnerDirectory::NearestFirst walk(directory, ray, -1, heap);
      for (pr::rt::OwnerEntry e; walk.next(std::numeric_limits<float>::infinity(), e);) walked.push_back({e.t, e.owner});
      std::sort(listed.begin(), listed.end());
      std::sort(walked.begin(), walked.end());
      CHECK(listed == walked);
      for (int pe = 0; pe < pes; ++pe) {
        pr::rt::Hit h;
        if (!bvhs[pe].intersect(ray, h)) continue;
        ++hits;
        auto it = std::find_if(owners.begin(), owners.end(), [&](const auto& e) { return e.owner == pe; });
        REQUIRE(it != owners.end());
        CHECK(it->t <= h.t);
      }
      // Leaving one owner out lists the others in the same order.
      const int except = i % pes;
      directory.ownersNearestFirst(ray, except, others, heap);
      std::vector<int> expected, got;
      for (const auto& e : owners)
        if (e.owner != except) expected.push_back(e.owner);
      for (const auto& e : others) got.push_back(e.owner);
      CHECK(got == expected);
    }
    CHECK(hits > 100);
    CHECK(asked < size_t(pes) * 400);  // bounds culling asks fewer owners than a broadcast would
  }
}

TEST_CASE("ObjectAssignment: owners get compact regions along the Morton curve") {
  // Six objects in a row along x: two PEs get the three left and the three right ones.
  const pr::scene::Scene s = objectsScene({100, 100, 100, 100, 100, 100});
  const ObjectAssignment a(s, {2, 100, 0.0f});
  for (const auto& piece : a.pieces()) CHECK(piece.owner == (piece.object < 3 ? 0 : 1));
}

TEST_CASE("OwnerDirectory: the box test is conservative for axis-parallel and boundary rays") {
  // One object whose bounds are the unit box (a triangle along its diagonal), one owner.
  pr::scene::Scene s = pr::test::emptyScene();
  pr::test::addTriangle(s, {0, 0, 0}, {1, 1, 0}, {1, 1, 1});
  auto reaches = [&](const Ray& ray, float margin) {
    const ObjectAssignment a(s, {1, 0, margin});
    std::vector<pr::rt::OwnerEntry> owners;
    std::vector<pr::rt::OwnerDirectory::NodeEntry> heap;
    pr::rt::OwnerDirectory(a).ownersNearestFirst(ray, -1, owners, heap);
    return !owners.empty();
  };
  Ray along;  // in the face plane x = 0, parallel to it
  along.origin = glm::vec3(0.0f, 0.5f, -1.0f);
  along.direction = glm::vec3(0.0f, 0.0f, 1.0f);
  CHECK(reaches(along, 0.0f));
  Ray nearlyAlong = along;  // 1 / 1e-39 overflows to inf: 0 * inf on the face must not drop it
  nearlyAlong.direction = glm::vec3(1e-39f, 0.0f, 1.0f);
  CHECK(reaches(nearlyAlong, 0.0f));
  along.origin.x = -1e-3f;
  CHECK(!reaches(along, 0.0f));
  CHECK(reaches(along, 2e-3f));  // the margin grows the box
  Ray touching;  // ends exactly on the face
  touching.origin = glm::vec3(0.5f, 0.5f, -1.0f);
  touching.direction = glm::vec3(0.0f, 0.0f, 1.0f);
  touching.tMax = 1.0f;
  CHECK(reaches(touching, 0.0f));
  touching.tMax = 0.5f;
  CHECK(!reaches(touching, 0.0f));
  Ray away = touching;  // pointing away
  away.tMax = pr::rt::kInfinity;
  away.direction = -away.direction;
  CHECK(!reaches(away, 0.0f));
}

TEST_CASE("ObjectAssignment: an assignment decoded from its encoding holds and routes as the one made, and bad bytes are refused") {
  pr::scene::Scene s = objectsScene({900, 100, 100, 100});
  addFloor(s);
  const ObjectAssignment made(s, {4, 0, 0.05f, 0.01});
  REQUIRE(!made.replicated().empty());
  pr::par::Bytes bytes;
  pr::par::WireWriter w(bytes);
  made.encode(w);
  pr::par::WireReader r(bytes);
  const ObjectAssignment decoded = ObjectAssignment::decode(r);
  CHECK(r.remaining() == 0);
  REQUIRE(decoded.pes() == made.pes());
  CHECK(decoded.margin() == made.margin());
  REQUIRE(decoded.pieces().size() == made.pieces().size());
  for (size_t i = 0; i < made.pieces().size(); ++i) {
    CHECK(decoded.pieces()[i].object == made.pieces()[i].object);
    CHECK(decoded.pieces()[i].owner == made.pieces()[i].owner);
    CHECK(decoded.pieces()[i].triangles == made.pieces()[i].triangles);
    CHECK(decoded.pieces()[i].bounds.min == made.pieces()[i].bounds.min);
    CHECK(decoded.pieces()[i].bounds.max == made.pieces()[i].bounds.max);
  }
  for (int pe = 0; pe < made.pes(); ++pe) {
    CHECK(std::ranges::equal(decoded.triangles(pe), made.triangles(pe)));
    CHECK(std::ranges::equal(decoded.piecesOf(pe), made.piecesOf(pe)));
  }
  CHECK(std::ranges::equal(decoded.replicated(), made.replicated()));
  CHECK(std::ranges::equal(decoded.curveOrder(), made.curveOrder()));
  // The directories made from both list the same owners for every ray.
  const pr::rt::OwnerDirectory a(made), b(decoded);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-2.0f, 12.0f);
  std::vector<pr::rt::OwnerEntry> fromMade, fromDecoded;
  std::vector<pr::rt::OwnerDirectory::NodeEntry> heap;
  size_t listed = 0;
  for (int i = 0; i < 200; ++i) {
    const glm::vec3 origin(u(rng), 4.0f, u(rng) * 0.1f);
    const Ray ray{origin, 0.0f, glm::normalize(glm::vec3(u(rng) - origin.x, -4.0f, 0.0f)), 100.0f};
    a.ownersNearestFirst(ray, -1, fromMade, heap);
    b.ownersNearestFirst(ray, -1, fromDecoded, heap);
    REQUIRE(fromMade.size() == fromDecoded.size());
    for (size_t k = 0; k < fromMade.size(); ++k) {
      CHECK(fromMade[k].owner == fromDecoded[k].owner);
      CHECK(fromMade[k].t == fromDecoded[k].t);
    }
    listed += fromMade.size();
  }
  CHECK(listed > 100);
  pr::par::Bytes truncated(bytes.begin(), bytes.end() - 1);
  pr::par::WireReader shortReader(truncated);
  CHECK_THROWS_AS(ObjectAssignment::decode(shortReader), pr::par::WireError);
  // A piece owner out of range (the first piece's owner follows the margin, the piece count
  // and its object index).
  pr::par::Bytes badOwner = bytes;
  const std::int32_t owner = 99;
  std::memcpy(badOwner.data() + sizeof(float) + sizeof(std::uint64_t) + sizeof(uint32_t), &owner, sizeof owner);
  pr::par::WireReader badReader(badOwner);
  CHECK_THROWS_AS(ObjectAssignment::decode(badReader), pr::par::WireError);
}
