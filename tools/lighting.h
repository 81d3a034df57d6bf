// The lighting options of the commands that render or plan a render (render, sweep, info): --env FILE.exr|.hdr
// (an equirectangular environment, --env-strength, --env-rotate degrees about +y) and the
// default light of a scene without lights (no punctual light and no emitter above 1 nit, the
// brightest glTF emission without KHR_materials_emissive_strength) - a uniform white environment, unless
// --no-default-light - so that a model downloaded without lights does not render black in the
// ray tracers and the rasterizer (which lights it by image-based lighting, or --headlight).
// Also --variant NAME (KHR_materials_variants), the other option that decides what the loaded
// scene is.
#pragma once

#include <string>

#include <CLI/CLI.hpp>

#include "common/scene/scene.h"

namespace pr::cli {

struct LightingOptions {
  std::string env;            // --env: file; empty = none
  float strength = 1.0f;      // --env-strength
  float rotateDegrees = 0.0f; // --env-rotate
  bool noDefault = false;     // --no-default-light
  std::string variant;        // --variant
};

void addLightingOptions(CLI::App& command, LightingOptions& options);

// Loads the scene with the options' material variant.
scene::Scene loadScene(const std::string& path, const LightingOptions& options);

// Sets scene.environment from the options; returns the summary line saying what lights the
// scene ("lighting: ..."). Throws pr::InputError for an unreadable or invalid environment file.
std::string applyLighting(scene::Scene& scene, const LightingOptions& options);

}  // namespace pr::cli
