/* tests/scenes_sky_test.c — the Preetham daylight sky and sun (scenes/sky.h):
 *   - the zenith values (Y_z, x_z, y_z) and the Perez distribution are the paper's formulas
 *     (Preetham, Shirley, Smits 1999, Appendix A.2), evaluated here again in double from their own
 *     copy of the coefficients, at several turbidities and sun angles, through xyY -> XYZ ->
 *     linear sRGB; Y_z(T = 3, 45 degrees) is the number the formula prints (7.3204 kcd/m^2), and
 *     the whole sky agrees within 1% with Mitsuba 0.5's sky (mitsuba-renderer/mitsuba,
 *     src/luminaires/sky.cpp, SkyLuminaire::configure: the same model with Preetham's unrounded
 *     coefficients);
 *   - the sun's luminance at the zenith (clear, T = 2) is the textbook 1.6e9 cd/m^2 within 10%,
 *     and the sun reddens as it sets;
 *   - the sky is brighter toward the sun than opposite it at equal elevation; the horizon is
 *     brighter than the zenith 90 degrees away from the sun; more turbidity whitens it;
 *   - the image: the texel that shading/envmap.h maps the sun's direction to holds the sun; the
 *     sun's power in the image (sum of radiance times texel solid angle) is the disc's within 1%
 *     at several elevations and azimuths (the seam, the pole, a coarse image), half of it at
 *     elevation 0; texels away from the disc are the sky's alone;
 *   - below the horizon every texel is the ground: albedo / pi times the horizontal irradiance
 *     the image itself gives (within 2%); a white plane under the default sky reflects ~1.0;
 *   - intensity scales everything; bad parameters and sizes are refused;
 *   - rs_sky_parse accepts the documented forms and refuses unknown keys, values out of range and
 *     junk with one line naming the key. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "scenes/sky.h"
#include "shading/envmap.h"

#define PI_D 3.14159265358979323846

/* ---- the paper's formulas, typed again ---- */

/* Appendix A.2: A..E for Y, x, y as (slope in T, intercept) */
static const double pz[3][5][2] = {
    {{0.1787, -1.4630}, {-0.3554, 0.4275}, {-0.0227, 5.3251}, {0.1206, -2.5771}, {-0.0670, 0.3703}},
    {{-0.0193, -0.2592},
     {-0.0665, 0.0008},
     {-0.0004, 0.2125},
     {-0.0641, -0.8989},
     {-0.0033, 0.0452}},
    {{-0.0167, -0.2608},
     {-0.0950, 0.0092},
     {-0.0079, 0.2102},
     {-0.0441, -1.6537},
     {-0.0109, 0.0529}},
};
/* Mitsuba 0.5 sky.cpp's coefficients (Preetham's code, unrounded) */
static const double pz_mts[3][5][2] = {
    {{0.17872, -1.46303},
     {-0.35540, 0.42749},
     {-0.02266, 5.32505},
     {0.12064, -2.57705},
     {-0.06696, 0.37027}},
    {{-0.01925, -0.25922},
     {-0.06651, 0.00081},
     {-0.00041, 0.21247},
     {-0.06409, -0.89887},
     {-0.00325, 0.04517}},
    {{-0.01669, -0.26078},
     {-0.09495, 0.00921},
     {-0.00792, 0.21023},
     {-0.04405, -1.65369},
     {-0.01092, 0.05291}},
};

typedef struct ref_sky {
    double c[3][5], zen[3], ts;
} ref_sky;

static double paper_Yz(double T, double ts)
{
    double chi = (4.0 / 9.0 - T / 120.0) * (PI_D - 2.0 * ts);
    return (4.0453 * T - 4.9710) * tan(chi) - 0.2155 * T + 2.4192;
}

/* x_z, y_z: [T^2 T 1] M [ts^3 ts^2 ts 1]^T with the paper's matrices (mitsuba = 1: Mitsuba's) */
static double paper_xz(double T, double t, int mitsuba)
{
    if (mitsuba)
        return (0.00165 * t * t * t - 0.00374 * t * t + 0.00208 * t) * T * T +
               (-0.02902 * t * t * t + 0.06377 * t * t - 0.03202 * t + 0.00394) * T +
               (0.11693 * t * t * t - 0.21196 * t * t + 0.06052 * t + 0.25885);
    return T * T * (0.00166 * t * t * t - 0.00375 * t * t + 0.00209 * t) +
           T * (-0.02903 * t * t * t + 0.06377 * t * t - 0.03202 * t + 0.00394) +
           (0.11693 * t * t * t - 0.21196 * t * t + 0.06052 * t + 0.25886);
}

