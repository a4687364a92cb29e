#pragma once

// PANMAP_HAVE_AVX2_PATH: this compiler can build functions for AVX2 next to the baseline
// x86-64 ones (with __attribute__((target("avx2"))) and <immintrin.h>); cpuHasAvx2() tells at
// run time whether this CPU may call them, cpuHasAvx2F16c() whether it may call those that
// also convert 2-byte floats (target("avx2,f16c"); every AVX2 CPU so far has F16C).
#if defined(__x86_64__) && defined(__GNUC__)
#include <cpuid.h>
#include <immintrin.h>
#define PANMAP_HAVE_AVX2_PATH 1
#endif

namespace panmap {

/// True when the CPU running this has AVX2 (checked once).
inline bool cpuHasAvx2() {
#ifdef PANMAP_HAVE_AVX2_PATH
  static const bool avx2 = __builtin_cpu_supports("avx2");
  return avx2;
#else
  return false;
#endif
}

/// True when the CPU running this has AVX2 and F16C (checked once).
inline bool cpuHasAvx2F16c() {
#ifdef PANMAP_HAVE_AVX2_PATH
  // CPUID leaf 1 directly: clang's __builtin_cpu_supports does not know "f16c".
  static const bool f16c = [] {
    unsigned eax = 0, ebx = 0, ecx = 0, edx = 0;
    return cpuHasAvx2() && __get_cpuid(1, &eax, &ebx, &ecx, &edx) != 0 && (ecx & bit_F16C) != 0;
  }();
  return f16c;
#else
  return false;
#endif
}

}  // namespace panmap
