// See module_loader.h.
#include "common/util/module_loader.h"

#include <dlfcn.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#ifndef PARRENDER_MODULE_DIR
#define PARRENDER_MODULE_DIR ""
#endif

namespace pr {

void* openModuleEntry(const char* file, const char* pathVariable, const char* entry) {
  namespace fs = std::filesystem;
  std::vector<fs::path> candidates;
  if (const char* path = std::getenv(pathVariable); path && *path) {
    candidates.emplace_back(path);
  } else {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) {
      candidates.push_back(exe.parent_path() / file);
      candidates.push_back(exe.parent_path().parent_path() / "lib" / file);
    }
    if (*PARRENDER_MODULE_DIR) candidates.push_back(fs::path(PARRENDER_MODULE_DIR) / file);
  }
  std::string looked;
  for (const fs::path& path : candidates) {
    std::error_code ec;
    if (!fs::is_regular_file(path, ec)) {
      looked += (looked.empty() ? "" : ", ") + path.string();
      continue;
    }
    // RTLD_LAZY: functions bound on first call, as the dynamic linker binds them at start-up
    // (binding all of a large library's dependencies at once costs ~15 % more). RTLD_LOCAL:
    // its symbols stay out of the program's namespace. Never closed: it lives as long as the
    // process.
    void* handle = dlopen(path.c_str(), RTLD_LAZY | RTLD_LOCAL);
    if (!handle) throw std::runtime_error("cannot open the module " + path.string() + ": " + dlerror());
    void* symbol = dlsym(handle, entry);
    if (!symbol) throw std::runtime_error("the module " + path.string() + " has no entry point " + entry);
    return symbol;
  }
  throw std::runtime_error(std::string("the module ") + file + " was not found (looked at " + looked +
                           "; build it with the program, or set " + pathVariable + " to its path)");
}

}  // namespace pr
