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
#if RS_DEVICE_PASS
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
/* pi/2 2^-94 (double) */
#define RS_HDM_PIO2_2M94 7.93049479854887923e-29
/* rs_powf's and rs_logf's double log2 and exp2 (tables as glibc's powf has them):
 * log2 x = k + log2 c_i + log2(1 + r), r = z / c_i - 1 in [-0.0151, 0.0235], z = x 2^-k in
 * [OFF, 2 OFF) by its bits, i = z's subinterval of 32 (c = 1 in the one holding 1);
 * log2(1 + r) = r L(r), relative error 2^-42.0.
 * 2^t = 2^(j/32) 2^e 2^r, |r| <= 1/64: 2^r = 1 + r X(r), relative error 2^-52.7. */
#define RS_HDM_LOG2_OFF 0x3f330000u
/* clang-format off */
#define RS_HDM_LOG2_INVC {0x1.6a13cd1537290p+0, 0x1.623fa77016240p+0, 0x1.5ac056b015ac0p+0, \
    0x1.5390948f40febp+0, 0x1.4cab88725af6ep+0, 0x1.460cbc7f5cf9ap+0, 0x1.3fb013fb013fbp+0, \
    0x1.3991c2c187f63p+0, 0x1.33ae45b57bcb2p+0, 0x1.2e025c04b8097p+0, 0x1.288b01288b013p+0, \
    0x1.23456789abcdfp+0, 0x1.1e2ef3b3fb874p+0, 0x1.19453808ca29cp+0, 0x1.1485f0e0acd3bp+0, \
    0x1.0fef010fef011p+0, 0x1.0b7e6ec259dc8p+0, 0x1.073260a47f7c6p+0, 0x1.03091b51f5e1ap+0, \
    0x1.0000000000000p+0, 0x1.ecc07b301ecc0p-1, 0x1.de5d6e3f8868ap-1, 0x1.d0cb58f6ec074p-1, \
    0x1.c3f8f01c3f8f0p-1, 0x1.b7d6c3dda338bp-1, 0x1.ac5701ac5701bp-1, 0x1.a16d3f97a4b02p-1, \
    0x1.970e4f80cb872p-1, 0x1.8d3018d3018d3p-1, 0x1.83c977ab2beddp-1, 0x1.7ad2208e0ecc3p-1, \
    0x1.724287f46debcp-1}
#define RS_HDM_LOG2_LOGC {-0x1.0014332be0032p-1, -0x1.dfdd89d586e2cp-2, -0x1.c043859e2fdb2p-2, \
    -0x1.a152f142981b5p-2, -0x1.8304d90c11fd1p-2, -0x1.6552b49986277p-2, -0x1.48365e695d797p-2, \
    -0x1.2baa0c34be1ebp-2, -0x1.0fa848044b352p-2, -0x1.e857d3d361368p-3, -0x1.b2602497d534ap-3, \
    -0x1.7d60496cfbb4cp-3, -0x1.494f863b8df32p-3, -0x1.162593186da70p-3, -0x1.c7b528b70f1bcp-4, \
    -0x1.64ce26c067157p-4, -0x1.0387efbca86a7p-4, -0x1.47aa07357703cp-5, -0x1.16a21e20a0a29p-6, \
    0x0.0p+0, 0x1.c4dfab90aab6ap-5, 0x1.918a16e46335ep-4, 0x1.1dcd197552b7dp-3, \
    0x1.70742d4ef0280p-3, 0x1.c0db6cdd94defp-3, 0x1.0790adbb03009p-2, 0x1.2db10fc4d9aaep-2, \
    0x1.52dbdfc4c96b5p-2, 0x1.771d2ba7efb3cp-2, 0x1.9a802391e2330p-2, 0x1.bd0f2e9e79032p-2, \
    0x1.ded3fd442364cp-2}
#define RS_HDM_EXP2_TAB {0x1.0000000000000p+0, 0x1.059b0d3158574p+0, 0x1.0b5586cf9890fp+0, \
    0x1.11301d0125b51p+0, 0x1.172b83c7d517bp+0, 0x1.1d4873168b9aap+0, 0x1.2387a6e756238p+0, \
    0x1.29e9df51fdee1p+0, 0x1.306fe0a31b715p+0, 0x1.371a7373aa9cbp+0, 0x1.3dea64c123422p+0, \
    0x1.44e086061892dp+0, 0x1.4bfdad5362a27p+0, 0x1.5342b569d4f82p+0, 0x1.5ab07dd485429p+0, \
    0x1.6247eb03a5585p+0, 0x1.6a09e667f3bcdp+0, 0x1.71f75e8ec5f74p+0, 0x1.7a11473eb0187p+0, \
    0x1.82589994cce13p+0, 0x1.8ace5422aa0dbp+0, 0x1.93737b0cdc5e5p+0, 0x1.9c49182a3f090p+0, \
    0x1.a5503b23e255dp+0, 0x1.ae89f995ad3adp+0, 0x1.b7f76f2fb5e47p+0, 0x1.c199bdd85529cp+0, \
    0x1.cb720dcef9069p+0, 0x1.d5818dcfba487p+0, 0x1.dfc97337b9b5fp+0, 0x1.ea4afa2a490dap+0, \
    0x1.f50765b6e4540p+0}
