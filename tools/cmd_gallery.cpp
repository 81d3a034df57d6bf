// `parrender gallery DIR -o OUT`: every glTF model under DIR rendered by the path tracer and
// the rasterizer side by side with the model's upstream screenshot (its screenshot/ folder),
// one row per model, into OUT/contact_sheet.png, with each render as its own PNG and
// OUT/index.html naming the rows - so a person can look at what both families make of each
// model. Models that fail to load are listed with their error and do not stop the sheet.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/image/codec_loader.h"
#include "common/image/image_io.h"
#include "common/parallel/runtime.h"
#include "common/scene/camera_select.h"
#include "common/scene/effect_analysis.h"
#include "common/util/error.h"
#include "raytrace/integrators/sampling.h"
#include "tools/commands.h"
#include "tools/lighting.h"
#include "tools/render_methods.h"

namespace pr::cli {

namespace fs = std::filesystem;

namespace {

constexpr int kGroupGap = 8;  // pixels between groups of rows

struct GalleryArgs {
  std::string dir;
  std::string output = "gallery";
  int size = 192;
  int spp = 32;
  int threads = 1;
  std::string rayMethod = "image-space";
  std::string rasterMethod = "sort-middle";
  LightingOptions lighting;
};

// The glTF files under dir, in path order.
std::vector<fs::path> findModels(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::recursive_directory_iterator(dir, fs::directory_options::skip_permission_denied | fs::directory_options::follow_directory_symlink)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".gltf" || ext == ".glb")) out.push_back(e.path());
  }
  std::sort(out.begin(), out.end());
  return out;
}

// <Model>/screenshot/screenshot.{png,jpg} for a file at <Model>/<variant>/<file>; empty if none.
fs::path screenshotOf(const fs::path& model) {
  for (fs::path dir = model.parent_path(); !dir.empty() && dir != dir.parent_path(); dir = dir.parent_path()) {
    for (const char* name : {"screenshot/screenshot.png", "screenshot/screenshot.jpg"})
      if (fs::is_regular_file(dir / name)) return dir / name;
    if (fs::exists(dir / "screenshot")) break;
  }
  return {};
}

// `image` scaled to fit a size x size cell (box filter when shrinking, nearest when growing),
// centred on black.
image::Image fitCell(const image::Image& in, int size) {
  image::Image cell(size, size);
  if (in.empty()) return cell;
  const float scale = std::min(float(size) / float(in.width), float(size) / float(in.height));
  const int w = std::max(1, int(float(in.width) * scale)), h = std::max(1, int(float(in.height) * scale));
  const int ox = (size - w) / 2, oy = (size - h) / 2;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int x0 = int(float(x) / scale), x1 = std::max(x0 + 1, int(float(x + 1) / scale));
      const int y0 = int(float(y) / scale), y1 = std::max(y0 + 1, int(float(y + 1) / scale));
      glm::vec3 sum(0.0f);
      int n = 0;
      for (int sy = y0; sy < std::min(y1, in.height); ++sy)
        for (int sx = x0; sx < std::min(x1, in.width); ++sx, ++n) sum += in.at(sx, sy);
      cell.at(ox + x, oy + y) = n > 0 ? sum / float(n) : glm::vec3(0.0f);
    }
  return cell;
}

image::Image renderWith(const std::string& methodName, const scene::Scene& scene, const GalleryArgs& a) {
  const RenderMethod& method = findRenderMethod(methodName);
  RenderSettings settings;
  settings.ray.integrator = "path";
  settings.ray.spp = a.spp;
  const scene::Camera camera = scene::selectCamera(scene, "", 1.0f);
  const scene::RenderPlan plan = scene::analyzeEffects(scene, &camera);
  par::Runtime runtime(par::RuntimeOptions{a.threads, "demand", {}, true});
  const RenderRequest request{scene, camera, a.size, a.size, settings, plan, runtime, {}};
  return method.make(method.name, request).image;
}

// The file's path under the gallery folder as a file name (Box/glTF/Box.gltf: Box_glTF_Box), so
// models that share a file name (variants of one model) keep their own images.
std::string safeName(const fs::path& p) {
  std::string s = p.parent_path().empty() ? p.stem().string() : (p.parent_path() / p.stem()).string();
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return s;
}

