/* tests/shading_lights_test.c — light sampling (shading/lights.h) against analytic irradiance.
 *
 * The irradiance at a point x with unit normal n is E = integral of Le(w) max(0, n.w) dw; light
 * sampling estimates it as the mean of Le cos / pdf over samples of rs_light_sample_at (the pdf
 * is over solid angle and includes the light's pick probability).  Each case draws enough
 * samples (fixed seed) that the standard error is below 0.2% of E (asserted), and requires the
 * estimate within 1% of the exact value (then at least 5 standard errors: a correct sampler
 * fails with probability < 6e-7).  References, in double precision:
 *
 *   sphere of radiance L, radius r, centre at distance d, receiver normal at angle tau to the
 *   centre direction: the sphere fills the cone of half-angle theta_max, sin theta_max = r / d,
 *   and by symmetry integral of w over the cone = pi sin^2(theta_max) times the axis, so
 *       E = pi L (r / d)^2 cos(tau)      while the cone is above the horizon (tau + theta_max
 *                                         <= 90 degrees, so cos > 0 over it);
 *   polygon of radiance L (Lambert 1760; Arvo 1995, "Applications of irradiance tensors"):
 *       E = L / 2 |sum_i gamma_i n . unit(r_i x r_{i+1})|,   r_i = v_i - x,
 *   gamma_i the angle between r_i and r_{i+1}, while the polygon is above the horizon.  The signed
 *   sum is positive when the vertices wind counter-clockwise about n (right-handed about n);
 *   test_contour_reference checks this, and the formula itself, against known limits.
 *
 * Also: several lights picked in proportion to power still sum to the total irradiance,
 * rs_light_pdf_hit gives the same pdf as rs_light_sample_at for the sampled point, and a moving
 * sphere light is sampled where it is at the time asked for. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/intersect.h"
#include "scenes/scene.h"
#include "shading/lights.h"
#include "test_rand.h"

#define PI_D 3.14159265358979323846

/* ---- helpers ------------------------------------------------------------------------------- */

/* A float uniform in [0, 1) with 24 random bits: never rounds up to 1. */
static float rnd_f(uint64_t *s) { return (float)(splitmix64(s) >> 40) * 0x1.0p-24f; }

typedef struct d3 {
    double x, y, z;
} d3;

static d3 d3_of(rs_vec3 a)
{
    d3 r;
    r.x = a.x;
    r.y = a.y;
    r.z = a.z;
    return r;
}

static d3 d3_make(double x, double y, double z)
{
    d3 r;
    r.x = x;
    r.y = y;
    r.z = z;
    return r;
}

