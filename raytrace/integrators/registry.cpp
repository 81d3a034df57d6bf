// The built-in integrator registry: one line per integrator of this library (name -> factory
// -> description). A program extends a copy of it with integrators of libraries that link
// raytrace (tools/integrators.cpp); feeds --integrator, its --help and validation.
#include <memory>

#include "raytrace/integrators/path_tracer.h"
#include "raytrace/integrators/whitted.h"

namespace pr::rt {

namespace {
template <class I>
std::shared_ptr<const Integrator> make(const IntegratorSetup& s) {
  return std::make_shared<const I>(s.scene, s.camera, s.width, s.height, s.options);
}
}  // namespace

const IntegratorRegistry& builtinIntegrators() {
  static const IntegratorRegistry kIntegrators(
      "integrator",
      {
          {"whitted", "Whitted ray tracing: direct light, ideal mirror reflection and refraction", make<WhittedIntegrator>},
          {"path", "path tracing with next-event estimation and MIS (the reference)", make<PathIntegrator>},
      });
  return kIntegrators;
}

std::shared_ptr<const Integrator> makeBuiltinIntegrator(IntegratorKind kind, const IntegratorSetup& setup) {
  return builtinIntegrators().find(toString(kind)).make(setup);
}

}  // namespace pr::rt