static double paper_yz(double T, double t, int mitsuba)
{
    if (mitsuba)
        return (0.00275 * t * t * t - 0.00610 * t * t + 0.00316 * t) * T * T +
               (-0.04214 * t * t * t + 0.08970 * t * t - 0.04153 * t + 0.00515) * T +
               (0.15346 * t * t * t - 0.26756 * t * t + 0.06669 * t + 0.26688);
    return T * T * (0.00275 * t * t * t - 0.00610 * t * t + 0.00317 * t) +
           T * (-0.04214 * t * t * t + 0.08970 * t * t - 0.04153 * t + 0.00516) +
           (0.15346 * t * t * t - 0.26756 * t * t + 0.06670 * t + 0.26688);
}

static void ref_init(ref_sky *r, double T, double elevation_deg, int mitsuba)
{
    int c, k;
    r->ts = (90.0 - elevation_deg) * PI_D / 180.0;
    for (c = 0; c < 3; c++)
        for (k = 0; k < 5; k++)
            r->c[c][k] = (mitsuba ? pz_mts : pz)[c][k][0] * T + (mitsuba ? pz_mts : pz)[c][k][1];
    r->zen[0] = paper_Yz(T, r->ts);
    r->zen[1] = paper_xz(T, r->ts, mitsuba);
    r->zen[2] = paper_yz(T, r->ts, mitsuba);
}

static double ref_perez(const double *c, double theta, double gamma)
{
    return (1 + c[0] * exp(c[1] / cos(theta))) *
           (1 + c[2] * exp(c[3] * gamma) + c[4] * cos(gamma) * cos(gamma));
}

/* xyY -> XYZ -> linear sRGB (IEC 61966-2-1), times the module's scale */
static void ref_rgb(double x, double y, double Y, double out[3])
{
    double X = x / y * Y, Z = (1 - x - y) / y * Y;
    out[0] = (3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z) * RS_SKY_SCALE;
    out[1] = (-0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z) * RS_SKY_SCALE;
    out[2] = (0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z) * RS_SKY_SCALE;
}

/* the reference sky toward (theta, gamma) */
static void ref_sky_rgb(const ref_sky *r, double theta, double gamma, double out[3])
{
    double v[3];
    int c;
    for (c = 0; c < 3; c++)
        v[c] = r->zen[c] * ref_perez(r->c[c], theta, gamma) / ref_perez(r->c[c], 0, r->ts);
    ref_rgb(v[1], v[2], v[0], out);
}

