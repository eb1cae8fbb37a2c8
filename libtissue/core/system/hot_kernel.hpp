// TISSUE_HOT_KERNEL: marks the few functions a step spends most of its time in (the rotation
// lanes, the tet kernel, the block mat-vec, the energy and turn checks of the large-turn
// protections) to be compiled twice, for baseline x86-64 and for
// x86-64-v3 (AVX2 and FMA: x86 CPUs since about 2015), the version picked once at load time from
// the CPU (GCC's target_clones, an ifunc). The library and the FMUs stay portable, and a CPU with
// AVX2 gets ~20% faster steps (docs/BENCHMARKS.md, issue 12). `flatten` inlines everything the
// kernel calls into each version: without it GCC does not inline baseline code (Eigen's) into a
// function of another architecture, and the clone ends up slower than the baseline.
//
// The two versions round differently (FMA contracts a * b + c), so results are bitwise
// reproducible on one machine, not across CPU generations; configure with
// -DTISSUE_CPU_DISPATCH=OFF for the baseline everywhere. Left out under the sanitizers, whose
// run-time set-up and ifunc resolvers do not mix well.
#pragma once

#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__) && \
    !defined(__SANITIZE_THREAD__) && !defined(TISSUE_NO_CPU_DISPATCH)
#define TISSUE_HOT_KERNEL __attribute__((flatten, target_clones("arch=x86-64-v3", "default")))
#else
#define TISSUE_HOT_KERNEL
#endif
