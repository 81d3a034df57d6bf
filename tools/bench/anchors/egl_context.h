// The OpenGL ES 3 context the llvmpipe anchor renders in: an EGL surfaceless display
// (EGL_MESA_platform_surfaceless) forced onto Mesa's llvmpipe software rasterizer, with no
// window and no pbuffer (drawing goes to an FBO). Created once per process by
// renderWithLlvmpipe (llvmpipe_anchor.cpp), the first caller fixing LP_NUM_THREADS.
#pragma once

#include <stdexcept>
#include <string>

namespace pr::bench {

// No usable llvmpipe context on this machine (no EGL, no surfaceless platform, no Mesa
// llvmpipe driver, or a hardware driver answered instead). Tests turn it into "SKIPPED".
class AnchorUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The process-wide llvmpipe context. llvmpipe reads LP_NUM_THREADS once, when EGL creates its
// screen, so a process renders with a single tile-thread count: the first acquire() sets
// LP_NUM_THREADS, LIBGL_ALWAYS_SOFTWARE, GALLIUM_DRIVER and EGL_PLATFORM before any EGL call;
// a later acquire() with another count throws std::logic_error (run the standalone
// llvmpipe_anchor program once per count instead). The context is current on the calling
// thread only; acquire() makes it current again, so call it from one thread at a time.
class EglContext {
 public:
  static EglContext& acquire(int threads);

  int threads() const { return threads_; }
  const std::string& renderer() const { return renderer_; }  // GL_RENDERER
  const std::string& version() const { return version_; }    // GL_VERSION

  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

 private:
  explicit EglContext(int threads);
  void makeCurrent();

  int threads_ = 0;
  void* display_ = nullptr;  // EGLDisplay
  void* context_ = nullptr;  // EGLContext
  std::string renderer_, version_;
};

}  // namespace pr::bench
