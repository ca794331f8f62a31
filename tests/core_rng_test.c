/* tests/core_rng_test.c — core/rng.h: Philox-4x32-10 keyed by (seed, pixel, sample, bounce, dim).
 *
 * What is checked:
 *   - known answers: the three Philox4x32-10 vectors published with Random123 (kat_vectors);
 *   - purity and key use: the same arguments give the same words; changing any single argument,
 *     the seed's high 32 bits included, changes them; rs_rng_float4 is rs_rng_to_float of the
 *     words;
 *   - uniformity: chi-square of 10^6 floats over 100 bins;
 *   - independence of neighbouring keys (pixel, sample, bounce, dim, seed low and high word) and
 *     of the four lanes of one call: chi-square of a 10 x 10 histogram of 10^5 pairs, and their
 *     Pearson correlation;
 *   - rs_rng_to_float lies in [0, 1), the all-ones word included, in steps of 2^-24.
 *
 * Statistical tests use a fixed seed, so each run is deterministic; the significance level says
 * how unlikely it is that a correct generator fails with the seed chosen here (1 in 100 for each
 * chi-square test at 0.01). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/rng.h"

/* Chi-square critical value for 99 degrees of freedom at significance 0.01 (upper tail). */
#define CHI2_99DOF_P01 134.642

#define TEST_SEED 0x0123456789abcdefull

#include "test_rand.h"

static int same_words(rs_rng_out a, rs_rng_out b) { return memcmp(a.v, b.v, sizeof a.v) == 0; }

/* ---- known answers --------------------------------------------------------------------------- */

static void expect_philox(const uint32_t c[4], const uint32_t k[2], const uint32_t want[4])
{
    rs_rng_out got = rs_philox4x32_10(c[0], c[1], c[2], c[3], k[0], k[1]);
    int i;
    for (i = 0; i < 4; ++i)
        if (got.v[i] != want[i])
            fail_msg("philox(ctr %08x %08x %08x %08x, key %08x %08x) word %d: got %08x, want %08x",
                     c[0], c[1], c[2], c[3], k[0], k[1], i, got.v[i], want[i]);
}

static void test_philox_known_answers(void **state)
{
    /* Random123 1.09, tests/kat_vectors: "philox4x32 10 ctr key expected" */
    static const uint32_t c0[4] = {0, 0, 0, 0}, k0[2] = {0, 0};
    static const uint32_t r0[4] = {0x6627e8d5u, 0xe169c58du, 0xbc57ac4cu, 0x9b00dbd8u};
    static const uint32_t c1[4] = {0xffffffffu, 0xffffffffu, 0xffffffffu, 0xffffffffu};
    static const uint32_t k1[2] = {0xffffffffu, 0xffffffffu};
    static const uint32_t r1[4] = {0x408f276du, 0x41c83b0eu, 0xa20bc7c6u, 0x6d5451fdu};
    static const uint32_t c2[4] = {0x243f6a88u, 0x85a308d3u, 0x13198a2eu, 0x03707344u};
    static const uint32_t k2[2] = {0xa4093822u, 0x299f31d0u};
    static const uint32_t r2[4] = {0xd16cfe09u, 0x94fdccebu, 0x5001e420u, 0x24126ea1u};
    (void)state;
    expect_philox(c0, k0, r0);
    expect_philox(c1, k1, r1);
    expect_philox(c2, k2, r2);
}

static void test_mulhilo(void **state)
{
    uint32_t hi;
    (void)state;
    assert_true(rs_mulhilo32(0xffffffffu, 0xffffffffu, &hi) == 0x00000001u);
    assert_true(hi == 0xfffffffeu);
    assert_true(rs_mulhilo32(0xD2511F53u, 2u, &hi) == 0xA4A23EA6u);
    assert_true(hi == 1u);
}

/* ---- purity and the use of every key field ------------------------------------------------- */