/* clang-format on */
#define RS_HDM_LOG2_L0 0x1.71547652b846ap+0
#define RS_HDM_LOG2_L1 -0x1.71547651dfe41p-1
#define RS_HDM_LOG2_L2 0x1.ec709d71b6df8p-2
#define RS_HDM_LOG2_L3 -0x1.7154dfd5f4dcap-2
#define RS_HDM_LOG2_L4 0x1.27868a4412163p-2
#define RS_HDM_LOG2_L5 -0x1.e22a81da9801ep-3
#define RS_HDM_EXP2_X0 0x1.62e42fefa39eep-1
#define RS_HDM_EXP2_X1 0x1.ebfbdff81326cp-3
#define RS_HDM_EXP2_X2 0x1.c6b08d709fe60p-5
#define RS_HDM_EXP2_X3 0x1.3b2b1bd9998e2p-7
#define RS_HDM_EXP2_X4 0x1.5d878e9057566p-10
#define RS_HDM_LN2_D   0x1.62e42fefa39efp-1 /* ln 2, double */
/* 2/pi in 32-bit words: word i >= 1 holds the bits 32 (i - 1) + 1 .. 32 i after the binary
 * point, word 0 the 32 zero bits before it; enough for a 96-bit window at any float's exponent */
/* clang-format off */
#define RS_HDM_TWO_OVER_PI_WORDS                                                                   \
    {0x00000000u, 0xa2f9836eu, 0x4e441529u, 0xfc2757d1u, 0xf534ddc0u,                              \
     0xdb629599u, 0x3c439041u, 0xfe5163abu, 0xdebbc561u}
/* clang-format on */

/* The tables, the host's and (under nvcc) the device's copy: rs_hdm_*_at picks. */
static const uint32_t rs_hdm_two_over_pi[9] = RS_HDM_TWO_OVER_PI_WORDS;
static const double rs_hdm_log2_invc[32] = RS_HDM_LOG2_INVC;
static const double rs_hdm_log2_logc[32] = RS_HDM_LOG2_LOGC;
static const double rs_hdm_exp2_tab[32] = RS_HDM_EXP2_TAB;
#if RS_CUDA_SOURCE
RS_CONST_TABLE uint32_t rs_hdm_two_over_pi_dev[9] = RS_HDM_TWO_OVER_PI_WORDS;
RS_CONST_TABLE double rs_hdm_log2_invc_dev[32] = RS_HDM_LOG2_INVC;
RS_CONST_TABLE double rs_hdm_log2_logc_dev[32] = RS_HDM_LOG2_LOGC;
RS_CONST_TABLE double rs_hdm_exp2_tab_dev[32] = RS_HDM_EXP2_TAB;
#endif

/* ---- bits ------------------------------------------------------------------------------------ */

RS_HD uint32_t rs_hdm_f2u(float f)
{
#if RS_DEVICE_PASS
    return __float_as_uint(f);
#else
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
#endif
}

RS_HD float rs_hdm_u2f(uint32_t u)
{
#if RS_DEVICE_PASS
    return __uint_as_float(u);
#else
    float f;
    memcpy(&f, &u, sizeof f);
    return f;
#endif
}

RS_HD uint64_t rs_hdm_d2u(double d)
{
#if RS_DEVICE_PASS
    return (uint64_t)__double_as_longlong(d);
#else
    uint64_t u;
    memcpy(&u, &d, sizeof u);
    return u;
#endif
}

RS_HD double rs_hdm_u2d(uint64_t u)
{
#if RS_DEVICE_PASS
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

#if RS_DEVICE_PASS
#  define RS_HDM_TABLE(name, i) name##_dev[i]
#else
#  define RS_HDM_TABLE(name, i) name[i]
#endif

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
    uint64_t t0 = RS_HDM_TABLE(rs_hdm_two_over_pi, w), t1 = RS_HDM_TABLE(rs_hdm_two_over_pi, w + 1);
    uint64_t t2 = RS_HDM_TABLE(rs_hdm_two_over_pi, w + 2), t3 = RS_HDM_TABLE(rs_hdm_two_over_pi, w + 3);
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
        int ki = (int)(ax * 0.636619772f + 0.5f);
        float k = (float)ki;
        float a = ax - k * RS_HDM_PIO2_0, k1 = k * RS_HDM_PIO2_1, k2 = k * RS_HDM_PIO2_2;
        float b = a - k1, r = b - k2;
        *hi = r;
        *lo = ((a - b) - k1) + ((b - r) - k2);
        return ki & 3;
    }
    return rs_hdm_reduce_big(ax, hi, lo);
}

/* sin x and cos x at once (one reduction); NaN for infinite or NaN x.  The quadrant picks and
 * negates the two polynomials' results by bit operations, not branches: q is as random as the
 * sampled angle, and mispredicted branches cost more than both polynomials. */
