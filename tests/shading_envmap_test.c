/* tests/shading_envmap_test.c — the environment map as a light (shading/envmap.h,
 * scenes/scene_env.c):
 *   - its pdf integrates to 1 over the sphere (midpoint quadrature, 2048 x 1024 cells);
 *   - the texels its samples land in follow the texel probabilities (chi-square, alpha = 0.001),
 *     and each sample's pdf and radiance are what rs_env_pdf and rs_env_radiance say for its
 *     direction;
 *   - light sampling estimates the irradiance the map gives a surface, against quadrature
 *     (within 1%, at least 5 standard errors);
 *   - the map's orientation and its rotation are as documented (-z is the image's middle, +y its
 *     top row);
 *   - a uniform map (every texel alike) is sampled uniformly over the sphere with constant pdf
 *     and radiance, turned or not (chi-square);
 *   - a furnace: an albedo-0.5 diffuse sphere under a uniform map renders 0.5 with every
 *     strategy (mis, mixture, bsdf, uniform), on the CPU device and the GPU fallback;
 *   - under a map with a small bright sun the four strategies agree on the image mean (as
 *     render_estimators_test checks for emitters) and MIS is less noisy than BSDF sampling;
 *   - bad maps (missing, negative or non-finite texels) are refused with one line. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "render_util.h"
#include "scenes/scene_json.h"
#include "shading/lights.h"
#include "test_files.h"
#include "test_rand.h"

#define PI_D 3.14159265358979323846
#define MW   32
#define MH   16

static float rnd_f(uint64_t *s) { return (float)(splitmix64(s) >> 40) * 0x1.0p-24f; }

/* A 32 x 16 map: a smooth sky, a black row (never sampled), and a bright 1-texel sun. */
static void sun_map(float *rgb)
{
    int i, j;
    for (j = 0; j < MH; ++j)
        for (i = 0; i < MW; ++i) {
            float *p = &rgb[3 * (j * MW + i)];
            float sky = 0.2f + 0.8f * (float)(MH - j) / MH + 0.1f * (float)((i * 7) % 5);
            p[0] = 0.5f * sky, p[1] = 0.7f * sky, p[2] = sky;
            if (j == 11)
                p[0] = p[1] = p[2] = 0.0f;
            if (j == 4 && i == 21)
                p[0] = 300.0f, p[1] = 250.0f, p[2] = 200.0f;
        }
}

/* A scene lit by map rgb (w x h) turned by `rot` (NULL: none), with a diffuse sphere of albedo
 * `albedo` at the origin (radius 1) when albedo >= 0, and a floor under it when `floor`. */
static rs_scene *env_scene(const float *rgb, uint32_t w, uint32_t h, const float *rot,
                           float albedo, int floor)
{
    rs_scene *s;
    uint32_t img, m;
    assert_int_equal(rs_scene_create("env", &s), RS_OK);
    assert_int_equal(rs_scene_add_image(s, w, h, rgb, &img), RS_OK);
    assert_int_equal(rs_scene_set_environment(s, img, rs_v3_splat(1.0f), rot), RS_OK);
    if (albedo >= 0) {
        rs_material mat = rs_mat_lambertian(rs_v3_splat(albedo));
        assert_int_equal(rs_scene_add_material(s, &mat, &m), RS_OK);
        assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, m), RS_OK);
        if (floor)
            assert_int_equal(rs_scene_add_quad(s, rs_v3(-4, -1, 4), rs_v3(8, 0, 0),
                                               rs_v3(0, 0, -8), m),
                             RS_OK);
    }
    s->camera.from = rs_v3(0, 0.5f, 4);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.vfov_deg = 40;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

static void test_pdf_normalised(void **state)
{
    float rgb[MW * MH * 3];
    static const float rot[9] = {0.36f, 0.48f, -0.8f, -0.8f, 0.6f, 0.0f, 0.48f, 0.64f, 0.6f};
    rs_scene *s;
    int i, j, r;
    (void)state;
    sun_map(rgb);
    for (r = 0; r < 2; ++r) {
        double sum = 0.0;
        const int NT = 1024, NP = 2048;
        s = env_scene(rgb, MW, MH, r ? rot : NULL, -1, 0);
        assert_true(s->env_pick == 1.0f);
        for (j = 0; j < NT; ++j) {
            double th = PI_D * (j + 0.5) / NT, dw = (PI_D / NT) * (2 * PI_D / NP) * sin(th);
            for (i = 0; i < NP; ++i) {
                double ph = 2 * PI_D * (i + 0.5) / NP;
                rs_vec3 d = rs_v3((float)(sin(th) * cos(ph)), (float)cos(th),
                                  (float)(sin(th) * sin(ph)));
                sum += rs_env_pdf(s, d) * dw;
            }
        }
        print_message("integral of the pdf (%s): %.6f\n", r ? "rotated" : "unrotated", sum);
        assert_true(fabs(sum - 1.0) < 2e-3);
        rs_scene_destroy(s);
    }
}

/* The inverse of the sampler's (u, v) mapping: texel (i, j) of a direction in the map's frame. */
static void texel_of_dir(const rs_scene *s, rs_vec3 d, uint32_t *i, uint32_t *j)
{
    float st;
    rs_env_texel_of(&s->images[s->env_image], rs_env_rot(s->env_rot, d), i, j, &st);
}

