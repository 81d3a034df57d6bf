// Assembles the program's integrator registry (see integrators.h). Explicit assembly rather
// than static self-registration: photonmap is a static library, and an object file of it that
// nothing references would be dropped by the linker with its registration.
#include "tools/integrators.h"

namespace pr::cli {

namespace {
rt::IntegratorRegistry assemble(const pm::PhotonMapSettings& photonmap) {
  rt::IntegratorRegistry registry = rt::builtinIntegrators();
  registry.add(pm::photonMapIntegratorEntry(photonmap));
  return registry;
}
}  // namespace

const rt::IntegratorRegistry& integrators() {
  static const rt::IntegratorRegistry kIntegrators = assemble({});
  return kIntegrators;
}

rt::IntegratorRegistry integrators(const pm::PhotonMapSettings& photonmap) { return assemble(photonmap); }

}  // namespace pr::cli
