/* tests/core_sobol_test.c — core/sobol.h: padded, Owen-scrambled, shuffled 2D Sobol points.
 *
 * What is checked:
 *   - the generator: dimensions 0 and 1 equal the XOR of Sobol direction numbers made here from
 *     the primitive polynomial's recurrence (Bratley and Fox 1988), on every index below 2^16 and
 *     on random 32-bit indices;
 *   - the shuffle: the nested uniform scramble of the indices [0, 2^k) is a permutation of one
 *     aligned block of 2^k indices (so each power-of-two prefix is a whole Sobol block);
 *   - stratification: for random (seed, pixel, bounce, group), the first 2^m samples (m = 1..10)
 *     of each pair put exactly one point in every elementary interval of area 2^-m, for every
 *     split of m into a + b (a (0,m,2)-net);
 *   - uniformity and independence: chi-square of 10^6 numbers of each lane over 100 bins, and
 *     of 10 x 10 histograms of the two pairs of one call, of two groups and of neighbouring
 *     pixels, at significance 0.01;
 *   - convergence: integrating a smooth 2D function over 256 pixels' independent scrambles, the
 *     mean is within 4.5 standard errors of the exact value and the RMSE at 1024 samples is
 *     below a quarter of the independent sampler's (which falls as N^-1/2; Owen-scrambled nets
 *     as about N^-3/4 or faster for smooth integrands).
 * Fixed seeds: every run is the same. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/sobol.h"
#include "test_rand.h"
#include "test_sampler.h"


/* Dimension `dim` (0 or 1) of point `index` from the direction numbers themselves. */
static uint32_t sobol_reference(uint32_t index, int dim)
{
    uint32_t v[33], x = 0;
    int k;
    for (k = 1; k <= 32; ++k)
        v[k] = dim == 0 ? 1u << (32 - k) /* van der Corput */
               : k == 1 ? 0x80000000u    /* x + 1: m_1 = 1, v_k = v_(k-1) ^ (v_(k-1) >> 1) */
                        : v[k - 1] ^ (v[k - 1] >> 1);
    for (k = 1; k <= 32; ++k)
        if (index & (1u << (k - 1)))
            x ^= v[k];
    return x;
}

static void test_generator_matches_direction_numbers(void **state)
{
    uint64_t s = 7;
    uint32_t i;
    int d;
    (void)state;
    /* Sobol's second dimension in index order (not Gray-code order): 0, 1/2, 3/4, 1/4, 5/8,
     * 1/8, 3/8, 7/8 */
    assert_true(rs_sobol_u32(2, 1) == 0xc0000000u && rs_sobol_u32(4, 1) == 0xa0000000u);
    assert_true(rs_sobol_u32(5, 1) == 0x20000000u && rs_sobol_u32(7, 1) == 0xe0000000u);
    for (d = 0; d < 2; ++d) {
        for (i = 0; i < 65536; ++i)
            if (rs_sobol_u32(i, (uint32_t)d) != sobol_reference(i, d))
                fail_msg("dimension %d, index %u: %08x, want %08x", d, i,
                         rs_sobol_u32(i, (uint32_t)d), sobol_reference(i, d));
        for (i = 0; i < 100000; ++i) {
            uint32_t x = (uint32_t)splitmix64(&s);
            assert_true(rs_sobol_u32(x, (uint32_t)d) == sobol_reference(x, d));
        }
    }
}

static void test_shuffle_keeps_blocks(void **state)
{
    static unsigned char seen[1u << 12];
    uint64_t s = 11;
    int k, t;
    (void)state;
    for (t = 0; t < 50; ++t) {
        uint32_t seed = (uint32_t)splitmix64(&s);
        for (k = 0; k <= 12; ++k) {
            uint32_t n = 1u << k, i, high = rs_nested_uniform_scramble(0, seed) >> k;
            memset(seen, 0, n);
            for (i = 0; i < n; ++i) {
                uint32_t x = rs_nested_uniform_scramble(i, seed);
                assert_true((x >> k) == high);   /* one aligned block */
                assert_false(seen[x & (n - 1)]); /* a permutation of it */
                seen[x & (n - 1)] = 1;
            }
        }
    }
}

