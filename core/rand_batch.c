/* core/rand_batch.c — see rand_batch.h.  The AVX2 code (and the Sobol points' GFNI variant) is
 * compiled for that target alone (function attributes), so the build runs on any x86-64 and
 * picks it at run time; other machines build the scalar loop only. */
#include "core/rand_batch.h"

#include <stdatomic.h>
#include <string.h>

#include "core/sobol.h"

#if defined(__x86_64__) && defined(__GNUC__)
#  define RS_RAND_HAVE_AVX2 1
#  include <immintrin.h>
#else
#  define RS_RAND_HAVE_AVX2 0
#endif

static atomic_int forced = RS_RAND_ISA_AUTO;

static int cpu_has_avx2(void)
{
#if RS_RAND_HAVE_AVX2
    return __builtin_cpu_supports("avx2");
#else
    return 0;
#endif
}

static int cpu_has_gfni(void)
{
#if RS_RAND_HAVE_AVX2
    return __builtin_cpu_supports("gfni");
#else
    return 0;
#endif
}

static rs_rand_isa resolve(void)
{
    int f = atomic_load_explicit(&forced, memory_order_relaxed);
    if (f == RS_RAND_ISA_SCALAR || !cpu_has_avx2())
        return RS_RAND_ISA_SCALAR;
    if (f != RS_RAND_ISA_AVX2 && cpu_has_gfni())
        return RS_RAND_ISA_AVX2_GFNI;
    return RS_RAND_ISA_AVX2;
}

rs_rand_isa rs_rand_batch_use(rs_rand_isa isa)
{
    atomic_store(&forced, (int)isa);
    return resolve();
}

#if RS_RAND_HAVE_AVX2
#  define AVX2 __attribute__((target("avx2")))

/* ---- eight lanes of the integer steps of core/sobol.h and core/rng.h ---- */

AVX2 static inline __m256i k8(uint32_t c) { return _mm256_set1_epi32((int)c); }

AVX2 static inline __m256i hash8(__m256i x) /* rs_hash_u32 */
{
    x = _mm256_xor_si256(x, _mm256_srli_epi32(x, 16));
    x = _mm256_mullo_epi32(x, k8(0x7feb352du));
    x = _mm256_xor_si256(x, _mm256_srli_epi32(x, 15));
    x = _mm256_mullo_epi32(x, k8(0x846ca68bu));
    return _mm256_xor_si256(x, _mm256_srli_epi32(x, 16));
}

AVX2 static inline __m256i lk8(__m256i x, __m256i seed) /* rs_lk_permute */
{
    x = _mm256_xor_si256(x, _mm256_mullo_epi32(x, k8(0x3d20adeau)));
    x = _mm256_add_epi32(x, seed);
    x = _mm256_mullo_epi32(x, _mm256_or_si256(_mm256_srli_epi32(seed, 16), k8(1u)));
    x = _mm256_xor_si256(x, _mm256_mullo_epi32(x, k8(0x05526c56u)));
    return _mm256_xor_si256(x, _mm256_mullo_epi32(x, k8(0x53a22864u)));
}

/* rs_reverse_bits: each byte's nibbles reversed by table and swapped, then the bytes of each
 * word reversed */
AVX2 static inline __m256i rev8(__m256i x)
{
    const __m256i nib = _mm256_setr_epi8(0x0, 0x8, 0x4, 0xc, 0x2, 0xa, 0x6, 0xe, 0x1, 0x9, 0x5,
                                         0xd, 0x3, 0xb, 0x7, 0xf, 0x0, 0x8, 0x4, 0xc, 0x2, 0xa,
                                         0x6, 0xe, 0x1, 0x9, 0x5, 0xd, 0x3, 0xb, 0x7, 0xf);
    const __m256i bytes = _mm256_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3,
                                           2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12);
    const __m256i lo4 = _mm256_set1_epi8(0x0f);
    __m256i lo = _mm256_shuffle_epi8(nib, _mm256_and_si256(x, lo4));
    __m256i hi = _mm256_shuffle_epi8(nib, _mm256_and_si256(_mm256_srli_epi32(x, 4), lo4));
    x = _mm256_or_si256(_mm256_slli_epi32(lo, 4), hi);
    return _mm256_shuffle_epi8(x, bytes);
}