void run(const GalleryArgs& a) {
  if (!fs::is_directory(a.dir)) throw InputError(a.dir + ": not a directory");
  const std::vector<fs::path> models = findModels(a.dir);
  if (models.empty()) throw InputError(a.dir + ": no .gltf or .glb files under it");
  image::imageCodec();  // opened before the first timed render, never beside it
  // Written to a new folder first, so an interrupted run leaves an earlier gallery intact.
  const fs::path out(a.output), temp = fs::path(a.output + ".partial");
  fs::remove_all(temp);
  fs::create_directories(temp);
  constexpr int kColumns = 3;  // screenshot | rasterizer | path tracer
  // Rows wrap into side-by-side groups so that the sheet stays roughly square.
  const int n = int(models.size());
  const int groups = std::max(1, int(std::lround(std::sqrt(double(n) / kColumns))));
  const int perGroup = (n + groups - 1) / groups;
  image::Image sheet(groups * kColumns * a.size + (groups - 1) * kGroupGap, perGroup * a.size);
  std::string rows;
  for (size_t i = 0; i < models.size(); ++i) {
    const fs::path& model = models[i];
    const std::string name = safeName(model.lexically_relative(a.dir));
    std::fprintf(stderr, "[%zu/%zu] %s\n", i + 1, models.size(), model.string().c_str());
    std::vector<image::Image> cells(kColumns);
    std::string note;
    const fs::path shot = screenshotOf(model);
    try {
      if (!shot.empty()) cells[0] = image::readImage(shot);
    } catch (const InputError& e) {
      note += std::string(" screenshot unreadable: ") + e.what();
    }
    try {
      scene::Scene scene = loadScene(model.string(), a.lighting);
      applyLighting(scene, a.lighting);
      cells[1] = renderWith(a.rasterMethod, scene, a);
      cells[2] = renderWith(a.rayMethod, scene, a);
      image::writeImage(temp / (name + "_" + a.rasterMethod + ".png"), cells[1]);
      image::writeImage(temp / (name + "_" + a.rayMethod + ".png"), cells[2]);
    } catch (const InputError& e) {
      note += std::string(" not rendered: ") + e.what();
      std::fprintf(stderr, "  %s\n", note.c_str());
    }
    const int left = int(i) / perGroup * (kColumns * a.size + kGroupGap), top = int(i) % perGroup * a.size;
    for (int c = 0; c < kColumns; ++c) {
      const image::Image cell = fitCell(cells[size_t(c)], a.size);
      for (int y = 0; y < a.size; ++y)
        for (int x = 0; x < a.size; ++x) sheet.at(left + c * a.size + x, top + y) = cell.at(x, y);
    }
    rows += "<tr><td>" + std::to_string(i + 1) + "</td><td>" + model.lexically_relative(a.dir).string() + "</td><td>" +
            (shot.empty() ? "(no screenshot)" : "") + "</td><td><img src=\"" + name + "_" + a.rasterMethod +
            ".png\"></td><td><img src=\"" + name + "_" + a.rayMethod + ".png\"></td><td>" + note + "</td></tr>\n";
  }
  image::writeImage(temp / "contact_sheet.png", sheet);
  std::ofstream html(temp / "index.html");
  html << "<!doctype html><meta charset=\"utf-8\"><title>parrender gallery</title>\n"
       << "<p><a href=\"contact_sheet.png\">contact_sheet.png</a> holds the rows below top to bottom in " << groups
       << " group(s) of " << perGroup << ", left to right. Each row: upstream screenshot | " << a.rasterMethod
       << " | " << a.rayMethod << " (path tracer, " << a.spp << " spp), " << a.size << " px.</p>\n"
       << "<table><tr><th>#</th><th>model</th><th>screenshot</th><th>" << a.rasterMethod << "</th><th>" << a.rayMethod
       << "</th><th>notes</th></tr>\n"
       << rows << "</table>\n";
  html.close();
  if (!html) throw InputError((temp / "index.html").string() + ": cannot write");
  // The earlier gallery is moved aside, then replaced, then removed: at no point is the new
  // one incomplete under OUT.
  const fs::path previous = fs::path(a.output + ".previous");
  fs::remove_all(previous);
  if (fs::exists(out)) fs::rename(out, previous);
  fs::rename(temp, out);
  fs::remove_all(previous);
  std::printf("gallery of %zu models -> %s (contact_sheet.png, index.html)\n", models.size(), out.string().c_str());
}

}  // namespace

void addGalleryCommand(CLI::App& app) {
  auto a = std::make_shared<GalleryArgs>();
  CLI::App* cmd = app.add_subcommand(
      "gallery", "render every glTF model under DIR with the rasterizer and the path tracer, side by side with each "
                 "model's screenshot, into OUT/contact_sheet.png and OUT/index.html");
  cmd->add_option("dir", a->dir, "folder searched recursively for .gltf/.glb files")->required();
  cmd->add_option("-o,--output", a->output, "output folder (replaced once the new gallery is complete)")->capture_default_str();
  cmd->add_option("--size", a->size, "cell size in pixels")->check(CLI::Range(16, 2048))->capture_default_str();
  cmd->add_option("--spp", a->spp, "path tracer samples per pixel")->check(CLI::Range(1, rt::kMaxSpp))->capture_default_str();
  cmd->add_option("--threads", a->threads, "P for every render")->check(CLI::Range(1, 4096))->capture_default_str();
  cmd->add_option("--ray-method", a->rayMethod, "ray-tracing method")->capture_default_str();
  cmd->add_option("--raster-method", a->rasterMethod, "rasterization method")->capture_default_str();
  addLightingOptions(*cmd, a->lighting);
  // The sky shows shapes, normal maps and metals as the screenshots do; --env FILE overrides.
  a->lighting.env = "sky";
  cmd->callback([a] {
    requireOneRank("gallery");
    run(*a);
  });
}

}  // namespace pr::cli
