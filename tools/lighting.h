// The lighting options of the commands that render or plan a render (render, sweep, info): --env FILE.exr|.hdr
// (an equirectangular environment, --env-strength, --env-rotate degrees about +y) and the
// default light of a scene without lights - a uniform white environment, unless
// --no-default-light - so that a model downloaded without lights does not render black in the
// ray tracers. The rasterizer keeps its headlight for such a scene (the summary says so).
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
};

void addLightingOptions(CLI::App& command, LightingOptions& options);

// Sets scene.environment from the options; returns the summary line saying what lights the
// scene ("lighting: ..."). Throws pr::InputError for an unreadable or invalid environment file.
std::string applyLighting(scene::Scene& scene, const LightingOptions& options);

}  // namespace pr::cli
