/* core/zsobol.h — Morton-ordered Owen-scrambled Sobol points (Ahmed and Wonka 2020, "Screen-space
 * blue-noise diffusion of Monte Carlo sampling error via hierarchical ordering of pixels", ACM
 * TOG 39(6); the sampler pbrt-v4 calls ZSobolSampler), with the call of core/sobol.h.
 *
 * core/sobol.h gives every pixel a scramble of its own of the same points: each pixel's samples
 * are a net, but neighbouring pixels' errors are independent (white noise on the screen).  Here
 * the whole image shares one sequence per 2D pair, and pixel (x, y) takes the block of 2^L
 * consecutive indices at its Morton code, L = ceil(log2 spp):
 *
 *     m = (morton(x, y) << L) | sample            (the Morton code over the power-of-two square
 *                                                  around the image, side 2^R)
 *
 * so an aligned 2x2 quad of pixels holds one block of 4 * 2^L indices, a 4x4 quad one of
 * 16 * 2^L, and so on: any such quad's samples together are a (0, 2j + L, 2)-net, and its
 * pixels' errors partly cancel (blue noise).  Which sub-block each pixel of a quad gets, and
 * which sample each index, is randomised per pair: every base-4 digit of m is permuted, by one of
 * the 24 permutations of {0, 1, 2, 3}, chosen by a hash of the digits above it and the pair's key
 * (a random tree of permutations: a bijection that maps aligned blocks of 4^j onto aligned
 * blocks).  An odd L leaves a last base-2 digit (the sample's lowest bit), flipped by a hash of
 * the digits above it instead.  The permuted index is evaluated as the first two Sobol dimensions
 * Owen-scrambled with the pair's seed (rs_owen_sobol2): each pixel's 2^L samples of a pair are an
 * aligned block of Sobol points, hence a (0, L, 2)-net, for odd L too (core_zsobol_test).
 *
 * Invariants: a number is a pure function of (seed, x, y, sample, L, R, bounce, group), with no
 * table and no state, RS_HD.  sample < 2^L is the render's case; a larger one starts a further,
 * independently scrambled block (the pair's seed hashes sample >> L).  The index keeps 62 bits
 * (R + ceil(L / 2) <= 31 base-4 digits); past that (images over 2^15 pixels wide at 2^32 spp,
 * or the like) the Morton code's top bits are dropped and far apart pixels share samples.  The
 * index's bits above 32 do not reach a 32-bit Sobol fraction; they are hashed into the scramble
 * seed instead, so images up to that 62-bit limit keep distinct points per pixel.
 *
 * Cost per 2D pair: R + ceil(L / 2) 64-bit hashes (the digit permutations) and the two Owen
 * scrambles; 12 hashes at 256x256 and 256 spp, against core/sobol.h's one index shuffle. */
#ifndef RS_CORE_ZSOBOL_H
#define RS_CORE_ZSOBOL_H

#include "core/sobol.h"

/* ceil(log2 n), 0 for n <= 1: the bits of n - 1 smeared down and counted, no loop. */
RS_HD uint32_t rs_ceil_log2(uint32_t n)
{
    uint32_t v = n > 1u ? n - 1u : 0u;
    v |= v >> 1;
    v |= v >> 2;
    v |= v >> 4;
    v |= v >> 8;
    v |= v >> 16;
    v = v - ((v >> 1) & 0x55555555u);
    v = (v & 0x33333333u) + ((v >> 2) & 0x33333333u);
    v = (v + (v >> 4)) & 0x0f0f0f0fu;
    return (v * 0x01010101u) >> 24;
}

/* A 64-bit mixer (Evensen's "Moremur" constants for the shift-multiply finaliser). */
RS_HD uint64_t rs_hash_u64(uint64_t x)
{
    x ^= x >> 27;
    x *= 0x3c79ac492ba7b653ull;
    x ^= x >> 33;
    x *= 0x1c69b3f74ac4ae35ull;
    x ^= x >> 27;
    return x;
}

/* The 32 bits of v at the even bit positions of the result. */
RS_HD uint64_t rs_spread_bits2(uint32_t v)
{
    uint64_t x = v;
    x = (x | (x << 16)) & 0x0000ffff0000ffffull;
    x = (x | (x << 8)) & 0x00ff00ff00ff00ffull;
    x = (x | (x << 4)) & 0x0f0f0f0f0f0f0f0full;
    x = (x | (x << 2)) & 0x3333333333333333ull;
    x = (x | (x << 1)) & 0x5555555555555555ull;
    return x;
}

/* The 2D Morton code (Z order) of pixel (x, y): x's bits at the even positions, y's at the odd;
 * each base-4 digit one level of the quadtree of pixels. */
RS_HD uint64_t rs_morton2(uint32_t x, uint32_t y)
{
    return rs_spread_bits2(x) | (rs_spread_bits2(y) << 1);
}