/* Wilson-Hilferty: the chi-square quantile for `dof` degrees of freedom at upper tail 0.001. */
static double chi2_crit_0001(int dof)
{
    const double z = 3.0902; /* the normal's 0.999 quantile */
    double k = dof, a = 2.0 / (9.0 * k);
    return k * pow(1.0 - a + z * sqrt(a), 3.0);
}

static void test_sampling_chi_square(void **state)
{
    float rgb[MW * MH * 3];
    static const float rot[9] = {0.36f, 0.48f, -0.8f, -0.8f, 0.6f, 0.0f, 0.48f, 0.64f, 0.6f};
    enum { N = 400000 };
    static double count[MW * MH];
    double expect[MW * MH], chi2 = 0, e_acc = 0, o_acc = 0;
    rs_scene *s;
    uint64_t st = 77;
    int k, dof = -1;
    uint32_t i, j;
    (void)state;
    sun_map(rgb);
    s = env_scene(rgb, MW, MH, rot, -1, 0);
    memset(count, 0, sizeof count);
    for (j = 0; j < MH; ++j)
        for (i = 0; i < MW; ++i)
            expect[j * MW + i] = N * (double)rs_env_texel_pdf(s, i, j) / (MW * MH);
    for (k = 0; k < N; ++k) {
        rs_vec3 wi, le, le2;
        float pdf, pdf2;
        if (!rs_env_sample(s, rnd_f(&st), rnd_f(&st), &wi, &pdf, &le))
            continue;
        texel_of_dir(s, wi, &i, &j);
        count[j * MW + i] += 1;
        pdf2 = rs_env_pdf(s, wi);
        le2 = rs_env_radiance(s, wi);
        /* the direction maps back into its texel but for rounding on a texel's edge */
        if (fabsf(pdf2 - pdf) > 1e-3f * pdf && k < 50)
            print_message("sample %d: pdf %g, pdf of its direction %g\n", k, pdf, pdf2);
        assert_true(fabsf(rs_v3_length(wi) - 1.0f) < 1e-5f);
        (void)le2;
    }
    /* the black row has probability 0 and gets nothing */
    for (i = 0; i < MW; ++i) {
        assert_true(expect[11 * MW + i] == 0.0);
        assert_true(count[11 * MW + i] == 0.0);
    }
    /* pool small cells (expected < 5) into one */
    for (k = 0; k < MW * MH; ++k) {
        if (expect[k] >= 5.0) {
            chi2 += (count[k] - expect[k]) * (count[k] - expect[k]) / expect[k];
            dof++;
        } else {
            e_acc += expect[k];
            o_acc += count[k];
        }
    }
    if (e_acc >= 5.0) {
        chi2 += (o_acc - e_acc) * (o_acc - e_acc) / e_acc;
        dof++;
    }
    print_message("chi-square %.1f for %d degrees of freedom (critical %.1f at 0.001)\n", chi2,
                  dof, chi2_crit_0001(dof));
    assert_true(dof > 100);
    assert_true(chi2 < chi2_crit_0001(dof));
    /* the sun texel, 1/512 of the map, draws most samples */
    assert_true(count[4 * MW + 21] > 0.5 * N);
    rs_scene_destroy(s);
}

/* Sampled pdf and radiance equal the direction's, away from texel edges. */
static void test_sample_consistency(void **state)
{
    float rgb[MW * MH * 3];
    rs_scene *s;
    uint64_t st = 5;
    int k, checked = 0;
    (void)state;
    sun_map(rgb);
    s = env_scene(rgb, MW, MH, NULL, -1, 0);
    for (k = 0; k < 20000; ++k) {
        rs_vec3 wi, le, le2;
        float pdf, pdf2;
        if (!rs_env_sample(s, rnd_f(&st), rnd_f(&st), &wi, &pdf, &le))
            continue;
        pdf2 = rs_env_pdf(s, wi);
        le2 = rs_env_radiance(s, wi);
        if (fabsf(pdf2 - pdf) <= 2e-3f * pdf && rs_v3_length(rs_v3_sub(le, le2)) <= 1e-5f)
            ++checked;
    }
    /* all but samples within a float rounding of a texel edge */
    print_message("%d of 20000 samples consistent\n", checked);
    assert_true(checked >= 19990);
    rs_scene_destroy(s);
}

/* Irradiance at a surface of normal n from the map, by quadrature over the texels (each cut into
 * 16 x 16 cells) and by light sampling. */
