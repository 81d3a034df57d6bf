// The program's integrator registry (name -> factory -> description): what `--integrator`
// accepts, lists in --help and names in the render summary. Assembled here, in tools/, the one
// place that links every library: raytrace's built-ins first, then the integrators of
// libraries further down the link order (photonmap), one add() line each in integrators.cpp.
#pragma once

#include "raytrace/integrators/integrator.h"

namespace pr::cli {

const rt::IntegratorRegistry& integrators();

}  // namespace pr::cli