static d3 d3_sub(d3 a, d3 b) { return d3_make(a.x - b.x, a.y - b.y, a.z - b.z); }
static double d3_dot(d3 a, d3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static d3 d3_cross(d3 a, d3 b)
{
    return d3_make(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static d3 d3_unit(d3 a)
{
    double l = sqrt(d3_dot(a, a));
    return d3_make(a.x / l, a.y / l, a.z / l);
}
static rs_vec3 v3_of(d3 a) { return rs_v3((float)a.x, (float)a.y, (float)a.z); }

/* The signed contour sum  1/2 sum_i gamma_i n . unit(r_i x r_{i+1})  of a polygon seen from x:
 * the irradiance from radiance 1 (up to its sign, see the file comment). */
static double contour_sum(const d3 *v, int nv, d3 x, d3 n)
{
    double sum = 0.0;
    int i;
    for (i = 0; i < nv; ++i) {
        d3 a = d3_unit(d3_sub(v[i], x)), b = d3_unit(d3_sub(v[(i + 1) % nv], x));
        double gamma = acos(fmax(-1.0, fmin(1.0, d3_dot(a, b))));
        sum += gamma * d3_dot(n, d3_unit(d3_cross(a, b)));
    }
    return 0.5 * sum;
}

/* Irradiance at x (normal n) from a polygon of radiance L entirely above x's horizon. */
static double polygon_irradiance(const d3 *v, int nv, d3 x, d3 n, double L)
{
    int i;
    for (i = 0; i < nv; ++i)
        assert_true(d3_dot(n, d3_sub(v[i], x)) > 0.0); /* the formula's precondition */
    return L * fabs(contour_sum(v, nv, x, n));
}

static void quad_vertices(rs_vec3 q, rs_vec3 u, rs_vec3 v, d3 out[4])
{
    out[0] = d3_of(q);
    out[1] = d3_make((double)q.x + u.x, (double)q.y + u.y, (double)q.z + u.z);
    out[2] = d3_make((double)q.x + u.x + v.x, (double)q.y + u.y + v.y, (double)q.z + u.z + v.z);
    out[3] = d3_make((double)q.x + v.x, (double)q.y + v.y, (double)q.z + v.z);
}

typedef struct estimate {
    double mean, se;
} estimate;

/* Light-sampling estimate of the irradiance at x with normal n at `time` (first channel of Le,
 * which the scenes here keep grey), from `count` samples. */
static estimate irradiance_mc_at(const rs_scene *s, rs_vec3 x, rs_vec3 n, float time,
                                 uint64_t seed, int count)
{
    uint64_t st = seed;
    double sum = 0.0, sum2 = 0.0, var;
    estimate e;
    int i;
    for (i = 0; i < count; ++i) {
        rs_light_sample ls;
        double c, val = 0.0;
        float up = rnd_f(&st), u1 = rnd_f(&st), u2 = rnd_f(&st);
        if (rs_light_sample_at(s, x, time, up, u1, u2, &ls)) {
            assert_true(ls.pdf > 0.0f);
            c = d3_dot(d3_of(n), d3_of(ls.wi));
            if (c > 0.0)
                val = (double)ls.le.x * c / ls.pdf;
        }
        sum += val;
        sum2 += val * val;
    }
    e.mean = sum / count;
    var = fmax(0.0, sum2 / count - e.mean * e.mean);
    e.se = sqrt(var / (count - 1));
    return e;
}

static estimate irradiance_mc(const rs_scene *s, rs_vec3 x, rs_vec3 n, uint64_t seed, int count)
{
    return irradiance_mc_at(s, x, n, 0.0f, seed, count);
}

/* Asserts the estimate's standard error < 0.2% of the exact value and agreement within 1%. */
static void check_irradiance(const char *name, estimate e, double exact)
{
    double rel = (e.mean - exact) / exact;
    print_message("%-34s E %.6g  exact %.6g  rel err %+.4f%%  (se %.4f%%)\n", name, e.mean, exact,
                  100.0 * rel, 100.0 * e.se / exact);
    assert_true(exact > 0.0);
    assert_true(e.se < 0.002 * exact);
    assert_true(fabs(rel) <= 0.01);
}

static rs_scene *new_scene(void)
{
    rs_scene *s = NULL;
    assert_int_equal(rs_scene_create("lights-test", &s), RS_OK);
    return s;
}

static uint32_t add_light(rs_scene *s, float radiance, int two_sided)
{
    rs_material m = rs_mat_light(rs_v3_splat(radiance), two_sided);
    uint32_t id;
    assert_int_equal(rs_scene_add_material(s, &m, &id), RS_OK);
    return id;
}

/* A unit vector at angle `tau` (radians) from unit a, toward some fixed perpendicular. */
static d3 tilt(d3 a, double tau)
{
    d3 helper = fabs(a.x) < 0.9 ? d3_make(1, 0, 0) : d3_make(0, 1, 0);
    d3 p = d3_unit(d3_cross(a, helper));
    return d3_make(cos(tau) * a.x + sin(tau) * p.x, cos(tau) * a.y + sin(tau) * p.y,
                   cos(tau) * a.z + sin(tau) * p.z);
}

#define N_SAMPLES 400000

/* ---- the reference itself ------------------------------------------------------------------ */

/* The contour formula against limits it must reproduce, and its sign convention:
 *   a small square of area A at distance h straight along n: E -> A / h^2 (radiance 1), the
 *   signed sum positive when the vertices wind counter-clockwise about n;
 *   a huge square covering the sky: E -> pi. */
static void test_contour_reference(void **state)
{
    d3 v[4], x = d3_make(0, 0, 0), n = d3_make(0, 0, 1);
    double a = 1e-3, h = 1.0, big = 1e5;
    (void)state;
    v[0] = d3_make(-a, -a, h);
    v[1] = d3_make(a, -a, h);
    v[2] = d3_make(a, a, h);
    v[3] = d3_make(-a, a, h);
    assert_true(contour_sum(v, 4, x, n) > 0.0);
    assert_true(fabs(contour_sum(v, 4, x, n) / (4.0 * a * a / (h * h)) - 1.0) < 1e-5);
    /* the reverse winding flips the sign */
    v[1] = d3_make(-a, a, h);
    v[3] = d3_make(a, -a, h);
    assert_true(contour_sum(v, 4, x, n) < 0.0);
    v[0] = d3_make(-big, -big, h);
    v[1] = d3_make(big, -big, h);
    v[2] = d3_make(big, big, h);
    v[3] = d3_make(-big, big, h);
    assert_true(fabs(contour_sum(v, 4, x, n) - PI_D) < 1e-4);
}

/* ---- sphere lights ------------------------------------------------------------------------- */

static void sphere_case(double d_over_r, double tau_deg, uint64_t seed)
{
    const float r = 0.75f, L = 3.0f;
    rs_scene *s = new_scene();
    uint64_t st = seed;
    d3 c = d3_make(0.3, -0.2, 0.5), dir = d3_of(rnd_unit(&st)), xd, n;
    double d = d_over_r * r, tau = tau_deg * PI_D / 180.0, exact;
    estimate e;
    char name[96];
    assert_int_equal(rs_scene_add_sphere(s, v3_of(c), r, add_light(s, L, 0)), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_int_equal(s->n_lights, 1);
    xd = d3_make(c.x + d * dir.x, c.y + d * dir.y, c.z + d * dir.z);
    /* the normal faces the centre, tilted by tau; the whole cone stays above the horizon */
    n = tilt(d3_make(-dir.x, -dir.y, -dir.z), tau);
    assert_true(tau + asin(1.0 / d_over_r) <= 0.5 * PI_D);
    /* the receiver point and normal go to the library in float: use their float values */
    {
        rs_vec3 xf = v3_of(xd), nf = v3_of(n);
        d3 to_c = d3_sub(c, d3_of(xf));
        double dd = sqrt(d3_dot(to_c, to_c)), ct = d3_dot(d3_of(nf), to_c) / dd;
        exact = PI_D * L * (r / dd) * (r / dd) * ct;
        e = irradiance_mc(s, xf, nf, seed * 7 + 1, N_SAMPLES);
    }
    snprintf(name, sizeof name, "sphere d = %4.1f r, tilt %2.0f deg", d_over_r, tau_deg);
    check_irradiance(name, e, exact);
    rs_scene_destroy(s);
}

static void test_sphere_light(void **state)
{
    (void)state;
    sphere_case(1.5, 0.0, 1);
    sphere_case(3.0, 0.0, 2);
    sphere_case(20.0, 0.0, 3);
    sphere_case(1.5, 30.0, 4);
    sphere_case(3.0, 60.0, 5);
    sphere_case(20.0, 85.0, 6);
}

/* A sphere light that moves (rs_scene_add_moving_sphere: radius 0.75 from c0 = (-2, 0, 0) at
 * t = 0 to c1 = (2, 0, 0) at t = 1) is sampled where it is at the time asked for, c(t) = c0 + 4t x:
 * from x = (0.5, 2.5, 0.3), at t = 0, 0.25, ..., 1, every sample lies on the sphere around c(t)
 * (along wi at distance dist, with the outward normal there), its pdf is what rs_light_pdf_hit
 * gives at t, and the irradiance at x toward c(t) is pi L (r / d(t))^2.  At t = 0.75 a point
 * 0.22 from c(0.75), inside the sphere then (outside it at any t < 0.69), gets points on the
 * sphere around c(0.75) (sampled by area).  Sampling the sphere where it stands at t = 0
 * fails every check for t > 0. */
static void test_moving_sphere_light(void **state)
{
    const float r = 0.75f, L = 3.0f;
    rs_scene *s = new_scene();
    rs_vec3 x = rs_v3(0.5f, 2.5f, 0.3f);
    uint64_t st = 77;
    int k, i;
    (void)state;
    assert_int_equal(rs_scene_add_moving_sphere(s, rs_v3(-2, 0, 0), 0.0f, rs_v3(2, 0, 0), 1.0f, r,
                                                add_light(s, L, 0)),
                     RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_int_equal(s->n_lights, 1);
    for (k = 0; k <= 5; ++k) {
        /* k = 5: from inside, at t = 0.75 */
        float t = k < 5 ? 0.25f * (float)k : 0.75f;
        d3 c = d3_make(-2.0 + 4.0 * t, 0, 0);
        rs_vec3 from = k < 5 ? x : rs_v3((float)c.x + 0.1f, 0.2f, 0.0f);
        char name[96];
        for (i = 0; i < 2000; ++i) {
            rs_light_sample ls;
            d3 p, off;
            double rad, pdf_hit;
            memset(&ls, 0, sizeof ls);
            assert_int_equal(
                rs_light_sample_at(s, from, t, rnd_f(&st), rnd_f(&st), rnd_f(&st), &ls), 1);
            p = d3_of(ls.point);
            off = d3_sub(p, c);
            rad = sqrt(d3_dot(off, off));
            if (!(fabs(rad - r) <= 1e-4))
                fail_msg("t = %.2f: a sample at (%g, %g, %g), %g from the centre (%g, 0, 0) the "
                         "sphere has then (radius %g)",
                         t, p.x, p.y, p.z, rad, c.x, r);
            /* along wi, at dist; the normal is the outward one there */
            assert_true(rs_v3_length(rs_v3_sub(rs_v3_madd(from, ls.wi, ls.dist), ls.point)) <=
                        1e-4f);
            assert_true(fabs(d3_dot(d3_of(ls.n), off) / rad - 1.0) <= 1e-4);
            pdf_hit = rs_light_pdf_hit(s, 0, from, t, ls.wi, ls.dist, ls.n);
            assert_true(fabs(pdf_hit - ls.pdf) <= 1e-3 * ls.pdf);
        }
        if (k < 5) {
            d3 to_c = d3_sub(c, d3_of(x));
            double d = sqrt(d3_dot(to_c, to_c));
            rs_vec3 n = v3_of(d3_make(to_c.x / d, to_c.y / d, to_c.z / d));
            double ct = d3_dot(d3_of(n), to_c) / d;
            snprintf(name, sizeof name, "moving sphere at t = %.2f", t);
            check_irradiance(name, irradiance_mc_at(s, x, n, t, 80 + (uint64_t)k, N_SAMPLES / 2),
                             PI_D * L * (r / d) * (r / d) * ct);
        }
    }
    rs_scene_destroy(s);
}

/* ---- quad and triangle lights -------------------------------------------------------------- */

/* The Cornell box light (RTROYL v4): Q (213, 554, 227), u (130, 0, 0), v (0, 0, 105), radiance
 * 15, one-sided, emitting along u x v = -y. */
static const float k_cornell_q[3] = {213, 554, 227}, k_cornell_u[3] = {130, 0, 0},
                   k_cornell_v[3] = {0, 0, 105};

static void quad_case(const char *name, rs_vec3 x, d3 n, uint64_t seed)
{
    rs_scene *s = new_scene();
    rs_vec3 q = rs_v3(k_cornell_q[0], k_cornell_q[1], k_cornell_q[2]);
    rs_vec3 u = rs_v3(k_cornell_u[0], k_cornell_u[1], k_cornell_u[2]);
    rs_vec3 v = rs_v3(k_cornell_v[0], k_cornell_v[1], k_cornell_v[2]);
    rs_vec3 nf = v3_of(d3_unit(n));
    d3 vert[4];
    assert_int_equal(rs_scene_add_quad(s, q, u, v, add_light(s, 15.0f, 0)), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    quad_vertices(q, u, v, vert);
    check_irradiance(name, irradiance_mc(s, x, nf, seed, N_SAMPLES),
                     polygon_irradiance(vert, 4, d3_of(x), d3_of(nf), 15.0));
    rs_scene_destroy(s);
}

static void test_quad_light(void **state)
{
    (void)state;
    quad_case("quad: floor below the centre", rs_v3(278, 0, 279.5f), d3_make(0, 1, 0), 11);
    quad_case("quad: 50 below the centre", rs_v3(278, 504, 279.5f), d3_make(0, 1, 0), 12);
    quad_case("quad: floor, off to the side", rs_v3(60, 0, 480), d3_make(0, 1, 0), 13);
    quad_case("quad: beside it, near", rs_v3(380, 480, 200), d3_make(0, 1, 0), 14);
    quad_case("quad: tilted receiver", rs_v3(278, 300, 279.5f), d3_make(0.5, 1, -0.3), 15);
    quad_case("quad: steeply tilted receiver", rs_v3(100, 200, 100), d3_make(1, 0.2, 0.8), 16);
}

static void triangle_case(const char *name, int two_sided, rs_vec3 x, d3 n, uint64_t seed)
{
    rs_scene *s = new_scene();
    rs_vec3 v0 = rs_v3(-1.0f, 2.0f, -0.5f), v1 = rs_v3(1.5f, 2.2f, 0.0f),
            v2 = rs_v3(0.2f, 1.8f, 1.6f);
    rs_vec3 nf = v3_of(d3_unit(n));
    d3 vert[3];
    assert_int_equal(rs_scene_add_triangle(s, v0, v1, v2, add_light(s, 4.0f, two_sided)), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    vert[0] = d3_of(v0);
    vert[1] = d3_of(v1);
    vert[2] = d3_of(v2);
    check_irradiance(name, irradiance_mc(s, x, nf, seed, N_SAMPLES),
                     polygon_irradiance(vert, 3, d3_of(x), d3_of(nf), 4.0));
    rs_scene_destroy(s);
}

/* The triangle's normal (v1 - v0) x (v2 - v0) points down (-y, roughly), toward the receivers
 * below it; from above, a one-sided triangle gives exactly nothing and a two-sided one the same
 * irradiance as from below. */
static void test_triangle_light(void **state)
{
    rs_scene *s;
    rs_vec3 v0 = rs_v3(-1.0f, 2.0f, -0.5f), v1 = rs_v3(1.5f, 2.2f, 0.0f),
            v2 = rs_v3(0.2f, 1.8f, 1.6f);
    estimate e;
    d3 ng = d3_cross(d3_sub(d3_of(v1), d3_of(v0)), d3_sub(d3_of(v2), d3_of(v0)));
    (void)state;
    assert_true(ng.y < 0.0);
    triangle_case("triangle: below", 0, rs_v3(0.1f, 0.0f, 0.3f), d3_make(0, 1, 0), 21);
    triangle_case("triangle: below, off to the side", 0, rs_v3(2.5f, 0.5f, -1.5f), d3_make(0, 1, 0),
                  22);
    triangle_case("triangle: below, tilted receiver", 0, rs_v3(0.0f, 1.0f, 0.0f),
                  d3_make(0.4, 1, 0.5), 23);
    triangle_case("triangle: two-sided, from above", 1, rs_v3(0.3f, 3.5f, 0.4f), d3_make(0, -1, 0),
                  24);
    /* one-sided, seen from its back: no light at all */
    s = new_scene();
    assert_int_equal(rs_scene_add_triangle(s, v0, v1, v2, add_light(s, 4.0f, 0)), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    e = irradiance_mc(s, rs_v3(0.3f, 3.5f, 0.4f), rs_v3(0, -1, 0), 25, 10000);
    print_message("triangle: one-sided, from its back: E %g (exact 0)\n", e.mean);
    assert_true(e.mean == 0.0);
    rs_scene_destroy(s);
}

/* ---- several lights ------------------------------------------------------------------------ */

/* Two quads of different power (the Cornell light, radiance 15, and a dimmer, larger one on the
 * wall at x = 555 facing -x, radiance 2): picking in proportion to power must still estimate the
 * sum of their irradiances, and pick each light with probability power / total (binomial test,
 * 5 standard errors).  Then a sphere, a triangle and the two quads together. */
static void test_several_lights(void **state)
{
    rs_scene *s = new_scene();
    rs_vec3 q1 = rs_v3(213, 554, 227), u1 = rs_v3(130, 0, 0), v1 = rs_v3(0, 0, 105);
    rs_vec3 q2 = rs_v3(554, 100, 100), u2 = rs_v3(0, 300, 0), v2 = rs_v3(0, 0, 200);
    rs_vec3 x = rs_v3(200, 50, 250), nrm = v3_of(d3_unit(d3_make(0.6, 1, 0.1)));
    d3 a[4], b[4];
    double e1, e2, p1, frac_want;
    uint64_t st = 31;
    int i, on1 = 0, count = N_SAMPLES;
    (void)state;
    /* u2 x v2 = (300 * 200, 0, 0): +x, away from the room: flip to face -x */
    assert_int_equal(rs_scene_add_quad(s, q1, u1, v1, add_light(s, 15.0f, 0)), RS_OK);
    assert_int_equal(
        rs_scene_add_quad(s, rs_v3_add(q2, v2), u2, rs_v3_neg(v2), add_light(s, 2.0f, 0)), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_int_equal(s->n_lights, 2);
    quad_vertices(q1, u1, v1, a);
    quad_vertices(rs_v3_add(q2, v2), u2, rs_v3_neg(v2), b);
    e1 = polygon_irradiance(a, 4, d3_of(x), d3_of(nrm), 15.0);
    e2 = polygon_irradiance(b, 4, d3_of(x), d3_of(nrm), 2.0);
    print_message("two quads: E1 %.6g + E2 %.6g\n", e1, e2);
    check_irradiance("two quads (power-proportional pick)", irradiance_mc(s, x, nrm, 32, count),
                     e1 + e2);
    /* the pick frequencies: light 1 has power pi 130 105 15, light 2 pi 300 200 2 */
    p1 = 130.0 * 105.0 * 15.0;
    frac_want = p1 / (p1 + 300.0 * 200.0 * 2.0);
    for (i = 0; i < count; ++i) {
        rs_light_sample ls;
        memset(&ls, 0, sizeof ls); /* set on success only, which gcc cannot see through */
        assert_int_equal(rs_light_sample_at(s, x, 0.0f, rnd_f(&st), rnd_f(&st), rnd_f(&st), &ls),
                         1);
        on1 += fabs(ls.point.y - 554.0f) < 1e-2f;
    }
    print_message("two quads: light 1 picked %.5f of the time (power share %.5f)\n",
                  (double)on1 / count, frac_want);
    assert_true(fabs((double)on1 / count - frac_want) <=
                5.0 * sqrt(frac_want * (1.0 - frac_want) / count));
    rs_scene_destroy(s);

    /* all three kinds at once */
    {
        const float sr = 40.0f;
        d3 sc = d3_make(400, 300, 400), tri[3];
        rs_vec3 t0 = rs_v3(100, 400, 150), t1 = rs_v3(100, 400, 350), t2 = rs_v3(250, 450, 250);
        double es, et, dd;
        d3 to_c;
        s = new_scene();
        assert_int_equal(rs_scene_add_sphere(s, v3_of(sc), sr, add_light(s, 6.0f, 0)), RS_OK);
        assert_int_equal(rs_scene_add_quad(s, q1, u1, v1, add_light(s, 15.0f, 0)), RS_OK);
        assert_int_equal(
            rs_scene_add_quad(s, rs_v3_add(q2, v2), u2, rs_v3_neg(v2), add_light(s, 2.0f, 0)),
            RS_OK);
        /* (t1 - t0) x (t2 - t0) = (0, 0, 200) x (150, 50, 100) = (-10000, 30000, 0): it faces up,
         * away from x, so it is made two-sided */
        assert_int_equal(rs_scene_add_triangle(s, t0, t1, t2, add_light(s, 5.0f, 1)), RS_OK);
        assert_int_equal(rs_scene_finalize(s), RS_OK);
        assert_int_equal(s->n_lights, 4);
        tri[0] = d3_of(t0);
        tri[1] = d3_of(t1);
        tri[2] = d3_of(t2);
        et = polygon_irradiance(tri, 3, d3_of(x), d3_of(nrm), 5.0);
        to_c = d3_sub(sc, d3_of(x));
        dd = sqrt(d3_dot(to_c, to_c));
        assert_true(acos(d3_dot(d3_of(nrm), to_c) / dd) + asin(sr / dd) < 0.5 * PI_D);
        es = PI_D * 6.0 * (sr / dd) * (sr / dd) * d3_dot(d3_of(nrm), to_c) / dd;
        print_message("four lights: sphere %.6g, quads %.6g + %.6g, triangle %.6g\n", es, e1, e2,
                      et);
        check_irradiance("sphere + two quads + triangle", irradiance_mc(s, x, nrm, 33, count),
                         es + e1 + e2 + et);
        rs_scene_destroy(s);
    }
}

/* ---- punctual lights ------------------------------------------------------------------------ */

/* Estimates from `subset`: the mean of Le cos / pdf (first channel). */
static estimate irradiance_subset(const rs_scene *s, int subset, rs_vec3 x, rs_vec3 n,
                                  uint64_t seed, int count)
{
    uint64_t st = seed;
    double sum = 0.0, sum2 = 0.0;
    estimate e;
    int i;
    for (i = 0; i < count; ++i) {
        rs_light_sample ls;
        double val = 0.0;
        float up = rnd_f(&st), u1 = rnd_f(&st), u2 = rnd_f(&st);
        if (rs_light_sample_in(s, subset, x, 0.0f, up, u1, u2, &ls)) {
            double c = d3_dot(d3_of(n), d3_of(ls.wi));
            if (c > 0.0)
                val = (double)ls.le.x * c / ls.pdf;
        }
        sum += val;
        sum2 += val * val;
    }
    e.mean = sum / count;
    e.se = sqrt(fmax(0.0, sum2 / count - e.mean * e.mean) / (count - 1));
    return e;
}

/* A point light of intensity I at distance d gives E = I cos / d^2; a spot the same times glTF's
 * falloff; a directional light E cos.  With an emitter quad besides: every light through
 * RS_LIGHTS_ALL sums to the total, RS_LIGHTS_DELTA to the punctual lights' part and
 * RS_LIGHTS_AREA to the quad's, each from its own pick probabilities (12 times the samples for
 * the mixes: the pick follows power, not what each light gives x). */
static void test_punctual(void **state)
{
    rs_scene *s = new_scene();
    rs_punctual p;
    rs_vec3 x = rs_v3(1, 0, 0), n = v3_of(d3_unit(d3_make(0.2, 1, -0.1)));
    rs_vec3 q = rs_v3(-1, 6, -1), u = rs_v3(0, 0, 2), v = rs_v3(2, 0, 0);
    d3 pp = d3_make(2, 4, 1), sp = d3_make(0, 3, 0), to, quad[4];
    double e_point, e_spot, e_dir, e_quad, c, cd, t;
    (void)state;
    memset(&p, 0, sizeof p);
    p.type = RS_PUNCTUAL_POINT;
    p.pos = v3_of(pp);
    p.intensity = rs_v3_splat(40.0f);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    p.type = RS_PUNCTUAL_SPOT;
    p.pos = v3_of(sp);
    p.dir = rs_v3(0.2f, -1, 0);
    p.intensity = rs_v3_splat(25.0f);
    p.cos_inner = cosf(0.05f);
    p.cos_outer = cosf(0.3f);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    p.type = RS_PUNCTUAL_DIRECTIONAL;
    p.dir = rs_v3(-0.3f, -1, 0.2f);
    p.intensity = rs_v3_splat(2.0f);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    /* u x v = (0, 0, 2) x (2, 0, 0) = (0, 4, 0): facing up, away from x: two-sided */
    assert_int_equal(rs_scene_add_quad(s, q, u, v, add_light(s, 3.0f, 1)), RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_int_equal(s->n_lights, 4u);
    assert_int_equal(s->n_area_lights, 1u);
    to = d3_sub(pp, d3_of(x));
    c = d3_dot(d3_of(n), d3_unit(to));
    e_point = 40.0 * c / d3_dot(to, to);
    to = d3_sub(sp, d3_of(x));
    c = d3_dot(d3_of(n), d3_unit(to));
    cd = -d3_dot(d3_unit(to), d3_unit(d3_make(0.2, -1, 0)));
    t = fmin(1.0, fmax(0.0, (cd - cos(0.3)) / (cos(0.05) - cos(0.3))));
    assert_true(t > 0.05 && t < 0.95); /* x lies in the falloff */
    e_spot = 25.0 * t * t * c / d3_dot(to, to);
    e_dir = 2.0 * d3_dot(d3_of(n), d3_unit(d3_make(0.3, 1, -0.2)));
    quad_vertices(q, u, v, quad);
    e_quad = polygon_irradiance(quad, 4, d3_of(x), d3_of(n), 3.0);
    print_message("point %.6g, spot %.6g, directional %.6g, quad %.6g\n", e_point, e_spot,
                  e_dir, e_quad);
    check_irradiance("every light (RS_LIGHTS_ALL)",
                     irradiance_subset(s, RS_LIGHTS_ALL, x, n, 41, 12 * N_SAMPLES),
                     e_point + e_spot + e_dir + e_quad);
    check_irradiance("punctual only (RS_LIGHTS_DELTA)",
                     irradiance_subset(s, RS_LIGHTS_DELTA, x, n, 42, 12 * N_SAMPLES),
                     e_point + e_spot + e_dir);
    check_irradiance("the quad only (RS_LIGHTS_AREA)",
                     irradiance_subset(s, RS_LIGHTS_AREA, x, n, 43, N_SAMPLES), e_quad);
    {
        /* outside the spot's outer cone it gives nothing */
        rs_light_sample ls;
        int k, lit = 0;
        uint64_t st = 44;
        for (k = 0; k < 2000; ++k)
            if (rs_light_sample_in(s, RS_LIGHTS_DELTA, rs_v3(5, 0, 0), 0.0f, rnd_f(&st),
                                   rnd_f(&st), rnd_f(&st), &ls) &&
                fabsf(ls.point.y - 3.0f) < 1e-6f && ls.point.x == 0.0f)
                ++lit;
        assert_int_equal(lit, 0);
    }
    rs_scene_destroy(s);
}

/* ---- pdf consistency ----------------------------------------------------------------------- */

/* For points x around a scene of a sphere, a one-sided quad and a two-sided triangle (all
 * lights; x sometimes inside the sphere, where it is sampled by area), every light sample's
 * reported pdf must equal rs_light_pdf_hit for the light the sample's own direction reaches at the
 * sampled distance (that light found by intersecting the ray with each light primitive), to
 * float rounding (relative 1e-3). */
static void test_pdf_consistency(void **state)
{
    rs_scene *s = new_scene();
    rs_geom g;
    uint64_t st = 41;
    double worst = 0.0;
    int i, checked = 0, inside = 0, per_light[3] = {0, 0, 0};
    (void)state;
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, add_light(s, 5.0f, 0)), RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-2, 3, -2), rs_v3(4, 0, 0), rs_v3(0, 0.5f, 3),
                                       add_light(s, 3.0f, 0)),
                     RS_OK);
    assert_int_equal(rs_scene_add_triangle(s, rs_v3(3, -1, -1), rs_v3(3, 1, 0), rs_v3(3.5f, 0, 2),
                                           add_light(s, 8.0f, 1)),
                     RS_OK);
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_int_equal(s->n_lights, 3);
    g = rs_scene_geom(s);
    for (i = 0; i < 20000; ++i) {
        rs_vec3 x = rnd_box(&st, 2.5f);
        rs_light_sample ls;
        rs_ray r;
        uint32_t l, best = UINT32_MAX;
        float best_dt = 1e30f, pdf_hit;
        if (!rs_light_sample_at(s, x, 0.0f, rnd_f(&st), rnd_f(&st), rnd_f(&st), &ls))
            continue;
        assert_true(ls.pdf > 0.0f);
        assert_true(fabs(rs_v3_length(ls.wi) - 1.0f) < 1e-5f);
        r = mk_ray(x, ls.wi, 0.0f, 1e30f);
        for (l = 0; l < s->n_lights; ++l) {
            float t, u, v;
            if (rs_geom_intersect(&g, s->lights[l].prim, &r, &t, &u, &v) &&
                fabsf(t - ls.dist) < best_dt) {
                best_dt = fabsf(t - ls.dist);
                best = l;
            }
        }
        /* the sampled point lies on the light along wi at distance dist */
        assert_true(best != UINT32_MAX);
        assert_true(best_dt <= 1e-3f * fmaxf(1.0f, ls.dist));
        {
            uint32_t prim = s->lights[best].prim;
            rs_vec3 p = rs_v3_madd(x, ls.wi, ls.dist);
            rs_vec3 ng = rs_prim_normal(s, prim, p, 0.0f);
            double cos_l = fabs(d3_dot(d3_of(ng), d3_of(ls.wi)));
            double rel;
            if (cos_l < 1e-2)
                continue; /* grazing: pdf ~ 1 / cos, too sensitive to float rounding */
            pdf_hit = rs_light_pdf_hit(s, best, x, 0.0f, ls.wi, ls.dist, ng);
            rel = fabs((double)pdf_hit - ls.pdf) / ls.pdf;
            worst = fmax(worst, rel);
            if (!(rel <= 1e-3))
                print_message("light %u at x (%g %g %g): sample pdf %g, pdf_hit %g\n", best, x.x,
                              x.y, x.z, ls.pdf, pdf_hit);
            assert_true(rel <= 1e-3);
            ++checked;
            inside += best == 0 && rs_v3_length(x) < 1.0f;
            ++per_light[best];
        }
    }
    print_message("pdf consistency: %d samples (sphere %d, %d of them from inside it; quad %d; "
                  "triangle %d), largest relative difference %.2e\n",
                  checked, per_light[0], inside, per_light[1], per_light[2], worst);
    assert_true(per_light[0] > 1000 && per_light[1] > 1000 && per_light[2] > 1000);
    assert_true(inside > 100);
    rs_scene_destroy(s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_contour_reference), cmocka_unit_test(test_sphere_light),
        cmocka_unit_test(test_moving_sphere_light),
        cmocka_unit_test(test_quad_light),        cmocka_unit_test(test_triangle_light),
        cmocka_unit_test(test_several_lights),    cmocka_unit_test(test_pdf_consistency),
        cmocka_unit_test(test_punctual),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
