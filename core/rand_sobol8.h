/* core/rand_sobol8.h — the batched Sobol points of core/rand_batch.c, eight lanes at a time,
 * written once for two instruction sets.  No include guard: rand_batch.c includes it once for
 * AVX2 alone and once for AVX2 with GFNI, each after defining
 *   RS_SOBOL8_ATTR      the functions' target attribute
 *   RS_SOBOL8_FN(x)     their names (prefix ## x)
 *   RS_SOBOL8_REV(x)    rs_reverse_bits on eight lanes
 * and it undefines them.  The helpers it calls (hash8, lk8, superset8, tofloat8, load_lanes8,
 * store_lanes8) are rand_batch.c's, compiled for AVX2, which either target includes. */

/* rs_sobol2 on eight lanes; rsample = rs_reverse_bits(sample) */
RS_SOBOL8_ATTR static inline void RS_SOBOL8_FN(sobol2x8)(__m256i seed, __m256i rsample, __m256 *x0,
                                                         __m256 *x1)
{
    __m256i index = RS_SOBOL8_REV(lk8(rsample, seed));
    *x0 = tofloat8(RS_SOBOL8_REV(lk8(index, hash8(_mm256_add_epi32(seed, k8(1u))))));
    *x1 = tofloat8(RS_SOBOL8_REV(lk8(superset8(index), hash8(_mm256_add_epi32(seed, k8(2u))))));
}

/* rs_sobol_float4 for entries [0, n) */
RS_SOBOL8_ATTR static void RS_SOBOL8_FN(sobol)(uint64_t seed, const uint32_t *pixel,
                                               const uint32_t *sample, uint32_t bounce,
                                               uint32_t group, uint32_t n, rs_rng_f4 *out)
{
    const __m256i lo = k8((uint32_t)seed), hi = k8((uint32_t)(seed >> 32));
    const __m256i hb = k8(rs_hash_u32(bounce * 8u + group));
    uint32_t i;
    for (i = 0; i < n; i += 8) {
        __m256i s, rs;
        __m256 a, b, c, d;
        load_lanes8(pixel, sample, i, n, &s, &rs);
        s = hash8(_mm256_xor_si256(s, hb));
        s = hash8(_mm256_xor_si256(hi, s));
        s = hash8(_mm256_xor_si256(lo, s));
        rs = RS_SOBOL8_REV(rs);
        RS_SOBOL8_FN(sobol2x8)(hash8(_mm256_xor_si256(s, k8(0x5bd1e995u))), rs, &a, &b);
        RS_SOBOL8_FN(sobol2x8)(hash8(_mm256_xor_si256(s, k8(0x27d4eb2fu))), rs, &c, &d);
        store_lanes8(a, b, c, d, out, i, n);
    }
}

#undef RS_SOBOL8_ATTR
#undef RS_SOBOL8_FN
#undef RS_SOBOL8_REV
