/* core/hdmath.h — the elementary functions shared code calls, with the same bits on every device.
 *
 * libm's sinf, cosf, powf, expf, acosf, atan2f and tanf are not correctly rounded, and glibc's
 * and CUDA's differ in the last bits (1-4 ulp), so the CUDA megakernel's image would differ from
 * the CPU's although both run the same RS_HD shading code.  The functions here are built from
 * operations that round alike on both (IEEE + - * / and sqrt, with contraction into FMA off:
 * -ffp-contract=off on the host, --fmad=false under nvcc), exact ones (float <-> bits casts,
 * integer arithmetic, conversions of exactly representable values, comparisons) and the IEEE
 * conversions double -> float and int64 -> double, which round to nearest on both.  Nothing
 * here reads errno or calls libm (RS_HDM_SQRTF below), and nothing calls fmaf.
 *
 * Error bounds (ulp of the correctly rounded float, measured by tests/core_hdmath_test.c over
 * dense sweeps plus an exhaustive one of |x| < 16 for sin and cos; the test asserts them):
 *   rs_sinf, rs_cosf, rs_sincosf  every finite x                 see the test's RS_HDM_BOUND_*
 *   rs_tanf                       every finite x
 *   rs_expf                       every x; overflow to inf from 88.7228394, 0 below -103.97
 *   rs_logf, rs_powf              every x (double inside: 0.5 ulp plus a hair)
 *   rs_acosf                      [-1, 1] (NaN outside: callers clamp)
 *   rs_atan2f                     every (y, x), with C99's zero, infinity and quadrant cases
 * rs_sinf(-x) is -rs_sinf(x) and rs_cosf(-x) is rs_cosf(x) bit for bit (the argument's sign is
 * taken off first), and rs_sincosf gives rs_sinf's and rs_cosf's bits.
 *
 * The polynomials are minimax fits (relative error) made by scripts/fit-hdmath.py (mpmath Remez
 * exchange, coefficients rounded to float; the script prints each fit's error) and evaluated
 * by Horner's rule; the split constants and the bits of 2/pi come from the same script.
 * Reductions: Cody and Waite with pi/2 in three parts for |x| < 16 (the shading's angles), and
 * for larger |x| Payne and Hanek's, exact in 64-bit integers, over a 96-bit window of 2/pi. */
#ifndef RS_CORE_HDMATH_H
#define RS_CORE_HDMATH_H

#include <stdint.h>
#include <string.h>

#include "core/hd.h"

/* The correctly rounded square root: __fsqrt_rn on the device whatever -prec-sqrt says; GCC's
 * and Clang's builtin on the host (an instruction; with math-errno on, which the build turns
 * off, they would also call libm for negative arguments, which never come here). */
#if defined(__CUDA_ARCH__)
#  define RS_HDM_SQRTF(x) __fsqrt_rn(x)
#elif defined(__GNUC__)
#  define RS_HDM_SQRTF(x) __builtin_sqrtf(x)
#else
#  include <math.h>
#  define RS_HDM_SQRTF(x) sqrtf(x)
#endif

/* ---- constants (scripts/fit-hdmath.py) ------------------------------------------------------ */

