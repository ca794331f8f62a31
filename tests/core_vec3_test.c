/* tests/core_vec3_test.c — core/vec3.h and the orthonormal basis of core/sampling.h.
 *
 * What is checked:
 *   - the component-wise operations, dot, length, min/max and axis access on exact values;
 *   - the cross product is right-handed (x × y = z and cyclic), anti-commutative, orthogonal to
 *     its arguments and obeys Lagrange's identity |a × b|^2 = |a|^2|b|^2 - (a·b)^2;
 *   - normalize gives unit length and keeps the direction over magnitudes 1e-15 .. 1e15;
 *   - rs_v3_rotate_y turns (1,0,0) by +90° into (0,0,-1) (RTIOW's rotate_y: right-handed about
 *     +y), keeps y and length, composes additively and is undone by the opposite angle;
 *   - rs_onb_from_normal gives an orthonormal, right-handed frame (t × b = n) for random unit
 *     normals, for normals within 1e-7 .. 1e-1 of ±z, and for exactly ±z and z = -0;
 *   - rs_fmaxf and rs_fminf give libm's fmaxf and fminf bit for bit on every pair of zeros of
 *     either sign, infinities, NaNs of either sign, denormals and random numbers.
 * Random inputs come from a fixed-seed splitmix64, so every run sees the same vectors. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/sampling.h"
#include "core/vec3.h"

#include "test_rand.h"

/* ---- helpers ------------------------------------------------------------------------------- */

static void expect_v3_near(rs_vec3 got, rs_vec3 want, float tol, const char *what)
{
    if (!(fabsf(got.x - want.x) <= tol && fabsf(got.y - want.y) <= tol &&
          fabsf(got.z - want.z) <= tol))
        fail_msg("%s: got (%.9g, %.9g, %.9g), want (%.9g, %.9g, %.9g) within %g", what, got.x,
                 got.y, got.z, want.x, want.y, want.z, tol);
}

static void expect_v3_exact(rs_vec3 got, float x, float y, float z, const char *what)
{
    if (!(got.x == x && got.y == y && got.z == z))
        fail_msg("%s: got (%.9g, %.9g, %.9g), want (%.9g, %.9g, %.9g) exactly", what, got.x, got.y,
                 got.z, x, y, z);
}

/* ---- component-wise operations --------------------------------------------------------------- */

static void test_basic_ops(void **state)
{
    rs_vec3 a = rs_v3(1.0f, -2.0f, 3.0f), b = rs_v3(4.0f, 0.5f, -6.0f);
    (void)state;
    expect_v3_exact(a, 1.0f, -2.0f, 3.0f, "rs_v3");
    expect_v3_exact(rs_v3_splat(2.5f), 2.5f, 2.5f, 2.5f, "splat");
    expect_v3_exact(rs_v3_add(a, b), 5.0f, -1.5f, -3.0f, "add");
    expect_v3_exact(rs_v3_sub(a, b), -3.0f, -2.5f, 9.0f, "sub");
    expect_v3_exact(rs_v3_mul(a, b), 4.0f, -1.0f, -18.0f, "mul");
    expect_v3_exact(rs_v3_scale(a, -2.0f), -2.0f, 4.0f, -6.0f, "scale");
    expect_v3_exact(rs_v3_neg(a), -1.0f, 2.0f, -3.0f, "neg");
    expect_v3_exact(rs_v3_madd(a, b, 2.0f), 9.0f, -1.0f, -9.0f, "madd");
    expect_v3_exact(rs_v3_min(a, b), 1.0f, -2.0f, -6.0f, "min");
    expect_v3_exact(rs_v3_max(a, b), 4.0f, 0.5f, 3.0f, "max");
    assert_true(rs_v3_dot(a, b) == 4.0f - 1.0f - 18.0f);
    assert_true(rs_v3_length2(a) == 14.0f);
    assert_float_equal(rs_v3_length(rs_v3(3.0f, 4.0f, 12.0f)), 13.0f, 0.0f);
    assert_true(rs_v3_max_comp(a) == 3.0f);
    assert_true(rs_v3_max_comp(rs_v3(-5.0f, -7.0f, -6.0f)) == -5.0f);
    assert_true(rs_v3_get(a, 0) == 1.0f);
    assert_true(rs_v3_get(a, 1) == -2.0f);
    assert_true(rs_v3_get(a, 2) == 3.0f);
    assert_true(rs_v3_is_zero(rs_v3(0.0f, -0.0f, 0.0f)));
    assert_false(rs_v3_is_zero(rs_v3(0.0f, 0.0f, 1e-30f)));
    /* the byte layout the header promises: 12 bytes, no padding */
    assert_int_equal(sizeof(rs_vec3), 12);
}