AVX2 static inline __m256i superset8(__m256i y) /* rs_superset_xor */
{
    y = _mm256_xor_si256(y, _mm256_and_si256(_mm256_srli_epi32(y, 1), k8(0x55555555u)));
    y = _mm256_xor_si256(y, _mm256_and_si256(_mm256_srli_epi32(y, 2), k8(0x33333333u)));
    y = _mm256_xor_si256(y, _mm256_and_si256(_mm256_srli_epi32(y, 4), k8(0x0f0f0f0fu)));
    y = _mm256_xor_si256(y, _mm256_and_si256(_mm256_srli_epi32(y, 8), k8(0x00ff00ffu)));
    return _mm256_xor_si256(y, _mm256_srli_epi32(y, 16));
}

AVX2 static inline __m256 tofloat8(__m256i u) /* rs_rng_to_float: exact, u >> 8 < 2^24 */
{
    return _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32(u, 8)),
                         _mm256_set1_ps(1.0f / 16777216.0f));
}

/* Four vectors of eight lanes (number k of lane i in v[k]) stored as eight rs_rng_f4. */
AVX2 static inline void store_f4x8(__m256 a, __m256 b, __m256 c, __m256 d, rs_rng_f4 *out)
{
    __m256 t0 = _mm256_unpacklo_ps(a, b), t1 = _mm256_unpackhi_ps(a, b);
    __m256 t2 = _mm256_unpacklo_ps(c, d), t3 = _mm256_unpackhi_ps(c, d);
    __m256 u0 = _mm256_shuffle_ps(t0, t2, 0x44), u1 = _mm256_shuffle_ps(t0, t2, 0xee);
    __m256 u2 = _mm256_shuffle_ps(t1, t3, 0x44), u3 = _mm256_shuffle_ps(t1, t3, 0xee);
    float *o = out[0].v;
    _mm256_storeu_ps(o + 0, _mm256_permute2f128_ps(u0, u1, 0x20));
    _mm256_storeu_ps(o + 8, _mm256_permute2f128_ps(u2, u3, 0x20));
    _mm256_storeu_ps(o + 16, _mm256_permute2f128_ps(u0, u1, 0x31));
    _mm256_storeu_ps(o + 24, _mm256_permute2f128_ps(u2, u3, 0x31));
}

/* Lanes i .. i + 7 of pixel[] and sample[] as vectors; where fewer than eight are left (n - i)
 * the missing lanes read zero. */
AVX2 static inline void load_lanes8(const uint32_t *pixel, const uint32_t *sample, uint32_t i,
                                    uint32_t n, __m256i *pix, __m256i *smp)
{
    uint32_t p[8], s[8], left = n - i;
    if (left >= 8) {
        *pix = _mm256_loadu_si256((const __m256i *)(pixel + i));
        *smp = _mm256_loadu_si256((const __m256i *)(sample + i));
        return;
    }
    memset(p, 0, sizeof p);
    memset(s, 0, sizeof s);
    memcpy(p, pixel + i, left * sizeof *p);
    memcpy(s, sample + i, left * sizeof *s);
    *pix = _mm256_loadu_si256((const __m256i *)p);
    *smp = _mm256_loadu_si256((const __m256i *)s);
}

/* Eight lanes' four numbers (store_f4x8) into out[i ..], only the n - i entries that exist. */
AVX2 static inline void store_lanes8(__m256 a, __m256 b, __m256 c, __m256 d, rs_rng_f4 *out,
                                     uint32_t i, uint32_t n)
{
    rs_rng_f4 tail[8];
    if (n - i >= 8) {
        store_f4x8(a, b, c, d, out + i);
        return;
    }
    store_f4x8(a, b, c, d, tail);
    memcpy(out + i, tail, (n - i) * sizeof *tail);
}

/* rs_reverse_bits with GFNI: each byte's bits reversed by one affine transform over GF(2) (the
 * anti-diagonal bit matrix), then the bytes of each word reversed */
#  define GFNI __attribute__((target("avx2,gfni")))
GFNI static inline __m256i rev8_gfni(__m256i x)
{
    const __m256i bytes = _mm256_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3,
                                           2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12);
    x = _mm256_gf2p8affine_epi64_epi8(x, _mm256_set1_epi64x((long long)0x8040201008040201ull), 0);
    return _mm256_shuffle_epi8(x, bytes);
}