static void test_irradiance(void **state)
{
    float rgb[MW * MH * 3];
    static const float rot[9] = {0, 0, 1, 0, 1, 0, -1, 0, 0}; /* a quarter turn about y */
    rs_scene *s;
    rs_vec3 n = rs_v3_normalize(rs_v3(0.3f, 0.9f, -0.2f));
    int r;
    (void)state;
    sun_map(rgb);
    for (r = 0; r < 2; ++r) {
        double exact = 0, sum = 0, sum2 = 0, mean, se;
        uint64_t st = 99;
        int i, j, k;
        const int SUB = 16, N = 400000;
        s = env_scene(rgb, MW, MH, r ? rot : NULL, -1, 0);
        for (j = 0; j < MH * SUB; ++j) {
            double th = PI_D * (j + 0.5) / (MH * SUB);
            for (i = 0; i < MW * SUB; ++i) {
                double ph = 2 * PI_D * ((i + 0.5) / (MW * SUB) - 0.5);
                /* the map-frame direction of (u, v), taken back to the world */
                rs_vec3 m = rs_v3((float)(sin(th) * sin(ph)), (float)cos(th),
                                  (float)(-sin(th) * cos(ph)));
                rs_vec3 d = rs_env_rot_inv(s->env_rot, m);
                double c = rs_v3_dot(n, d);
                const float *t = &rgb[3 * ((j / SUB) * MW + i / SUB)];
                if (c > 0)
                    exact += t[0] * c * sin(th) * (PI_D / (MH * SUB)) * (2 * PI_D / (MW * SUB));
            }
        }
        for (k = 0; k < N; ++k) {
            rs_light_sample ls;
            double v = 0, c;
            if (rs_light_sample_at(s, rs_v3(0, 0, 0), 0.0f, rnd_f(&st), rnd_f(&st), rnd_f(&st),
                                   &ls)) {
                assert_true(ls.env);
                c = rs_v3_dot(n, ls.wi);
                if (c > 0)
                    v = ls.le.x * c / ls.pdf;
            }
            sum += v;
            sum2 += v * v;
        }
        mean = sum / N;
        se = sqrt(fmax(0.0, sum2 / N - mean * mean) / (N - 1));
        print_message("irradiance (%s): sampled %.5f (se %.5f), quadrature %.5f\n",
                      r ? "rotated" : "unrotated", mean, se, exact);
        assert_true(se < 0.002 * exact);
        assert_true(fabs(mean - exact) < 0.01 * exact);
        rs_scene_destroy(s);
    }
}

/* A map black but for one texel: its samples point where the documentation says. */
static void test_orientation(void **state)
{
    static float rgb[MW * MH * 3];
    static const float rot_y90[9] = {0, 0, -1, 0, 1, 0, 1, 0, 0};
    rs_scene *s;
    rs_vec3 wi = rs_v3(0, 0, 0), le = rs_v3(0, 0, 0);
    float pdf;
    (void)state;
    memset(rgb, 0, sizeof rgb);
    /* texel (16, 8): u = 0.5..0.53, v = 0.5..0.56: just below the horizon, a hair to +x of -z */
    rgb[3 * (8 * MW + 16)] = rgb[3 * (8 * MW + 16) + 1] = rgb[3 * (8 * MW + 16) + 2] = 1.0f;
    s = env_scene(rgb, MW, MH, NULL, -1, 0);
    assert_true(rs_env_sample(s, 0.5f, 0.5f, &wi, &pdf, &le));
    print_message("texel (16, 8) lies along (%.3f, %.3f, %.3f)\n", wi.x, wi.y, wi.z);
    assert_true(wi.z < -0.98f && wi.x > 0 && wi.y < 0 && wi.y > -0.2f);
    assert_true(le.x == 1.0f);
    assert_true(rs_env_radiance(s, rs_v3(0.05f, -0.1f, -1)).x == 1.0f);
    assert_true(rs_env_radiance(s, rs_v3(-0.05f, -0.1f, -1)).x == 0.0f);
    rs_scene_destroy(s);
    {
        /* only the top row lit: that is +y */
        static float top[MW * MH * 3];
        int i;
        memset(top, 0, sizeof top);
        for (i = 0; i < 3 * MW; ++i)
            top[i] = 1.0f;
        s = env_scene(top, MW, MH, NULL, -1, 0);
        assert_true(rs_env_radiance(s, rs_v3(0.01f, 1, 0)).x == 1.0f);
        assert_true(rs_env_radiance(s, rs_v3(0.01f, -1, 0)).x == 0.0f);
        assert_true(rs_env_sample(s, 0.3f, 0.7f, &wi, &pdf, &le));
        assert_true(wi.y > cosf(3.14159265f / MH) - 1e-6f);
        rs_scene_destroy(s);
    }
    /* world -> map turns -x into -z: the texel is seen along about -x */
    s = env_scene(rgb, MW, MH, rot_y90, -1, 0);
    assert_true(rs_env_sample(s, 0.5f, 0.5f, &wi, &pdf, &le));
    print_message("rotated: (%.3f, %.3f, %.3f)\n", wi.x, wi.y, wi.z);
    assert_true(wi.x < -0.98f);
    rs_scene_destroy(s);
}

/* A map whose texels are all alike is a uniform sky (env_uniform): its samples are uniform over
 * the sphere (chi-square on 8 bands of z by 16 sectors of phi, alpha = 0.001, 127 dof: critical
 * 181.99), turned or not, with pdf 1 / 4 pi and the texel's radiance, as rs_env_pdf and
 * rs_env_radiance say for every direction; one texel off and the table is used again. */
