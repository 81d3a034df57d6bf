// Sort-last: the sort sits after rasterization. Each PE renders its own primitives (geometry
// batches under the runtime's schedule) over the whole screen into its own full-screen depth
// buffer, and the Compositor (direct-send or binary-swap, full frame or sparse) redistributes
// the fragments by screen region, keeping the nearest per pixel (visibility); each region's
// owner then shades the visible fragments of its region once, and delivers the region to the
// assembler (frame_assembly.h). Shading after visibility, as in PixelFlow (Molnar et al. 1992):
// a PE that shaded its own fragments first would also shade every fragment another PE hides,
// which on a depth-complex scene is most of its screen at every P. A fragment's key names its
// primitive and fan piece (depth_resolve.h), so the owner recomputes the screen triangle of a
// fragment another PE sent from the replicated scene (world model: any PE may take any
// geometry batch).
// Each PE keeps the bounding rectangle of the pixels its buffer holds (drawn or merged): only
// that is cleared next frame, and sparse compositing sends only its part of each region, so a
// PE whose primitives cover a corner of the screen pays for the corner. The shading stage
// counts the work of each row (its covered pixels and the triangles recomputed for other PEs'
// fragments), and the next frame's direct-send strips are cut at equal work, so the owners'
// shading work stays even when the picture is not (sky above, terrain below; far terrain,
// where a pixel's triangle is more often another PE's, above near terrain).
#include <algorithm>

#include "common/parallel/cell_split.h"
#include "common/parallel/per_pe.h"
#include "common/util/error.h"

#include "raster/composite/compositor.h"
#include "raster/frame_assembly.h"
#include "raster/scene_distribution.h"
#include "raster/sort/sort_point.h"
#include "raster/stages/geometry.h"
#include "raster/stages/rasterize.h"
#include "raster/stages/setup.h"
#include "raster/stages/shade.h"

namespace pr::raster {
namespace {

class SortLast : public SortPoint {
 public:
  std::string_view name() const override { return "sort-last"; }
  bool runsAcrossRanks() const override { return true; }
  std::vector<ShadeCounters> takeShadeCounters() override {
    std::vector<ShadeCounters> out;
    for (int p = 0; p < pe_.size(); ++p) out.push_back(std::exchange(pe_[p].shade, {}));
    return out;
  }

