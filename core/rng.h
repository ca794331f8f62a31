/* core/rng.h — counter-based random numbers (Philox-4x32-10, Salmon et al. 2011, "Parallel random
 * numbers: as easy as 1, 2, 3").
 *
 * A random number is a pure function of (seed, pixel, sample, bounce, dimension): there is no
 * generator state to carry, so an image does not depend on thread counts, chunk sizes or which
 * device traced which ray.  One call returns four independent 32-bit words; `dim` numbers the
 * group of four inside one bounce (see shading/dims.h for who uses which group). */
#ifndef RS_CORE_RNG_H
#define RS_CORE_RNG_H

#include "core/hd.h"

typedef struct rs_rng_out {
    uint32_t v[4];
} rs_rng_out;

RS_HD uint32_t rs_mulhilo32(uint32_t a, uint32_t b, uint32_t *hi)
{
    uint64_t p = (uint64_t)a * (uint64_t)b;
    *hi = (uint32_t)(p >> 32);
    return (uint32_t)p;
}

/* Philox-4x32 with 10 rounds on counter c and key k. */
RS_HD rs_rng_out rs_philox4x32_10(uint32_t c0, uint32_t c1, uint32_t c2, uint32_t c3, uint32_t k0,
                                  uint32_t k1)
{
    const uint32_t m0 = 0xD2511F53u, m1 = 0xCD9E8D57u;
    const uint32_t w0 = 0x9E3779B9u, w1 = 0xBB67AE85u;
    rs_rng_out out;
    int round;
    for (round = 0; round < 10; ++round) {
        uint32_t hi0, hi1;
        uint32_t lo0 = rs_mulhilo32(m0, c0, &hi0);
        uint32_t lo1 = rs_mulhilo32(m1, c2, &hi1);
        uint32_t n0 = hi1 ^ c1 ^ k0;
        uint32_t n2 = hi0 ^ c3 ^ k1;
        c0 = n0;
        c1 = lo1;
        c2 = n2;
        c3 = lo0;
        k0 += w0;
        k1 += w1;
    }
    out.v[0] = c0;
    out.v[1] = c1;
    out.v[2] = c2;
    out.v[3] = c3;
    return out;
}

/* Four random words for (seed, pixel, sample, bounce, dim). */
RS_HD rs_rng_out rs_rng_u32x4(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce,
                              uint32_t dim)
{
    return rs_philox4x32_10(pixel, sample, bounce, dim, (uint32_t)seed, (uint32_t)(seed >> 32));
}

/* A uniform float in [0, 1) from the top 24 bits of a word (exactly representable steps). */
RS_HD float rs_rng_to_float(uint32_t u) { return (float)(u >> 8) * (1.0f / 16777216.0f); }

typedef struct rs_rng_f4 {
    float v[4];
} rs_rng_f4;

/* Four uniform floats in [0, 1) for (seed, pixel, sample, bounce, dim). */
RS_HD rs_rng_f4 rs_rng_float4(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce,
                              uint32_t dim)
{
    rs_rng_out w = rs_rng_u32x4(seed, pixel, sample, bounce, dim);
    rs_rng_f4 f;
    f.v[0] = rs_rng_to_float(w.v[0]);
    f.v[1] = rs_rng_to_float(w.v[1]);
    f.v[2] = rs_rng_to_float(w.v[2]);
    f.v[3] = rs_rng_to_float(w.v[3]);
    return f;
}

#endif
