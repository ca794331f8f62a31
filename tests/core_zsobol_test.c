/* tests/core_zsobol_test.c — core/zsobol.h: Owen-scrambled Sobol points in Morton order over the
 * image (Ahmed and Wonka 2020; pbrt-v4's ZSobolSampler).
 *
 * What is checked:
 *   - the helpers: rs_ceil_log2 and rs_morton2 against loops; rs_permute_digit4 reaches all 24
 *     permutations of {0, 1, 2, 3}, and with random hashes each about equally often (chi-square,
 *     23 degrees of freedom, significance 0.01);
 *   - the index: over every pixel of the power-of-two square and every sample, for L = 0..6 and
 *     R = 0..3, it is a permutation of [0, 4^R 2^L), each pixel's samples one aligned block of
 *     2^L and each aligned 2x2 quad's one block of 4 2^L (the hierarchy);
 *   - stratification: at spp = 2^L (L = 1..10, odd L included) the 2^L samples of a pixel put
 *     exactly one point of each pair in every elementary interval of area 2^-L, for every split
 *     of L into a + b (a (0,L,2)-net), and the 4 2^L samples of an aligned 2x2 quad of pixels
 *     form a (0,L+2,2)-net; random pixels, bounces and groups, a 256x256 and a 200x120 image;
 *   - uniformity and independence: chi-square of 10^6 numbers of each lane over 100 bins (a
 *     whole 61x64 image at 256 spp; and one pixel's sample under 10^6 seeds), and of 10 x 10
 *     histograms of the two pairs of one call, of two groups, two bounces and neighbouring
 *     pixels, at significance 0.01;
 *   - distinct pixels: the points of a 32x32 image at 4 spp are 4096 different points, and no two
 *     pixels of a 64x64 image share their first point; determinism: the same arguments give the
 *     same bits whatever was computed before, and a different seed different numbers;
 *   - convergence and the point of the sampler: integrating a smooth 2D function per pixel of a
 *     64x64 image, the mean is within 4.5 standard errors of the exact value, each pixel's RMSE
 *     at 64 samples is no worse than 1.5x the sobol sampler's, and the RMSE of 2x2 pixel means
 *     (what blue noise is for: neighbours' errors cancel) is at least 2x below the sobol
 *     sampler's, whose pixels' errors are independent.
 * Fixed seeds: every run is the same. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/zsobol.h"
#include "test_rand.h"
#include "test_sampler.h"

#define CHI2_23DOF_P01 41.638

static void test_helpers(void **state)
{
    uint64_t s = 3;
    uint32_t n, i;
    (void)state;
    for (n = 0; n < 5000; ++n) {
        uint32_t want = 0;
        while (((uint64_t)1 << want) < n)
            ++want;
        assert_int_equal(rs_ceil_log2(n), want);
    }
    assert_int_equal(rs_ceil_log2(0x80000000u), 31);
    assert_int_equal(rs_ceil_log2(0x80000001u), 32);
    assert_int_equal(rs_ceil_log2(0xffffffffu), 32);
    for (i = 0; i < 10000; ++i) {
        uint32_t x = (uint32_t)splitmix64(&s), y = (uint32_t)splitmix64(&s);
        uint64_t want = 0;
        int b;
        for (b = 0; b < 32; ++b)
            want |= (uint64_t)((x >> b) & 1u) << (2 * b) | (uint64_t)((y >> b) & 1u) << (2 * b + 1);
        assert_true(rs_morton2(x, y) == want);
    }
    assert_true(rs_morton2(1, 0) == 1 && rs_morton2(0, 1) == 2 && rs_morton2(3, 3) == 15);
}

/* A permutation of {0, 1, 2, 3} as one number 0..255 (its four 2-bit images). */
static uint32_t perm_code(uint64_t h)
{
    uint32_t d, c = 0;
    for (d = 0; d < 4; ++d)
        c |= rs_permute_digit4(d, h) << (2 * d);
    return c;
}

