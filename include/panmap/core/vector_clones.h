#pragma once

// PANMAP_VECTOR_CLONES marks a hot per-row loop function to be compiled twice, for AVX2 and
// for the baseline, with the CPU's choice made once at load time: the build targets baseline
// x86-64 (SSE2), and the 8-wide clone roughly halves the per-pixel stages. Results do not
// change: the loops do the same IEEE operations per pixel (no contraction into FMA in ISO C++
// mode, no reassociation), only more pixels at once.
// Not under ThreadSanitizer: its instrumented ifunc resolvers run before it is initialised and
// crash at load time.
#if defined(__SANITIZE_THREAD__)
#define PANMAP_VECTOR_CLONES
#endif
#if !defined(PANMAP_VECTOR_CLONES) && defined(__x86_64__) && defined(__GNUC__) && \
    defined(__has_attribute)
#if __has_attribute(target_clones)
#define PANMAP_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef PANMAP_VECTOR_CLONES
#define PANMAP_VECTOR_CLONES
#endif
