// Names of the punctual light types, as printed by `parrender info` and written to run records.
#include "common/scene/light.h"

namespace pr::scene {

std::string_view toString(LightType type) {
  switch (type) {
    case LightType::Point: return "point";
    case LightType::Spot: return "spot";
    case LightType::Directional: return "directional";
  }
  return "unknown";
}

}  // namespace pr::scene
