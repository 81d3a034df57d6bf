// Materials and textures of a glTF file (internal to the loader): samplers, images decoded
// by tinygltf converted to 8-bit RGBA, and pbrMetallicRoughness plus the KHR material
// extensions parrender honours, converted into Scene::textures and Scene::materials.
#pragma once

#include "common/scene/gltf_context.h"

namespace pr::scene::gltf {

// Fills scene.textures, one per glTF texture (same indices). A texture whose image file is
// missing is an input error; one without a decodable source stays empty, with a warning.
// Decoded 8-bit RGBA images are moved out of `images` (the model's), not copied.
void loadTextures(Context& context, std::vector<tinygltf::Image>& images);

// Fills scene.materials, one per glTF material (same indices), then the glTF default material
// last. Texture slots referring to an empty texture are left unset.
void loadMaterials(Context& context);

}  // namespace pr::scene::gltf
