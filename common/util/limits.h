// Count limits of packed indices (32-bit vertex indices, 29-bit primitive ids in the raster
// depth key, 27-bit BVH leaf offsets), checked where input enters so that a legal but huge
// scene is an input error naming the limit and the count found, not an internal check failure.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "common/util/error.h"

namespace pr {

// "" when count <= limit, otherwise "<where>: <count> <noun> exceed the limit of <limit> (<why>)".
inline std::string countLimitProblem(std::string_view where, std::string_view noun, uint64_t count, uint64_t limit,
                                     std::string_view why) {
  if (count <= limit) return {};
  return std::string(where) + ": " + std::to_string(count) + " " + std::string(noun) + " exceed the limit of " +
         std::to_string(limit) + " (" + std::string(why) + ")";
}

// Throws pr::InputError with countLimitProblem's message when count > limit.
inline void checkCountLimit(std::string_view where, std::string_view noun, uint64_t count, uint64_t limit,
                            std::string_view why) {
  std::string problem = countLimitProblem(where, noun, count, limit, why);
  if (!problem.empty()) throw InputError(problem);
}

}  // namespace pr