/* sin(r) = r + r^3 S(r^2), cos(r) = 1 - r^2/2 + r^4 C(r^2), |r| <= pi/4 */
#define RS_HDM_SIN0 -1.666665524e-01f
#define RS_HDM_SIN1 8.332161233e-03f
#define RS_HDM_SIN2 -1.951529994e-04f
#define RS_HDM_COS0 4.166664556e-02f
#define RS_HDM_COS1 -1.388731645e-03f
#define RS_HDM_COS2 2.443317499e-05f
/* exp(r) = 1 + r + r^2 E(r), |r| <= ln 2 / 2 */
#define RS_HDM_EXP0 4.999999404e-01f
#define RS_HDM_EXP1 1.666652113e-01f
#define RS_HDM_EXP2 4.166838527e-02f
#define RS_HDM_EXP3 8.368681185e-03f
#define RS_HDM_EXP4 1.381467213e-03f
/* atan(u) = u + u^3 A(u^2), |u| <= tan(pi/8) */
#define RS_HDM_ATAN0 -3.333331645e-01f
#define RS_HDM_ATAN1 1.999847144e-01f
#define RS_HDM_ATAN2 -1.424353868e-01f
#define RS_HDM_ATAN3 1.059385687e-01f
#define RS_HDM_ATAN4 -6.078336388e-02f
/* asin(x) = x + x^3 B(x^2), |x| <= 1/2 */
#define RS_HDM_ASIN0 1.666675210e-01f
#define RS_HDM_ASIN1 7.495303452e-02f
#define RS_HDM_ASIN2 4.546960816e-02f
#define RS_HDM_ASIN3 2.418361604e-02f
#define RS_HDM_ASIN4 4.215885699e-02f
/* pi/2 = PIO2_0 + PIO2_1 + PIO2_2: 20 and 20 significant bits (k PIO2_0, k PIO2_1 exact for
 * k < 16) and a float */
#define RS_HDM_PIO2_0 1.570795059e+00f
#define RS_HDM_PIO2_1 1.267590051e-06f
#define RS_HDM_PIO2_2 7.443547731e-13f
/* ln 2 = LN2_0 (16 bits: k LN2_0 exact for |k| < 256) + LN2_1 */
#define RS_HDM_LN2_0 6.931457520e-01f
#define RS_HDM_LN2_1 1.428606765e-06f
/* pi/4 = PIO4_0 (21 bits: m PIO4_0 exact for m <= 4) + PIO4_1; pi/2 and pi as float + float */
#define RS_HDM_PIO4_0  7.853980064e-01f
#define RS_HDM_PIO4_1  1.569582366e-07f
#define RS_HDM_PIO2F_0 1.570796251e+00f
#define RS_HDM_PIO2F_1 7.549790126e-08f
#define RS_HDM_PIF_0   3.141592503e+00f
#define RS_HDM_PIF_1   1.509958025e-07f
/* ln 2 = LN2D_0 (32 bits) + LN2D_1 for the double log and exp; pi/2 2^-94 */
#define RS_HDM_LN2D_0    6.93147180369123816e-01
#define RS_HDM_LN2D_1    1.90821492927058770e-10
#define RS_HDM_PIO2_2M94 7.93049479854887923e-29
/* 2/pi in 32-bit words: word i >= 1 holds the bits 32 (i - 1) + 1 .. 32 i after the binary
 * point, word 0 the 32 zero bits before it; enough for a 96-bit window at any float's exponent */
/* clang-format off */
#define RS_HDM_TWO_OVER_PI_WORDS                                                                   \
    {0x00000000u, 0xa2f9836eu, 0x4e441529u, 0xfc2757d1u, 0xf534ddc0u,                              \
     0xdb629599u, 0x3c439041u, 0xfe5163abu, 0xdebbc561u}
/* clang-format on */

static const uint32_t rs_hdm_two_over_pi[9] = RS_HDM_TWO_OVER_PI_WORDS;
#if defined(__CUDACC__)
RS_CONST_TABLE uint32_t rs_hdm_two_over_pi_dev[9] = RS_HDM_TWO_OVER_PI_WORDS;
#endif

/* ---- bits ------------------------------------------------------------------------------------ */

RS_HD uint32_t rs_hdm_f2u(float f)
{
#if defined(__CUDA_ARCH__)
    return __float_as_uint(f);
#else
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
#endif
}

RS_HD float rs_hdm_u2f(uint32_t u)
{
#if defined(__CUDA_ARCH__)
    return __uint_as_float(u);
#else
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
#endif
}

