// Image assembly in the ray tracers: results are transfers too (shared/DESIGN.md rule 1). The
// assembler PE (PE 0, where the seed's system controller collects the picture, section 3.1.4)
// holds the image's film; every other PE delivers the film contributions it made as FilmBlock
// messages on the "image" Channel (kind results), which the assembler's handler adds in.
// Sums are fixed point, so the order in which blocks arrive cannot change the image. Used by
// image-space (one block per finished tile) and the partitioned tracers (each PE's film, tile
// by tile, at the end).
#pragma once

#include <vector>

#include "common/parallel/channel.h"
#include "raytrace/integrators/film.h"

namespace pr::rt {

inline constexpr int kAssemblerPe = 0;

class FilmAssembly {
 public:
  // image: the assembler's film, the one the render returns. Created between stages.
  FilmAssembly(par::Runtime& rt, Film& image)
      : image_(image), blocks_(rt, "image", par::MessageKind::Results, [this](par::Pe&, FilmBlock&& b) {
          image_.addBlock(b);
        }) {}

  // On PE pe inside a task: the sums of `part` inside rect reach the image, in place on the
  // assembler, as one message from any other PE. skipEmpty: a block with no contribution is not
  // sent (a partitioned tracer's PE that shaded nothing there).
  void deliver(par::Pe& pe, const Film& part, const PixelRect& rect, bool skipEmpty) {
    if (skipEmpty && !part.anyIn(rect)) return;
    FilmBlock block = part.block(rect);
    if (pe.id() == kAssemblerPe) {
      image_.addBlock(block);
      return;
    }
    blocks_.send(pe, kAssemblerPe, std::move(block));
  }

  // In a stage of its own, on every PE but the assembler: its whole film, tile by tile.
  // The assembler's own film must be `image` itself (nothing to move).
  void deliverFilms(par::Runtime& rt, const std::vector<Film*>& films, const std::vector<PixelRect>& tiles) {
    rt.runOnEachPe("assemble", [&](par::Pe& pe) {
      if (pe.id() == kAssemblerPe) return;
      for (const PixelRect& r : tiles) deliver(pe, *films[size_t(pe.id())], r, true);
    });
  }

 private:
  Film& image_;
  par::Channel<FilmBlock> blocks_;
};

}  // namespace pr::rt
