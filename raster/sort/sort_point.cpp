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

namespace {

// Which sort point fills each counter, and its name in the run record (Category/what).
struct SortCounterField {
  std::string_view sortPoint;
  std::string_view name;
  uint64_t SortCounters::*value;
};
constexpr SortCounterField kSortCounterFields[] = {
    {"sort-first", "Sort/primitives_routed", &SortCounters::primitivesRouted},
    {"sort-first", "Sort/primitives_sent", &SortCounters::primitivesSent},
    {"sort-first", "Sort/primitives_duplicated", &SortCounters::primitivesDuplicated},
    {"sort-first", "Sort/primitives_migrated", &SortCounters::primitivesMigrated},
    {"sort-first", "Sort/pre_transforms", &SortCounters::preTransforms},
    {"sort-first", "Sort/geometry_repeated", &SortCounters::geometryRepeated},
    {"sort-middle", "Sort/triangles_routed", &SortCounters::trianglesRouted},
    {"sort-middle", "Sort/triangles_sent", &SortCounters::trianglesSent},
    {"sort-middle", "Sort/triangles_duplicated", &SortCounters::trianglesDuplicated},
    {"sort-last", "Sort/pixels_sent", &SortCounters::pixelsSent},
    {"sort-last", "Sort/composite_messages", &SortCounters::compositeMessages},
    {"sort-last", "Sort/composite_bytes", &SortCounters::compositeBytes},
};

}  // namespace

SortCounters recordSortCounters(std::string_view sortPoint, const std::vector<SortCounters>& perPe,
                                par::Runtime& runtime) {
  PR_CHECK(perPe.size() == size_t(runtime.pes()),
           "sort counters for " + std::to_string(perPe.size()) + " PEs on a runtime of " +
               std::to_string(runtime.pes()));
  bool known = false;
  for (const SortCounterField& f : kSortCounterFields) {
    if (f.sortPoint != sortPoint) continue;
    known = true;
    for (int p = 0; p < runtime.pes(); ++p) runtime.addCounter(f.name, p, double(perPe[size_t(p)].*f.value));
  }
  PR_CHECK(known, "no sort counters belong to '" + std::string(sortPoint) + "'");
  SortCounters sum;
  for (const SortCounters& c : perPe) sum += c;
  return sum;
}

const SortPointRegistry& sortPoints() {
  static const SortPointRegistry kSortPoints(
      "raster method",
      {
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
