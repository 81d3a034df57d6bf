// View work: where the camera rays of a render land, estimated without tracing, for splitting
// a scene into parts of equal work (object-space voxels, voxel_split.h). Each triangle is
// projected into the image; its on-screen area in pixels is the number of camera rays per
// sample that reach it when nothing in front hides it, and the paths they start do most of
// their work near it. A triangle is cut into four by its edges' midpoints until each piece
// covers at most kViewWorkPiecePixels, so a wall or floor of two triangles gives work along its
// whole visible extent, not at one point. Occlusion is ignored: an estimate, cheap enough for
// one PE (one projection per vertex), not a render.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "common/scene/camera.h"
#include "common/scene/scene.h"

namespace pr::rt {

// Work at a point: here a piece of a triangle in the view, at its centroid, weighing the pixels
// it covers.
struct WorkPoint {
  glm::vec3 position{0.0f};
  float weight = 0.0f;
};

inline constexpr float kViewWorkPiecePixels = 64.0f;

// The work points of every triangle of the scene seen by camera in a width x height image;
// pieces outside the image or behind the camera give none.
std::vector<WorkPoint> viewWork(const scene::Scene& scene, const scene::Camera& camera, int width, int height);

}  // namespace pr::rt
