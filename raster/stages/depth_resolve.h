// Visibility (z-buffer) with a deterministic tie-break by primitive order, shared by all three
// sort points: a fragment is reduced to one 64-bit key (depth, primitive, sub-triangle) and the
// smallest key wins. The winner of a pixel is then a function of the SET of its fragments only,
// so any region split, any primitive order and any compositing order give identical pixels.
#pragma once

#include <bit>
#include <cstdint>
#include <limits>

namespace pr::raster {

class RegionFramebuffer;

// Key layout, most significant first: 32 bits of order-preserving depth, 29 bits of primitive
// id (the scene triangle index: primitive order), 3 bits of sub-triangle (the fan index of a
// triangle split by clipping, at most 6 pieces). Smaller depth is nearer (see geometry.h).
inline constexpr int kSubTriangleBits = 3;
inline constexpr uint32_t kMaxPrimitives = 1u << (32 - kSubTriangleBits);
inline constexpr uint64_t kClearKey = std::numeric_limits<uint64_t>::max();

// Maps a float to a uint32 with the same order (IEEE 754: flip all bits of negatives, set the
// sign bit of positives), so -inf < -1 < -0 < +0 < 1 < +inf compare as integers.
inline uint32_t orderedDepthBits(float depth) {
  uint32_t bits = std::bit_cast<uint32_t>(depth);
  return (bits & 0x80000000u) ? ~bits : (bits | 0x80000000u);
}

inline float depthFromBits(uint32_t ordered) {
  uint32_t bits = (ordered & 0x80000000u) ? (ordered & 0x7fffffffu) : ~ordered;
  return std::bit_cast<float>(bits);
}

// The low 32 bits of a key: primitive order then sub-triangle.
inline uint32_t primitiveOrder(uint32_t primitive, uint32_t sub) {
  return (primitive << kSubTriangleBits) | sub;
}

inline uint64_t fragmentKey(float depth, uint32_t order) {
  return (static_cast<uint64_t>(orderedDepthBits(depth)) << 32) | order;
}

inline float keyDepth(uint64_t key) { return depthFromBits(static_cast<uint32_t>(key >> 32)); }
inline uint32_t keyPrimitive(uint64_t key) { return static_cast<uint32_t>(key) >> kSubTriangleBits; }
inline bool keyCovered(uint64_t key) { return key != kClearKey; }

// Z-test: true (and the caller stores the fragment) when the fragment beats the stored one.
// Keys are unique per (pixel, sub-triangle), so there is never a tie to break by arrival order.
inline bool depthTest(uint64_t stored, uint64_t candidate) { return candidate < stored; }

// Depth compositing of shaded framebuffers: for every pixel of src that lies inside dst, keeps
// the fragment with the smaller key (colour, key and triangle index travel together). Used to
// assemble region framebuffers into the full image and, in sort-last, to merge PE images.
void resolveInto(const RegionFramebuffer& src, RegionFramebuffer& dst);

}  // namespace pr::raster