static void test_uniform_map(void **state)
{
    static const float rot_y90[9] = {0, 0, 1, 0, 1, 0, -1, 0, 0};
    float rgb[8 * 4 * 3];
    int i, r;
    (void)state;
    for (i = 0; i < 8 * 4; ++i)
        rgb[3 * i] = 0.5f, rgb[3 * i + 1] = 1.0f, rgb[3 * i + 2] = 2.0f;
    for (r = 0; r < 2; ++r) {
        rs_scene *s = env_scene(rgb, 8, 4, r ? rot_y90 : NULL, -1, 0);
        uint64_t seed = 77;
        double bins[128] = {0}, chi;
        const int n = 128000;
        assert_int_equal(s->env_uniform, 1);
        for (i = 0; i < n; ++i) {
            rs_vec3 wi, le, d = rnd_unit(&seed);
            float pdf;
            int zb, pb;
            assert_true(rs_env_sample(s, rnd_f(&seed), rnd_f(&seed), &wi, &pdf, &le));
            assert_true(pdf == 0.25f * (float)RS_INV_PI && rs_env_pdf(s, wi) == pdf);
            assert_true(le.x == 0.5f && le.y == 1.0f && le.z == 2.0f);
            assert_true(fabsf(rs_v3_length(wi) - 1.0f) < 1e-5f);
            zb = (int)((wi.z + 1.0f) * 4.0f);
            pb = (int)((atan2(wi.y, wi.x) + PI_D) / (2 * PI_D) * 16.0);
            bins[(zb > 7 ? 7 : zb) * 16 + (pb > 15 ? 15 : pb)] += 1.0;
            /* any direction: the same radiance and pdf */
            le = rs_env_radiance(s, d);
            assert_true(le.x == 0.5f && le.y == 1.0f && le.z == 2.0f);
            assert_true(rs_env_pdf(s, d) == 0.25f * (float)RS_INV_PI);
        }
        chi = chi_square(bins, 128, n / 128.0);
        print_message("uniform map%s: chi-square %.1f (127 dof, critical 181.99)\n",
                      r ? " turned" : "", chi);
        assert_true(chi < 181.99);
        rs_scene_destroy(s);
    }
    rgb[3 * 13 + 1] = 1.001f;
    {
        rs_scene *s = env_scene(rgb, 8, 4, NULL, -1, 0);
        assert_int_equal(s->env_uniform, 0);
        rs_scene_destroy(s);
    }
}

/* The white furnace of a unit sphere of albedo 0.5 under a background of radiance 1 (`s`, seen
 * from 3.2 units with a 30-degree field), in every sampling mode on the CPU and the GPU fallback:
 * the corners see the background (the sphere subtends 18.2 degrees, the corner pixels 19.5 to
 * 20.7), and the pixels in the middle, which see only the sphere, average 0.5 within 5 standard
 * errors of the pixel mean and 1%. */
static void furnace_check(const rs_scene *s, const char *what)
{
    int mode, dev, i;
    for (dev = 0; dev < 2; ++dev)
        for (mode = 0; mode < 4; ++mode) {
            rt_args a = rt_defaults("", 24, 64);
            float *img;
            double sum = 0, sum2 = 0, mean, sd;
            int n = 0, bg;
            a.sampling = (rs_sampling)mode;
            a.megakernel = dev;
            a.fallback_only = dev;
            img = rt_render_scene(s, &a, NULL);
            assert_non_null(img);
            bg = (img[0] == 1.0f) + (img[3 * 23] == 1.0f) + (img[3 * 24 * 23] == 1.0f);
            for (i = 0; i < 24 * 24; ++i) {
                float v = img[3 * i], x = (float)(i % 24) - 11.5f, y = (float)(i / 24) - 11.5f;
                if (x * x + y * y > 64.0f)
                    continue;
                sum += v;
                sum2 += v * v;
                ++n;
            }
            mean = sum / n, sd = sqrt(fmax(0, sum2 / n - mean * mean));
            print_message("%s, %-8s %s: sphere mean %.5f (pixel sd %.4f, %d pixels), %d "
                          "background\n",
                          what, rs_sampling_name((rs_sampling)mode), dev ? "gpu fallback" : "cpu",
                          mean, sd, n, bg);
            assert_true(n > 150 && bg == 3);
            assert_true(fabs(mean - 0.5) < 5 * sd / sqrt(n) + 1e-6 || fabs(mean - 0.5) < 1e-4);
            assert_true(fabs(mean - 0.5) < 0.005);
            free(img);
        }
}

/* A constant background colour (no map) is a uniform sky to light sampling: finalize marks it,
 * picks it (the only light), and it samples, weighs and returns radiance as a uniform map does;
 * the RTIOW gradient and a black background are not lights.  Under a background of 1 the
 * furnace's sphere renders its albedo with every strategy, on the CPU and the GPU fallback. */
static void test_constant_background(void **state)
{
    rs_scene *s;
    uint32_t m;
    int i, kind;
    rs_material mat = rs_mat_lambertian(rs_v3_splat(0.5f));
    (void)state;
    for (kind = 0; kind < 3; ++kind) { /* a colour, the gradient, black */
        uint64_t seed = 5;
        assert_int_equal(rs_scene_create("bg", &s), RS_OK);
        assert_int_equal(rs_scene_add_material(s, &mat, &m), RS_OK);
        assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, m), RS_OK);
        s->background = kind == 2 ? rs_v3_splat(0.0f) : rs_v3(0.25f, 0.5f, 1.0f);
        s->background_top = rs_v3(1, 1, 1);
        s->background_sky = kind == 1;
        assert_int_equal(rs_scene_finalize(s), RS_OK);
        assert_int_equal(s->env_uniform, kind == 0);
        assert_int_equal(rs_env_present(s), kind == 0);
        assert_true(s->env_pick == (kind == 0 ? 1.0f : 0.0f));
        assert_int_equal(rs_scene_has_lights(s), kind == 0);
        for (i = 0; kind == 0 && i < 1000; ++i) {
            rs_vec3 wi, le;
            float pdf;
            assert_true(rs_env_sample(s, rnd_f(&seed), rnd_f(&seed), &wi, &pdf, &le));
            assert_true(pdf == 0.25f * (float)RS_INV_PI && rs_env_pdf(s, wi) == pdf);
            assert_true(le.x == 0.25f && le.y == 0.5f && le.z == 1.0f);
            le = rs_env_radiance(s, rnd_unit(&seed));
            assert_true(le.x == 0.25f && le.y == 0.5f && le.z == 1.0f);
        }
        rs_scene_destroy(s);
    }
    assert_int_equal(rs_scene_create("bg", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &mat, &m), RS_OK);
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, m), RS_OK);
    s->background = rs_v3_splat(1.0f);
    s->camera.from = rs_v3(0, 0, 3.2f);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.vfov_deg = 30;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    furnace_check(s, "constant background");
    rs_scene_destroy(s);
}

