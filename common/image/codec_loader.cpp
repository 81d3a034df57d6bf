// The image codec module's loader (see codec_loader.h), over module_loader.h: the module is
// libparrender_image_codec.so, or the file $PARRENDER_IMAGE_CODEC names.
#include "common/image/codec_loader.h"

#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

#include "common/util/module_loader.h"

namespace pr::image {
namespace {

struct Loaded {
  const ImageCodec* codec = nullptr;
  std::string error;
};

Loaded open() {
  try {
    using Entry = const ImageCodec* (*)();
    const auto entry = reinterpret_cast<Entry>(
        openModuleEntry("libparrender_image_codec.so", "PARRENDER_IMAGE_CODEC", "parrender_image_codec"));
    return {entry(), ""};
  } catch (const std::exception& e) {
    return {nullptr, std::string("image codec: ") + e.what()};
  }
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