RS_HD uint64_t rs_hdm_d2u(double d)
{
#if defined(__CUDA_ARCH__)
    return (uint64_t)__double_as_longlong(d);
#else
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return u;
#endif
}

RS_HD double rs_hdm_u2d(uint64_t u)
{
#if defined(__CUDA_ARCH__)
    return __longlong_as_double((long long)u);
#else
    double d;
    memcpy(&d, &u, sizeof d);
    return d;
#endif
}

#define RS_HDM_INF rs_hdm_u2f(0x7f800000u)
#define RS_HDM_NAN rs_hdm_u2f(0x7fc00000u)

/* 2^n as a float, n in [-126, 127] (exact) */
RS_HD float rs_hdm_pow2(int n) { return rs_hdm_u2f((uint32_t)(n + 127) << 23); }

RS_HD uint32_t rs_hdm_two_over_pi_word(int i)
{
#if defined(__CUDA_ARCH__)
    return rs_hdm_two_over_pi_dev[i];
#else
    return rs_hdm_two_over_pi[i];
#endif
}

/* ---- sine and cosine ------------------------------------------------------------------------ */

/* sin r and cos r for r = hi + lo, |r| <= pi/4 (a little over is fine), |lo| <= ulp(hi): the
 * polynomial at hi, plus lo cos hi (sin), minus lo sin hi (cos), to first order.  cos: 1 - hi^2/2
 * rounded, then its rounding error recovered exactly (Fast2Sum: 1 >= hi^2/2) and added with the
 * tail. */
RS_HD float rs_hdm_sin_poly(float hi, float lo)
{
    float z = hi * hi;
    return hi + ((hi * z) * (RS_HDM_SIN0 + z * (RS_HDM_SIN1 + z * RS_HDM_SIN2)) +
                 lo * (1.0f - 0.5f * z));
}

RS_HD float rs_hdm_cos_poly(float hi, float lo)
{
    float z = hi * hi, hz = 0.5f * z, w = 1.0f - hz;
    return w + ((((1.0f - w) - hz) - hi * lo) +
                (z * z) * (RS_HDM_COS0 + z * (RS_HDM_COS1 + z * RS_HDM_COS2)));
}

/* Payne and Hanek: ax = |x| >= 16, finite, = m 2^e with the integer m < 2^24.  The bits of 2/pi
 * of weight 2^-i for i < e - 1 add multiples of 4 to x 2/pi and are skipped; the next 96 bits
 * (W) times m give x 2/pi mod 4 with 94 fraction bits, exactly (2/pi's further bits add less
 * than 2^-70).  The nearest integer k (mod 4) is taken off and the fraction, as a double,
 * times pi/2 is r, which keeps its bits however near x comes to a multiple of pi/2 (a float
 * below 51000 comes no nearer than 2^-27.8, at k = 161: scripts/fit-hdmath.py). */
RS_HD_COLD int rs_hdm_reduce_big(float ax, float *hi, float *lo)
{
    uint32_t u = rs_hdm_f2u(ax);
    int e = (int)(u >> 23) - 150; /* ax = m 2^e, e >= -19 */
    uint64_t m = (u & 0x7fffffu) | 0x800000u;
    int g = e + 30; /* the window's first bit, 2^-(e - 1), in the table */
    int w = g >> 5, s = g & 31;
    uint64_t t0 = rs_hdm_two_over_pi_word(w), t1 = rs_hdm_two_over_pi_word(w + 1);
    uint64_t t2 = rs_hdm_two_over_pi_word(w + 2), t3 = rs_hdm_two_over_pi_word(w + 3);
    uint64_t w2 = (((t0 << 32) | t1) >> (32 - s)) & 0xffffffffu;
    uint64_t w1 = (((t1 << 32) | t2) >> (32 - s)) & 0xffffffffu;
    uint64_t w0 = (((t2 << 32) | t3) >> (32 - s)) & 0xffffffffu;
    uint64_t p0 = m * w0, p1 = m * w1 + (p0 >> 32), p2 = m * w2 + (p1 >> 32);
    uint64_t top = (p2 << 32) | (p1 & 0xffffffffu); /* 2 integer bits, 62 fraction bits */
    uint64_t k = (top + (1ull << 61)) >> 62;
    int64_t f = (int64_t)(top - (k << 62)); /* in [-2^61, 2^61) */
    double d = ((double)f * 4294967296.0 + (double)(p0 & 0xffffffffu)) * RS_HDM_PIO2_2M94;
    *hi = (float)d;
    *lo = (float)(d - (double)*hi);
    return (int)(k & 3u);
}