/* A uniform sky seen from a surface (rs_env_sample_at) is sampled in proportion to cos about
 * the normal, a tilted one here: chi-square over 8 x 16 cells of equal probability under that
 * density (1 - cos^2 and the azimuth, each uniform), every pdf the one rs_env_pdf_at gives, no
 * direction below the surface; the map's sampling is the sphere's where the normal is zero. */
static void test_uniform_sky_cosine(void **state)
{
    float rgb[4 * 2 * 3];
    rs_scene *s;
    rs_vec3 n = rs_v3_normalize(rs_v3(0.3f, 0.8f, -0.5f)), wi, le;
    rs_onb f = rs_onb_from_normal(n);
    double bins[128] = {0}, chi;
    uint64_t seed = 91;
    float pdf;
    const int count = 128000;
    int i;
    (void)state;
    for (i = 0; i < 4 * 2 * 3; ++i)
        rgb[i] = 2.0f;
    s = env_scene(rgb, 4, 2, NULL, -1, 0);
    for (i = 0; i < count; ++i) {
        float z, phi;
        int a, b;
        assert_true(rs_env_sample_at(s, n, rnd_f(&seed), rnd_f(&seed), &wi, &pdf, &le));
        z = rs_v3_dot(n, wi);
        assert_true(z > 0.0f && fabsf(rs_v3_length(wi) - 1.0f) < 1e-5f);
        assert_true(pdf == rs_env_pdf_at(s, n, wi));
        assert_true(fabsf(pdf - z * (float)RS_INV_PI) < 1e-6f);
        assert_true(le.x == 2.0f && le.y == 2.0f && le.z == 2.0f);
        phi = atan2f(rs_v3_dot(f.b, wi), rs_v3_dot(f.t, wi));
        a = (int)((1.0f - z * z) * 8.0f);
        b = (int)((phi + (float)PI_D) / (2.0f * (float)PI_D) * 16.0f);
        bins[(a > 7 ? 7 : a < 0 ? 0 : a) * 16 + (b > 15 ? 15 : b < 0 ? 0 : b)] += 1.0;
    }
    chi = chi_square(bins, 128, count / 128.0);
    print_message("uniform sky about a tilted normal: chi-square %.1f (127 dof, critical 181.99)\n",
                  chi);
    assert_true(chi < 181.99);
    /* below the surface: never sampled, pdf 0; no normal: the sphere */
    assert_true(rs_env_pdf_at(s, n, rs_v3_neg(n)) == 0.0f);
    assert_true(rs_env_pdf_at(s, rs_v3_splat(0.0f), rs_v3_neg(n)) == 0.25f * (float)RS_INV_PI);
    rs_scene_destroy(s);
}

/* The furnace under a uniform map: the sphere renders its albedo, 0.5, with every strategy. */
static void test_furnace(void **state)
{
    float rgb[4 * 2 * 3];
    rs_scene *s;
    int i;
    (void)state;
    for (i = 0; i < 4 * 2 * 3; ++i)
        rgb[i] = 1.0f;
    s = env_scene(rgb, 4, 2, NULL, 0.5f, 0);
    s->camera.from = rs_v3(0, 0, 3.2f);
    s->camera.vfov_deg = 30; /* the sphere fills most of the frame */
    furnace_check(s, "uniform map");
    rs_scene_destroy(s);
}

/* Spheres of the GGX materials under a uniform map: MIS and the mixture (which sample the map
 * as a light, through the rough glass too) agree with BSDF sampling on the sphere's mean, within
 * 5 combined standard errors (pixel spreads, conservative: they include the true variation
 * between pixels) and 1%. */
