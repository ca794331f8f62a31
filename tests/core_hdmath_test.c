/* tests/core_hdmath_test.c — core/hdmath.h against glibc's double functions rounded to float.
 *
 * What is checked:
 *   - each function's distance, in floats (ulp of the correctly rounded result), from the
 *     double-precision libm value rounded to float, over dense sweeps: every 127th float bit
 *     pattern of either sign (denormals to the largest float), 4M random arguments in the
 *     shading's ranges, the floats nearest to k pi/2 for every k < 2^15 with their neighbours
 *     (where the reduction cancels most), |x| near 1 for acos and log, the Phong exponents and
 *     negative ones for pow, random pairs over all magnitudes and the axes for atan2.  The
 *     largest distance must not pass the function's RS_HDM_BOUND_* below: the maximum measured
 *     over every float (RS_HDMATH_EXHAUSTIVE=1 in the environment sweeps every bit pattern of
 *     the one-argument functions, several minutes) plus one ulp of margin.  Each prints its
 *     maximum and where it was reached;
 *   - C99's special values: zeros of both signs, infinities, NaNs, pow's x = 0, x = 1, y = 0,
 *     negative x with integer y, atan2's axes and quadrants, expf's overflow to inf at
 *     88.7228394 and underflow to 0, acos and log outside their domains;
 *   - identities that hold bit for bit by construction: sin(-x) = -sin x, cos(-x) = cos x,
 *     tan(-x) = -tan x, atan2(-y, x) = -atan2(y, x), rs_sincosf = (rs_sinf, rs_cosf); and
 *     sin^2 + cos^2 within 2^-22 of 1. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/hdmath.h"

#include "test_rand.h"

/* Bounds, in ulp: the maximum over every float (RS_HDMATH_EXHAUSTIVE=1) plus one. */
#define RS_HDM_BOUND_SIN   2
#define RS_HDM_BOUND_COS   2
#define RS_HDM_BOUND_TAN   3
#define RS_HDM_BOUND_EXP   2
#define RS_HDM_BOUND_LOG   1
#define RS_HDM_BOUND_POW   1
#define RS_HDM_BOUND_ACOS  2
#define RS_HDM_BOUND_ATAN2 2

/* ---- ulp bookkeeping ------------------------------------------------------------------------- */

