#include "common/util/log.h"

#include <atomic>
#include <cstdio>

namespace pr {

namespace {
std::atomic<bool> gQuiet{false};
}

void warn(const std::string& message) {
  if (!gQuiet.load(std::memory_order_relaxed)) std::fprintf(stderr, "parrender: warning: %s\n", message.c_str());
}

void setQuiet(bool q) { gQuiet.store(q, std::memory_order_relaxed); }
bool quiet() { return gQuiet.load(std::memory_order_relaxed); }

}  // namespace pr