/* ---- cross product --------------------------------------------------------------------------- */

static void test_cross_orientation(void **state)
{
    rs_vec3 x = rs_v3(1.0f, 0.0f, 0.0f), y = rs_v3(0.0f, 1.0f, 0.0f), z = rs_v3(0.0f, 0.0f, 1.0f);
    (void)state;
    /* right-handed: x × y = z, y × z = x, z × x = y */
    expect_v3_exact(rs_v3_cross(x, y), 0.0f, 0.0f, 1.0f, "x cross y");
    expect_v3_exact(rs_v3_cross(y, z), 1.0f, 0.0f, 0.0f, "y cross z");
    expect_v3_exact(rs_v3_cross(z, x), 0.0f, 1.0f, 0.0f, "z cross x");
    expect_v3_exact(rs_v3_cross(y, x), 0.0f, 0.0f, -1.0f, "y cross x");
    expect_v3_exact(rs_v3_cross(x, x), 0.0f, 0.0f, 0.0f, "x cross x");
    /* a general exact case: (1,2,3) × (4,5,6) = (-3, 6, -3) */
    expect_v3_exact(rs_v3_cross(rs_v3(1.0f, 2.0f, 3.0f), rs_v3(4.0f, 5.0f, 6.0f)), -3.0f, 6.0f,
                    -3.0f, "(1,2,3) cross (4,5,6)");
}

static void test_cross_random_properties(void **state)
{
    uint64_t s = 0x5eed0001u;
    int i;
    (void)state;
    for (i = 0; i < 10000; ++i) {
        rs_vec3 a = rs_v3(rnd_range(&s, -10, 10), rnd_range(&s, -10, 10), rnd_range(&s, -10, 10));
        rs_vec3 b = rs_v3(rnd_range(&s, -10, 10), rnd_range(&s, -10, 10), rnd_range(&s, -10, 10));
        rs_vec3 c = rs_v3_cross(a, b), d = rs_v3_cross(b, a);
        double la = rs_v3_length(a), lb = rs_v3_length(b), ab = rs_v3_dot(a, b);
        double lagrange = la * la * lb * lb - ab * ab;
        /* anti-commutative, exactly: each component is the same products, swapped */
        expect_v3_exact(d, -c.x, -c.y, -c.z, "b cross a = -(a cross b)");
        /* orthogonal to both, relative to the sizes involved (float rounding: ~1e-6) */
        assert_true(fabs(rs_v3_dot(c, a)) <= 1e-4 * la * la * lb);
        assert_true(fabs(rs_v3_dot(c, b)) <= 1e-4 * la * lb * lb);
        assert_true(fabs(rs_v3_length2(c) - lagrange) <= 1e-4 * la * la * lb * lb);
    }
}

/* ---- normalize ------------------------------------------------------------------------------- */

static void test_normalize(void **state)
{
    uint64_t s = 0x5eed0002u;
    int i;
    (void)state;
    expect_v3_exact(rs_v3_normalize(rs_v3(0.0f, -3.0f, 0.0f)), 0.0f, -1.0f, 0.0f, "axis");
    expect_v3_near(rs_v3_normalize(rs_v3(3.0f, 0.0f, 4.0f)), rs_v3(0.6f, 0.0f, 0.8f), 1e-7f,
                   "3-4-5");
    for (i = 0; i < 10000; ++i) {
        /* magnitudes from 1e-15 to 1e15: |a|^2 stays inside float's normal range */
        float mag = powf(10.0f, rnd_range(&s, -15.0f, 15.0f));
        rs_vec3 dir = rnd_unit(&s);
        rs_vec3 a = rs_v3_scale(dir, mag), n = rs_v3_normalize(a);
        float len = rs_v3_length(n);
        assert_true(fabsf(len - 1.0f) <= 1e-6f);
        /* same direction: n is parallel to a and points the same way */
        assert_true(rs_v3_length(rs_v3_cross(n, dir)) <= 1e-5f);
        assert_true(rs_v3_dot(n, dir) > 0.99999f);
    }
}

/* ---- rotation about y ------------------------------------------------------------------------ */

