// A hash of a loaded scene's content, so ranks that each loaded "the same" scene can check they
// hold the same data (the farm's servers, common/parallel/farm/farm.h): the same file name on
// two machines may be two different files.
#pragma once

#include <cstdint>

#include "common/scene/scene.h"

namespace pr::scene {

// FNV-1a over the vertex attributes, the triangles, every texture's pixels and the materials'
// names and number: what an edit of the file would change (material factors are not hashed:
// their structs have padding whose bytes are not part of the value).
std::uint64_t contentHash(const Scene& scene);

}  // namespace pr::scene