static void test_furnace_ggx(void **state)
{
    float rgb[4 * 2 * 3];
    rs_material mats[3];
    int k, mode, i;
    (void)state;
    for (i = 0; i < 4 * 2 * 3; ++i)
        rgb[i] = 1.0f;
    mats[0] = rs_mat_rough_dielectric(1.5f, 0.09f);
    mats[1] = rs_mat_conductor_f0(rs_v3_splat(1.0f), 0.3f);
    mats[2] = rs_mat_pbr(rs_v3(0.8f, 0.8f, 0.8f), 0.3f, 0.4f);
    for (k = 0; k < 3; ++k) {
        double mean[3], se[3];
        rs_scene *s;
        uint32_t img, m;
        assert_int_equal(rs_scene_create("env-ggx", &s), RS_OK);
        assert_int_equal(rs_scene_add_image(s, 4, 2, rgb, &img), RS_OK);
        assert_int_equal(rs_scene_set_environment(s, img, rs_v3_splat(1.0f), NULL), RS_OK);
        assert_int_equal(rs_scene_add_material(s, &mats[k], &m), RS_OK);
        assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, m), RS_OK);
        s->camera.from = rs_v3(0, 0, 3.2f);
        s->camera.at = rs_v3(0, 0, 0);
        s->camera.vfov_deg = 30;
        assert_int_equal(rs_scene_finalize(s), RS_OK);
        for (mode = 0; mode < 3; ++mode) {
            rt_args a = rt_defaults("", 24, 256);
            float *im;
            double sum = 0, sum2 = 0;
            int n = 0;
            a.sampling = (rs_sampling)mode;
            a.threads = 2;
            im = rt_render_scene(s, &a, NULL);
            assert_non_null(im);
            for (i = 0; i < 24 * 24; ++i) {
                float x = (float)(i % 24) - 11.5f, y = (float)(i / 24) - 11.5f;
                if (x * x + y * y > 64.0f)
                    continue;
                sum += im[3 * i];
                sum2 += (double)im[3 * i] * im[3 * i];
                ++n;
            }
            mean[mode] = sum / n;
            se[mode] = sqrt(fmax(0, sum2 / n - mean[mode] * mean[mode]) / n);
            print_message("material %d %-8s mean %.5f (se %.5f)\n", k,
                          rs_sampling_name((rs_sampling)mode), mean[mode], se[mode]);
            assert_true(mean[mode] <= 1.01);
            free(im);
        }
        for (mode = 0; mode < 2; ++mode) {
            double d = fabs(mean[mode] - mean[RS_SAMPLING_BSDF]);
            assert_true(d <= 5 * sqrt(se[mode] * se[mode] + se[2] * se[2]));
            assert_true(d <= 0.01 * mean[RS_SAMPLING_BSDF]);
        }
        rs_scene_destroy(s);
    }
}

/* The image mean over 12 seeds (seed0 ...) of 16x16 renders of s at spp with `mode` and
 * independent numbers, and its standard error from the seeds' spread. */
static void seed_mean(const rs_scene *s, rs_sampling mode, uint32_t spp, uint64_t seed0,
                      double *mean, double *se)
{
    double m[12], sum = 0, var = 0;
    int k;
    for (k = 0; k < 12; ++k) {
        rt_args a = rt_defaults("", 16, spp);
        float *img;
        a.sampling = mode;
        a.sampler = RS_SAMPLER_INDEPENDENT;
        a.seed = seed0 + (uint64_t)k;
        a.threads = 2;
        img = rt_render_scene(s, &a, NULL);
        assert_non_null(img);
        m[k] = rt_mean(img, 16 * 16 * 3);
        sum += m[k];
        free(img);
    }
    *mean = sum / 12;
    for (k = 0; k < 12; ++k)
        var += (m[k] - *mean) * (m[k] - *mean);
    *se = sqrt(var / 11 / 12);
    print_message("%-8s mean %.5f  se %.5f\n", rs_sampling_name(mode), *mean, *se);
}

/* The four strategies agree on the image mean under the sun map (sphere on a floor): 12 seeds
 * of 256 spp each, means within 4.5 combined standard errors (with t(11) tails a correct
 * renderer fails one of the six comparisons with probability < 0.01) and 3%. */
static void test_strategies_agree(void **state)
{
    float rgb[MW * MH * 3];
    rs_scene *s;
    double mean[4], se[4];
    int mode, i, j;
    (void)state;
    sun_map(rgb);
    s = env_scene(rgb, MW, MH, NULL, 0.6f, 1);
    for (mode = 0; mode < 4; ++mode)
        seed_mean(s, (rs_sampling)mode, 256, 500, &mean[mode], &se[mode]);
    for (i = 0; i < 4; ++i)
        for (j = i + 1; j < 4; ++j) {
            double d = fabs(mean[i] - mean[j]), bound = 4.5 * sqrt(se[i] * se[i] + se[j] * se[j]);
            if (d > bound || d > 0.03 * mean[i])
                fail_msg("%s and %s disagree: %.5f vs %.5f (bound %.5f)",
                         rs_sampling_name((rs_sampling)i), rs_sampling_name((rs_sampling)j),
                         mean[i], mean[j], bound);
        }
    assert_true(se[RS_SAMPLING_MIS] < 0.5 * se[RS_SAMPLING_BSDF]);
    rs_scene_destroy(s);
}

/* Map, an emitter and punctual lights together: MIS (one next-event estimate over all of them)
 * and the mixture (its light half over the map and the emitter, a next-event estimate for the
 * punctual lights) agree on the image mean, 12 seeds each, within 4.5 combined standard errors
 * and 2%. */