  void renderFrame(const FrameInputs& f, par::Runtime& rt, RegionFramebuffer& image) override {
    const int pes = rt.pes();
    // The compositor is chosen (and a bad name rejected) before any work is done.
    std::unique_ptr<Compositor> compositor = makeCompositor(f.options.compositor);
    const Rect screen{0, 0, f.view.width, f.view.height};
    const ShadingContext ctx = makeShadingContext(f.scene, f.view, f.options.effects, f.options.headlight);
    declareSortCounters(name(), rt);
    if (distribution_.firstFrame(f.scene, rt)) distributeReplicated(rt, f.scene);

    // Every PE clears what its full-screen buffer (kept from frame to frame) holds: the keys
    // where it drew or merged, the colours where it shaded. Triangle indices need no clearing:
    // one is read only where this frame wrote a key, and whatever wrote it set the index.
    buffers_.resize(pes);
    drawn_.resize(pes);
    pe_.resize(pes);
    rt.runOnEachPeInFull("sort-last clear", [&](par::Pe& pe) {
      RegionFramebuffer& mine = buffers_[pe.id()];
      PeFrame& state = pe_[pe.id()];
      if (mine.rect() == screen) {
        mine.window(intersect(drawn_[pe.id()], screen)).clearKeys();
        mine.window(intersect(state.shaded, screen)).clearColours();
      } else {
        mine = RegionFramebuffer(screen);
      }
      drawn_[pe.id()] = state.shaded = Rect{};
    });
    std::vector<RegionFramebuffer>& buffers = buffers_;

    // Stage 1, geometry and rasterization of a PE's batches into its own full-screen buffer;
    // the triangle list stays with the PE for deferred shading (triangle index = list position).
    for (int p = 0; p < pes; ++p) pe_[p].tris.clear();  // storage kept: no page faults per frame
    const uint32_t total = static_cast<uint32_t>(f.scene.triangles.size());
    const uint32_t batch = f.options.batchSize;
    const size_t batches = (total + batch - 1) / batch;
    rt.runStage("sort-last render", par::TaskSet::uniform(batches), [&](par::Pe& pe, par::TaskId t) {
      std::vector<ScreenTriangle>& mine = pe_[pe.id()].tris;
      const size_t before = mine.size();
      const uint32_t first = static_cast<uint32_t>(t) * batch;
      processTriangles(f.scene, f.view, first, std::min(batch, total - first), mine);
      for (size_t i = before; i < mine.size(); ++i)
        rasterizeTriangle(mine[i], static_cast<uint32_t>(i), buffers[pe.id()].window(), nullptr,
                          ctx.alphaTested ? &f.scene : nullptr);
      const std::span<const ScreenTriangle> batchTriangles(mine.data() + before, mine.size() - before);
      drawn_[pe.id()] = enclose(drawn_[pe.id()], intersect(pixelBounds(batchTriangles), screen));
    });

    // Stage 2, the sort: depth compositing by screen region (its counters go to the record),
    // the regions cut by the last frame's shading work per row.
    if (rowCost_.size() != size_t(f.view.height)) rowCost_.assign(size_t(f.view.height), 0.0);
    else std::fill(rowCost_.begin(), rowCost_.end(), 0.0);
    for (int p = 0; p < pes; ++p)
      if (pe_[p].rowCost.size() == rowCost_.size())
        for (size_t y = 0; y < rowCost_.size(); ++y) rowCost_[y] += pe_[p].rowCost[y];
    rt.sumAcrossRanks(rowCost_);  // a rank holds its own PEs' costs: every rank cuts the same strips
    const std::vector<Rect> regions = compositor->composite(rt, buffers, drawn_, f.options.sparse, rowCost_);

    // Stage 3, shading of the visible fragments of each PE's region, in its own buffer. Where
    // the regions are strips of equal height (direct-send's first frame), each screen row is a
    // cell the simulator can cut into strips again at another P: its share of the PE's measured
    // time in proportion to its work (its covered pixels and recomputed triangles).
    const bool rowCells = compositor->cutsEqualStrips(rowCost_, f.view.height);
    rt.runOnEachPe("sort-last shade", [&](par::Pe& pe) {
      const double t0 = rt.now();
      PeFrame& state = pe_[pe.id()];
      state.shade = ShadeCounters{};
      state.rowCost.assign(size_t(f.view.height), 0.0);
      const Rect visible = intersect(regions[pe.id()], drawn_[pe.id()]);
      if (visible.empty()) return;
      state.shaded = visible;
      PixelWindow pixels = buffers[pe.id()].window(visible);
      adoptForeignFragments(f, pixels, state.tris, state.adopted, state.rowCost);
      shadeRegion(ctx, state.tris, pixels, &state.shade);
      if (rowCells) recordRowCells(rt, pe, visible, state.rowCost, rt.now() - t0);
    });
    if (rowCells) rt.describeCells(par::kStripCells, f.view.height, -1);

    // Each PE delivers the rectangle it composited to the assembler (in place on PE 0).
    FrameAssembly frame(rt, image, pool_);
    rt.runOnEachPe("sort-last assemble", [&](par::Pe& pe) {
      frame.deliver(pe, buffers[pe.id()], regions[pe.id()]);
    });
  }

 private:
  // Where a PE keeps the screen triangles it recomputed for other PEs' fragments this frame:
  // per scene triangle, the index in the PE's triangle list of its first fan piece, valid when
  // its stamp is the current frame's (no clearing between frames).
  struct AdoptedTriangles {
    std::vector<uint32_t> stamp, first;
    uint32_t frame = 0;
    void nextFrame(size_t primitives) {
      if (stamp.size() != primitives || ++frame == 0) {
        stamp.assign(primitives, 0);
        first.resize(primitives);
        frame = 1;
      }
    }
  };