static void test_pure_and_keyed(void **state)
{
    uint64_t s = 42;
    int i;
    (void)state;
    for (i = 0; i < 10000; ++i) {
        uint64_t seed = splitmix64(&s);
        uint32_t w = (uint32_t)splitmix64(&s);
        uint32_t p = w, smp = w >> 7, b = w & 15u, d = (w >> 4) & 3u;
        rs_rng_out base = rs_rng_u32x4(seed, p, smp, b, d);
        rs_rng_f4 f = rs_rng_float4(seed, p, smp, b, d);
        int k;
        /* a pure function: no hidden state */
        assert_true(same_words(base, rs_rng_u32x4(seed, p, smp, b, d)));
        for (k = 0; k < 4; ++k)
            assert_true(f.v[k] == rs_rng_to_float(base.v[k]));
        /* every argument reaches the output */
        assert_false(same_words(base, rs_rng_u32x4(seed ^ 1u, p, smp, b, d)));
        assert_false(same_words(base, rs_rng_u32x4(seed ^ (1ull << 32), p, smp, b, d)));
        assert_false(same_words(base, rs_rng_u32x4(seed ^ (1ull << 63), p, smp, b, d)));
        assert_false(same_words(base, rs_rng_u32x4(seed, p + 1u, smp, b, d)));
        assert_false(same_words(base, rs_rng_u32x4(seed, p, smp + 1u, b, d)));
        assert_false(same_words(base, rs_rng_u32x4(seed, p, smp, b + 1u, d)));
        assert_false(same_words(base, rs_rng_u32x4(seed, p, smp, b, d + 1u)));
        /* swapping two counter fields gives another stream (no symmetric mixing) */
        if (p != smp)
            assert_false(same_words(base, rs_rng_u32x4(seed, smp, p, b, d)));
    }
}

/* ---- floats --------------------------------------------------------------------------------- */

static void test_float_range(void **state)
{
    uint64_t s = 7;
    float prev = -1.0f;
    uint32_t u;
    int i;
    (void)state;
    assert_true(rs_rng_to_float(0u) == 0.0f);
    assert_true(rs_rng_to_float(0xffffffffu) < 1.0f);
    assert_true(rs_rng_to_float(0xffffffffu) == 1.0f - 0x1.0p-24f);
    assert_true(rs_rng_to_float(0xffffff00u) == rs_rng_to_float(0xffffffffu));
    assert_true(rs_rng_to_float(0x80000000u) == 0.5f);
    assert_true(rs_rng_to_float(0x100u) == 0x1.0p-24f);
    assert_true(rs_rng_to_float(0xffu) == 0.0f);
    /* monotone in the word, over a sweep of the top bits */
    for (u = 0; u < 0xffffffu; u += 0x1357u) {
        float f = rs_rng_to_float(u << 8);
        assert_true(f > prev);
        assert_true(f == (float)u * 0x1.0p-24f);
        prev = f;
    }
    for (i = 0; i < 1000000; ++i) {
        float f = rs_rng_to_float((uint32_t)splitmix64(&s));
        assert_true(f >= 0.0f && f < 1.0f);
    }
}

/* ---- uniformity ----------------------------------------------------------------------------- */

static void test_uniform_chi_square(void **state)
{
    /* 10^6 floats: the four lanes of 250000 consecutive pixels.  H0: uniform on [0, 1).
     * 100 equiprobable bins, 10^4 expected per bin, 99 degrees of freedom; reject at 0.01 when
     * X² > 134.64.  Also sanity-check the mean (sd of the mean = 1/sqrt(12 n) = 2.9e-4; a 6 sd
     * bound fails a correct generator with probability < 1e-8). */
    enum { N_CALLS = 250000, BINS = 100 };
    double hist[BINS] = {0}, sum = 0.0, x2;
    uint32_t i;
    int k;
    (void)state;
    for (i = 0; i < N_CALLS; ++i) {
        rs_rng_f4 f = rs_rng_float4(TEST_SEED, i, 3, 1, 0);
        for (k = 0; k < 4; ++k) {
            int bin = (int)(f.v[k] * BINS);
            assert_true(f.v[k] >= 0.0f && f.v[k] < 1.0f);
            hist[bin] += 1.0;
            sum += f.v[k];
        }
    }
    x2 = chi_square(hist, BINS, 4.0 * N_CALLS / BINS);
    print_message("uniformity: X^2 = %.2f (99 dof, critical %.2f at 0.01), mean %.6f\n", x2,
                  CHI2_99DOF_P01, sum / (4.0 * N_CALLS));
    assert_true(x2 < CHI2_99DOF_P01);
    assert_true(fabs(sum / (4.0 * N_CALLS) - 0.5) < 6.0 / sqrt(12.0 * 4.0 * N_CALLS));
}

/* ---- independence --------------------------------------------------------------------------- */

enum {
    FIELD_PIXEL,
    FIELD_SAMPLE,
    FIELD_BOUNCE,
    FIELD_DIM,
    FIELD_SEED_LO,
    FIELD_SEED_HI,
    FIELD_LANES
};

static const char *field_name(int f)
{
    static const char *names[] = {"pixel",
                                  "sample",
                                  "bounce",
                                  "dim",
                                  "seed (low word)",
                                  "seed (high word)",
                                  "lane 0 vs lane 1..3"};
    return names[f];
}

