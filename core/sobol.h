/* core/sobol.h — padded 2D Sobol points, Owen-scrambled and shuffled (Burley 2020, "Practical
 * Hash-based Owen Scrambling", JCGT 9(4); pbrt-v4's PaddedSobolSampler pads the same way): the
 * low-discrepancy counterpart of core/rng.h, with the same call.
 *
 * One call returns four numbers as two 2D points of the first two Sobol dimensions, each pair
 * with seeds of its own, a hash of (seed, pixel, bounce, group, pair).  The seed both shuffles
 * the sample index (a nested uniform scramble of it: the first 2^k samples of a pixel are still
 * one aligned block of 2^k Sobol points) and Owen-scrambles each dimension.  Sobol's first two
 * dimensions form a (0,2)-sequence, and Owen scrambling keeps that: the first 2^k samples of a
 * pixel put exactly one point of each pair in every elementary interval of area 2^-k (tested in
 * core_rng_test).  Pairs and groups are decorrelated from each other by their seeds ("padding"),
 * and a number is a pure function of (seed, pixel, sample, bounce, group): images do not depend
 * on threads, chunks or devices.
 *
 * Cost: dimension 0 is the bit reversal of the index, dimension 1 (the Pascal matrix mod 2) a
 * superset-XOR transform of its bits in five shift steps; no table and no loop, so the code is
 * RS_HD and about as cheap as Philox. */
#ifndef RS_CORE_SOBOL_H
#define RS_CORE_SOBOL_H

#include "core/rng.h"

RS_HD uint32_t rs_reverse_bits(uint32_t x)
{
#if RS_DEVICE_PASS
    return __brev(x);
#else
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
#endif
}

/* Bit i of the result is the XOR of the bits j of y whose set bits include i's (j ⊇ i).  With
 * Lucas's theorem that is the Pascal matrix mod 2, Sobol's second generator matrix, applied to
 * the index bits (before the bit reversal that makes a fraction of it). */
RS_HD uint32_t rs_superset_xor(uint32_t y)
{
    y ^= (y >> 1) & 0x55555555u;
    y ^= (y >> 2) & 0x33333333u;
    y ^= (y >> 4) & 0x0f0f0f0fu;
    y ^= (y >> 8) & 0x00ff00ffu;
    y ^= (y >> 16) & 0x0000ffffu;
    return y;
}

/* Sobol dimension `dim` (0 or 1) of point `index`, as a 32-bit fraction. */
RS_HD uint32_t rs_sobol_u32(uint32_t index, uint32_t dim)
{
    return rs_reverse_bits(dim == 0 ? index : rs_superset_xor(index));
}

/* Laine and Karras's permutation in Burley's improved form (2020, section 3; the hash Cycles'
 * Sobol-Burley sampler uses): each output bit depends only on the input bits below it (adds,
 * odd multiplies and x ^= x * even constant all carry upward only), a random one for each seed. */
RS_HD uint32_t rs_lk_permute(uint32_t x, uint32_t seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}

/* An Owen scramble of a 32-bit fraction: each bit flipped by a hash of the bits above it. */
RS_HD uint32_t rs_nested_uniform_scramble(uint32_t x, uint32_t seed)
{
    return rs_reverse_bits(rs_lk_permute(rs_reverse_bits(x), seed));
}

/* A 32-bit mixer (Wellons' lowbias32) for seeds. */
RS_HD uint32_t rs_hash_u32(uint32_t x)
{
    x ^= x >> 16;
    x *= 0x7feb352du;
    x ^= x >> 15;
    x *= 0x846ca68bu;
    x ^= x >> 16;
    return x;
}

/* Point `index` of the first two Sobol dimensions, each Owen-scrambled with a seed made from
 * `seed`.  (The scramble of dimension d is reverse(lk(reverse(sobol_d))), and reverse(sobol_d) is
 * the index itself or its superset-XOR, so each dimension costs one bit reversal.) */
RS_HD_HOT void rs_owen_sobol2(uint32_t seed, uint32_t index, float *x0, float *x1)
{
    *x0 = rs_rng_to_float(rs_reverse_bits(rs_lk_permute(index, rs_hash_u32(seed + 1u))));
    *x1 = rs_rng_to_float(
        rs_reverse_bits(rs_lk_permute(rs_superset_xor(index), rs_hash_u32(seed + 2u))));
}

/* The 2D point of sample `sample` for `seed`: shuffled index, both dimensions Owen-scrambled. */
RS_HD void rs_sobol2(uint32_t seed, uint32_t sample, float *x0, float *x1)
{
    rs_owen_sobol2(seed, rs_nested_uniform_scramble(sample, seed), x0, x1);
}

/* The two pairs' seeds of one group of four numbers, for (seed, pixel, bounce, group): how every
 * decision of every bounce gets dimensions of its own, without a table (shading/dims.h numbers
 * the groups; there are fewer than 8).  core/zsobol.h takes them with pixel 0: its pixels share
 * one sequence per pair. */
#define RS_SOBOL_PAIR0 0x5bd1e995u
#define RS_SOBOL_PAIR1 0x27d4eb2fu

RS_HD uint32_t rs_sobol_group_seed(uint64_t seed, uint32_t pixel, uint32_t bounce, uint32_t group)
{
    return rs_hash_u32((uint32_t)seed ^
                       rs_hash_u32((uint32_t)(seed >> 32) ^
                                   rs_hash_u32(pixel ^ rs_hash_u32(bounce * 8u + group))));
}

/* Four numbers in [0, 1) for (seed, pixel, sample, bounce, group), like rs_rng_float4: the 2D
 * points (v[0], v[1]) and (v[2], v[3]). */
RS_HD rs_rng_f4 rs_sobol_float4(uint64_t seed, uint32_t pixel, uint32_t sample, uint32_t bounce,
                                uint32_t group)
{
    uint32_t s = rs_sobol_group_seed(seed, pixel, bounce, group);
    rs_rng_f4 f;
    rs_sobol2(rs_hash_u32(s ^ RS_SOBOL_PAIR0), sample, &f.v[0], &f.v[1]);
    rs_sobol2(rs_hash_u32(s ^ RS_SOBOL_PAIR1), sample, &f.v[2], &f.v[3]);
    return f;
}

#endif