static void test_digit_permutations(void **state)
{
    static int code_of[256];
    double counts[24];
    uint64_t s = 5;
    uint32_t sigma, k, d, n_codes = 0, i;
    (void)state;
    memset(code_of, -1, sizeof code_of);
    /* every (sigma, k) a permutation, and all 24 of them different */
    for (sigma = 0; sigma < 6; ++sigma)
        for (k = 0; k < 4; ++k) {
            /* a hash that picks sigma (low word) and k (top bits) */
            uint64_t h = ((uint64_t)k << 62) | ((((uint64_t)sigma << 32) + 5u) / 6u);
            uint32_t c = perm_code(h), seen = 0;
            for (d = 0; d < 4; ++d)
                seen |= 1u << rs_permute_digit4(d, h);
            assert_int_equal(seen, 15);
            assert_int_equal(rs_permute_digit4(0, h), k);
            assert_int_equal(code_of[c], -1);
            code_of[c] = (int)n_codes++;
        }
    assert_int_equal(n_codes, 24);
    /* random hashes: the 24 equally likely */
    memset(counts, 0, sizeof counts);
    for (i = 0; i < 240000; ++i) {
        int c = code_of[perm_code(splitmix64(&s))];
        assert_true(c >= 0);
        counts[c] += 1.0;
    }
    {
        double c2 = chi_square(counts, 24, 10000.0);
        print_message("digit permutations: chi-square %.1f (23 dof, 0.01 critical %.1f)\n", c2,
                      CHI2_23DOF_P01);
        assert_true(c2 < CHI2_23DOF_P01);
    }
}

/* The index is a bijection of the whole image's [0, 4^R 2^L), one aligned block per pixel and
 * per aligned 2x2 quad. */
static void test_index_hierarchy(void **state)
{
    static unsigned char seen[1u << 12];
    uint64_t s = 7;
    uint32_t L, R;
    (void)state;
    for (R = 0; R <= 3; ++R)
        for (L = 0; L <= 6; ++L) {
            uint32_t side = 1u << R, spp = 1u << L, t;
            uint64_t total = (uint64_t)side * side * spp;
            for (t = 0; t < 8; ++t) {
                uint64_t key = splitmix64(&s);
                uint32_t x, y, i;
                memset(seen, 0, sizeof seen);
                for (y = 0; y < side; ++y)
                    for (x = 0; x < side; ++x) {
                        uint64_t m = rs_morton2(x, y);
                        uint64_t pix = rs_zsobol_index(m, 0, L, R, key) >> L;
                        uint64_t quad = rs_zsobol_index(m, 0, L, R, key) >> (L + 2);
                        for (i = 0; i < spp; ++i) {
                            uint64_t j = rs_zsobol_index(m, i, L, R, key);
                            assert_true(j < total);
                            assert_false(seen[j]);
                            seen[j] = 1;
                            assert_true(j >> L == pix);
                            if (R > 0) {
                                /* the quad of (x, y): the same block of 4 2^L as its corner */
                                uint64_t c = rs_morton2(x & ~1u, y & ~1u);
                                assert_true(j >> (L + 2) == quad);
                                assert_true(rs_zsobol_index(c, 0, L, R, key) >> (L + 2) == quad);
                            }
                        }
                    }
            }
        }
}

static void test_pixels_and_quads_are_nets(void **state)
{
    static float p[4][1u << 12];
    static const uint32_t sizes[2][2] = {{256, 256}, {200, 120}};
    uint64_t s = 13;
    int t, L, z;
    (void)state;
    for (z = 0; z < 2; ++z) {
        uint32_t w = sizes[z][0], h = sizes[z][1], R = rs_zsobol_log2_res(w, h);
        assert_int_equal(R, 8);
        for (L = 1; L <= 10; ++L)
            for (t = 0; t < 12; ++t) {
                uint64_t seed = splitmix64(&s);
                uint32_t x = (uint32_t)(splitmix64(&s) % (w / 2)) * 2,
                         y = (uint32_t)(splitmix64(&s) % (h / 2)) * 2,
                         bounce = (uint32_t)(splitmix64(&s) % 50),
                         group = (uint32_t)(splitmix64(&s) % 4), n = 1u << L, i, q;
                char what[96];
                /* pixel (x, y) alone, then the quad it is the corner of */
                for (q = 0; q < 4; ++q)
                    for (i = 0; i < n; ++i) {
                        rs_rng_f4 f = rs_zsobol_float4(seed, x + (q & 1), y + (q >> 1), i,
                                                       (uint32_t)L, R, bounce, group);
                        int j;
                        for (j = 0; j < 4; ++j) {
                            assert_true(f.v[j] >= 0.0f && f.v[j] < 1.0f);
                            p[j][q * n + i] = f.v[j];
                        }
                    }
                snprintf(what, sizeof what, "%ux%u pixel (%u, %u), L %d", w, h, x, y, L);
                expect_net(p[0], p[1], L, what);
                expect_net(p[2], p[3], L, what);
                snprintf(what, sizeof what, "%ux%u quad at (%u, %u), L %d", w, h, x, y, L);
                expect_net(p[0], p[1], L + 2, what);
                expect_net(p[2], p[3], L + 2, what);
            }
    }
}