static double lum(rs_vec3 c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

static rs_sky_params params(float el, float az, float T)
{
    rs_sky_params p;
    rs_sky_defaults(&p);
    p.elevation_deg = el;
    p.azimuth_deg = az;
    p.turbidity = T;
    return p;
}

/* the unit direction at elevation el, azimuth az (degrees), the sun's convention */
static rs_vec3 dir(double el, double az)
{
    el *= PI_D / 180;
    az *= PI_D / 180;
    return rs_v3((float)(cos(el) * sin(az)), (float)sin(el), (float)(-cos(el) * cos(az)));
}

static void expect_rel(double got, double want, double tol, const char *what)
{
    if (!(fabs(got - want) <= tol * fabs(want) + 1e-9))
        fail_msg("%s: %.9g, want %.9g (tolerance %g)", what, got, want, tol);
}

/* ---- the model ---- */

static void test_defaults(void **state)
{
    rs_sky_params p;
    rs_vec3 s;
    (void)state;
    rs_sky_defaults(&p);
    assert_true(p.elevation_deg == 45.0f && p.azimuth_deg == 0.0f && p.turbidity == 3.0f &&
                p.intensity == 1.0f && p.sun == 1);
    s = rs_sky_sun_direction(&p);
    expect_rel(s.x, 0.0, 1e-6, "sun x");
    expect_rel(s.y, sqrt(0.5), 1e-6, "sun y");
    expect_rel(s.z, -sqrt(0.5), 1e-6, "sun z");
    p.azimuth_deg = 90.0f;
    p.elevation_deg = 0.0f;
    s = rs_sky_sun_direction(&p);
    expect_rel(s.x, 1.0, 1e-6, "azimuth 90 lies toward +x");
}

/* The zenith: F(0, theta_s) / F(0, theta_s) = 1, so the radiance there is the zenith's xyY. */
static void test_zenith_matches_paper(void **state)
{
    static const double cases[][2] = {{2, 90}, {3, 45}, {4, 30}, {6, 60}, {8, 15}, {10, 5}, {3, 0}};
    size_t k;
    (void)state;
    /* the formula's value at T = 3, theta_s = 45 degrees: chi = (4/9 - 1/40) pi / 2 */
    expect_rel(paper_Yz(3, PI_D / 4), 7.3203583, 1e-7, "Y_z(3, 45 deg)");
    for (k = 0; k < sizeof cases / sizeof *cases; k++) {
        double T = cases[k][0], el = cases[k][1], want[3];
        rs_sky_params p = params((float)el, 0, (float)T);
        rs_vec3 got = rs_sky_radiance(&p, rs_v3(0, 1, 0));
        double ts = (90 - el) * PI_D / 180;
        char what[64];
        ref_rgb(paper_xz(T, ts, 0), paper_yz(T, ts, 0), paper_Yz(T, ts), want);
        snprintf(what, sizeof what, "zenith T=%g el=%g", T, el);
        expect_rel(got.x, want[0], 1e-4, what);
        expect_rel(got.y, want[1], 1e-4, what);
        expect_rel(got.z, want[2], 1e-4, what);
    }
}

/* Everywhere above the horizon: the Perez ratio times the zenith values. */
static void test_perez_matches_paper(void **state)
{
    static const double cases[][2] = {{2, 60}, {3, 45}, {5, 20}, {10, 70}};
    static const double dirs[][2] = {{80, 0}, {40, 0}, {30, 90}, {10, 180}, {2, -135}, {60, 30}};
    size_t k, q;
    (void)state;
    for (k = 0; k < sizeof cases / sizeof *cases; k++) {
        double T = cases[k][0], el = cases[k][1];
        rs_sky_params p = params((float)el, 0, (float)T);
        ref_sky r, m;
        ref_init(&r, T, el, 0);
        ref_init(&m, T, el, 1);
        for (q = 0; q < sizeof dirs / sizeof *dirs; q++) {
            rs_vec3 d = dir(dirs[q][0], dirs[q][1]), s = rs_sky_sun_direction(&p);
            rs_vec3 got = rs_sky_radiance(&p, d);
            double theta = acos(d.y), gamma = acos(fmin(1.0, rs_v3_dot(d, s))), want[3], mts[3];
            char what[96];
            ref_sky_rgb(&r, theta, gamma, want);
            ref_sky_rgb(&m, theta, gamma, mts);
            snprintf(what, sizeof what, "T=%g sun el=%g toward (%g, %g)", T, el, dirs[q][0],
                     dirs[q][1]);
            expect_rel(got.x, want[0], 1e-4, what);
            expect_rel(got.y, want[1], 1e-4, what);
            expect_rel(got.z, want[2], 1e-4, what);
            /* Mitsuba 0.5's rounding of the same model */
            expect_rel(lum(got), 0.2126 * mts[0] + 0.7152 * mts[1] + 0.0722 * mts[2], 0.01, what);
        }
    }
}

static void test_sky_shape(void **state)
{
    float el;
    (void)state;
    for (el = 10; el <= 60; el += 25) {
        rs_sky_params p = params(el, 30, 3);
        /* toward the sun vs opposite, at the sun's elevation and at 10 degrees */
        assert_true(lum(rs_sky_radiance(&p, dir(el, 30))) >
                    2 * lum(rs_sky_radiance(&p, dir(el, 210))));
        assert_true(lum(rs_sky_radiance(&p, dir(10, 30))) > lum(rs_sky_radiance(&p, dir(10, 210))));
    }
    {
        /* away from the sun (90 degrees of azimuth) the horizon outshines the zenith */
        rs_sky_params p = params(45, 0, 3);
        assert_true(lum(rs_sky_radiance(&p, dir(1, 90))) > lum(rs_sky_radiance(&p, dir(90, 0))));
        p = params(30, 0, 2);
        assert_true(lum(rs_sky_radiance(&p, dir(1, 90))) > lum(rs_sky_radiance(&p, dir(90, 0))));
    }
    {
        /* haze whitens: blue / red falls as turbidity rises, at the zenith and 90 degrees away */
        double last_z = 1e30, last_h = 1e30;
        float T;
        for (T = 2; T <= 10; T += 2) {
            rs_sky_params p = params(45, 0, T);
            rs_vec3 z = rs_sky_radiance(&p, dir(90, 0)), h = rs_sky_radiance(&p, dir(20, 90));
            assert_true(z.z / z.x < last_z);
            assert_true(h.z / h.x < last_h);
            last_z = z.z / z.x;
            last_h = h.z / h.x;
        }
        assert_true(last_z < 1.6); /* T = 10: nearly white (3.4 at T = 2) */
    }
}

static void test_sun_radiance(void **state)
{
    rs_sky_params p = params(90, 0, 2);
    double L = lum(rs_sky_sun_radiance(&p)) / RS_SKY_SCALE * 1000.0; /* cd/m^2 */
    rs_vec3 hi, lo;
    (void)state;
    if (L < 1.6e9 * 0.9 || L > 1.6e9 * 1.1)
        fail_msg("noon sun luminance %.4g cd/m^2, want 1.6e9 within 10%%", L);
    p = params(60, 0, 3);
    hi = rs_sky_sun_radiance(&p);
    p.elevation_deg = 5;
    lo = rs_sky_sun_radiance(&p);
    assert_true(lo.z / lo.x < 0.5 * hi.z / hi.x); /* redder low */
    assert_true(lum(lo) < lum(hi));
    p.turbidity = 8; /* hazier: dimmer */
    assert_true(lum(rs_sky_sun_radiance(&p)) < lum(lo));
}

/* ---- the image ---- */

static double texel_solid_angle(uint32_t w, uint32_t h, uint32_t j)
{
    return 2 * PI_D / w * (cos(PI_D * j / h) - cos(PI_D * (j + 1) / h));
}

static float *image(const rs_sky_params *p, uint32_t w, uint32_t h)
{
    float *im = NULL;
    if (rs_sky_image(p, w, h, &im) != RS_OK)
        fail_msg("rs_sky_image: %s", rs_error_message());
    return im;
}

static void test_sun_in_image(void **state)
{
    static const float cases[][2] = {{45, 0}, {5, 30}, {30, 180}, {60, -100}, {90, 0}, {0, 45}};
    const double disc = 2 * PI_D * (1 - cos(RS_SKY_SUN_RADIUS_DEG * PI_D / 180));
    const uint32_t W = RS_SKY_WIDTH, H = RS_SKY_HEIGHT;
    size_t k;
    (void)state;
    for (k = 0; k < sizeof cases / sizeof *cases; k++) {
        rs_sky_params p = params(cases[k][0], cases[k][1], 3), q;
        float *with = image(&p, W, H), *without;
        rs_vec3 s = rs_sky_sun_direction(&p), L = rs_sky_sun_radiance(&p);
        rs_image im;
        uint32_t i, j, si, sj, c;
        float st;
        double power[3] = {0, 0, 0}, want;
        q = p;
        q.sun = 0;
        without = image(&q, W, H);
        im.width = W;
        im.height = H;
        im.rgb = with;
        rs_env_texel_of(&im, s, &si, &sj, &st);
        /* the sun's texel by the renderer's own mapping is a sun texel */
        if (cases[k][0] > 0.5f) {
            float *t = &with[3 * ((size_t)sj * W + si)];
            if (!(t[1] > 0.25 * L.y))
                fail_msg("el %g az %g: texel (%u, %u) holds %g, the sun %g", cases[k][0],
                         cases[k][1], si, sj, t[1], L.y);
        }
        for (j = 0; j < H; j++) {
            double om = texel_solid_angle(W, H, j);
            for (i = 0; i < W; i++) {
                const float *a = &with[3 * ((size_t)j * W + i)],
                            *b = &without[3 * ((size_t)j * W + i)];
                if (a[0] == b[0] && a[1] == b[1] && a[2] == b[2])
                    continue;
                /* only texels near the disc differ: within 3 texels' angle of its edge */
                {
                    double th = (j + 0.5) * PI_D / H, ph = ((i + 0.5) / W - 0.5) * 2 * PI_D;
                    rs_vec3 d = rs_v3((float)(sin(th) * sin(ph)), (float)cos(th),
                                      (float)(-sin(th) * cos(ph)));
                    double ang = acos(fmin(1.0, rs_v3_dot(d, s)));
                    if (ang > RS_SKY_SUN_RADIUS_DEG * PI_D / 180 + 3.5 * PI_D / H)
                        fail_msg("texel (%u, %u) %g degrees from the sun differs", i, j,
                                 ang * 180 / PI_D);
                }
                for (c = 0; c < 3; c++)
                    power[c] += ((double)a[c] - b[c]) * om;
            }
        }
        want = lum(L) * disc * (cases[k][0] == 0 ? 0.5 : 1.0);
        {
            char what[64];
            snprintf(what, sizeof what, "sun power el %g az %g", cases[k][0], cases[k][1]);
            expect_rel(0.2126 * power[0] + 0.7152 * power[1] + 0.0722 * power[2], want,
                       cases[k][0] == 0 ? 0.05 : 0.01, what);
            if (cases[k][0] > 0)
                expect_rel(power[0], L.x * disc, 0.01, what);
        }
        rs_free(with);
        rs_free(without);
    }
    {
        /* a coarse image: the disc far smaller than a texel still carries its power */
        rs_sky_params p = params(37, 12, 4), q = p;
        float *with = image(&p, 64, 32), *without;
        double power = 0;
        uint32_t i, j;
        q.sun = 0;
        without = image(&q, 64, 32);
        for (j = 0; j < 32; j++)
            for (i = 0; i < 64; i++)
                power += ((double)with[3 * (j * 64 + i) + 1] - without[3 * (j * 64 + i) + 1]) *
                         texel_solid_angle(64, 32, j);
        expect_rel(power, rs_sky_sun_radiance(&p).y * disc, 0.01, "coarse sun power");
        rs_free(with);
        rs_free(without);
    }
}

/* Below the horizon: the ground, albedo / pi times the irradiance the image's upper half gives
 * a horizontal plane; and the scale: a white plane under the default sky reflects about 1. */
static void test_ground_and_scale(void **state)
{
    const uint32_t W = RS_SKY_WIDTH, H = RS_SKY_HEIGHT;
    float els[] = {45, 10, 80};
    size_t k;
    (void)state;
    for (k = 0; k < 3; k++) {
        rs_sky_params p = params(els[k], 20, 3);
        float *im = image(&p, W, H);
        rs_vec3 g = rs_sky_ground_radiance(&p), r = rs_sky_radiance(&p, rs_v3(0.3f, -0.5f, 0.1f));
        double e[3] = {0, 0, 0};
        uint32_t i, j, c;
        for (j = 0; j < H / 2; j++) {
            double om = texel_solid_angle(W, H, j), ct = cos((j + 0.5) * PI_D / H);
            for (i = 0; i < W; i++)
                for (c = 0; c < 3; c++)
                    e[c] += im[3 * ((size_t)j * W + i) + c] * om * ct;
        }
        for (j = H / 2; j < H; j++)
            for (i = 0; i < W; i += 7)
                assert_true(im[3 * ((size_t)j * W + i)] == g.x &&
                            im[3 * ((size_t)j * W + i) + 2] == g.z);
        assert_true(r.x == g.x && r.y == g.y && r.z == g.z);
        expect_rel(g.x, RS_SKY_GROUND_ALBEDO / PI_D * e[0], 0.02, "ground red");
        expect_rel(g.y, RS_SKY_GROUND_ALBEDO / PI_D * e[1], 0.02, "ground green");
        expect_rel(g.z, RS_SKY_GROUND_ALBEDO / PI_D * e[2], 0.02, "ground blue");
        assert_true(g.y > 0);
        if (els[k] == 45) {
            double white = (0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]) / PI_D;
            if (white < 0.9 || white > 1.1)
                fail_msg("a white plane under the default sky reflects %g, want ~1", white);
        }
        rs_free(im);
    }
}

