// What the processor offers beyond x86-64's baseline (SSE2), asked once per process: kernels
// compiled for a wider ISA (the headlit shading kernel, the BVH slab test) run only where it
// is there, and every width gives bit-identical results.
#pragma once

namespace pr {

inline bool hasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}

}  // namespace pr
