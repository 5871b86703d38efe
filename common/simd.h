/* simd.h: code on vectors of four doubles, built for AVX2 and run where the processor has it.
 *
 * The four-lane functions (hexapod_batch.c, motion_ahead.c, kins_tcp.c) compute four poses
 * or path places at once as GCC vectors of four doubles, one AVX2 register each, lane by
 * lane the operations of the scalar function each stands for, so the same bits. Built for
 * the baseline x86-64 (SSE2), GCC split every vector in two and spilled them to memory: the
 * four-pose inverse took four times as long as with AVX2, slower than four scalar calls, and
 * `hexcnc check` of the dense hour 1.7 times as long. So they are built for AVX2 alone
 * (HEXCNC_AVX2) and called only where hexcnc_avx2() finds it; elsewhere their callers take
 * the scalar functions, the same bits by construction.
 *
 * Loops GCC vectorises by itself (check_sim.c's leg_batch) are built for both, the one the
 * processor runs chosen when the program loads (HEXCNC_CLONES, GCC's target_clones).
 *
 * The sanitizer build (make sanitize) defines HEXCNC_BASELINE: no AVX2 code at all, so the
 * whole test suite runs the way a processor without AVX2 goes, where the ordinary build runs
 * the vectors.
 */
#ifndef HEXCNC_SIMD_H
#define HEXCNC_SIMD_H

#ifdef HEXCNC_BASELINE
#define HEXCNC_AVX2
#define HEXCNC_CLONES
#else
#define HEXCNC_AVX2 __attribute__((target("avx2")))
#define HEXCNC_CLONES __attribute__((target_clones("avx2", "default")))
#endif

/* Whether the processor runs HEXCNC_AVX2 code (and the operating system keeps its
 * registers). */
static inline int hexcnc_avx2(void)
{
#ifdef HEXCNC_BASELINE
    return 0;
#else
    return __builtin_cpu_supports("avx2");
#endif
}

#endif