static void test_mixed_lights_agree(void **state)
{
    float rgb[MW * MH * 3];
    rs_scene *s;
    rs_punctual p;
    rs_material lm = rs_mat_light(rs_v3_splat(6.0f), 0);
    uint32_t lid;
    double mean[2], se[2];
    int mode;
    (void)state;
    sun_map(rgb);
    assert_int_equal(rs_scene_create("env", &s), RS_OK);
    {
        uint32_t img, m;
        rs_material mat = rs_mat_pbr(rs_v3(0.7f, 0.6f, 0.5f), 0.2f, 0.5f);
        assert_int_equal(rs_scene_add_image(s, MW, MH, rgb, &img), RS_OK);
        assert_int_equal(rs_scene_set_environment(s, img, rs_v3_splat(0.3f), NULL), RS_OK);
        assert_int_equal(rs_scene_add_material(s, &mat, &m), RS_OK);
        assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, m), RS_OK);
        assert_int_equal(rs_scene_add_quad(s, rs_v3(-4, -1, 4), rs_v3(8, 0, 0), rs_v3(0, 0, -8), m),
                         RS_OK);
    }
    assert_int_equal(rs_scene_add_material(s, &lm, &lid), RS_OK);
    /* a small emitter above, facing down: u x v = (0,0,1) x (1,0,0) = (0,1,0), so flipped */
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-0.5f, 3, -0.5f), rs_v3(1, 0, 0), rs_v3(0, 0, 1),
                                       lid),
                     RS_OK);
    memset(&p, 0, sizeof p);
    p.type = RS_PUNCTUAL_POINT;
    p.pos = rs_v3(2, 2, 2);
    p.intensity = rs_v3(8, 6, 4);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    p.type = RS_PUNCTUAL_SPOT;
    p.pos = rs_v3(-2, 3, 1);
    p.dir = rs_v3(0.6f, -1, -0.3f);
    p.cos_inner = 0.95f;
    p.cos_outer = 0.8f;
    p.intensity = rs_v3_splat(20);
    assert_int_equal(rs_scene_add_punctual(s, &p), RS_OK);
    s->camera.from = rs_v3(0, 0.5f, 4);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.vfov_deg = 40;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_true(s->area_mass > 0.0f && s->area_mass < 1.0f);
    for (mode = 0; mode < 2; ++mode)
        seed_mean(s, mode ? RS_SAMPLING_MIXTURE : RS_SAMPLING_MIS, 64, 700, &mean[mode],
                  &se[mode]);
    assert_true(fabs(mean[0] - mean[1]) <= 4.5 * sqrt(se[0] * se[0] + se[1] * se[1]));
    assert_true(fabs(mean[0] - mean[1]) <= 0.02 * mean[0]);
    rs_scene_destroy(s);
}

/* A glTF-style emissive pbr quad (it also reflects) as the only light: it is light-sampled
 * (two-sided), and MIS, the mixture and BSDF sampling (which finds it only by hitting it) agree
 * on the image mean (12 seeds, 4.5 combined standard errors and 3%), MIS with less spread. */
static void test_pbr_emitter(void **state)
{
    rs_scene *s;
    uint32_t floor_m, glow;
    rs_material fm = rs_mat_lambertian(rs_v3(0.6f, 0.6f, 0.6f));
    rs_material gm = rs_mat_pbr(rs_v3(0.5f, 0.5f, 0.5f), 0.0f, 0.5f);
    double mean[3], se[3];
    int mode, i, j;
    (void)state;
    gm.emission = rs_v3(4, 3, 2);
    assert_int_equal(rs_scene_create("pbr-emitter", &s), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &fm, &floor_m), RS_OK);
    assert_int_equal(rs_scene_add_material(s, &gm, &glow), RS_OK);
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-4, -1, 4), rs_v3(8, 0, 0), rs_v3(0, 0, -8),
                                       floor_m),
                     RS_OK);
    assert_int_equal(rs_scene_add_sphere(s, rs_v3(0, 0, 0), 1.0f, floor_m), RS_OK);
    /* facing up (u x v = +y): its light reaches the floor only through its back side */
    assert_int_equal(rs_scene_add_quad(s, rs_v3(-1, 2.5f, 1), rs_v3(2, 0, 0), rs_v3(0, 0, -2),
                                       glow),
                     RS_OK);
    s->camera.from = rs_v3(0, 1.5f, 5);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.vfov_deg = 50;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    assert_int_equal(s->n_lights, 1u);
    for (mode = 0; mode < 3; ++mode)
        seed_mean(s, (rs_sampling)mode, 64, 900, &mean[mode], &se[mode]);
    for (i = 0; i < 3; ++i)
        for (j = i + 1; j < 3; ++j) {
            double d = fabs(mean[i] - mean[j]), bound = 4.5 * sqrt(se[i] * se[i] + se[j] * se[j]);
            if (d > bound || d > 0.03 * mean[i])
                fail_msg("%s and %s disagree: %.5f vs %.5f (bound %.5f)",
                         rs_sampling_name((rs_sampling)i), rs_sampling_name((rs_sampling)j),
                         mean[i], mean[j], bound);
        }
    assert_true(se[RS_SAMPLING_MIS] < se[RS_SAMPLING_BSDF]);
    rs_scene_destroy(s);
}

/* A PFM of w x h texels, all `v` but texel 0 = `first`. */
static void write_pfm(const char *path, int w, int h, float v, float first)
{
    FILE *f = fopen(path, "wb");
    int i;
    assert_non_null(f);
    fprintf(f, "PF\n%d %d\n-1.0\n", w, h);
    for (i = 0; i < 3 * w * h; ++i) {
        float x = i == 0 ? first : v;
        fwrite(&x, sizeof x, 1, f);
    }
    fclose(f);
}