static void test_pairs_are_nets(void **state)
{
    static float p[4][1u << 10];
    uint64_t s = 13;
    int t, m;
    (void)state;
    for (t = 0; t < 40; ++t) {
        uint64_t seed = splitmix64(&s);
        uint32_t pixel = (uint32_t)splitmix64(&s), bounce = (uint32_t)(splitmix64(&s) % 50),
                 group = (uint32_t)(splitmix64(&s) % 4), i;
        for (i = 0; i < (1u << 10); ++i) {
            rs_rng_f4 f = rs_sobol_float4(seed, pixel, i, bounce, group);
            int j;
            for (j = 0; j < 4; ++j)
                p[j][i] = f.v[j];
        }
        for (m = 1; m <= 10; ++m) {
            expect_net(p[0], p[1], m, "pair (v0, v1)");
            expect_net(p[2], p[3], m, "pair (v2, v3)");
        }
    }
}

static void test_uniform_chi_square(void **state)
{
    static double bins[4][100];
    const uint32_t n = 1000000;
    uint32_t i;
    int j;
    (void)state;
    memset(bins, 0, sizeof bins);
    /* 3907 pixels x 256 samples: whole nets per pixel, independent scrambles across pixels */
    for (i = 0; i < n; ++i) {
        rs_rng_f4 f = rs_sobol_float4(99, i / 256, i % 256, 1, 2);
        for (j = 0; j < 4; ++j) {
            assert_true(f.v[j] >= 0.0f && f.v[j] < 1.0f);
            bins[j][(int)(f.v[j] * 100.0f)] += 1.0;
        }
    }
    for (j = 0; j < 4; ++j) {
        double c = chi_square(bins[j], 100, n / 100.0);
        print_message("lane %d: chi-square %.1f (99 dof, 0.01 critical %.1f)\n", j, c,
                      CHI2_99DOF_P01);
        assert_true(c < CHI2_99DOF_P01);
    }
}

static rs_rng_f4 sobol5(uint32_t pixel, uint32_t sample, uint32_t bounce, uint32_t group)
{
    return rs_sobol_float4(5, pixel, sample, bounce, group);
}

static void test_independence(void **state)
{
    (void)state;
    expect_independent_decisions(sobol5);
}

/* Mean and RMSE over 256 pixels of the n-sample estimate of the integral. */
static void integrate(int sobol, uint32_t n, double exact, double *mean, double *rmse_out)
{
    double sum = 0.0, sq = 0.0;
    uint32_t px, i;
    for (px = 0; px < 256; ++px) {
        double e = 0.0;
        for (i = 0; i < n; ++i) {
            rs_rng_f4 f = sobol ? rs_sobol_float4(3, px, i, 0, 1) : rs_rng_float4(3, px, i, 0, 1);
            e += smooth(f.v[0], f.v[1]);
        }
        e /= n;
        sum += e;
        sq += (e - exact) * (e - exact);
    }
    *mean = sum / 256.0;
    *rmse_out = sqrt(sq / 256.0);
}

static void test_converges_faster(void **state)
{
    double exact = smooth_integral(), m_s, r_s, m_i, r_i, m64, r64;
    (void)state;
    integrate(1, 1024, exact, &m_s, &r_s);
    integrate(0, 1024, exact, &m_i, &r_i);
    integrate(1, 64, exact, &m64, &r64);
    print_message("exact %.6f; 1024 samples: sobol mean %.6f rmse %.2e, independent mean %.6f "
                  "rmse %.2e; sobol 64 samples rmse %.2e\n",
                  exact, m_s, r_s, m_i, r_i, r64);
    /* unbiased: the mean over 256 independent scrambles within 4.5 standard errors */
    assert_true(fabs(m_s - exact) < 4.5 * r_s / sqrt(256.0) + 1e-7);
    assert_true(fabs(m_i - exact) < 4.5 * r_i / sqrt(256.0));
    assert_true(r_s < 0.25 * r_i);
    /* 16x the samples: at least 6x less error (N^-1/2 would give 4x) */
    assert_true(r_s < r64 / 6.0);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_generator_matches_direction_numbers),
        cmocka_unit_test(test_shuffle_keeps_blocks),
        cmocka_unit_test(test_pairs_are_nets),
        cmocka_unit_test(test_uniform_chi_square),
        cmocka_unit_test(test_independence),
        cmocka_unit_test(test_converges_faster),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
