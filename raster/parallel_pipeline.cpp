// Parallel raster entry point: a frame is a cleared full-screen image plus one renderFrame of
// the chosen sort point; the orbit camera for multi-frame runs.
#include "raster/parallel_pipeline.h"

#include <glm/gtc/matrix_transform.hpp>
#include "raster/stages/background.h"

namespace pr::raster {

void renderFrame(SortPoint& sortPoint, const scene::Scene& scene, const FrameView& view, const SortOptions& options,
                 par::Runtime& runtime, RegionFramebuffer& image) {
  checkRasterLimits("scene " + scene.source.string(), scene.triangles.size());
  const Rect screen{0, 0, view.width, view.height};
  if (!(image.rect() == screen)) image = RegionFramebuffer(screen);
  sortPoint.renderFrame(FrameInputs{scene, view, options}, runtime, image);
  if (showsEnvironment(scene, options.headlight)) fillBackground(view, *scene.environment, image);
  // The plan's skipped work leaves the sort point as run-record counters, per PE.
  const std::vector<ShadeCounters> shade = sortPoint.takeShadeCounters();
  for (size_t p = 0; p < shade.size() && int(p) < runtime.pes(); ++p) {
    runtime.addCounter("Plan/texture_evaluations_skipped", int(p), double(shade[p].textureEvaluationsSkipped));
    runtime.addCounter("Plan/emission_skipped", int(p), double(shade[p].emissionSkipped));
    runtime.addCounter("Plan/light_samples_skipped", int(p), double(shade[p].lightSamplesSkipped));
  }
}

RegionFramebuffer renderFrame(SortPoint& sortPoint, const scene::Scene& scene, const FrameView& view,
                              const SortOptions& options, par::Runtime& runtime) {
  RegionFramebuffer image;
  renderFrame(sortPoint, scene, view, options, runtime, image);
  return image;
}

RegionFramebuffer renderParallel(const scene::Scene& scene, const FrameView& view, std::string_view method,
                                 const SortOptions& options, par::Runtime& runtime) {
  std::unique_ptr<SortPoint> sortPoint = makeSortPoint(method);
  return renderFrame(*sortPoint, scene, view, options, runtime);
}

scene::Camera orbitCamera(const scene::Camera& camera, glm::vec3 centre, float angleRadians) {
  scene::Camera c = camera;
  const glm::mat4 turn = glm::translate(glm::mat4(1.0f), centre) *
                         glm::rotate(glm::mat4(1.0f), angleRadians, glm::vec3(0.0f, 1.0f, 0.0f)) *
                         glm::translate(glm::mat4(1.0f), -centre);
  c.cameraToWorld = turn * camera.cameraToWorld;
  return c;
}

}  // namespace pr::raster