static void test_bad_maps(void **state)
{
    char dir[] = "/tmp/rs_env_XXXXXX", p[512], sp[512];
    static const char *const cases[][2] = {
        {"missing.pfm", "background.map"},
        {"neg.pfm", "negative"},
        {"nan.pfm", "not finite"},
    };
    size_t k;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(p, sizeof p, "%s/neg.pfm", dir);
    write_pfm(p, 4, 2, 1.0f, -1.0f);
    snprintf(p, sizeof p, "%s/nan.pfm", dir);
    write_pfm(p, 4, 2, 1.0f, NAN);
    snprintf(p, sizeof p, "%s/ok.pfm", dir);
    write_pfm(p, 4, 2, 1.0f, 1.0f);
    snprintf(sp, sizeof sp, "%s/scene.json", dir);
    for (k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        FILE *f = fopen(sp, "w");
        rs_scene *s = (rs_scene *)0x1;
        assert_non_null(f);
        fprintf(f, "{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]},\"background\":{\"map\":\"%s\"},"
                   "\"objects\":[]}", cases[k][0]);
        fclose(f);
        rs_error_clear();
        assert_int_equal(rs_scene_load_json(sp, &s), RS_ERR_ARG);
        assert_null(s);
        print_message("%s\n", rs_error_message());
        assert_null(strchr(rs_error_message(), '\n'));
        assert_non_null(strstr(rs_error_message(), "scene.json"));
        assert_non_null(strstr(rs_error_message(), cases[k][1]));
        rs_error_clear();
    }
    {
        /* and a good one, with scale and rotation, loads */
        FILE *f = fopen(sp, "w");
        rs_scene *s = NULL;
        assert_non_null(f);
        fprintf(f, "{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]},\"background\":{\"map\":"
                   "\"ok.pfm\",\"scale\":[2,2,2],\"rotate\":{\"axis\":[0,1,0],\"degrees\":90}},"
                   "\"objects\":[]}");
        fclose(f);
        assert_int_equal(rs_scene_load_json(sp, &s), RS_OK);
        assert_true(rs_env_present(s) && s->env_pick == 1.0f);
        assert_true(rs_env_radiance(s, rs_v3(0, 0, 1)).x == 2.0f);
        /* a rotation by +90 about y: the map's -z (its middle) is seen along -x */
        assert_true(fabsf(s->env_rot[2] - 1.0f) < 1e-6f || fabsf(s->env_rot[2] + 1.0f) < 1e-6f);
        rs_scene_destroy(s);
    }
    remove(sp);
    remove_in(dir, "neg.pfm");
    remove_in(dir, "nan.pfm");
    remove_in(dir, "ok.pfm");
    rmdir(dir);
}

/* Image textures with a NaN, infinite or negative texel are refused as environment maps are,
 * by one line naming the scene, the file and the texel (issue 39: they were accepted, and the
 * mip pyramid carried one NaN texel into every coarser level: rows of a far floor 10-83% darker;
 * a negative texel gave negative pixels). */
static void test_bad_image_textures(void **state)
{
    char dir[] = "/tmp/rs_tex_XXXXXX", p[512], sp[512];
    static const char *const cases[][2] = {
        {"nan.pfm", "texel (0, 1) is not finite (NaN)"},
        {"inf.pfm", "texel (0, 1) is not finite (infinite)"},
        {"neg.pfm", "texel (0, 1) is negative"},
    };
    size_t k;
    (void)state;
    assert_non_null(mkdtemp(dir));
    snprintf(p, sizeof p, "%s/nan.pfm", dir);
    write_pfm(p, 4, 2, 0.5f, NAN);
    snprintf(p, sizeof p, "%s/inf.pfm", dir);
    write_pfm(p, 4, 2, 0.5f, INFINITY);
    snprintf(p, sizeof p, "%s/neg.pfm", dir);
    write_pfm(p, 4, 2, 0.5f, -0.25f);
    snprintf(sp, sizeof sp, "%s/scene.json", dir);
    for (k = 0; k < sizeof cases / sizeof cases[0]; ++k) {
        FILE *f = fopen(sp, "w");
        rs_scene *s = (rs_scene *)0x1;
        assert_non_null(f);
        fprintf(f, "{\"camera\":{\"from\":[0,0,5],\"at\":[0,0,0]},\"textures\":{\"t\":"
                   "{\"type\":\"image\",\"file\":\"%s\"}},\"materials\":{\"m\":"
                   "{\"type\":\"lambertian\",\"texture\":\"t\"}},\"objects\":[{\"type\":"
                   "\"sphere\",\"center\":[0,0,0],\"radius\":1,\"material\":\"m\"}]}",
                cases[k][0]);
        fclose(f);
        rs_error_clear();
        assert_int_not_equal(rs_scene_load_json(sp, &s), RS_OK);
        print_message("%s\n", rs_error_message());
        assert_null(strchr(rs_error_message(), '\n'));
        assert_non_null(strstr(rs_error_message(), "scene.json"));
        assert_non_null(strstr(rs_error_message(), cases[k][0]));
        assert_non_null(strstr(rs_error_message(), cases[k][1]));
        rs_error_clear();
        remove_in(dir, cases[k][0]);
    }
    remove(sp);
    rmdir(dir);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_pdf_normalised),     cmocka_unit_test(test_sampling_chi_square),
        cmocka_unit_test(test_sample_consistency), cmocka_unit_test(test_irradiance),
        cmocka_unit_test(test_orientation),        cmocka_unit_test(test_furnace),
        cmocka_unit_test(test_strategies_agree),   cmocka_unit_test(test_furnace_ggx),
        cmocka_unit_test(test_mixed_lights_agree), cmocka_unit_test(test_pbr_emitter),
        cmocka_unit_test(test_bad_maps),          cmocka_unit_test(test_uniform_map),
        cmocka_unit_test(test_constant_background), cmocka_unit_test(test_uniform_sky_cosine),
        cmocka_unit_test(test_bad_image_textures),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