static void test_intensity_and_bad_args(void **state)
{
    rs_sky_params p = params(30, 10, 4), q = p;
    rs_vec3 a, b;
    float *im = (float *)&p;
    (void)state;
    q.intensity = 2.5f;
    a = rs_sky_radiance(&p, dir(20, 50));
    b = rs_sky_radiance(&q, dir(20, 50));
    expect_rel(b.y, 2.5 * a.y, 1e-6, "intensity, sky");
    expect_rel(rs_sky_sun_radiance(&q).x, 2.5 * rs_sky_sun_radiance(&p).x, 1e-6, "intensity, sun");
    expect_rel(rs_sky_ground_radiance(&q).z, 2.5 * rs_sky_ground_radiance(&p).z, 1e-6,
               "intensity, ground");
    q = p;
    q.turbidity = 11;
    assert_int_equal(rs_sky_image(&q, 64, 32, &im), RS_ERR_ARG);
    assert_null(im);
    q = p;
    q.elevation_deg = -1;
    assert_int_equal(rs_sky_image(&q, 64, 32, &im), RS_ERR_ARG);
    q = p;
    q.sun = 2;
    assert_int_equal(rs_sky_image(&q, 64, 32, &im), RS_ERR_ARG);
    assert_int_equal(rs_sky_image(&p, 1, 32, &im), RS_ERR_ARG);
    assert_int_equal(rs_sky_image(&p, 64, 0, &im), RS_ERR_ARG);
    assert_int_equal(rs_sky_image(NULL, 64, 32, &im), RS_ERR_ARG);
    rs_alloc_fail_after(0);
    assert_int_equal(rs_sky_image(&p, 64, 32, &im), RS_ERR_NOMEM);
    rs_alloc_fail_after(-1);
    assert_null(im);
}