static void test_uniform_chi_square(void **state)
{
    static double bins[4][100];
    const uint32_t w = 61, h = 64, spp = 256, L = 8, R = rs_zsobol_log2_res(61, 64);
    double n = 0.0;
    uint32_t x, y, i;
    int j;
    (void)state;
    memset(bins, 0, sizeof bins);
    for (y = 0; y < h; ++y)
        for (x = 0; x < w; ++x)
            for (i = 0; i < spp; ++i) {
                rs_rng_f4 f = rs_zsobol_float4(99, x, y, i, L, R, 1, 2);
                for (j = 0; j < 4; ++j)
                    bins[j][(int)(f.v[j] * 100.0f)] += 1.0;
                n += 1.0;
            }
    for (j = 0; j < 4; ++j) {
        double c = chi_square(bins[j], 100, n / 100.0);
        print_message("lane %d, one image: chi-square %.1f (99 dof, 0.01 critical %.1f)\n", j, c,
                      CHI2_99DOF_P01);
        assert_true(c < CHI2_99DOF_P01);
    }
    /* The image's numbers are one net, far more even than random ones (the statistic is far
     * below its mean of 99); so also one number under 10^6 seeds, where it is a random variable
     * of the scrambles alone and the statistic follows the chi-square law: pixel (37, 20),
     * sample 5 of 16, of a 200x120 image. */
    memset(bins, 0, sizeof bins);
    for (i = 0; i < 1000000; ++i) {
        rs_rng_f4 f = rs_zsobol_float4(1000u + i, 37, 20, 5, 4, 8, 1, 2);
        for (j = 0; j < 4; ++j)
            bins[j][(int)(f.v[j] * 100.0f)] += 1.0;
    }
    for (j = 0; j < 4; ++j) {
        double c = chi_square(bins[j], 100, 10000.0);
        print_message("lane %d, 10^6 seeds: chi-square %.1f (99 dof, 0.01 critical %.1f)\n", j, c,
                      CHI2_99DOF_P01);
        assert_true(c < CHI2_99DOF_P01);
    }
}

static rs_rng_f4 z4(uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t group)
{
    return rs_zsobol_float4(5, pixel % 256, pixel / 256, sample, 6, 8, bounce, group);
}

static void test_independence(void **state)
{
    (void)state;
    expect_independent_decisions(z4);
}

static int cmp_u64(const void *a, const void *b)
{
    uint64_t x = *(const uint64_t *)a, y = *(const uint64_t *)b;
    return x < y ? -1 : x > y;
}

/* a point as one number: its two 24-bit coordinates */
static uint64_t point_key(float a, float b)
{
    return ((uint64_t)(a * 16777216.0f) << 24) | (uint64_t)(b * 16777216.0f);
}