/* The Sobol points twice: sobol_avx2 and, for CPUs with GFNI (a sixth fewer operations: the
 * bit reversals, seven a group, are two instructions instead of eight), sobol_gfni. */
#  define RS_SOBOL8_ATTR AVX2
#  define RS_SOBOL8_FN(x) x##_avx2
#  define RS_SOBOL8_REV(x) rev8(x)
#  include "core/rand_sobol8.h"
#  define RS_SOBOL8_ATTR GFNI
#  define RS_SOBOL8_FN(x) x##_gfni
#  define RS_SOBOL8_REV(x) rev8_gfni(x)
#  include "core/rand_sobol8.h"

/* rs_mulhilo32 of each lane of c by the constant m */
AVX2 static inline void mulhilo8(__m256i m, __m256i c, __m256i *lo, __m256i *hi)
{
    __m256i even = _mm256_mul_epu32(c, m);
    __m256i odd = _mm256_mul_epu32(_mm256_srli_epi64(c, 32), m);
    *lo = _mm256_blend_epi32(even, _mm256_slli_epi64(odd, 32), 0xaa);
    *hi = _mm256_blend_epi32(_mm256_srli_epi64(even, 32), odd, 0xaa);
}

AVX2 static void philox_avx2(uint64_t seed, const uint32_t *pixel, const uint32_t *sample,
                             uint32_t bounce, uint32_t group, uint32_t n, rs_rng_f4 *out)
{
    const __m256i m0 = k8(0xD2511F53u), m1 = k8(0xCD9E8D57u);
    uint32_t i;
    for (i = 0; i < n; i += 8) {
        uint32_t k0 = (uint32_t)seed, k1 = (uint32_t)(seed >> 32);
        __m256i c0, c1, c2 = k8(bounce), c3 = k8(group);
        int round;
        load_lanes8(pixel, sample, i, n, &c0, &c1);
        for (round = 0; round < 10; ++round) { /* rs_philox4x32_10 */
            __m256i lo0, hi0, lo1, hi1;
            mulhilo8(m0, c0, &lo0, &hi0);
            mulhilo8(m1, c2, &lo1, &hi1);
            c0 = _mm256_xor_si256(_mm256_xor_si256(hi1, c1), k8(k0));
            c2 = _mm256_xor_si256(_mm256_xor_si256(hi0, c3), k8(k1));
            c1 = lo1;
            c3 = lo0;
            k0 += 0x9E3779B9u;
            k1 += 0xBB67AE85u;
        }
        store_lanes8(tofloat8(c0), tofloat8(c1), tofloat8(c2), tofloat8(c3), out, i, n);
    }
}
#endif

void rs_rand_batch_sobol(uint64_t seed, const uint32_t *pixel, const uint32_t *sample,
                         uint32_t bounce, uint32_t group, uint32_t n, rs_rng_f4 *out)
{
    uint32_t i;
#if RS_RAND_HAVE_AVX2
    rs_rand_isa isa = resolve();
    if (isa == RS_RAND_ISA_AVX2_GFNI) {
        sobol_gfni(seed, pixel, sample, bounce, group, n, out);
        return;
    }
    if (isa == RS_RAND_ISA_AVX2) {
        sobol_avx2(seed, pixel, sample, bounce, group, n, out);
        return;
    }
#endif
    for (i = 0; i < n; ++i)
        out[i] = rs_sobol_float4(seed, pixel[i], sample[i], bounce, group);
}

void rs_rand_batch_philox(uint64_t seed, const uint32_t *pixel, const uint32_t *sample,
                          uint32_t bounce, uint32_t group, uint32_t n, rs_rng_f4 *out)
{
    uint32_t i;
#if RS_RAND_HAVE_AVX2
    if (resolve() != RS_RAND_ISA_SCALAR) { /* Philox has no use for GFNI */
        philox_avx2(seed, pixel, sample, bounce, group, n, out);
        return;
    }
#endif
    for (i = 0; i < n; ++i)
        out[i] = rs_rng_float4(seed, pixel[i], sample[i], bounce, group);
}
