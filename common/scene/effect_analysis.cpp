// EffectAnalysis (see effect_analysis.h): reads the Scene's used materials, its lights and its
// geometry once, on the controlling thread before a render, and decides each effect. The
// material tests bound what a material can become once textures are applied (a texture only
// scales its factor by a texel in [0, 1]), so a textured material is judged by the widest
// range its factors allow; the geometric test asks whether any surface can see another.
#include "common/scene/effect_analysis.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <vector>

#include "common/util/error.h"

namespace pr::scene {

namespace {

constexpr std::array<Effect, kEffectCount> kEffects = {
    Effect::DirectLight,  Effect::Shadows,         Effect::IdealSpecular, Effect::GlossySpecular, Effect::Transmission,
    Effect::Caustics,     Effect::IndirectDiffuse, Effect::Anisotropy,    Effect::Textures,       Effect::Emission};

// What one used material can contribute, from the range of values its factors and textures
// allow (the integrators' ShadingMaterial, raytrace/integrators/bsdf.h, is the model).
struct MaterialTraits {
  bool emissive = false;
  bool dielectric = false;  // a smooth refracting part: transmission > 0 and not fully metallic
  bool opaque = false;      // a reflecting (non-dielectric) part
  bool diffuse = false;     // a Lambertian part: (1 - metallic)(1 - transmission) base colour > 0
  bool ideal = false;       // an opaque mirror lobe: specular F0 > 0 with roughness < kIdealSpecularRoughness
  bool glossy = false;      // an opaque GGX lobe with roughness >= kIdealSpecularRoughness
  bool anisotropic = false;
  int textures = 0;         // texture slots referenced
};

MaterialTraits traitsOf(const Material& m) {
  MaterialTraits t;
  auto range = [](float factor, const TextureRef& tex) {
    const float hi = std::clamp(factor, 0.0f, 1.0f);
    return std::pair<float, float>(tex.present() ? 0.0f : hi, hi);
  };
  // Plain variables, not structured bindings: the lambda below captures them (clang 14).
  const std::pair<float, float> metallic = range(m.metallicFactor, m.metallicRoughnessTexture);
  const std::pair<float, float> roughness = range(m.roughnessFactor, m.metallicRoughnessTexture);
  const std::pair<float, float> transmission = range(m.transmissionFactor, m.transmissionTexture);
  const float metallicMin = metallic.first, metallicMax = metallic.second;
  const float roughnessMin = roughness.first, roughnessMax = roughness.second;
  const float transmissionMin = transmission.first, transmissionMax = transmission.second;
  const bool base = glm::any(glm::greaterThan(glm::vec3(m.baseColorFactor), glm::vec3(0.0f)));
  t.emissive = m.isEmissive();
  t.dielectric = transmissionMax > 0.0f && metallicMin < 1.0f;
  // The dielectric weight is transmission * (1 - metallic): it is all of the surface only when
  // transmission is 1 and metallic 0 everywhere.
  t.opaque = !(transmissionMin >= 1.0f && metallicMax <= 0.0f);
  t.diffuse = t.opaque && base && metallicMin < 1.0f && transmissionMin < 1.0f;
  // specularF0 = mix(F0 (1 - transmission), base, metallic) > 0, or F90 > 0: a dielectric layer
  // unless KHR_materials_specular's factor is 0 (a texture only scales it), or a metal part.
  const bool dielectricCoat = transmissionMin < 1.0f && metallicMin < 1.0f && m.specularFactor > 0.0f;
  const bool specular = dielectricCoat || (metallicMax > 0.0f && base);
  t.ideal = t.opaque && roughnessMin < kIdealSpecularRoughness && specular;
  t.glossy = t.opaque && roughnessMax >= kIdealSpecularRoughness && specular;
  // The clear coat is a GGX lobe of its own, never narrow enough to be a mirror in the tracers.
  t.glossy = t.glossy || (t.opaque && m.hasClearcoat());
  t.anisotropic = m.anisotropyStrength > 0.0f;
  for (const TextureRef* r : {&m.baseColorTexture, &m.metallicRoughnessTexture, &m.normalTexture, &m.emissiveTexture,
                              &m.transmissionTexture, &m.anisotropyTexture, &m.specularTexture, &m.specularColorTexture,
                              &m.clearcoatTexture, &m.clearcoatRoughnessTexture, &m.clearcoatNormalTexture,
                              &m.sheenColorTexture, &m.sheenRoughnessTexture})
    t.textures += r->present() ? 1 : 0;
  return t;
}

// The materials the triangles use, with how many triangles and objects use each.
struct MaterialUse {
  uint32_t id = 0;
  MaterialTraits traits;
  size_t triangles = 0, objects = 0;
};

std::vector<MaterialUse> usedMaterials(const Scene& scene) {
  std::vector<size_t> triangles(scene.materials.size(), 0), objects(scene.materials.size(), 0);
  for (const Triangle& t : scene.triangles)
    if (t.material < triangles.size()) ++triangles[t.material];
  for (const Object& o : scene.objects) {
    std::vector<uint32_t> seen;
    for (uint32_t i = o.firstTriangle; i < o.firstTriangle + o.triangleCount && i < scene.triangles.size(); ++i) {
      const uint32_t m = scene.triangles[i].material;
      if (m < objects.size() && std::find(seen.begin(), seen.end(), m) == seen.end()) {
        seen.push_back(m);
        ++objects[m];
      }
    }
  }
  std::vector<MaterialUse> out;
  for (uint32_t m = 0; m < scene.materials.size(); ++m)
    if (triangles[m] > 0) out.push_back({m, traitsOf(scene.materials[m]), triangles[m], objects[m]});
  return out;
}

std::string plural(size_t n, const std::string& word) { return std::to_string(n) + " " + word + (n == 1 ? "" : "s"); }

// "2 materials (mirror, glass) on 3 objects" for the used materials that pass `pick`.
template <class Pick>
std::string describe(const std::vector<MaterialUse>& used, const Scene& scene, const std::string& noun, Pick pick) {
  size_t count = 0, objects = 0;
  std::string names;
  for (const MaterialUse& u : used)
    if (pick(u)) {
      ++count;
      objects += u.objects;
      if (count <= 4) names += (names.empty() ? "" : ", ") + scene.materials[u.id].name;
    }
  if (count > 4) names += ", ...";
  return plural(count, noun + " material") + " (" + names + ") on " + plural(objects, "object");
}

template <class Pick>
bool any(const std::vector<MaterialUse>& used, Pick pick) {
  return std::any_of(used.begin(), used.end(), pick);
}

// Whether any surface can send light to another (or to itself): the geometric condition of
// shadows, indirect light, caustics and reflection rays that hit something.
//
// Argument: a ray leaving side S of a triangle's plane travels strictly into that open half
// space; when no scene vertex lies in it, the ray hits nothing. Every ray the integrators
// spawn from an opaque hit (shadow, reflection, diffuse bounce) leaves on the side of the
// hit (they test against the geometric normal), so if every side that can be hit has an
// empty half space in front of it, no ray after the camera's hits anything. A side can be hit
// only by a camera ray or a ray refracted into it: without transmission it suffices that the
// camera is on the empty side of each triangle's plane, or that the surface is closed and
// convex (every triangle has the whole scene behind it, every edge shared by two triangles)
// with the camera outside it, which then sees front sides only. Coplanar triangles (the whole
// scene in one plane) satisfy the test for either side. Vertices within a tolerance of a plane
// count as on it (1e-5 of the scene extent, far above float rounding of the plane test and far
// below any modelled gap). The test is O(triangles x vertices) but stops at the first triangle
// with geometry on both sides, which in most scenes is the first; past a work limit the answer
// is "yes, they can" (conservative).
struct Visibility {
  bool canSee = true;
  std::string reason;
};

Visibility surfacesSeeEachOther(const Scene& scene, const std::vector<Camera>& cameras, bool transmission) {
  constexpr double kWorkLimit = 2.0e8;
  if (scene.triangles.empty()) return {false, "no triangles"};
  const glm::vec3 extent = scene.bounds.extent();
  const float tolerance = 1.0e-5f * std::max({extent.x, extent.y, extent.z, 1.0e-6f});
  bool allFrontEmpty = true, coplanar = true, cameraDecides = true;
  double work = 0.0;  // vertex-plane tests so far; most scenes stop at their first triangle
  for (const Triangle& t : scene.triangles) {
    work += double(scene.positions.size());
    if (work > kWorkLimit) return {true, "scene too large for the convexity test (assumed)"};
    const glm::vec3 a = scene.positions[t.v[0]], b = scene.positions[t.v[1]], c = scene.positions[t.v[2]];
    const glm::vec3 n = glm::cross(b - a, c - a);
    const float len = glm::length(n);
    if (!(len > 0.0f) || !std::isfinite(len)) continue;  // degenerate: never hit
    const glm::vec3 u = n / len;
    bool front = false, back = false;
    for (const glm::vec3& p : scene.positions) {
      const float d = glm::dot(p - a, u);
      front |= d > tolerance;
      back |= d < -tolerance;
      if (front && back) return {true, "surfaces face each other"};
    }
    allFrontEmpty &= !front;
    coplanar &= !front && !back;
    // The side a camera ray can hit must be the empty one.
    for (const Camera& cam : cameras) {
      const float side = glm::dot(cam.position() - a, u);
      if (front ? !(side < -tolerance) : back ? !(side > tolerance) : false) cameraDecides = false;
    }
  }
  if (coplanar) return {false, "all surfaces lie in one plane"};
  if (transmission) return {true, "refraction can carry light to the back side of surfaces"};
  if (!cameras.empty() && cameraDecides)
    return {false, "every surface the camera sees has no geometry in front of it"};
  if (!allFrontEmpty || cameras.empty()) return {true, "surfaces can face each other"};
  // Closed and convex with the camera outside: every edge is shared by exactly two triangles
  // (end points welded on a grid of 1e-4 of the scene extent, so the duplicated vertices of a
  // texture seam match; a pair that straddles a grid line makes the surface look open, which
  // errs on the safe side), and the camera is in front of some triangle's plane.
  const float cell = 1.0e-4f * std::max({extent.x, extent.y, extent.z, 1.0e-6f});
  auto weld = [&](glm::vec3 p) {
    const glm::vec3 q = glm::floor((p - scene.bounds.min) / cell);
    return std::tuple<int64_t, int64_t, int64_t>(int64_t(q.x), int64_t(q.y), int64_t(q.z));
  };
  using Key = std::pair<std::tuple<int64_t, int64_t, int64_t>, std::tuple<int64_t, int64_t, int64_t>>;
  std::map<Key, int> edges;
  for (const Triangle& t : scene.triangles)
    for (int e = 0; e < 3; ++e) {
      auto p = weld(scene.positions[t.v[e]]), q = weld(scene.positions[t.v[(e + 1) % 3]]);
      if (p == q) continue;
      if (q < p) std::swap(p, q);
      ++edges[Key{p, q}];
    }
  for (const auto& [key, count] : edges)
    if (count != 2) return {true, "an open surface: its inside can be seen"};
  for (const Camera& cam : cameras) {
    bool outside = false;
    for (const Triangle& t : scene.triangles) {
      const glm::vec3 a = scene.positions[t.v[0]];
      const glm::vec3 n = glm::cross(scene.positions[t.v[1]] - a, scene.positions[t.v[2]] - a);
      if (glm::dot(cam.position() - a, n) > tolerance * glm::length(n)) {
        outside = true;
        break;
      }
    }
    if (!outside) return {true, "the camera is inside a closed surface"};
  }
  return {false, "one closed convex surface seen from outside"};
}

}  // namespace

std::string_view toString(Effect effect) {
  switch (effect) {
    case Effect::DirectLight: return "direct";
    case Effect::Shadows: return "shadows";
    case Effect::IdealSpecular: return "specular";
    case Effect::GlossySpecular: return "glossy";
    case Effect::Transmission: return "transmission";
    case Effect::Caustics: return "caustics";
    case Effect::IndirectDiffuse: return "indirect";
    case Effect::Anisotropy: return "anisotropy";
    case Effect::Textures: return "textures";
    case Effect::Emission: return "emission";
  }
  return "unknown";
}

const std::array<Effect, kEffectCount>& allEffects() { return kEffects; }

EffectSet RenderPlan::enabled() const {
  EffectSet set = EffectSet::none();
  for (const EffectDecision& d : effects) set.set(d.effect, d.on);
  return set;
}

std::string RenderPlan::line(Effect e) const {
  const EffectDecision& d = (*this)[e];
  std::string out = std::string(toString(e)) + ": " + (d.on ? "on" : "off");
  if (d.forced) out += std::string(" (forced ") + (d.on ? "on" : "off") + "; analysis: " + (d.analysed ? "on" : "off") + ")";
  return out + " - " + d.reason;
}

bool EffectOverrides::empty() const {
  return std::none_of(forced.begin(), forced.end(), [](const std::optional<bool>& f) { return f.has_value(); });
}

EffectOverrides parseEffectOverrides(std::string_view text) {
  std::string names;
  for (Effect e : kEffects) names += (names.empty() ? "" : ", ") + std::string(toString(e));
  auto fail = [&](const std::string& what) {
    throw InputError("--effects: " + what + " (expected NAME=on|off[,NAME=on|off...] with NAME one of " + names + ")");
  };
  EffectOverrides out;
  size_t pos = 0;
  while (pos < text.size()) {
    const size_t comma = std::min(text.find(',', pos), text.size());
    const std::string_view item = text.substr(pos, comma - pos);
    pos = comma + 1;
    const size_t eq = item.find('=');
    if (item.empty()) fail("empty item");
    if (eq == std::string_view::npos) fail("'" + std::string(item) + "' has no '=on' or '=off'");
    const std::string_view name = item.substr(0, eq), value = item.substr(eq + 1);
    const Effect* effect = nullptr;
    for (const Effect& e : kEffects)
      if (toString(e) == name) effect = &e;
    if (!effect) fail("unknown effect '" + std::string(name) + "'");
    if (value != "on" && value != "off") fail("effect " + std::string(name) + ": value '" + std::string(value) + "' is not on or off");
    out.forced[size_t(*effect)] = value == "on";
    if (comma == text.size()) break;
    if (pos == text.size()) fail("empty item");
  }
  return out;
}

RenderPlan analyzeEffects(const Scene& scene, const Camera* camera) {
  const std::vector<MaterialUse> used = usedMaterials(scene);
  auto has = [&](auto pick) { return any(used, pick); };
  auto what = [&](const std::string& noun, auto pick) { return describe(used, scene, noun, pick); };

  // Lights: punctual lights that emit, and emissive triangles with area.
  size_t punctual = 0;
  for (const PunctualLight& l : scene.lights)
    if (l.intensity > 0.0f && glm::any(glm::greaterThan(l.color, glm::vec3(0.0f)))) ++punctual;
  size_t areaTriangles = 0;
  for (const AreaLight& a : scene.areaLights)
    if (a.triangle < scene.triangles.size() && a.area > 0.0f && std::isfinite(a.area) &&
        scene.triangles[a.triangle].material < scene.materials.size() &&
        scene.materials[scene.triangles[a.triangle].material].isEmissive())
      ++areaTriangles;
  const bool emission = has([](const MaterialUse& u) { return u.traits.emissive; });
  const bool environment = scene.environment && scene.environment->meanLuminance() > 0.0f;
  const bool light = punctual > 0 || areaTriangles > 0 || environment;
  std::string lights = punctual == 0 && areaTriangles == 0 ? std::string()
                       : punctual == 0                     ? plural(areaTriangles, "emissive triangle")
                       : areaTriangles == 0                ? plural(punctual, "punctual light")
                                                           : plural(punctual, "punctual light") + " and " +
                                                                 plural(areaTriangles, "emissive triangle");
  if (environment) lights += (lights.empty() ? "" : " and ") + std::string("the environment (") + scene.environment->description() + ")";
  const std::string noLight = "no light: no punctual lights, no emissive triangles and no environment";

  const bool dielectric = has([](const MaterialUse& u) { return u.traits.dielectric; });
  const bool ideal = has([](const MaterialUse& u) { return u.traits.ideal; });
  const bool glossy = has([](const MaterialUse& u) { return u.traits.glossy; });
  const bool diffuse = has([](const MaterialUse& u) { return u.traits.diffuse; });
  // Direct light lands only where the BSDF has a non-delta lobe (diffuse or glossy): mirrors
  // and glass get their light through reflection and refraction rays.
  const bool receiver = diffuse || glossy;

  std::vector<Camera> cameras = camera ? std::vector<Camera>{*camera} : scene.cameras;
  const Visibility vis = surfacesSeeEachOther(scene, cameras, dielectric);

  RenderPlan plan;
  auto decide = [&](Effect e, bool on, std::string reason) {
    plan[e] = EffectDecision{e, on, on, false, std::move(reason)};
  };

  // Direct light and shadows.
  if (!light)
    decide(Effect::DirectLight, false, noLight);
  else if (!receiver)
    decide(Effect::DirectLight, false, lights + ", but no diffuse or glossy surface to receive it (only mirrors, glass or emitters)");
  else
    decide(Effect::DirectLight, true, lights + " light " + what("diffuse or glossy", [](const MaterialUse& u) {
                                        return u.traits.diffuse || u.traits.glossy; }));
  if (!plan.on(Effect::DirectLight))
    decide(Effect::Shadows, false, "no direct light to occlude");
  else
    decide(Effect::Shadows, vis.canSee, vis.canSee ? "occluders possible: " + vis.reason : "nothing can occlude a light: " + vis.reason);

  // Reflection and refraction. A reflection ray that leaves the scene still sees the
  // environment where it emits light, so only without one does "no surface can see another"
  // turn reflection off.
  auto transport = [&](Effect e, bool materials, const std::string& noun, auto pick, const std::string& none) {
    if (!light)
      decide(e, false, noLight);
    else if (!materials)
      decide(e, false, none);
    else if (!vis.canSee && e != Effect::Transmission && !environment)
      decide(e, false, what(noun, pick) + ", but no surface can see another (" + vis.reason +
                           ") and no environment emits: reflection rays leave the scene into darkness");
    else if (!vis.canSee && e != Effect::Transmission)
      decide(e, true, what(noun, pick) + ": reflection rays that leave the scene see the environment");
    else
      decide(e, true, what(noun, pick));
  };
  transport(Effect::IdealSpecular, ideal, "mirror-like (roughness < 0.0316)", [](const MaterialUse& u) { return u.traits.ideal; },
            "no material with a mirror lobe (specular with roughness < 0.0316)");
  transport(Effect::GlossySpecular, glossy, "glossy (specular, roughness >= 0.0316)",
            [](const MaterialUse& u) { return u.traits.glossy; },
            "no material with a glossy lobe (specular with roughness in [0.0316, 1), or a rough metal)");
  transport(Effect::Transmission, dielectric, "transmissive", [](const MaterialUse& u) { return u.traits.dielectric; },
            "no transmissive material (KHR_materials_transmission 0 everywhere)");

  // Caustics: light through mirrors or refraction onto a surface with a non-delta lobe, where
  // a path arriving by a diffuse or glossy bounce continues through the specular vertex.
  const bool focusing = ideal || dielectric;
  if (!light)
    decide(Effect::Caustics, false, noLight);
  else if (!focusing)
    decide(Effect::Caustics, false, "no ideal specular or transmissive surface to focus light");
  else if (!receiver)
    decide(Effect::Caustics, false, "no diffuse or glossy surface for focused light to land on");
  else if (!vis.canSee)
    decide(Effect::Caustics, false, "no surface can see another (" + vis.reason + ")");
  else
    decide(Effect::Caustics, true,
           what("mirror or transmissive", [](const MaterialUse& u) { return u.traits.ideal || u.traits.dielectric; }) +
               " can send light from " + lights + " to diffuse or glossy surfaces");

  // Indirect diffuse.
  if (!light)
    decide(Effect::IndirectDiffuse, false, noLight);
  else if (!diffuse)
    decide(Effect::IndirectDiffuse, false, "no diffuse surface (every material is metallic, transmissive or black)");
  else if (!vis.canSee)
    decide(Effect::IndirectDiffuse, false, "no surface can receive light from another: " + vis.reason);
  else
    decide(Effect::IndirectDiffuse, true, what("diffuse", [](const MaterialUse& u) { return u.traits.diffuse; }) +
                                              " can receive light other surfaces reflect: " + vis.reason);

  // Material features.
  const bool anisotropic = has([](const MaterialUse& u) { return u.traits.anisotropic; });
  decide(Effect::Anisotropy, anisotropic,
         anisotropic ? what("anisotropic", [](const MaterialUse& u) { return u.traits.anisotropic; })
                     : "no material with KHR_materials_anisotropy strength > 0");
  const bool textured = has([](const MaterialUse& u) { return u.traits.textures > 0; });
  decide(Effect::Textures, textured,
         textured ? what("textured", [](const MaterialUse& u) { return u.traits.textures > 0; }) + ", " +
                        plural(scene.textures.size(), "texture")
                  : "no material references a texture");
  decide(Effect::Emission, emission,
         emission ? what("emissive", [](const MaterialUse& u) { return u.traits.emissive; }) + ", " +
                        plural(areaTriangles, "emissive triangle")
                  : "no emissive material");
  return plan;
}

RenderPlan applyOverrides(RenderPlan plan, const EffectOverrides& overrides) {
  for (Effect e : kEffects)
    if (const std::optional<bool>& f = overrides.forced[size_t(e)]; f.has_value()) {
      plan[e].on = *f;
      plan[e].forced = true;
    }
  return plan;
}

}  // namespace pr::scene
