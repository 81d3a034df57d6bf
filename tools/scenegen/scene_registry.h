// The bundled scenes `parrender generate` can write: one line each (name, description, what
// --size means and its range, whether --seed is used) and the function that builds it. The
// table feeds --help, argument validation and scenes/README.md.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/util/registry.h"
#include "tools/scenegen/gltf_builder.h"

namespace pr::scenegen {

struct SceneParams {
  int size = 0;       // meaning per scene: SceneProperties::sizeMeaning
  uint64_t seed = 0;  // used only where SceneProperties::usesSeed
};

// What a scene declares beside its name and description.
struct SceneProperties {
  std::string_view sizeMeaning;  // what --size sets
  int defaultSize = 0, minSize = 0, maxSize = 0;
  bool usesSeed = false;
  uint64_t defaultSeed = 0;
};
// The factory writes the scene into the builder.
using SceneBuild = void (*)(GltfBuilder& builder, const SceneParams& params);
using SceneEntry = RegistryEntry<SceneBuild, SceneProperties>;
using SceneRegistry = Registry<SceneBuild, SceneProperties>;

const SceneRegistry& sceneRegistry();

// The entry called `name`; pr::InputError listing the known names otherwise.
const SceneEntry& findScene(std::string_view name);

// Builds scene `name`: checks the size range (InputError naming it), then runs the builder.
// The asset's generator string records the scene, size and seed, so the file says how to
// regenerate it.
GltfBuilder generateScene(const SceneEntry& scene, const SceneParams& params);

// The builders, one per file (cornell.cpp, landscape.cpp, hotspot.cpp).
void buildCornell(GltfBuilder& builder, const SceneParams& params);
void buildCornellDiffuse(GltfBuilder& builder, const SceneParams& params);
void buildCornellGlass(GltfBuilder& builder, const SceneParams& params);
void buildCornellRough(GltfBuilder& builder, const SceneParams& params);
void buildLandscape(GltfBuilder& builder, const SceneParams& params);
void buildHotspot(GltfBuilder& builder, const SceneParams& params);
// stress.cpp: the scenes that stress the numerics.
void buildStressScaleSmall(GltfBuilder& builder, const SceneParams& params);
void buildStressScaleLarge(GltfBuilder& builder, const SceneParams& params);
void buildStressDegenerate(GltfBuilder& builder, const SceneParams& params);
void buildStressZFight(GltfBuilder& builder, const SceneParams& params);
void buildStressCameraInside(GltfBuilder& builder, const SceneParams& params);
void buildStressLightInside(GltfBuilder& builder, const SceneParams& params);
void buildStressLightOnSurface(GltfBuilder& builder, const SceneParams& params);
void buildStressThinGlass(GltfBuilder& builder, const SceneParams& params);
void buildStressDielectrics(GltfBuilder& builder, const SceneParams& params);
void buildStressFireflies(GltfBuilder& builder, const SceneParams& params);
void buildStressHugeTriangle(GltfBuilder& builder, const SceneParams& params);
void buildStressTotalReflection(GltfBuilder& builder, const SceneParams& params);

}  // namespace pr::scenegen