/* ax = |x| finite: ax = k pi/2 + hi + lo, |hi| <= pi/4 (a hair over when ax 2/pi rounds across
 * a half), lo the part of r = hi + lo that a float hi cannot hold; returns k mod 4.
 * Below 16 (Cody and Waite), k <= 10 and k PIO2_0, k PIO2_1 are exact, a = ax - k PIO2_0 is
 * exact (Sterbenz), b = a - k PIO2_1 is exact but for |b| > 2^-15, and each of the last two
 * steps' rounding errors is recovered exactly (Fast2Sum: |a| >= k PIO2_1 when b rounds, and
 * |b| >= 2^-26.3 > k PIO2_2, 2^-26.3 being the nearest approach of a float below 16 to a
 * multiple of pi/2, at 3 pi/2); pi/2's 64 bits leave r an error under 2^-60. */
RS_HD int rs_hdm_reduce(float ax, float *hi, float *lo)
{
    if (ax < 16.0f) {
        float k = (float)(int)(ax * 0.636619772f + 0.5f);
        float a = ax - k * RS_HDM_PIO2_0, k1 = k * RS_HDM_PIO2_1, k2 = k * RS_HDM_PIO2_2;
        float b = a - k1, r = b - k2;
        *hi = r;
        *lo = ((a - b) - k1) + ((b - r) - k2);
        return (int)k & 3;
    }
    return rs_hdm_reduce_big(ax, hi, lo);
}

/* sin x and cos x at once (one reduction); NaN for infinite or NaN x. */
RS_HD void rs_sincosf(float x, float *s, float *c)
{
    uint32_t u = rs_hdm_f2u(x), sign = u & 0x80000000u;
    float ax = rs_hdm_u2f(u ^ sign), hi, lo, ps, pc, so, co;
    int q;
    if (!(ax < RS_HDM_INF)) {
        *s = *c = x - x;
        return;
    }
    q = rs_hdm_reduce(ax, &hi, &lo);
    ps = rs_hdm_sin_poly(hi, lo);
    pc = rs_hdm_cos_poly(hi, lo);
    so = (q & 1) ? pc : ps;
    co = (q & 1) ? ps : pc;
    if (q & 2)
        so = -so;
    if ((q + 1) & 2)
        co = -co;
    *s = rs_hdm_u2f(rs_hdm_f2u(so) ^ sign);
    *c = co;
}

RS_HD float rs_sinf(float x)
{
    uint32_t u = rs_hdm_f2u(x), sign = u & 0x80000000u;
    float ax = rs_hdm_u2f(u ^ sign), hi, lo, v;
    int q;
    if (!(ax < RS_HDM_INF))
        return x - x;
    q = rs_hdm_reduce(ax, &hi, &lo);
    v = (q & 1) ? rs_hdm_cos_poly(hi, lo) : rs_hdm_sin_poly(hi, lo);
    if (q & 2)
        v = -v;
    return rs_hdm_u2f(rs_hdm_f2u(v) ^ sign);
}

RS_HD float rs_cosf(float x)
{
    float ax = rs_hdm_u2f(rs_hdm_f2u(x) & 0x7fffffffu), hi, lo, v;
    int q;
    if (!(ax < RS_HDM_INF))
        return x - x;
    q = rs_hdm_reduce(ax, &hi, &lo);
    v = (q & 1) ? rs_hdm_sin_poly(hi, lo) : rs_hdm_cos_poly(hi, lo);
    return ((q + 1) & 2) ? -v : v;
}

