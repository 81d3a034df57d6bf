// The sort-point registry (name -> factory -> description) and the counters' names: what the
// render command and the tests use to pick sequential-raster (the one-PE reference),
// sort-first, sort-middle or sort-last by name.
#include "raster/sort/sort_point.h"

#include "common/util/error.h"

namespace pr::raster {

const std::vector<std::string_view>& sortCounterNames(std::string_view sortPoint) {
  static const std::vector<std::string_view> kFirst = {
      "Sort/primitives_routed", "Sort/primitives_sent", "Sort/primitives_duplicated",
      "Sort/primitives_migrated", "Sort/pre_transforms", "Sort/geometry_repeated"};
  static const std::vector<std::string_view> kMiddle = {"Sort/triangles_routed", "Sort/triangles_sent",
                                                       "Sort/triangles_duplicated"};
  static const std::vector<std::string_view> kLast = {"Sort/pixels_sent", "Sort/composite_messages",
                                                     "Sort/composite_bytes"};
  if (sortPoint == "sort-first") return kFirst;
  if (sortPoint == "sort-middle") return kMiddle;
  PR_CHECK(sortPoint == "sort-last", "no sort counters belong to '" + std::string(sortPoint) + "'");
  return kLast;
}

void declareSortCounters(std::string_view sortPoint, par::Runtime& runtime) {
  for (std::string_view name : sortCounterNames(sortPoint)) runtime.addCounter(name, 0, 0.0);
}

const SortPointRegistry& sortPoints() {
  static const SortPointRegistry kSortPoints(
      "raster method",
      {
          // The reference first: compare checks every image of the family against the first.
          {"sequential-raster", "one PE, the sequential pipeline, nothing sorted (the reference: the family's Ts)",
           &makeSequentialRaster},
          {"sort-first", "primitives pre-transformed and sent to screen-region owners, who run the whole pipeline",
           &makeSortFirst},
          {"sort-middle", "screen triangles sent from geometry to the region owners, who rasterize", &makeSortMiddle},
          {"sort-last", "every PE renders its primitives full screen; pixels depth-composited by region", &makeSortLast},
      });
  return kSortPoints;
}

bool isSortPoint(std::string_view name) { return sortPoints().contains(name); }

std::unique_ptr<SortPoint> makeSortPoint(std::string_view name) { return sortPoints().find(name).make(); }

}  // namespace pr::raster