/* One of the 24 permutations of {0, 1, 2, 3}, picked by the hash h, applied to `digit`.  Each is
 * sigma(digit) ^ k: k = pi(0) from h's top two bits, sigma one of the 6 permutations that fix 0,
 * from h's low word (the 6 packed as bytes of 2-bit entries: 0123, 0132, 0213, 0231, 0312,
 * 0321).  Every (sigma, k) gives a different permutation, so all 24 are reached, each with
 * probability 1/24 to within 2^-32. */
RS_HD uint32_t rs_permute_digit4(uint32_t digit, uint64_t h)
{
    uint32_t sigma = (uint32_t)(((h & 0xffffffffu) * 6u) >> 32);
    uint32_t k = (uint32_t)(h >> 62);
    return ((uint32_t)(0x6c9c78d8b4e4ull >> (8u * sigma + 2u * digit)) & 3u) ^ k;
}

/* The permuted index of m = (morton << L) | sample (sample < 2^L) for the pair with 64-bit key
 * `key` (see the file's top).  Each digit's permutation is hashed from the digits above it with
 * a sentinel bit on top, so prefixes of different lengths never share a hash input. */
RS_HD uint64_t rs_zsobol_index(uint64_t morton, uint32_t sample, uint32_t log2_spp,
                               uint32_t log2_res, uint64_t key)
{
    uint32_t odd = log2_spp & 1u;
    uint32_t digits = log2_res + (log2_spp + 1u) / 2u; /* base-4 digits of m, odd L padded */
    uint64_t m, out = 0;
    int i;
    if (digits > 31u)
        digits = 31u;
    /* an odd L gets a zero bit below the sample, so the sample fills whole digits (pbrt-v4) */
    m = (morton << (log2_spp + odd)) | ((uint64_t)sample << odd); /* log2_spp <= 32 */
    m = (m & (((uint64_t)1 << (2u * digits)) - 1u)) | ((uint64_t)1 << (2u * digits));
    for (i = (int)digits - 1; i >= (int)odd; --i) {
        uint32_t shift = 2u * (uint32_t)i;
        uint32_t digit = (uint32_t)(m >> shift) & 3u;
        out |= (uint64_t)rs_permute_digit4(digit, rs_hash_u64((m >> (shift + 2u)) ^ key)) << shift;
    }
    if (odd) {
        /* the last digit is the sample's lowest bit (and the zero below it): shift the padding
         * out and flip that bit by a hash of the digits above */
        out = ((out | (m & 3u)) >> 1) ^ (rs_hash_u64((m >> 2) ^ key) & 1u);
    }
    return out;
}

/* The 2D point of one pair: index from rs_zsobol_index, `seed` the pair's 32-bit seed. */
RS_HD void rs_zsobol2(uint32_t seed, uint64_t morton, uint32_t sample, uint32_t log2_spp,
                      uint32_t log2_res, float *x0, float *x1)
{
    uint64_t index;
    if (log2_spp < 32u && (sample >> log2_spp) != 0u) { /* past the render's spp: a new block */
        seed = rs_hash_u32(seed ^ rs_hash_u32(sample >> log2_spp));
        sample &= (1u << log2_spp) - 1u;
    }
    index = rs_zsobol_index(morton, sample, log2_spp, log2_res,
                            rs_hash_u64(((uint64_t)seed << 32) | (seed ^ 0x9e3779b9u)));
    /* bits 32 and up pick the scramble (rs_hash_u32(0) = 0: unchanged below 2^32) */
    rs_owen_sobol2(seed ^ rs_hash_u32((uint32_t)(index >> 32)), (uint32_t)index, x0, x1);
}

/* log2 of the render's spp (rounded up) and of the side of the power-of-two square around its
 * width x height pixels, the two sizes the index needs. */
RS_HD uint32_t rs_zsobol_log2_res(uint32_t width, uint32_t height)
{
    return rs_ceil_log2(width > height ? width : height);
}

/* Four numbers in [0, 1) for (seed, pixel (x, y), sample, bounce, group), like rs_sobol_float4:
 * the 2D points (v[0], v[1]) and (v[2], v[3]), each pair with its seeds from
 * rs_sobol_group_seed (pixel 0: one sequence for the whole image). */
RS_HD rs_rng_f4 rs_zsobol_float4(uint64_t seed, uint32_t x, uint32_t y, uint32_t sample,
                                 uint32_t log2_spp, uint32_t log2_res, uint32_t bounce,
                                 uint32_t group)
{
    uint32_t s = rs_sobol_group_seed(seed, 0u, bounce, group);
    uint64_t morton = rs_morton2(x, y);
    rs_rng_f4 f;
    rs_zsobol2(rs_hash_u32(s ^ RS_SOBOL_PAIR0), morton, sample, log2_spp, log2_res, &f.v[0],
               &f.v[1]);
    rs_zsobol2(rs_hash_u32(s ^ RS_SOBOL_PAIR1), morton, sample, log2_spp, log2_res, &f.v[2],
               &f.v[3]);
    return f;
}

#endif