/* tan x = sin / cos of the reduced argument (cos / -sin in odd quadrants: both polynomials are
 * accurate relative to their values, so the quotient is, up to the pole). */
RS_HD float rs_tanf(float x)
{
    uint32_t u = rs_hdm_f2u(x), sign = u & 0x80000000u;
    float ax = rs_hdm_u2f(u ^ sign), hi, lo, ps, pc, v;
    int q;
    if (!(ax < RS_HDM_INF))
        return x - x;
    q = rs_hdm_reduce(ax, &hi, &lo);
    ps = rs_hdm_sin_poly(hi, lo);
    pc = rs_hdm_cos_poly(hi, lo);
    v = (q & 1) ? -pc / ps : ps / pc;
    return rs_hdm_u2f(rs_hdm_f2u(v) ^ sign);
}

/* ---- exponential ---------------------------------------------------------------------------- */

/* e^x = 2^k e^r, k = round(x / ln 2), r = x - k ln 2 (Cody and Waite: x - k LN2_0 is exact).
 * The scaling by 2^k is exact, but for results under 2^-126, which round once, in the last
 * multiplication. */
RS_HD float rs_expf(float x)
{
    float k, r, p;
    int ki;
    if (!(x == x))
        return x + x;
    if (x > 89.0f)
        return RS_HDM_INF;
    if (x < -104.0f) /* e^-104 is under half the least subnormal */
        return 0.0f;
    ki = (int)(x * 1.44269504f + (x < 0.0f ? -0.5f : 0.5f));
    k = (float)ki;
    r = (x - k * RS_HDM_LN2_0) - k * RS_HDM_LN2_1;
    /* clang-format off */
    p = 1.0f + (r + (r * r) * (RS_HDM_EXP0 +
                               r * (RS_HDM_EXP1 + r * (RS_HDM_EXP2 + r * (RS_HDM_EXP3 +
                                                                          r * RS_HDM_EXP4)))));
    /* clang-format on */
    if (ki > 127)
        return (p * rs_hdm_pow2(127)) * rs_hdm_pow2(ki - 127); /* inf past FLT_MAX */
    if (ki < -126)
        return (p * rs_hdm_pow2(ki + 64)) * rs_hdm_pow2(-64);
    return p * rs_hdm_pow2(ki);
}

/* ---- logarithm and power (in double: 0.5 ulp and a hair after the final rounding) ------------ */

/* ln x for a double x > 0 that came from a float (normal in double): x = 2^e f, f in
 * [sqrt 1/2, sqrt 2), ln f = 2 atanh(t), t = (f - 1) / (f + 1), |t| <= 0.1716: the series to
 * t^19 (the first term left out is under 2^-50 relative). */
RS_HD double rs_hdm_log_d(double x)
{
    uint64_t u = rs_hdm_d2u(x);
    int e = (int)((u >> 52) & 0x7ffu) - 1023;
    double f = rs_hdm_u2d((u & 0x000fffffffffffffull) | 0x3ff0000000000000ull), t, t2, s;
    if (f > 1.4142135623730951) {
        f *= 0.5;
        e += 1;
    }
    t = (f - 1.0) / (f + 1.0);
    t2 = t * t;
    /* clang-format off */
    s = 2.0 + t2 * (2.0 / 3 + t2 * (2.0 / 5 + t2 * (2.0 / 7 + t2 * (2.0 / 9 + t2 * (2.0 / 11 +
        t2 * (2.0 / 13 + t2 * (2.0 / 15 + t2 * (2.0 / 17 + t2 * (2.0 / 19)))))))));
    /* clang-format on */
    return (double)e * RS_HDM_LN2D_0 + ((double)e * RS_HDM_LN2D_1 + t * s);
}