static void test_distinct_and_deterministic(void **state)
{
    static uint64_t keys[64 * 64];
    uint32_t x, y, i, n = 0;
    rs_rng_f4 a, b, c;
    (void)state;
    /* 32x32 pixels x 4 samples: the whole image is one block of 2^12 indices, so its points of a
     * pair are 4096 different points (a (0,12,2)-net) */
    for (y = 0; y < 32; ++y)
        for (x = 0; x < 32; ++x)
            for (i = 0; i < 4; ++i) {
                rs_rng_f4 f = rs_zsobol_float4(17, x, y, i, 2, 5, 4, 1);
                keys[n++] = point_key(f.v[2], f.v[3]);
            }
    qsort(keys, n, sizeof keys[0], cmp_u64);
    for (i = 1; i < n; ++i)
        assert_true(keys[i] != keys[i - 1]);
    /* 64x64 pixels, each pixel's first point of the camera pair at 16 spp: all different */
    n = 0;
    for (y = 0; y < 64; ++y)
        for (x = 0; x < 64; ++x) {
            rs_rng_f4 f = rs_zsobol_float4(17, x, y, 0, 4, 6, 0, 0);
            keys[n++] = point_key(f.v[0], f.v[1]);
        }
    qsort(keys, n, sizeof keys[0], cmp_u64);
    for (i = 1; i < n; ++i)
        assert_true(keys[i] != keys[i - 1]);
    /* a pure function: the same bits after other calls; a different seed, other numbers */
    a = rs_zsobol_float4(123456789012345ull, 77, 33, 5, 4, 8, 2, 1);
    (void)rs_zsobol_float4(1, 2, 3, 4, 5, 6, 7, 0);
    b = rs_zsobol_float4(123456789012345ull, 77, 33, 5, 4, 8, 2, 1);
    c = rs_zsobol_float4(123456789012346ull, 77, 33, 5, 4, 8, 2, 1);
    assert_memory_equal(&a, &b, sizeof a);
    assert_true(a.v[0] != c.v[0] && a.v[2] != c.v[2]);
    /* past the render's spp: still numbers in [0, 1), another block than sample % spp */
    b = rs_zsobol_float4(123456789012345ull, 77, 33, 5 + 16, 4, 8, 2, 1);
    assert_true(b.v[0] >= 0.0f && b.v[0] < 1.0f && b.v[0] != a.v[0]);
}

#define IMG 64

/* Per-pixel n-sample estimates of the integral over a 64x64 image (zsobol or sobol, lane pair
 * (v0, v1) of group 1): their mean, their RMSE, and the RMSE of the means of 2x2 pixels. */
static void integrate(int z, uint32_t n, double exact, double *mean, double *rmse_px,
                      double *rmse_quad)
{
    static double e[IMG * IMG];
    double sum = 0.0, sq = 0.0, sq4 = 0.0;
    uint32_t x, y, i, L = rs_ceil_log2(n);
    for (y = 0; y < IMG; ++y)
        for (x = 0; x < IMG; ++x) {
            double v = 0.0;
            for (i = 0; i < n; ++i) {
                rs_rng_f4 f = z ? rs_zsobol_float4(3, x, y, i, L, 6, 0, 1)
                                : rs_sobol_float4(3, y * IMG + x, i, 0, 1);
                v += smooth(f.v[0], f.v[1]);
            }
            v /= n;
            e[y * IMG + x] = v;
            sum += v;
            sq += (v - exact) * (v - exact);
        }
    for (y = 0; y < IMG; y += 2)
        for (x = 0; x < IMG; x += 2) {
            double q = 0.25 * (e[y * IMG + x] + e[y * IMG + x + 1] + e[(y + 1) * IMG + x] +
                               e[(y + 1) * IMG + x + 1]);
            sq4 += (q - exact) * (q - exact);
        }
    *mean = sum / (IMG * IMG);
    *rmse_px = sqrt(sq / (IMG * IMG));
    *rmse_quad = sqrt(sq4 / (IMG * IMG / 4));
}

static void test_converges_and_diffuses_error(void **state)
{
    double exact = smooth_integral(), mz, pz, qz, ms, ps, qs;
    (void)state;
    integrate(1, 64, exact, &mz, &pz, &qz);
    integrate(0, 64, exact, &ms, &ps, &qs);
    print_message("exact %.6f; 64 samples: zsobol mean %.6f pixel rmse %.2e quad rmse %.2e; "
                  "sobol mean %.6f pixel rmse %.2e quad rmse %.2e\n",
                  exact, mz, pz, qz, ms, ps, qs);
    /* unbiased: the image mean within 4.5 standard errors (pixels' errors taken as independent,
     * which overstates the zsobol mean's error: its pixels' errors cancel) */
    assert_true(fabs(mz - exact) < 4.5 * pz / IMG + 1e-7);
    assert_true(pz < 1.5 * ps);
    assert_true(qz < 0.5 * qs);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_helpers),
        cmocka_unit_test(test_digit_permutations),
        cmocka_unit_test(test_index_hierarchy),
        cmocka_unit_test(test_pixels_and_quads_are_nets),
        cmocka_unit_test(test_uniform_chi_square),
        cmocka_unit_test(test_independence),
        cmocka_unit_test(test_distinct_and_deterministic),
        cmocka_unit_test(test_converges_and_diffuses_error),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
