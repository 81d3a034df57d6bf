// Binning, the step on both sides of a sort: a sender groups what it has by the owners of the
// screen regions it overlaps (one message per owner), and an owner groups what it received by
// its own regions before rasterizing them. Shared by sort-first and sort-middle.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "raster/framebuffer.h"
#include "raster/sort/region_assignment.h"
#include "raster/stages/geometry.h"
#include "raster/stages/shade.h"

namespace pr::raster {

// Distinct owners of the regions a pixel rectangle overlaps, in increasing PE order; scratch
// is a per-caller mark buffer of size P (all zero on entry and on return).
void ownersOf(const RegionGrid& grid, const Rect& bounds, std::vector<char>& scratch, std::vector<int>& owners);

// The region framebuffers of PE pe: each of its regions gets the triangles whose pixel bounds
// overlap it, rasterized and shaded there. Called by the owner on its own triangles only.
// Returned in the order of grid.regionsOf(pe).
std::vector<RegionFramebuffer> drawOwnedRegions(const ShadingContext& ctx, std::span<const ScreenTriangle> tris,
                                                const RegionGrid& grid, int pe);

}  // namespace pr::raster