static uint32_t f2u(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static float u2f(uint32_t u)
{
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
}

/* floats in order as integers: -0 and +0 both 0, neighbours one apart, inf next to FLT_MAX */
static int64_t ord(float f)
{
    int32_t i = (int32_t)f2u(f);
    return i >= 0 ? (int64_t)i : (int64_t)INT32_MIN - (int64_t)i;
}

typedef struct ulp_stats {
    const char *name;
    int64_t max;      /* largest distance seen */
    float at_x, at_y; /* where */
    float got, want;
    uint64_t n;         /* arguments checked */
    uint64_t nan_wrong; /* NaN where libm has a number or the other way round */
} ulp_stats;

static void note(ulp_stats *st, float x, float y, float got, double ref)
{
    float want = (float)ref;
    int64_t d;
    st->n++;
    if (isnan(want) || isnan(got)) {
        if (isnan(want) != isnan(got)) {
            if (st->nan_wrong++ == 0)
                print_message("%s(%a, %a): got %a, want %a\n", st->name, x, y, got, want);
        }
        return;
    }
    d = ord(got) - ord(want);
    if (d < 0)
        d = -d;
    if (d > st->max) {
        st->max = d;
        st->at_x = x;
        st->at_y = y;
        st->got = got;
        st->want = want;
    }
}

static void report(const ulp_stats *st, int64_t bound)
{
    print_message("%-6s max %lld ulp (bound %lld) over %llu arguments, at (%.9g, %.9g): got %.9g, "
                  "want %.9g\n",
                  st->name, (long long)st->max, (long long)bound, (unsigned long long)st->n,
                  (double)st->at_x, (double)st->at_y, (double)st->got, (double)st->want);
    assert_int_equal(st->nan_wrong, 0);
    if (st->max > bound)
        fail_msg("%s: %lld ulp past the bound %lld", st->name, (long long)st->max,
                 (long long)bound);
}

static int exhaustive(void)
{
    const char *e = getenv("RS_HDMATH_EXHAUSTIVE");
    return e && e[0] == '1';
}

/* Every `stride`-th bit pattern of positive finite floats (offset by `phase`), and its negation:
 * the whole range, denormals included; every float with stride 1. */
#define SWEEP_BITS(u, stride, phase)                                                               \
  for (uint64_t u##_i = (phase); u##_i < 0x7f800000u; u##_i += (stride))                           \
    for (int u##_s = 0; u##_s < 2; ++u##_s)                                                        \
      for (uint32_t u = (uint32_t)u##_i | (u##_s ? 0x80000000u : 0u), u##_once = 1; u##_once;      \
           u##_once = 0)

static uint32_t sweep_stride(void) { return exhaustive() ? 1u : 127u; }

/* ---- sine, cosine, tangent ------------------------------------------------------------------- */

static void check_sin_cos_tan(ulp_stats *s, ulp_stats *c, ulp_stats *t, float x)
{
    float sv = rs_sinf(x), cv = rs_cosf(x), tv = rs_tanf(x), ss, cc;
    rs_sincosf(x, &ss, &cc);
    if (f2u(ss) != f2u(sv) || f2u(cc) != f2u(cv))
        fail_msg("rs_sincosf(%a) = (%a, %a), rs_sinf, rs_cosf = (%a, %a)", x, ss, cc, sv, cv);
    if (f2u(rs_sinf(-x)) != (f2u(sv) ^ 0x80000000u) || f2u(rs_cosf(-x)) != f2u(cv) ||
        f2u(rs_tanf(-x)) != (f2u(tv) ^ 0x80000000u))
        fail_msg("symmetry at %a", x);
    note(s, x, 0.0f, sv, sin((double)x));
    note(c, x, 0.0f, cv, cos((double)x));
    note(t, x, 0.0f, tv, tan((double)x));
    if (isfinite(x) && fabs((double)sv * sv + (double)cv * cv - 1.0) > 0x1p-22)
        fail_msg("sin^2 + cos^2 - 1 = %g at %a", (double)sv * sv + (double)cv * cv - 1.0, x);
}

static void test_sin_cos_tan(void **state)
{
    ulp_stats s = {.name = "sin"}, c = {.name = "cos"}, t = {.name = "tan"};
    uint64_t rng = 1;
    uint32_t stride = sweep_stride();
    int i, k, j;
    (void)state;
    SWEEP_BITS(u, stride, 0) check_sin_cos_tan(&s, &c, &t, u2f(u));
    for (i = 0; i < 4000000; ++i) /* the shading's angles: 2 pi u, the lens, rotations */
        check_sin_cos_tan(&s, &c, &t, rnd_range(&rng, -7.0, 7.0));
    for (i = 0; i < 1000000; ++i)
        check_sin_cos_tan(&s, &c, &t, rnd_range(&rng, -5000.0, 5000.0));
    /* the floats nearest k pi/2, where x - k pi/2 cancels most, and their neighbours */
    for (k = 1; k < 32768; ++k) {
        uint32_t b = f2u((float)(k * 1.5707963267948966));
        for (j = -3; j <= 3; ++j)
            check_sin_cos_tan(&s, &c, &t, u2f(b + (uint32_t)j));
    }
    /* specials */
    assert_true(f2u(rs_sinf(0.0f)) == 0u && f2u(rs_sinf(-0.0f)) == 0x80000000u);
    assert_true(rs_cosf(0.0f) == 1.0f && rs_cosf(-0.0f) == 1.0f);
    assert_true(f2u(rs_tanf(-0.0f)) == 0x80000000u);
    assert_true(rs_sinf(0x1p-149f) == 0x1p-149f && rs_sinf(-0x1p-140f) == -0x1p-140f);
    assert_true(isnan(rs_sinf(INFINITY)) && isnan(rs_cosf(-INFINITY)) && isnan(rs_tanf(NAN)));
    {
        float ss, cc;
        rs_sincosf(INFINITY, &ss, &cc);
        assert_true(isnan(ss) && isnan(cc));
    }
    report(&s, RS_HDM_BOUND_SIN);
    report(&c, RS_HDM_BOUND_COS);
    report(&t, RS_HDM_BOUND_TAN);
}

/* ---- exp and log ----------------------------------------------------------------------------- */

static void test_exp(void **state)
{
    ulp_stats e = {.name = "exp"};
    uint64_t rng = 2;
    uint32_t stride = sweep_stride();
    int i;
    (void)state;
    SWEEP_BITS(u, stride, 3) note(&e, u2f(u), 0.0f, rs_expf(u2f(u)), exp((double)u2f(u)));
    for (i = 0; i < 4000000; ++i) { /* Beer-Lambert's -sigma len, the sheen's exponents */
        float x = rnd_range(&rng, -30.0, 5.0);
        note(&e, x, 0.0f, rs_expf(x), exp((double)x));
    }
    for (i = 0; i < 1000000; ++i) { /* the whole range, overflow and subnormal results */
        float x = rnd_range(&rng, -110.0, 95.0);
        note(&e, x, 0.0f, rs_expf(x), exp((double)x));
    }
    /* overflow exactly where expf's does, underflow to 0 */
    assert_true(isfinite(rs_expf(88.7228317f)) && isfinite(expf(88.7228317f)) &&
                rs_expf(nextafterf(88.7228317f, INFINITY)) == INFINITY &&
                expf(nextafterf(88.7228317f, INFINITY)) == INFINITY);
    assert_true(rs_expf(1000.0f) == INFINITY && rs_expf(INFINITY) == INFINITY);
    assert_true(rs_expf(-104.0f) == 0.0f && rs_expf(-INFINITY) == 0.0f);
    assert_true(rs_expf(-103.9f) == 0x1p-149f);
    assert_true(rs_expf(0.0f) == 1.0f && rs_expf(-0.0f) == 1.0f && isnan(rs_expf(NAN)));
    assert_true(rs_expf(0x1p-30f) == 1.0f && rs_expf(-0x1p-30f) == 1.0f);
    report(&e, RS_HDM_BOUND_EXP);
}

static void test_log(void **state)
{
    ulp_stats l = {.name = "log"};
    uint32_t stride = sweep_stride(), u;
    (void)state;
    SWEEP_BITS(b, stride, 5) note(&l, u2f(b), 0.0f, rs_logf(u2f(b)), log((double)u2f(b)));
    for (u = f2u(0.5f); u < f2u(2.0f); u += 7) /* near 1: every 7th float of [1/2, 2) */
        note(&l, u2f(u), 0.0f, rs_logf(u2f(u)), log((double)u2f(u)));
    assert_true(rs_logf(1.0f) == 0.0f && f2u(rs_logf(1.0f)) == 0u);
    assert_true(rs_logf(0.0f) == -INFINITY && rs_logf(-0.0f) == -INFINITY);
    assert_true(isnan(rs_logf(-1.0f)) && isnan(rs_logf(-INFINITY)) && isnan(rs_logf(NAN)));
    assert_true(rs_logf(INFINITY) == INFINITY && rs_logf(0x1p-149f) == logf(0x1p-149f));
    report(&l, RS_HDM_BOUND_LOG);
}

/* ---- pow ------------------------------------------------------------------------------------- */

static void test_pow(void **state)
{
    static const float ys[] = {0.5f,  1.0f,  2.0f,   3.0f,    0.2f,     1.0f / 3.0f, 5.5f,
                               10.0f, 64.0f, 100.0f, 1000.0f, 10000.0f, 12345.6f,    -1.0f,
                               -2.0f, -0.5f, -2.5f,  -10.0f,  -100.0f,  -3.0f,       0.19823f};
    ulp_stats p = {.name = "pow"};
    uint64_t rng = 3;
    uint32_t stride = exhaustive() ? 61u : 997u;
    size_t k;
    int i;
    (void)state;
    for (k = 0; k < sizeof ys / sizeof ys[0]; ++k) {
        float y = ys[k];
        uint32_t u;
        for (u = 0; u < 0x7f800000u; u += stride) /* every x > 0, with stride */
            note(&p, u2f(u), y, rs_powf(u2f(u), y), pow((double)u2f(u), (double)y));
    }
    for (i = 0; i < 3000000; ++i) { /* Phong: cos in [0, 1], exponents up to 10^4 */
        float x = (float)rnd01(&rng), y = rnd_range(&rng, 0.0, i % 3 ? 100.0 : 10000.0);
        note(&p, x, y, rs_powf(x, y), pow((double)x, (double)y));
    }
    for (i = 0; i < 1000000; ++i) { /* sampling: u^(1/(n+1)); and any x with y in [-20, 20] */
        float x = (float)rnd01(&rng), y = 1.0f / (rnd_range(&rng, 0.0, 10000.0) + 1.0f);
        note(&p, x, y, rs_powf(x, y), pow((double)x, (double)y));
        x = u2f((uint32_t)(splitmix64(&rng) % 0x7f800000u));
        y = rnd_range(&rng, -20.0, 20.0);
        note(&p, x, y, rs_powf(x, y), pow((double)x, (double)y));
    }
    for (i = 0; i < 200000; ++i) { /* negative x with integer and other y */
        float x = -rnd_range(&rng, 0.0, 4.0), y = (float)(int)rnd_range(&rng, -40.0, 40.0);
        note(&p, x, y, rs_powf(x, y), pow((double)x, (double)y));
        y += 0.5f;
        note(&p, x, y, rs_powf(x, y), pow((double)x, (double)y));
    }
    /* C99's special cases, compared with glibc's powf bit for bit */
    {
        static const float sv[] = {0.0f,  -0.0f,    1.0f,        -1.0f,      0.5f,
                                   -0.5f, 2.0f,     -2.0f,       3.0f,       -3.0f,
                                   0.1f,  INFINITY, -INFINITY,   NAN,        0x1p-149f,
                                   1e30f, -1e30f,   16777216.0f, 33554434.0f};
        size_t a, b;
        for (a = 0; a < sizeof sv / sizeof sv[0]; ++a)
            for (b = 0; b < sizeof sv / sizeof sv[0]; ++b) {
                float x = sv[a], y = sv[b], got = rs_powf(x, y), want = powf(x, y);
                if (isnan(want) ? !isnan(got) : f2u(got) != f2u(want))
                    fail_msg("rs_powf(%a, %a) = %a, powf = %a", x, y, got, want);
            }
    }
    assert_true(rs_powf(0.0f, 10000.0f) == 0.0f && rs_powf(0.0f, -1.0f) == INFINITY);
    assert_true(rs_powf(1.0f, NAN) == 1.0f && rs_powf(NAN, 0.0f) == 1.0f);
    report(&p, RS_HDM_BOUND_POW);
}

/* ---- acos and atan2 ------------------------------------------------------------------------- */

static void test_acos(void **state)
{
    ulp_stats a = {.name = "acos"};
    uint32_t stride = exhaustive() ? 1u : 31u, u;
    int s;
    (void)state;
    for (s = 0; s < 2; ++s)
        for (u = 0; u <= f2u(1.0f); u += (u > f2u(0.999f) ? 1 : stride)) {
            float x = u2f(u | (s ? 0x80000000u : 0u));
            note(&a, x, 0.0f, rs_acosf(x), acos((double)x));
        }
    for (u = f2u(0.49f); u < f2u(0.51f); ++u) { /* both sides of the switch at 1/2 */
        note(&a, u2f(u), 0.0f, rs_acosf(u2f(u)), acos((double)u2f(u)));
        note(&a, -u2f(u), 0.0f, rs_acosf(-u2f(u)), acos(-(double)u2f(u)));
    }
    assert_true(f2u(rs_acosf(1.0f)) == 0u && rs_acosf(-1.0f) == (float)3.14159265358979323846);
    assert_true(rs_acosf(0.0f) == (float)1.57079632679489661923 &&
                rs_acosf(-0.0f) == (float)1.57079632679489661923);
    assert_true(isnan(rs_acosf(1.0000001f)) && isnan(rs_acosf(-2.0f)) &&
                isnan(rs_acosf(INFINITY)) && isnan(rs_acosf(NAN)));
    report(&a, RS_HDM_BOUND_ACOS);
}

static void check_atan2(ulp_stats *a, float y, float x)
{
    float got = rs_atan2f(y, x);
    if (!isnan(y) && !isnan(x) && f2u(rs_atan2f(-y, x)) != (f2u(got) ^ 0x80000000u))
        fail_msg("atan2(-y, x) != -atan2(y, x) at (%a, %a)", y, x);
    note(a, y, x, got, atan2((double)y, (double)x));
}

static void test_atan2(void **state)
{
    static const float sv[] = {0.0f,      -0.0f, 1.0f,   -1.0f,      0x1p-149f, -0x1p-149f,
                               0x1p-126f, 3.0f,  -7.5f,  3.4e38f,    -3.4e38f,  INFINITY,
                               -INFINITY, NAN,   1e-30f, 0.41421356f};
    ulp_stats a = {.name = "atan2"};
    uint64_t rng = 4;
    size_t i, j;
    int n;
    (void)state;
    for (n = 0; n < 4000000; ++n) { /* directions: unit vectors' components */
        float y = rnd_range(&rng, -1.0, 1.0), x = rnd_range(&rng, -1.0, 1.0);
        check_atan2(&a, y, x);
    }
    for (n = 0; n < 2000000; ++n) { /* any finite magnitudes, near the octant lines too */
        float y = u2f((uint32_t)(splitmix64(&rng) % 0xff800000u));
        float x = u2f((uint32_t)(splitmix64(&rng) % 0xff800000u));
        if ((f2u(x) & 0x7fffffffu) >= 0x7f800000u || (f2u(y) & 0x7fffffffu) >= 0x7f800000u)
            continue;
        check_atan2(&a, y, x);
        check_atan2(&a, y, y * (float)(1.0 + (n % 64) * 0x1p-9)); /* |y| ~ |x| */
        check_atan2(&a, y, y * 2.4142135f * (float)(1.0 + (n % 64 - 32) * 0x1p-14));
    }
    for (n = 1; n < 100000; ++n) { /* the axes */
        float v = (float)n * 0.37f;
        check_atan2(&a, v, 0.0f);
        check_atan2(&a, v, -0.0f);
        check_atan2(&a, 0.0f, v);
        check_atan2(&a, 0.0f, -v);
    }
    /* every pair of special values, bit for bit with glibc's atan2f */
    for (i = 0; i < sizeof sv / sizeof sv[0]; ++i)
        for (j = 0; j < sizeof sv / sizeof sv[0]; ++j) {
            float y = sv[i], x = sv[j], got = rs_atan2f(y, x), want = atan2f(y, x);
            if (isnan(want) ? !isnan(got)
                            : (isinf(want) || want == 0.0f || isinf(x) || isinf(y) || x == 0.0f ||
                               y == 0.0f) &&
                                  f2u(got) != f2u(want))
                fail_msg("rs_atan2f(%a, %a) = %a, atan2f = %a", y, x, got, want);
            check_atan2(&a, y, x);
        }
    report(&a, RS_HDM_BOUND_ATAN2);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_sin_cos_tan), cmocka_unit_test(test_exp),
        cmocka_unit_test(test_log),         cmocka_unit_test(test_pow),
        cmocka_unit_test(test_acos),        cmocka_unit_test(test_atan2),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