static void test_rotate_y_known(void **state)
{
    (void)state;
    /* RTIOW's rotate_y maps object to world by x' = cos x + sin z, z' = -sin x + cos z:
     * +90° takes +x to -z and +z to +x. */
    expect_v3_near(rs_v3_rotate_y(rs_v3(1.0f, 0.0f, 0.0f), 90.0f), rs_v3(0.0f, 0.0f, -1.0f), 1e-6f,
                   "rotate_y((1,0,0), 90)");
    expect_v3_near(rs_v3_rotate_y(rs_v3(0.0f, 0.0f, 1.0f), 90.0f), rs_v3(1.0f, 0.0f, 0.0f), 1e-6f,
                   "rotate_y((0,0,1), 90)");
    expect_v3_near(rs_v3_rotate_y(rs_v3(1.0f, 0.0f, 0.0f), -90.0f), rs_v3(0.0f, 0.0f, 1.0f), 1e-6f,
                   "rotate_y((1,0,0), -90)");
    expect_v3_near(rs_v3_rotate_y(rs_v3(1.0f, 2.0f, 0.0f), 180.0f), rs_v3(-1.0f, 2.0f, 0.0f), 1e-6f,
                   "rotate_y((1,2,0), 180)");
    /* the Cornell box's tall block turns 15°: (1,0,0) goes to (cos 15°, 0, -sin 15°) */
    expect_v3_near(rs_v3_rotate_y(rs_v3(1.0f, 0.0f, 0.0f), 15.0f),
                   rs_v3(0.96592583f, 0.0f, -0.25881905f), 1e-6f, "rotate_y((1,0,0), 15)");
    /* the y axis is fixed */
    expect_v3_near(rs_v3_rotate_y(rs_v3(0.0f, 5.0f, 0.0f), 37.0f), rs_v3(0.0f, 5.0f, 0.0f), 1e-6f,
                   "rotate_y((0,5,0), 37)");
}

static void test_rotate_y_properties(void **state)
{
    uint64_t s = 0x5eed0003u;
    int i;
    (void)state;
    for (i = 0; i < 10000; ++i) {
        rs_vec3 p = rs_v3(rnd_range(&s, -5, 5), rnd_range(&s, -5, 5), rnd_range(&s, -5, 5));
        float a = rnd_range(&s, -360.0f, 360.0f), b = rnd_range(&s, -360.0f, 360.0f);
        float small = rnd_range(&s, 1.0f, 179.0f);
        rs_vec3 r = rs_v3_rotate_y(p, a);
        rs_vec3 back = rs_v3_rotate_y(r, -a);
        rs_vec3 ab = rs_v3_rotate_y(rs_v3_rotate_y(p, a), b), sum = rs_v3_rotate_y(p, a + b);
        rs_vec3 flat = rs_v3(p.x, 0.0f, p.z), turned = rs_v3_rotate_y(flat, small);
        float scale = 1e-5f * (1.0f + rs_v3_length(p));
        assert_true(r.y == p.y);
        assert_true(fabsf(rs_v3_length(r) - rs_v3_length(p)) <= scale);
        expect_v3_near(back, p, scale, "rotate by a then -a");
        expect_v3_near(ab, sum, 4.0f * scale, "rotate by a then b equals a + b");
        /* right-hand rule: for 0 < angle < 180 the turn p -> R p is counter-clockwise seen from
         * +y, i.e. (p × R p).y > 0 (it equals |p_xz|^2 sin angle) */
        if (rs_v3_length2(flat) > 1e-2f)
            assert_true(rs_v3_cross(flat, turned).y > 0.0f);
    }
}

/* ---- orthonormal basis ----------------------------------------------------------------------- */