/* 10^5 pairs (x, y): x from a random base key, y from the same key with `field` + 1 (or, for
 * FIELD_LANES, another lane of the same call), each pair's lane chosen in turn.
 *
 * Under H0 (x, y independent uniforms):
 *   - the 10 x 10 histogram has 1000 expected per cell, X² ~ chi-square(99); reject at 0.01
 *     when X² > 134.64;
 *   - Pearson's r is approximately normal with sd 1/sqrt(n) = 0.00316; |r| < 5/sqrt(n) fails a
 *     correct generator with probability 5.7e-7 (a five-sigma bound), while a linear dependence
 *     as weak as r = 0.016 is caught. */
static void check_pair_independence(int field)
{
    enum { N = 100000, B = 10 };
    static double hist[B * B];
    uint64_t s = 0xfeedbeefu + (uint64_t)field;
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0, x2, r, cov, bound = 5.0 / sqrt((double)N);
    int i;
    memset(hist, 0, sizeof hist);
    for (i = 0; i < N; ++i) {
        uint64_t seed = splitmix64(&s), w = splitmix64(&s);
        uint32_t p = (uint32_t)w, smp = (uint32_t)(w >> 32) & 0xffffu;
        uint32_t b = (uint32_t)(w >> 48) & 0xffu, d = (uint32_t)(w >> 56) & 0xfu;
        uint32_t lane = (uint32_t)i & 3u;
        rs_rng_out a = rs_rng_u32x4(seed, p, smp, b, d), c;
        double x, y;
        switch (field) {
        case FIELD_PIXEL: c = rs_rng_u32x4(seed, p + 1u, smp, b, d); break;
        case FIELD_SAMPLE: c = rs_rng_u32x4(seed, p, smp + 1u, b, d); break;
        case FIELD_BOUNCE: c = rs_rng_u32x4(seed, p, smp, b + 1u, d); break;
        case FIELD_DIM: c = rs_rng_u32x4(seed, p, smp, b, d + 1u); break;
        case FIELD_SEED_LO: c = rs_rng_u32x4(seed + 1u, p, smp, b, d); break;
        case FIELD_SEED_HI: c = rs_rng_u32x4(seed + (1ull << 32), p, smp, b, d); break;
        default: c = a; break;
        }
        x = rs_rng_to_float(a.v[field == FIELD_LANES ? 0u : lane]);
        y = rs_rng_to_float(c.v[field == FIELD_LANES ? 1u + (uint32_t)i % 3u : lane]);
        hist[(int)(x * B) * B + (int)(y * B)] += 1.0;
        sx += x;
        sy += y;
        sxx += x * x;
        syy += y * y;
        sxy += x * y;
    }
    x2 = chi_square(hist, B * B, (double)N / (B * B));
    cov = sxy / N - (sx / N) * (sy / N);
    r = cov / sqrt((sxx / N - (sx / N) * (sx / N)) * (syy / N - (sy / N) * (sy / N)));
    print_message("%-20s X^2 = %7.2f (critical %.2f), r = %+.5f (bound %.5f)\n", field_name(field),
                  x2, CHI2_99DOF_P01, r, bound);
    if (!(x2 < CHI2_99DOF_P01))
        fail_msg("%s neighbours: 2D chi-square %.2f >= %.2f", field_name(field), x2,
                 CHI2_99DOF_P01);
    if (!(fabs(r) < bound))
        fail_msg("%s neighbours: correlation %.5f, bound %.5f", field_name(field), r, bound);
}

static void test_independent_pixel(void **state)
{
    (void)state;
    check_pair_independence(0);
}
static void test_independent_sample(void **state)
{
    (void)state;
    check_pair_independence(1);
}
static void test_independent_bounce(void **state)
{
    (void)state;
    check_pair_independence(2);
}
static void test_independent_dim(void **state)
{
    (void)state;
    check_pair_independence(3);
}
static void test_independent_seed_lo(void **state)
{
    (void)state;
    check_pair_independence(4);
}
static void test_independent_seed_hi(void **state)
{
    (void)state;
    check_pair_independence(5);
}
static void test_independent_lanes(void **state)
{
    (void)state;
    check_pair_independence(6);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_philox_known_answers), cmocka_unit_test(test_mulhilo),
        cmocka_unit_test(test_pure_and_keyed),       cmocka_unit_test(test_float_range),
        cmocka_unit_test(test_uniform_chi_square),   cmocka_unit_test(test_independent_pixel),
        cmocka_unit_test(test_independent_sample),   cmocka_unit_test(test_independent_bounce),
        cmocka_unit_test(test_independent_dim),      cmocka_unit_test(test_independent_seed_lo),
        cmocka_unit_test(test_independent_seed_hi),  cmocka_unit_test(test_independent_lanes),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
