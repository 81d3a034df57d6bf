// glTF materials and textures into the render-ready scene (glTF 2.0 spec 3.8 "Materials",
// 3.9 "Textures"; KHR_materials_* and KHR_texture_transform extension specs). Runs once at
// load, before any PE exists; renderers only read the result.
#include "common/scene/gltf_material.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace pr::scene::gltf {

namespace {

// ---- reading extension objects (tinygltf keeps them as generic Values) ----

const tinygltf::Value* extension(const tinygltf::ExtensionMap& extensions, const char* name) {
  auto it = extensions.find(name);
  return it != extensions.end() && it->second.IsObject() ? &it->second : nullptr;
}

float number(const tinygltf::Value& object, const char* key, float fallback) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  return v.IsNumber() ? float(v.GetNumberAsDouble()) : fallback;
}

template <int N>
glm::vec<N, float> numbers(const tinygltf::Value& object, const char* key, glm::vec<N, float> fallback) {
  if (!object.Has(key)) return fallback;
  const tinygltf::Value& v = object.Get(key);
  if (!v.IsArray() || v.ArrayLen() != size_t(N)) return fallback;
  glm::vec<N, float> out;
  for (int i = 0; i < N; ++i) {
    if (!v.Get(i).IsNumber()) return fallback;
    out[i] = float(v.Get(i).GetNumberAsDouble());
  }
  return out;
}

// ---- textures ----

Wrap toWrap(int mode) {
  switch (mode) {
    case TINYGLTF_TEXTURE_WRAP_CLAMP_TO_EDGE: return Wrap::ClampToEdge;
    case TINYGLTF_TEXTURE_WRAP_MIRRORED_REPEAT: return Wrap::MirroredRepeat;
    default: return Wrap::Repeat;
  }
}

// Mipmap modes keep their base (within-level) filter: there are no mip levels here.
Filter toFilter(int mode) {
  switch (mode) {
    case TINYGLTF_TEXTURE_FILTER_NEAREST:
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_NEAREST:
    case TINYGLTF_TEXTURE_FILTER_NEAREST_MIPMAP_LINEAR: return Filter::Nearest;
    default: return Filter::Linear;  // LINEAR*, or unset (-1): the viewer's choice
  }
}

// tinygltf decodes PNG/JPEG with stb_image to 8 or 16 bits and (by default) 4 channels;
// convert whatever it gives to 8-bit RGBA (16-bit: keep the high byte; grey: replicate).
std::vector<uint8_t> toRgba8(const tinygltf::Image& image) {
  const size_t texels = size_t(image.width) * size_t(image.height);
  const int channels = image.component;
  const int bytes = image.bits == 16 ? 2 : 1;
  std::vector<uint8_t> rgba(texels * 4, 255);
  for (size_t i = 0; i < texels; ++i) {
    auto channel = [&](int c) {
      // 16-bit stb data is native-endian uint16: the high byte is the 8-bit value.
      size_t at = (i * size_t(channels) + size_t(c)) * size_t(bytes);
      if (bytes == 1) return image.image[at];
      uint16_t v;
      std::memcpy(&v, &image.image[at], 2);
      return uint8_t(v >> 8);
    };
    uint8_t* out = &rgba[i * 4];
    if (channels >= 3) {
      out[0] = channel(0), out[1] = channel(1), out[2] = channel(2);
      if (channels == 4) out[3] = channel(3);
    } else {
      out[0] = out[1] = out[2] = channel(0);
      if (channels == 2) out[3] = channel(1);
    }
  }
  return rgba;
}

// ---- materials ----

// A textureInfo: index (checked), UV set, and KHR_texture_transform.
TextureRef textureRef(Context& ctx, const tinygltf::TextureInfo& info, const std::string& where) {
  TextureRef ref;
  if (info.index < 0) return ref;
  if (size_t(info.index) >= ctx.scene.textures.size()) {
    ctx.fail(where + ": texture " + std::to_string(info.index) + " is out of range (the file has " +
             std::to_string(ctx.scene.textures.size()) + " textures)");
  }
  if (ctx.scene.textures[size_t(info.index)].rgba8.empty()) return ref;  // warned in loadTextures
  ref.texture = info.index;
  ref.texCoord = info.texCoord;
  if (const tinygltf::Value* t = extension(info.extensions, "KHR_texture_transform")) {
    glm::vec2 offset = numbers<2>(*t, "offset", glm::vec2(0.0f));
    float rotation = number(*t, "rotation", 0.0f);
    glm::vec2 scale = numbers<2>(*t, "scale", glm::vec2(1.0f));
    if (t->Has("texCoord")) ref.texCoord = wholeNumber(ctx, t->Get("texCoord"), where + ": KHR_texture_transform texCoord");
    // uv' = T * R * S * (u, v, 1) with R rotating UVs counter-clockwise in the texture's
    // (u right, v down) frame: u' = cos*u + sin*v, v' = -sin*u + cos*v (extension spec).
    float c = std::cos(rotation), s = std::sin(rotation);
    glm::mat3 translation(1, 0, 0, 0, 1, 0, offset.x, offset.y, 1);
    glm::mat3 rotate(c, -s, 0, s, c, 0, 0, 0, 1);
    glm::mat3 scaling(scale.x, 0, 0, 0, scale.y, 0, 0, 0, 1);
    ref.uvTransform = translation * rotate * scaling;
  }
  if (ref.texCoord != 0) {
    ctx.warn(where + " uses TEXCOORD_" + std::to_string(ref.texCoord) + "; only TEXCOORD_0 is loaded, so it samples set 0");
  }
  return ref;
}