/* ---- parsing ---- */

static void expect_refused(const char *spec, const char *needle1, const char *needle2)
{
    rs_sky_params p;
    char why[200];
    rs_sky_defaults(&p);
    p.elevation_deg = 12.5f; /* left alone on failure */
    if (rs_sky_parse(spec, &p, why, sizeof why))
        fail_msg("'sky%s' was accepted", spec);
    assert_true(p.elevation_deg == 12.5f);
    if (!strstr(why, needle1) || (needle2 && !strstr(why, needle2)))
        fail_msg("'sky%s': message '%s' lacks '%s' / '%s'", spec, why, needle1,
                 needle2 ? needle2 : "");
    assert_null(strchr(why, '\n'));
}

static void test_parse(void **state)
{
    rs_sky_params p;
    char why[200];
    (void)state;
    memset(&p, 0, sizeof p);
    assert_true(rs_sky_parse("", &p, why, sizeof why));
    assert_true(p.elevation_deg == 45 && p.azimuth_deg == 0 && p.turbidity == 3 &&
                p.intensity == 1 && p.sun == 1);
    assert_true(rs_sky_parse(":elevation=30,azimuth=120,turbidity=4,intensity=2,sun=0", &p, why,
                             sizeof why));
    assert_true(p.elevation_deg == 30 && p.azimuth_deg == 120 && p.turbidity == 4 &&
                p.intensity == 2 && p.sun == 0);
    assert_true(rs_sky_parse(":turbidity=2.5", &p, why, sizeof why));
    assert_true(p.turbidity == 2.5f && p.elevation_deg == 45 && p.sun == 1); /* the rest default */
    assert_true(rs_sky_parse(":elevation=0,azimuth=-360,turbidity=10,intensity=0", &p, NULL, 0));
    assert_true(rs_sky_parse(":elevation=90,azimuth=360,elevation=1e1", &p, why, 4));
    assert_true(p.elevation_deg == 10 && p.azimuth_deg == 360);

    expect_refused(":foo=1", "foo", "elevation");
    expect_refused(":elevation=30,colour=red", "colour", NULL);
    expect_refused(":turbidity=12", "turbidity", "2..10");
    expect_refused(":turbidity=1.5", "turbidity", "2..10");
    expect_refused(":elevation=-5", "elevation", "0..90");
    expect_refused(":elevation=91", "elevation", "0..90");
    expect_refused(":azimuth=400", "azimuth", "-360..360");
    expect_refused(":intensity=-1", "intensity", NULL);
    expect_refused(":sun=2", "sun", "0 or 1");
    expect_refused(":sun=0.5", "sun", NULL);
    expect_refused(":elevation=abc", "elevation", "not a number");
    expect_refused(":elevation=30x", "elevation", NULL);
    expect_refused(":elevation=nan", "elevation", NULL);
    expect_refused(":elevation=inf", "elevation", NULL);
    expect_refused(":elevation=", "elevation", NULL);
    expect_refused(":elevation", "elevation", "key=value");
    expect_refused(":", "empty", NULL);
    expect_refused(":elevation=30,", "empty", NULL);
    expect_refused("x", "':", NULL);
    expect_refused(":=3", "unknown key", NULL);
    /* a short buffer is cut, not overrun */
    memset(why, 'z', sizeof why);
    assert_false(rs_sky_parse(":turbidity=99", &p, why, 8));
    assert_int_equal(strlen(why), 7);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_defaults),
        cmocka_unit_test(test_zenith_matches_paper),
        cmocka_unit_test(test_perez_matches_paper),
        cmocka_unit_test(test_sky_shape),
        cmocka_unit_test(test_sun_radiance),
        cmocka_unit_test(test_sun_in_image),
        cmocka_unit_test(test_ground_and_scale),
        cmocka_unit_test(test_intensity_and_bad_args),
        cmocka_unit_test(test_parse),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