/* e^z as a double for any double z, exact to ~2^-50 relative where a float result is not 0 or
 * inf (z in [-104, 89]): 2^k e^r, |r| <= ln 2 / 2, Taylor to r^11 (r^12/12! < 2^-47). */
RS_HD double rs_hdm_exp_d(double z)
{
    double k, r, p;
    int ki;
    if (!(z == z))
        return z + z;
    if (z > 89.0)
        return (double)RS_HDM_INF;
    if (z < -104.0)
        return 0.0;
    ki = (int)(z * 1.4426950408889634 + (z < 0.0 ? -0.5 : 0.5));
    k = (double)ki;
    r = (z - k * RS_HDM_LN2D_0) - k * RS_HDM_LN2D_1;
    /* clang-format off */
    p = 1.0 + r * (1.0 + r * (1.0 / 2 + r * (1.0 / 6 + r * (1.0 / 24 + r * (1.0 / 120 +
        r * (1.0 / 720 + r * (1.0 / 5040 + r * (1.0 / 40320 + r * (1.0 / 362880 +
        r * (1.0 / 3628800 + r * (1.0 / 39916800)))))))))));
    /* clang-format on */
    return p * rs_hdm_u2d((uint64_t)(ki + 1023) << 52);
}

/* ln x: -inf at +-0, NaN below 0, inf at inf. */
RS_HD float rs_logf(float x)
{
    if (!(x == x))
        return x + x;
    if (x < 0.0f)
        return RS_HDM_NAN;
    if (x == 0.0f)
        return -RS_HDM_INF;
    if (x == RS_HDM_INF)
        return x;
    return (float)rs_hdm_log_d((double)x);
}

/* 0: y is not an integer; 1: an odd one; 2: an even one (infinities are even); y != 0, not NaN */
RS_HD int rs_hdm_int_kind(float y)
{
    uint32_t u = rs_hdm_f2u(y);
    int e = (int)((u >> 23) & 0xffu) - 127;
    if (e < 0)
        return 0;
    if (e >= 24)
        return 2;
    if (u & (0x7fffffu >> e))
        return 0;
    return (((u & 0x7fffffu) | 0x800000u) >> (23 - e)) & 1u ? 1 : 2;
}

/* x^y as C99's powf: 1 for y = +-0 or x = 1 (even with a NaN), +0 or +inf for x = +0, NaN for
 * x < 0 and y not an integer, the sign of x for odd integer y.  |x|^y = e^(y ln|x|) in double. */
RS_HD float rs_powf(float x, float y)
{
    uint32_t ux = rs_hdm_f2u(x), rsign = 0;
    float ax = rs_hdm_u2f(ux & 0x7fffffffu), v;
    if (y == 0.0f || x == 1.0f)
        return 1.0f;
    if (!(x == x) || !(y == y))
        return x + y;
    if (ux >> 31) {
        int kind = rs_hdm_int_kind(y);
        if (ax == 1.0f && !(y - y == 0.0f)) /* (-1)^(+-inf) */
            return 1.0f;
        if (kind == 0 && ax != 0.0f && ax != RS_HDM_INF)
            return RS_HDM_NAN;
        if (kind == 1)
            rsign = 0x80000000u;
    }
    if (ax == 0.0f)
        v = y < 0.0f ? RS_HDM_INF : 0.0f;
    else if (ax == RS_HDM_INF)
        v = y < 0.0f ? 0.0f : RS_HDM_INF;
    else
        v = (float)rs_hdm_exp_d((double)y * rs_hdm_log_d((double)ax));
    return rs_hdm_u2f(rs_hdm_f2u(v) | rsign);
}

/* ---- inverse trigonometric functions -------------------------------------------------------- */