  // Recomputing a triangle for another PE's fragment costs about as much as shading four
  // pixels (on the landscape on the 2-core machine: 130-160 ns a triangle, 27-37 ns a pixel).
  static constexpr double kRecomputedTriangleCost = 4.0;

  // Gives every visible fragment that came from another PE (triangle index kNoTriangle) an
  // index into `tris`, appending the screen triangles of its primitive, recomputed by the
  // geometry stage, once per primitive. Puts each row's work in rowCost (indexed by screen
  // row): its covered pixels, and its recomputed triangles at kRecomputedTriangleCost each,
  // the work the next frame's regions are cut by.
  static void adoptForeignFragments(const FrameInputs& f, const PixelWindow& pixels, std::vector<ScreenTriangle>& tris,
                                    AdoptedTriangles& adopted, std::vector<double>& rowCost) {
    adopted.nextFrame(f.scene.triangles.size());
    ScreenTriangle pieces[kMaxSubTriangles];
    for (int y = pixels.rect.y0; y < pixels.rect.y1; ++y) {
      uint32_t covered = 0, recomputed = 0;
      for (int x = pixels.rect.x0; x < pixels.rect.x1; ++x) {
        const size_t i = pixels.index(x, y);
        const uint64_t key = pixels.keys[i];
        if (!keyCovered(key)) continue;
        ++covered;
        if (pixels.triangles[i] != kNoTriangle) continue;
        const uint32_t primitive = keyPrimitive(key);
        if (adopted.stamp[primitive] != adopted.frame) {
          ++recomputed;
          const int n = processTriangle(f.scene, f.view, primitive, pieces);
          adopted.stamp[primitive] = adopted.frame;
          adopted.first[primitive] = static_cast<uint32_t>(tris.size());
          tris.insert(tris.end(), pieces, pieces + n);
        }
        // The fragment's fan piece among the primitive's pieces (one, unless clipped).
        const uint32_t sub = static_cast<uint32_t>(key) & ((1u << kSubTriangleBits) - 1);
        uint32_t at = adopted.first[primitive];
        while (tris[at].sub != sub) {
          ++at;
          PR_CHECK(at < tris.size() && tris[at].primitive == primitive, "sort-last: a fragment's fan piece is missing");
        }
        pixels.triangles[i] = at;
      }
      rowCost[size_t(y)] = double(covered) + kRecomputedTriangleCost * double(recomputed);
    }
  }

  // The rows of `visible` as cells: the PE's measured seconds shared out by each row's work.
  static void recordRowCells(par::Runtime& rt, const par::Pe& pe, const Rect& visible, const std::vector<double>& rowCost,
                             double seconds) {
    double total = 0.0;
    for (int y = visible.y0; y < visible.y1; ++y) total += rowCost[size_t(y)];
    if (!(total > 0.0)) return;
    for (int y = visible.y0; y < visible.y1; ++y)
      if (rowCost[size_t(y)] > 0.0) rt.recordCell(pe, y, seconds * rowCost[size_t(y)] / total, 0);
  }

  // What a PE writes while it renders and shades, kept between frames.
  struct PeFrame {
    Rect shaded;                     // its colours are 0 outside this rectangle
    AdoptedTriangles adopted;
    std::vector<ScreenTriangle> tris;  // this frame's screen triangles
    ShadeCounters shade;               // the last frame's
    std::vector<double> rowCost;       // the last frame: covered pixels per row it shaded
  };
  std::vector<RegionFramebuffer> buffers_;  // per PE, full screen, kept between frames
  std::vector<Rect> drawn_;                 // per PE: its keys are clear outside this rectangle
  par::PerPe<PeFrame> pe_;
  std::vector<double> rowCost_;             // the PEs' row costs summed, per screen row
  RegionBufferPool pool_;                   // region message storage, kept between frames
  SceneDistribution distribution_;
};

}  // namespace

std::unique_ptr<SortPoint> makeSortLast() { return std::make_unique<SortLast>(); }

}  // namespace pr::raster
