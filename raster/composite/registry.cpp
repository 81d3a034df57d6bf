// The compositor registry: one line per sort-last compositor (name -> factory -> description).
// Feeds `parrender render --compositor`, its --help text and validation.
#include "raster/composite/compositor.h"

namespace pr::raster {

const CompositorRegistry& compositors() {
  static const CompositorRegistry kCompositors(
      "compositor",
      {
          {"direct-send", "each PE sends each screen region straight to its owner (P - 1 messages per PE)", makeDirectSend},
          {"binary-swap", "log2 P pairwise exchanges of halves (Ma et al. 1994); P a power of two", makeBinarySwap},
      });
  return kCompositors;
}

std::unique_ptr<Compositor> makeCompositor(std::string_view name) { return compositors().find(name).make(); }

}  // namespace pr::raster
