// Shared state of one glTF load (internal to gltf_loader.cpp and its helper files): the
// tinygltf model, the file name every error message starts with, and warning collection.
// Not part of the scene API: only the loader's own .cpp files include it.
#pragma once

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include <tiny_gltf.h>

#include "common/scene/scene.h"
#include "common/util/error.h"
#include "common/util/log.h"
#include "common/util/memory_limit.h"

namespace pr::scene::gltf {

struct Context {
  const tinygltf::Model& model;
  std::string file;  // as given by the user, so messages name what they typed
  Scene& scene;
  MemoryBudget& budget;          // every large allocation of the load is charged here first
  std::set<std::string> warned;  // each distinct warning once, however many instances repeat it
  int variant = -1;              // KHR_materials_variants index applied, -1 = default materials

  // Bad input: one message naming the file, the element and the problem.
  [[noreturn]] void fail(const std::string& what) const { throw InputError(file + ": " + what); }

  // Charges `bytes` for `what` to the budget; an input error naming the file when over.
  void charge(uint64_t bytes, const std::string& what) const {
    try {
      budget.charge(bytes, what);
    } catch (const InputError& e) {
      fail(e.what());
    }
  }

  // Optional content skipped or ignored: printed once and kept in Scene::warnings.
  void warn(const std::string& what) {
    if (!warned.insert(what).second) return;
    scene.warnings.push_back(what);
    pr::warn(file + ": " + what);
  }
};

// An integer that an extension holds as a raw JSON value (a light or material index, a
// TEXCOORD set): its value when it is a whole number within int's range, otherwise an input
// error naming `what`. tinygltf's GetNumberAsInt converts any real, which is undefined
// behaviour for one outside int's range (1e30 in a fuzzed file). A JSON integer beyond int's
// range cannot be caught here: tinygltf's parser has already wrapped it to an int (defined,
// modulo 2^32), so such an index reads as another one (4294967296 as 0).
inline int wholeNumber(const Context& ctx, const tinygltf::Value& v, const std::string& what) {
  if (v.IsInt()) return v.GetNumberAsInt();
  const double d = v.IsNumber() ? v.GetNumberAsDouble() : std::nan("");
  constexpr double lo = std::numeric_limits<int>::min(), hi = std::numeric_limits<int>::max();
  if (!(d >= lo && d <= hi) || d != std::floor(d)) ctx.fail(what + " is not a whole number within int's range");
  return int(d);
}

// "mesh 2 'Box'" (the name only when the file gives one), for messages.
inline std::string describe(const char* kind, int index, const std::string& name) {
  std::string s = std::string(kind) + " " + std::to_string(index);
  if (!name.empty()) s += " '" + name + "'";
  return s;
}

}  // namespace pr::scene::gltf
