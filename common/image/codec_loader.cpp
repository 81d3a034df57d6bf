// The image codec module's loader (see codec_loader.h). The module is looked for beside the
// executable, in ../lib from it (the build tree's layout: build/tools/parrender and
// build/lib/), in the build's own lib directory, or at $PARRENDER_IMAGE_CODEC when set.
#include "common/image/codec_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "common/util/error.h"

#ifndef PARRENDER_CODEC_DIR
#define PARRENDER_CODEC_DIR ""
#endif

namespace pr::image {
namespace {

namespace fs = std::filesystem;

constexpr const char* kModule = "libparrender_image_codec.so";

struct Loaded {
  const ImageCodec* codec = nullptr;
  std::string error;
};

std::vector<fs::path> candidates() {
  if (const char* path = std::getenv("PARRENDER_IMAGE_CODEC"); path && *path) return {fs::path(path)};
  std::vector<fs::path> out;
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    out.push_back(exe.parent_path() / kModule);
    out.push_back(exe.parent_path().parent_path() / "lib" / kModule);
  }
  if (*PARRENDER_CODEC_DIR) out.push_back(fs::path(PARRENDER_CODEC_DIR) / kModule);
  return out;
}

Loaded open() {
  std::string looked;
  for (const fs::path& path : candidates()) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      looked += (looked.empty() ? "" : ", ") + path.string();
      continue;
    }
    // RTLD_LAZY: functions bound on first call, as the dynamic linker binds them at start-up
    // (binding all of OpenImageIO's dependencies at once costs ~15 % more). RTLD_LOCAL: its
    // symbols stay out of the program's namespace. Never closed: the codec lives as long as
    // the process.
    void* handle = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (!handle) return {nullptr, "cannot open the image codec " + path.string() + ": " + dlerror()};
    using Entry = const ImageCodec* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, "parrender_image_codec"));
    if (!entry) return {nullptr, "the image codec " + path.string() + " has no entry point parrender_image_codec"};
    return {entry(), ""};
  }
  return {nullptr, std::string("the image codec module ") + kModule + " was not found (looked at " + looked +
                       "; build it with the program, or set PARRENDER_IMAGE_CODEC to its path)"};
}

// One per process. Its destructor waits for a preload still running at exit, so the library's
// constructors never race the process's own teardown.
struct CodecState {
  std::once_flag once;
  Loaded loaded;
  std::mutex preloadMutex;
  std::thread preload;
  ~CodecState() {
    if (preload.joinable()) preload.join();
  }
  const Loaded& load() {
    std::call_once(once, [this] { loaded = open(); });
    return loaded;
  }
};

CodecState& state() {
  static CodecState s;
  return s;
}

}  // namespace

void preloadImageCodec() {
  CodecState& s = state();
  std::lock_guard lock(s.preloadMutex);
  if (!s.preload.joinable()) s.preload = std::thread([&s] { s.load(); });
}

const ImageCodec& imageCodec() {
  const Loaded& loaded = state().load();
  if (!loaded.codec) throw std::runtime_error(loaded.error);
  return *loaded.codec;
}

}  // namespace pr::image
