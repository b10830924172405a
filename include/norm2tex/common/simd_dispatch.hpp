#pragma once
// Hot loops written as plain C++ that the compiler vectorises are built twice on x86-64 with
// GCC or Clang: for AVX2 (8 floats a step) and for the baseline (SSE2, 4); one is picked when the
// library loads. Both do the same operations in the same order and the core is built with
// -ffp-contract=off (src/core/CMakeLists.txt), so they give the same floats. That flag is what
// keeps a*b+c from becoming one fused multiply-add, which rounds once instead of twice: ISO
// C++ mode does not (GCC contracts by default in every C++ mode; only ISO C forbids it), and
// with -mfma or -march=native the compiler would emit vfmadd in one build and not the other.

#if defined(__GNUC__)
#define NORM2TEX_ALWAYS_INLINE __attribute__((always_inline)) inline
#else
#define NORM2TEX_ALWAYS_INLINE inline
#endif

#if defined(__GNUC__) && defined(__x86_64__)
#define NORM2TEX_HAS_AVX2_BUILD 1
#define NORM2TEX_TARGET_AVX2 __attribute__((target("avx2")))
#else
#define NORM2TEX_HAS_AVX2_BUILD 0
#define NORM2TEX_TARGET_AVX2
#endif

namespace norm2tex {

/// True when the AVX2 builds may run on this CPU.
inline bool cpuHasAvx2() {
#if NORM2TEX_HAS_AVX2_BUILD
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
#else
  return false;
#endif
}

/// The AVX2 build of a function where it can run, else the baseline one.
template <typename Function>
Function pickSimd(Function avx2, Function baseline) {
  return cpuHasAvx2() ? avx2 : baseline;
}

}  // namespace norm2tex
