// What the processor offers beyond x86-64's baseline (SSE2), asked once per process: kernels
// compiled for a wider ISA (the headlit shading kernel, the BVH slab test) run only where it
// is there, and every width gives bit-identical results.
#pragma once

namespace pr {

inline bool hasAvx2() {
  // Initialised here too: a static initialiser in another file may ask before libgcc's has run.
  static const bool has = (__builtin_cpu_init(), __builtin_cpu_supports("avx2"));
  return has;
}

}  // namespace pr

// Opens and closes a region whose functions are compiled for AVX2 (and run only where
// hasAvx2()). Everything defined inside must have internal linkage, and every header it needs
// must be included before it opens: an inline function first seen inside would be compiled for
// AVX2, and the linker could hand that copy to every caller.
#if defined(__clang__)
#define PR_BEGIN_AVX2 _Pragma("clang attribute push(__attribute__((target(\"avx2\"))), apply_to = function)")
#define PR_END_AVX2 _Pragma("clang attribute pop")
#else
#define PR_BEGIN_AVX2 _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define PR_END_AVX2 _Pragma("GCC pop_options")
#endif