TextureRef textureRef(Context& ctx, const tinygltf::Value& ext, const char* key, const std::string& where) {
  tinygltf::TextureInfo info;
  if (!ext.Has(key) || !ext.Get(key).IsObject()) return {};
  const tinygltf::Value& v = ext.Get(key);
  if (!v.Has("index")) return {};
  info.index = wholeNumber(ctx, v.Get("index"), where + " index");
  if (v.Has("texCoord")) info.texCoord = wholeNumber(ctx, v.Get("texCoord"), where + " texCoord");
  if (v.Has("extensions") && v.Get("extensions").IsObject()) {
    const tinygltf::Value& exts = v.Get("extensions");
    for (const std::string& name : exts.Keys()) info.extensions[name] = exts.Get(name);
  }
  return textureRef(ctx, info, where);
}

Material convert(Context& ctx, const tinygltf::Material& m, const std::string& where) {
  Material out;
  out.name = m.name;
  const auto& pbr = m.pbrMetallicRoughness;
  if (pbr.baseColorFactor.size() == 4) {
    out.baseColorFactor = glm::vec4(pbr.baseColorFactor[0], pbr.baseColorFactor[1], pbr.baseColorFactor[2],
                                    pbr.baseColorFactor[3]);
  }
  out.baseColorTexture = textureRef(ctx, pbr.baseColorTexture, where + " baseColorTexture");
  out.metallicFactor = float(pbr.metallicFactor);
  out.roughnessFactor = float(pbr.roughnessFactor);
  out.metallicRoughnessTexture = textureRef(ctx, pbr.metallicRoughnessTexture, where + " metallicRoughnessTexture");
  tinygltf::TextureInfo normalInfo;
  normalInfo.index = m.normalTexture.index;
  normalInfo.texCoord = m.normalTexture.texCoord;
  normalInfo.extensions = m.normalTexture.extensions;
  out.normalTexture = textureRef(ctx, normalInfo, where + " normalTexture");
  out.normalScale = float(m.normalTexture.scale);
  if (m.emissiveFactor.size() == 3) out.emissiveFactor = glm::vec3(m.emissiveFactor[0], m.emissiveFactor[1], m.emissiveFactor[2]);
  out.emissiveTexture = textureRef(ctx, m.emissiveTexture, where + " emissiveTexture");
  out.doubleSided = m.doubleSided;
  out.alphaMode = m.alphaMode == "MASK" ? AlphaMode::Mask : m.alphaMode == "BLEND" ? AlphaMode::Blend : AlphaMode::Opaque;
  out.alphaCutoff = float(m.alphaCutoff);

  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_emissive_strength")) {
    out.emissiveStrength = number(*e, "emissiveStrength", 1.0f);
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_transmission")) {
    out.transmissionFactor = number(*e, "transmissionFactor", 0.0f);
    out.transmissionTexture = textureRef(ctx, *e, "transmissionTexture", where + " transmissionTexture");
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_ior")) {
    out.ior = number(*e, "ior", 1.5f);
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_volume")) {
    out.thicknessFactor = number(*e, "thicknessFactor", 0.0f);
    out.attenuationColor = numbers<3>(*e, "attenuationColor", glm::vec3(1.0f));
    // Absent distance means no absorption: infinity (extension spec default).
    out.attenuationDistance = number(*e, "attenuationDistance", std::numeric_limits<float>::infinity());
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_anisotropy")) {
    out.anisotropyStrength = number(*e, "anisotropyStrength", 0.0f);
    out.anisotropyRotation = number(*e, "anisotropyRotation", 0.0f);
    out.anisotropyTexture = textureRef(ctx, *e, "anisotropyTexture", where + " anisotropyTexture");
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_specular")) {
    out.specularFactor = number(*e, "specularFactor", 1.0f);
    out.specularTexture = textureRef(ctx, *e, "specularTexture", where + " specularTexture");
    out.specularColorFactor = numbers<3>(*e, "specularColorFactor", glm::vec3(1.0f));
    out.specularColorTexture = textureRef(ctx, *e, "specularColorTexture", where + " specularColorTexture");
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_clearcoat")) {
    out.clearcoatFactor = number(*e, "clearcoatFactor", 0.0f);
    out.clearcoatTexture = textureRef(ctx, *e, "clearcoatTexture", where + " clearcoatTexture");
    out.clearcoatRoughnessFactor = number(*e, "clearcoatRoughnessFactor", 0.0f);
    out.clearcoatRoughnessTexture = textureRef(ctx, *e, "clearcoatRoughnessTexture", where + " clearcoatRoughnessTexture");
    out.clearcoatNormalTexture = textureRef(ctx, *e, "clearcoatNormalTexture", where + " clearcoatNormalTexture");
    if (e->Has("clearcoatNormalTexture") && e->Get("clearcoatNormalTexture").IsObject())
      out.clearcoatNormalScale = number(e->Get("clearcoatNormalTexture"), "scale", 1.0f);
  }
  if (const tinygltf::Value* e = extension(m.extensions, "KHR_materials_sheen")) {
    out.sheenColorFactor = numbers<3>(*e, "sheenColorFactor", glm::vec3(0.0f));
    out.sheenColorTexture = textureRef(ctx, *e, "sheenColorTexture", where + " sheenColorTexture");
    out.sheenRoughnessFactor = number(*e, "sheenRoughnessFactor", 0.0f);
    out.sheenRoughnessTexture = textureRef(ctx, *e, "sheenRoughnessTexture", where + " sheenRoughnessTexture");
  }
  return out;
}

}  // namespace

