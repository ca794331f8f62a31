/* core/rand_batch.h — many paths' random numbers at once, for the host's stream stages.
 *
 * rs_rng_float4 (core/rng.h) and rs_sobol_float4 (core/sobol.h) give one path's four numbers;
 * the functions here give them for n paths that share (seed, bounce, group) and differ in
 * (pixel, sample), with AVX2 (eight paths per instruction) where the CPU has it and the RS_HD
 * functions themselves otherwise.  Both are integer arithmetic only, ending in the same exact
 * conversion to float, so every number is the scalar one bit for bit (core_rand_batch_test
 * compares them on every instruction set this machine has).  Host only: the CUDA device keeps
 * calling the RS_HD functions, one thread per path.
 *
 * Cost, one 2D-pair of Sobol numbers: the scalar code spends ~350 instructions per call of four
 * numbers, about half in bit reversals (five mask-and-shift steps each, twelve per call); the
 * AVX2 code does a bit reversal of eight words in eight instructions (nibble table lookups). */
#ifndef RS_CORE_RAND_BATCH_H
#define RS_CORE_RAND_BATCH_H

#include "core/rng.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Which code the batch functions run. */
typedef enum rs_rand_isa {
    RS_RAND_ISA_AUTO = 0,   /* the best this CPU has (the default) */
    RS_RAND_ISA_SCALAR = 1, /* the RS_HD functions in a loop */
    RS_RAND_ISA_AVX2 = 2,   /* x86-64 with AVX2 */
    RS_RAND_ISA_AVX2_GFNI = 3 /* AVX2, and GFNI's byte transforms for the Sobol points' bit
                                 reversals (Intel since Ice Lake, AMD since Zen 4) */
} rs_rand_isa;

/* Chooses the code for later calls (tests compare the choices); returns the choice in effect,
 * which falls back to RS_RAND_ISA_SCALAR where the CPU (or the build) lacks the one asked for.
 * Not thread safe against concurrent batch calls: call it between renders. */
rs_rand_isa rs_rand_batch_use(rs_rand_isa isa);

/* out[i] = rs_sobol_float4(seed, pixel[i], sample[i], bounce, group) for i < n. */
void rs_rand_batch_sobol(uint64_t seed, const uint32_t *pixel, const uint32_t *sample,
                         uint32_t bounce, uint32_t group, uint32_t n, rs_rng_f4 *out);

/* out[i] = rs_rng_float4(seed, pixel[i], sample[i], bounce, group) for i < n (Philox). */
void rs_rand_batch_philox(uint64_t seed, const uint32_t *pixel, const uint32_t *sample,
                          uint32_t bounce, uint32_t group, uint32_t n, rs_rng_f4 *out);

#ifdef __cplusplus
}
#endif

#endif
