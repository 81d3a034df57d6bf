// The sort-point registry (name -> factory -> description) and counter arithmetic: what the
// render command and the tests use to pick sort-first, sort-middle or sort-last by name.
#include "raster/sort/sort_point.h"

#include "common/util/error.h"

namespace pr::raster {

SortCounters& SortCounters::operator+=(const SortCounters& o) {
  primitivesRouted += o.primitivesRouted;
  primitivesSent += o.primitivesSent;
  primitivesDuplicated += o.primitivesDuplicated;
  primitivesMigrated += o.primitivesMigrated;
  preTransforms += o.preTransforms;
  geometryRepeated += o.geometryRepeated;
  trianglesRouted += o.trianglesRouted;
  trianglesSent += o.trianglesSent;
  trianglesDuplicated += o.trianglesDuplicated;
  pixelsSent += o.pixelsSent;
  compositeMessages += o.compositeMessages;
  compositeBytes += o.compositeBytes;
  return *this;
}

const std::vector<SortPointInfo>& sortPoints() {
  static const std::vector<SortPointInfo> kSortPoints = {
      {"sort-first", "primitives pre-transformed and sent to screen-region owners, who run the whole pipeline",
       &makeSortFirst},
      {"sort-middle", "screen triangles sent from geometry to the region owners, who rasterize", &makeSortMiddle},
      {"sort-last", "every PE renders its primitives full screen; pixels depth-composited by region", &makeSortLast},
  };
  return kSortPoints;
}

bool isSortPoint(std::string_view name) {
  for (const SortPointInfo& s : sortPoints())
    if (s.name == name) return true;
  return false;
}

std::unique_ptr<SortPoint> makeSortPoint(std::string_view name) {
  std::string names;
  for (const SortPointInfo& s : sortPoints()) {
    if (s.name == name) return s.make();
    names += (names.empty() ? "" : ", ") + std::string(s.name);
  }
  throw InputError("unknown raster method '" + std::string(name) + "' (expected one of: " + names + ")");
}

}  // namespace pr::raster