/* Checks that f is an orthonormal right-handed frame around n, to within tol. */
static void expect_onb(rs_vec3 n, float tol)
{
    rs_onb f = rs_onb_from_normal(n);
    rs_vec3 tb = rs_v3_cross(f.t, f.b);
    char what[160];
    snprintf(what, sizeof what, "frame around (%.9g, %.9g, %.9g)", n.x, n.y, n.z);
    if (!(f.n.x == n.x && f.n.y == n.y && f.n.z == n.z))
        fail_msg("%s: f.n is not n", what);
    if (!(fabsf(rs_v3_length(f.t) - 1.0f) <= tol && fabsf(rs_v3_length(f.b) - 1.0f) <= tol))
        fail_msg("%s: |t| = %.9g, |b| = %.9g", what, rs_v3_length(f.t), rs_v3_length(f.b));
    if (!(fabsf(rs_v3_dot(f.t, f.b)) <= tol && fabsf(rs_v3_dot(f.t, n)) <= tol &&
          fabsf(rs_v3_dot(f.b, n)) <= tol))
        fail_msg("%s: t.b = %.3g, t.n = %.3g, b.n = %.3g", what, rs_v3_dot(f.t, f.b),
                 rs_v3_dot(f.t, n), rs_v3_dot(f.b, n));
    /* right-handed: t × b = n (not -n) */
    expect_v3_near(tb, n, tol, what);
    /* local z maps to n, local x to t */
    expect_v3_near(rs_onb_to_world(&f, rs_v3(0.0f, 0.0f, 1.0f)), n, tol, what);
    expect_v3_near(rs_onb_to_world(&f, rs_v3(1.0f, 0.0f, 0.0f)), f.t, tol, what);
}

static void test_onb_random_normals(void **state)
{
    uint64_t s = 0x5eed0004u;
    int i;
    (void)state;
    for (i = 0; i < 100000; ++i)
        expect_onb(rs_v3_normalize(rnd_unit(&s)), 2e-6f);
}

static void test_onb_near_poles(void **state)
{
    uint64_t s = 0x5eed0005u;
    int i;
    (void)state;
    expect_onb(rs_v3(0.0f, 0.0f, 1.0f), 1e-7f);
    expect_onb(rs_v3(0.0f, 0.0f, -1.0f), 1e-7f);
    /* z = -0: copysign gives sign -1, the frame must still be right-handed */
    expect_onb(rs_v3(1.0f, 0.0f, -0.0f), 1e-7f);
    expect_onb(rs_v3(0.0f, 1.0f, -0.0f), 1e-7f);
    expect_onb(rs_v3(0.0f, -1.0f, 0.0f), 1e-7f);
    expect_onb(rs_v3(-1.0f, 0.0f, 0.0f), 1e-7f);
    for (i = 0; i < 100000; ++i) {
        /* tilt of 1e-7 .. 1e-1 radians away from +z or -z, random azimuth */
        float tilt = powf(10.0f, rnd_range(&s, -7.0f, -1.0f));
        float phi = rnd_range(&s, 0.0f, 6.2831853f);
        float zs = (i & 1) ? -1.0f : 1.0f;
        rs_vec3 n =
            rs_v3_normalize(rs_v3(sinf(tilt) * cosf(phi), sinf(tilt) * sinf(phi), zs * cosf(tilt)));
        expect_onb(n, 2e-6f);
    }
}

/* ---- rs_fmaxf / rs_fminf against libm ------------------------------------------------------ */

static uint32_t float_bits(float f)
{
    uint32_t u;
    memcpy(&u, &f, sizeof u);
    return u;
}

static void test_fmax_fmin_match_libm(void **state)
{
    /* through volatile pointers: the compiler must call libm, not fold or inline the calls */
    float (*volatile lib_max)(float, float) = fmaxf;
    float (*volatile lib_min)(float, float) = fminf;
    float v[64];
    uint64_t s = 99;
    int n = 0, i, j;
    (void)state;
    v[n++] = 0.0f;
    v[n++] = -0.0f;
    v[n++] = 1.0f;
    v[n++] = -1.0f;
    v[n++] = INFINITY;
    v[n++] = -INFINITY;
    v[n++] = NAN;
    v[n++] = -NAN;
    v[n++] = 1e-45f;
    v[n++] = -1e-45f;
    v[n++] = 0.05f;
    v[n++] = 0.95f;
    while (n < 64)
        v[n++] = rnd_range(&s, -2.0, 2.0);
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            assert_int_equal(float_bits(rs_fmaxf(v[i], v[j])), float_bits(lib_max(v[i], v[j])));
            assert_int_equal(float_bits(rs_fminf(v[i], v[j])), float_bits(lib_min(v[i], v[j])));
        }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_basic_ops),
        cmocka_unit_test(test_cross_orientation),
        cmocka_unit_test(test_cross_random_properties),
        cmocka_unit_test(test_normalize),
        cmocka_unit_test(test_rotate_y_known),
        cmocka_unit_test(test_rotate_y_properties),
        cmocka_unit_test(test_onb_random_normals),
        cmocka_unit_test(test_onb_near_poles),
        cmocka_unit_test(test_fmax_fmin_match_libm),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