void loadTextures(Context& ctx, std::vector<tinygltf::Image>& images) {
  const auto& model = ctx.model;
  ctx.scene.textures.resize(model.textures.size());
  for (size_t i = 0; i < model.textures.size(); ++i) {
    const tinygltf::Texture& gt = model.textures[i];
    Texture& t = ctx.scene.textures[i];
    const std::string where = describe("texture", int(i), gt.name);
    if (gt.sampler >= 0) {
      if (size_t(gt.sampler) >= model.samplers.size()) {
        ctx.fail(where + ": sampler " + std::to_string(gt.sampler) + " is out of range (the file has " +
                 std::to_string(model.samplers.size()) + " samplers)");
      }
      const tinygltf::Sampler& s = model.samplers[size_t(gt.sampler)];
      t.sampler = Sampler{toWrap(s.wrapS), toWrap(s.wrapT), toFilter(s.magFilter), toFilter(s.minFilter)};
    }
    if (gt.source < 0) {
      // Only an extension (KTX2, WebP, ...) gives this texture an image: none of ours.
      ctx.warn(where + " has no PNG/JPEG source (extension image formats are not supported); treated as absent");
      continue;
    }
    if (size_t(gt.source) >= images.size()) {
      ctx.fail(where + ": image " + std::to_string(gt.source) + " is out of range (the file has " +
               std::to_string(images.size()) + " images)");
    }
    tinygltf::Image& image = images[size_t(gt.source)];
    t.name = !image.name.empty() ? image.name : !image.uri.empty() && image.uri.rfind("data:", 0) != 0 ? image.uri
                                                                                                     : where;
    if (image.image.empty() || image.width <= 0 || image.height <= 0) {
      if (!image.uri.empty() && image.uri.rfind("data:", 0) != 0) {
        ctx.fail(describe("image", gt.source, image.name) + ": texture file '" + image.uri +
                 "' is missing or unreadable (looked next to the glTF file)");
      }
      ctx.fail(describe("image", gt.source, image.name) + ": image data could not be decoded");
    }
    if (image.component < 1 || image.component > 4 || (image.bits != 8 && image.bits != 16) ||
        image.image.size() < size_t(image.width) * size_t(image.height) * size_t(image.component) * size_t(image.bits / 8)) {
      ctx.fail(describe("image", gt.source, image.name) + ": unsupported decoded layout (" +
               std::to_string(image.component) + " channels, " + std::to_string(image.bits) + " bits)");
    }
    t.width = image.width;
    t.height = image.height;
    // Usually already 8-bit RGBA: take the texels over unless another texture shares the image.
    const bool shared = std::count_if(model.textures.begin(), model.textures.end(),
                                      [&](const tinygltf::Texture& o) { return o.source == gt.source; }) > 1;
    if (image.component == 4 && image.bits == 8 && !shared) {
      t.rgba8 = std::move(image.image);
      t.rgba8.resize(size_t(image.width) * size_t(image.height) * 4);
      image.image.clear();
      image.width = image.height = -1;
    } else {
      t.rgba8 = toRgba8(image);
    }
  }
}

void loadMaterials(Context& ctx) {
  const auto& model = ctx.model;
  ctx.scene.materials.clear();
  ctx.scene.materials.reserve(model.materials.size() + 1);
  for (size_t i = 0; i < model.materials.size(); ++i) {
    ctx.scene.materials.push_back(convert(ctx, model.materials[i], describe("material", int(i), model.materials[i].name)));
  }
  // glTF 3.8.5 default material: white, metallic 1, roughness 1 (the Material defaults).
  Material fallback;
  fallback.name = "default";
  ctx.scene.materials.push_back(fallback);
}

}  // namespace pr::scene::gltf
