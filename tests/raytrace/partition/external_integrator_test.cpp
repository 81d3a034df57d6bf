// A render job carries a ready-built integrator (TraceJob::integrator): an integrator defined
// outside raytrace — here a constant-radiance one in this file, added to a copy of the
// built-in registry the way tools/ adds photonmap's — is the one every tracer shades with:
// image-space and sequential through its own instantiation of the world-model loop, the
// object-space and object tracers through shade per hit message.
#include <memory>
#include <string>

#include <doctest/doctest.h>

#include "common/scene/camera_select.h"
#include "common/scene/gltf_loader.h"
#include "raytrace/integrators/trace_loop.h"
#include "raytrace/partition/partition.h"
#include "test_support.h"

using namespace pr;

namespace {

// Every hit adds the same radiance, whatever the surface; nothing is spawned, so a pixel is
// kRadiance where its camera rays hit the scene and black where they miss. Values exact in
// the film's fixed point.
const glm::vec3 kRadiance(0.25f, 0.5f, 1.0f);

class ConstantIntegrator final : public rt::IntegratorBase<ConstantIntegrator> {
 public:
  using IntegratorBase::IntegratorBase;
  std::string_view name() const override { return "constant"; }
  void shade(const rt::SurfaceInteraction&, const rt::RayMessage& msg, rt::Emit& out) const override {
    out.addRadiance(msg.pixel, kRadiance * msg.throughput);
  }
};

rt::IntegratorRegistry extendedRegistry() {
  rt::IntegratorRegistry registry = rt::builtinIntegrators();
  registry.add({"constant", "every hit adds one constant radiance (test)", [](const rt::IntegratorSetup& s) {
                  return std::shared_ptr<const rt::Integrator>(
                      std::make_shared<const ConstantIntegrator>(s.scene, s.camera, s.width, s.height, s.options));
                }});
  return registry;
}

}  // namespace

TEST_CASE("ExternalIntegrator: a registry extended from outside raytrace lists and builds the new integrator") {
  const rt::IntegratorRegistry registry = extendedRegistry();
  CHECK(registry.joinedNames() == "whitted, path, constant");
  CHECK(registry.describe().find("every hit adds one constant radiance") != std::string::npos);
  CHECK_THROWS_WITH_AS(registry.find("photons"), "unknown integrator 'photons' (expected one of: whitted, path, constant)",
                       InputError);
  // The library's own registry is untouched.
  CHECK(rt::builtinIntegrators().joinedNames() == "whitted, path");
}

TEST_CASE("ExternalIntegrator: the job's integrator is the one image-space, object-space and object tracers use") {
  const scene::Scene s = scene::loadGltf(test::sourceDir() / "scenes" / "cornell.gltf");
  constexpr int kW = 24, kH = 18;
  const scene::Camera cam = scene::selectCamera(s, "", float(kW) / float(kH));
  rt::IntegratorOptions io;
  io.spp = 2;
  io.maxDepth = 4;
  const rt::IntegratorSetup setup{s, cam, kW, kH, io};
  const std::shared_ptr<const rt::Integrator> constant = extendedRegistry().find("constant").make(setup);
  REQUIRE(constant->name() == "constant");

  image::Image reference;
  for (const std::string partition : {"sequential", "image-space", "image-space-cached", "object-space", "object"}) {
    CAPTURE(partition);
    rt::TraceJob job{s, cam, kW, kH, rt::TraceOptions{}};
    job.options.tileSizePx = 8;
    job.integrator = constant;
    par::Runtime runtime(partition == "sequential" ? 1 : 2, "demand");
    const rt::TraceResult r = rt::renderRays(job, partition, runtime);
    // A pixel is kRadiance times the fraction of its 2 samples that hit: 0, 1/2 or 1 — a
    // value the built-in integrators (lit walls, glass, mirror) would not give everywhere.
    size_t lit = 0, half = 0, black = 0;
    for (const glm::vec3& p : r.image.pixels) {
      lit += p == kRadiance;
      half += p == 0.5f * kRadiance;
      black += p == glm::vec3(0.0f);
    }
    CHECK(lit + half + black == r.image.pixels.size());
    CHECK(lit > r.image.pixels.size() / 2);
    // One camera ray per sample and nothing spawned: the rays the tracer counted.
    CHECK(r.rays.cameraRays == uint64_t(kW) * kH * 2);
    CHECK(r.rays.continuationRays == 0);
    CHECK(r.rays.shadowRays == 0);
    if (reference.empty()) reference = r.image;
    CHECK(r.image.pixels == reference.pixels);
  }
}