/* asin's polynomial part: asin x = x + x^3 B(x^2) for |x| <= 1/2 */
RS_HD float rs_hdm_asin_b(float z)
{
    return RS_HDM_ASIN0 +
           z * (RS_HDM_ASIN1 + z * (RS_HDM_ASIN2 + z * (RS_HDM_ASIN3 + z * RS_HDM_ASIN4)));
}

/* acos x for x in [-1, 1], NaN outside (the callers clamp a cosine rounded past 1).
 * |x| <= 1/2: pi/2 - asin x; past that acos |x| = 2 asin(sqrt((1 - |x|) / 2)) (1 - |x| exact),
 * and acos x = pi - acos |x| for x < 0; pi/2 and pi in two parts. */
RS_HD float rs_acosf(float x)
{
    uint32_t u = rs_hdm_f2u(x);
    float ax = rs_hdm_u2f(u & 0x7fffffffu), z, s, w;
    if (!(ax <= 1.0f))
        return x == x ? RS_HDM_NAN : x + x;
    if (ax <= 0.5f) {
        z = x * x;
        return RS_HDM_PIO2F_0 - (x - (RS_HDM_PIO2F_1 - (x * z) * rs_hdm_asin_b(z)));
    }
    z = (1.0f - ax) * 0.5f;
    s = RS_HDM_SQRTF(z);
    w = s + (s * z) * rs_hdm_asin_b(z); /* asin s = acos(|x|) / 2 */
    return (u >> 31) ? RS_HDM_PIF_0 - (2.0f * w - RS_HDM_PIF_1) : 2.0f * w;
}

/* The angle of (x, y) in [-pi, pi] as C99's atan2f, its zeros, infinities and NaNs included.
 * With n = min(|x|, |y|), d = max: atan(n/d) for n/d <= tan(pi/8), else pi/4 + atan(u) with
 * u = (n - d) / (n + d) (no rounded quotient n/d in between), so the polynomial sees
 * |u| <= tan(pi/8); the octant then gives angle = m pi/4 +- atan(u), m = 0..4, with m pi/4 in
 * two parts (the first exact), and y's sign. */
RS_HD float rs_atan2f(float y, float x)
{
    uint32_t ux = rs_hdm_f2u(x), uy = rs_hdm_f2u(y);
    float ax = rs_hdm_u2f(ux & 0x7fffffffu), ay = rs_hdm_u2f(uy & 0x7fffffffu);
    int xneg = (int)(ux >> 31), m, neg = 0;
    float u = 0.0f, p, a;
    if (!(x == x) || !(y == y))
        return x + y;
    if (ay == 0.0f && ax == 0.0f) {
        m = xneg ? 4 : 0;
    } else if (ax == ay) { /* finite or both infinite */
        m = xneg ? 3 : 1;
    } else {
        int swap = ay > ax;
        float n = swap ? ax : ay, d = swap ? ay : ax; /* n < d, d > 0 */
        if (n <= 0.414213568f * d) {
            u = n / d;
            m = swap ? 2 : (xneg ? 4 : 0);
        } else {
            if (d > 8.507059173e37f) { /* 2^126: n + d must not overflow */
                n *= 0.25f;
                d *= 0.25f;
            }
            u = (n - d) / (n + d);
            m = xneg ? 3 : 1;
        }
        neg = swap == xneg ? 0 : 1; /* angle = m pi/4 - atan(u) */
    }
    /* clang-format off */
    p = u + (u * (u * u)) * (RS_HDM_ATAN0 + (u * u) * (RS_HDM_ATAN1 + (u * u) * (RS_HDM_ATAN2 +
                                   (u * u) * (RS_HDM_ATAN3 + (u * u) * RS_HDM_ATAN4))));
    /* clang-format on */
    a = (float)m * RS_HDM_PIO4_0 + ((float)m * RS_HDM_PIO4_1 + (neg ? -p : p));
    return rs_hdm_u2f(rs_hdm_f2u(a) | (uy & 0x80000000u));
}

#endif
