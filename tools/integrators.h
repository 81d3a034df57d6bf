// The program's integrator registry (name -> factory -> description): what `--integrator`
// accepts, lists in --help and names in the render summary. Assembled here, in tools/, the one
// place that links every library: raytrace's built-ins first, then the integrators of
// libraries further down the link order (photonmap), one add() line each in integrators.cpp.
#pragma once

#include "photonmap/photon_map_integrator.h"
#include "raytrace/integrators/integrator.h"

namespace pr::cli {

// With the photon map's default settings: what --integrator validates against and --help lists.
const rt::IntegratorRegistry& integrators();
// The same integrators, the photon map's factory built with `photonmap` (one render's options).
rt::IntegratorRegistry integrators(const pm::PhotonMapSettings& photonmap);

}  // namespace pr::cli
