// The copy of a scene that one PE of a partitioned method may read when it holds only some
// triangles. Every vertex that no held triangle uses is NaN (position, normal, uv, colour), so
// a read of geometry another PE holds, outside a counted message or broadcast, changes the
// image. Every PE of the partitioned ray tracers and of sort-first reads one across ranks (its
// share installed from messages: primitive_batch.h); in one process the tests turn it on
// (TraceOptions / SortOptions::poisonForeignGeometry), renders do not.
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "common/scene/scene.h"

namespace pr::scene {

// held and alsoHeld: triangle indices whose vertices stay intact (e.g. a PE's own triangles
// and the replicated emitters).
inline std::unique_ptr<Scene> poisonedView(const Scene& s, std::span<const uint32_t> held,
                                           std::span<const uint32_t> alsoHeld = {}) {
  auto view = std::make_unique<Scene>(s);
  std::vector<char> keep(s.positions.size(), 0);
  for (std::span<const uint32_t> list : {held, alsoHeld})
    for (uint32_t t : list)
      for (uint32_t v : s.triangles[t].v) keep[v] = 1;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (size_t v = 0; v < keep.size(); ++v) {
    if (keep[v]) continue;
    view->positions[v] = glm::vec3(nan);
    if (v < view->normals.size()) view->normals[v] = glm::vec3(nan);
    if (v < view->uvs.size()) view->uvs[v] = glm::vec2(nan);
    if (v < view->colors.size()) view->colors[v] = glm::vec4(nan);
    if (v < view->tangents.size()) view->tangents[v] = glm::vec4(nan);
  }
  return view;
}

}  // namespace pr::scene
