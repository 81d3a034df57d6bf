// EGL surfaceless context on Mesa llvmpipe for the raster anchor (see egl_context.h).
// Order matters: the environment is set before the first EGL call, because Mesa's EGL picks
// the platform and driver, and llvmpipe its tile-thread count, when the display initializes.
#include "tools/bench/anchors/egl_context.h"

#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <GLES3/gl3.h>

namespace pr::bench {
namespace {

std::mutex gMutex;
std::unique_ptr<EglContext> gContext;
std::string gFailure;  // why the first attempt failed; later calls report the same reason

bool hasExtension(const char* list, const std::string& name) {
  if (!list) return false;
  const std::string all = std::string(" ") + list + " ";
  return all.find(" " + name + " ") != std::string::npos;
}

std::string eglErrorText(const char* what) {
  char code[16];
  std::snprintf(code, sizeof code, "0x%04X", unsigned(eglGetError()));
  return std::string(what) + " failed (EGL error " + code + ")";
}

}  // namespace

EglContext& EglContext::acquire(int threads) {
  if (threads < 0) throw std::invalid_argument("llvmpipe threads must be >= 0, got " + std::to_string(threads));
  std::lock_guard lock(gMutex);
  if (!gContext) {
    if (!gFailure.empty()) throw AnchorUnavailable(gFailure);
    try {
      gContext.reset(new EglContext(threads));
    } catch (const AnchorUnavailable& e) {
      gFailure = e.what();
      throw;
    }
  } else if (gContext->threads_ != threads) {
    throw std::logic_error("llvmpipe already runs with LP_NUM_THREADS=" + std::to_string(gContext->threads_) +
                           " in this process; it cannot switch to " + std::to_string(threads) +
                           " (run the llvmpipe_anchor program once per thread count)");
  }
  gContext->makeCurrent();
  return *gContext;
}

EglContext::EglContext(int threads) : threads_(threads) {
  // Step 1: the environment Mesa reads when the display initializes (overriding the caller's).
  setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), 1);
  setenv("LIBGL_ALWAYS_SOFTWARE", "1", 1);
  setenv("GALLIUM_DRIVER", "llvmpipe", 1);
  setenv("EGL_PLATFORM", "surfaceless", 1);

  // Step 2: a surfaceless display, through the platform extension when the client offers it.
  const char* clientExtensions = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  if (!hasExtension(clientExtensions, "EGL_MESA_platform_surfaceless"))
    throw AnchorUnavailable("EGL client extension EGL_MESA_platform_surfaceless is missing (is Mesa's libegl-mesa0 installed?)");
  auto getPlatformDisplay =
      reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!getPlatformDisplay) throw AnchorUnavailable("eglGetPlatformDisplayEXT is not available");
  EGLDisplay display = getPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (display == EGL_NO_DISPLAY) throw AnchorUnavailable(eglErrorText("eglGetPlatformDisplayEXT(surfaceless)"));
  EGLint major = 0, minor = 0;
  if (!eglInitialize(display, &major, &minor)) throw AnchorUnavailable(eglErrorText("eglInitialize"));
  display_ = display;

  // Step 3: an OpenGL ES 3 context made current with no surface (drawing goes to an FBO).
  if (!hasExtension(eglQueryString(display, EGL_EXTENSIONS), "EGL_KHR_surfaceless_context"))
    throw AnchorUnavailable("EGL display lacks EGL_KHR_surfaceless_context");
  const EGLint configAttributes[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_ES3_BIT, EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint configCount = 0;
  if (!eglChooseConfig(display, configAttributes, &config, 1, &configCount) || configCount < 1)
    throw AnchorUnavailable(eglErrorText("eglChooseConfig(OpenGL ES 3)"));
  if (!eglBindAPI(EGL_OPENGL_ES_API)) throw AnchorUnavailable(eglErrorText("eglBindAPI(OpenGL ES)"));
  const EGLint contextAttributes[] = {EGL_CONTEXT_MAJOR_VERSION, 3, EGL_CONTEXT_MINOR_VERSION, 0, EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, contextAttributes);
  if (context == EGL_NO_CONTEXT) throw AnchorUnavailable(eglErrorText("eglCreateContext(OpenGL ES 3.0)"));
  context_ = context;
  makeCurrent();

  // Step 4: make sure it is llvmpipe, not a hardware driver or another software rasterizer.
  const auto* renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  const auto* version = reinterpret_cast<const char*>(glGetString(GL_VERSION));
  renderer_ = renderer ? renderer : "";
  version_ = version ? version : "";
  if (renderer_.find("llvmpipe") == std::string::npos)
    throw AnchorUnavailable("GL_RENDERER is \"" + renderer_ + "\", not llvmpipe (is libgl1-mesa-dri installed?)");
}

void EglContext::makeCurrent() {
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
    throw AnchorUnavailable(eglErrorText("eglMakeCurrent(surfaceless)"));
}

}  // namespace pr::bench