RS_HD void rs_sincosf(float x, float *s, float *c)
{
    uint32_t u = rs_hdm_f2u(x), sign = u & 0x80000000u, ps, pc, odd;
    float ax = rs_hdm_u2f(u ^ sign), hi, lo;
    int q;
    if (!(ax < RS_HDM_INF)) {
        *s = *c = x - x;
        return;
    }
    q = rs_hdm_reduce(ax, &hi, &lo);
    ps = rs_hdm_f2u(rs_hdm_sin_poly(hi, lo));
    pc = rs_hdm_f2u(rs_hdm_cos_poly(hi, lo));
    odd = 0u - (uint32_t)(q & 1); /* quadrants 1 and 3: sin x = +-cos r, cos x = -+sin r */
    *s = rs_hdm_u2f(((ps & ~odd) | (pc & odd)) ^ ((uint32_t)(q & 2) << 30) ^ sign);
    *c = rs_hdm_u2f(((pc & ~odd) | (ps & odd)) ^ ((uint32_t)((q + 1) & 2) << 30));
}

/* rs_sincosf's sine and cosine (the same bits: the compiler drops the half not used but for
 * the shared reduction and selection). */
RS_HD float rs_sinf(float x)
{
    float s, c;
    rs_sincosf(x, &s, &c);
    return s;
}

RS_HD float rs_cosf(float x)
{
    float s, c;
    rs_sincosf(x, &s, &c);
    return c;
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

/* log2 x as a double for a float x > 0, finite (relative error about 2^-42, and exact at 1):
 * the constants' comment above.  A subnormal x is scaled by 2^23 first (exactly). */
RS_HD double rs_hdm_log2_d(float x)
{
    uint32_t ix = rs_hdm_f2u(x), tmp;
    int i, k;
    double z, r, r2, p;
    if (ix < 0x00800000u)
        ix = rs_hdm_f2u(x * 8388608.0f) - (23u << 23);
    tmp = ix - RS_HDM_LOG2_OFF;
    i = (int)((tmp >> 18) & 31u);
    k = (int)(tmp >> 23) - (int)((tmp >> 31) << 9); /* tmp >> 23 as a signed 32-bit value */
    z = (double)rs_hdm_u2f(ix - (tmp & 0xff800000u));
    r = z * RS_HDM_TABLE(rs_hdm_log2_invc, i) - 1.0;
    r2 = r * r;
    /* Estrin's scheme (shorter chains than Horner's: this sits on the Phong lobe's path) */
    p = (RS_HDM_LOG2_L0 + r * RS_HDM_LOG2_L1) + r2 * (RS_HDM_LOG2_L2 + r * RS_HDM_LOG2_L3) +
        (r2 * r2) * (RS_HDM_LOG2_L4 + r * RS_HDM_LOG2_L5);
    return (double)k + (RS_HDM_TABLE(rs_hdm_log2_logc, i) + r * p);
}

/* 2^t as a double for a double t, not NaN (relative error about 2^-52): 0 at or below -160,
 * inf at or above 129, where a float would be 0 or inf anyway. */
RS_HD double rs_hdm_exp2_d(double t)
{
    int kb;
    double r, r2, p;
    if (t >= 129.0)
        return (double)RS_HDM_INF;
    if (t <= -160.0)
        return 0.0;
    kb = (int)(t * 32.0 + 5120.5); /* round(32 t) + 5120: positive, so (int) floors */
    r = t - (double)(kb - 5120) * (1.0 / 32); /* exact (Sterbenz) */
    r2 = r * r;
    p = (RS_HDM_EXP2_X0 + r * RS_HDM_EXP2_X1) + r2 * (RS_HDM_EXP2_X2 + r * RS_HDM_EXP2_X3) +
        (r2 * r2) * RS_HDM_EXP2_X4;
    return RS_HDM_TABLE(rs_hdm_exp2_tab, kb & 31) *
           rs_hdm_u2d((uint64_t)((kb >> 5) - 160 + 1023) << 52) * (1.0 + r * p);
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
    return (float)(rs_hdm_log2_d(x) * RS_HDM_LN2_D);
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

/* rs_powf's cases off the common one (x in (0, inf), y finite): C99's zeros, infinities and
 * NaNs, and negative x. */
RS_HD_COLD float rs_hdm_pow_special(float x, float y)
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
        v = (float)rs_hdm_exp2_d((double)y * rs_hdm_log2_d(ax));
    return rs_hdm_u2f(rs_hdm_f2u(v) | rsign);
}

/* x^y as C99's powf: 1 for y = +-0 or x = 1 (even with a NaN), +0 or +inf for x = +0, NaN for
 * x < 0 and y not an integer, the sign of x for odd integer y.  x^y = 2^(y log2 x) in double
 * for x in (0, inf) and finite y (the common case, one test: x = 1 and y = 0 give 2^0 = 1 there
 * too), rs_hdm_pow_special for the rest. */
RS_HD float rs_powf(float x, float y)
{
    uint32_t ux = rs_hdm_f2u(x), uy = rs_hdm_f2u(y);
    if (ux - 1u < 0x7f7fffffu && (uy & 0x7fffffffu) < 0x7f800000u)
        return (float)rs_hdm_exp2_d((double)y * rs_hdm_log2_d(x));
    return rs_hdm_pow_special(x, y);
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
