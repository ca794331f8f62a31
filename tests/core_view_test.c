/* tests/core_view_test.c — core/view.h: the view transforms of 8-bit outputs, and
 * rs_image_write_view (core/image_io.h).
 *
 * What is checked:
 *   - names: NULL and "standard" are the standard view, "agx" is "filmic", unknown and empty
 *     names and exposures outside [-64, 64] (and NaN) are refused with a one-line reason that
 *     lists the built-in views;
 *   - exposure is exact: a view at EV k gives, bit for bit, what it gives at 0 EV for the input
 *     times 2^k (whole k), and exp2(EV) for a fractional EV;
 *   - standard is rs_srgb_encode bit for bit (negatives, NaN, over 1 included);
 *   - each built-in curve, on a fine ramp of greys from 0 to 2^12, is monotone per channel,
 *     stays in [0, 1], maps 0 to 0 (filmic: the polynomial fit gives -0.00232 at black, which
 *     the view clamps to 0; PBR Neutral's published black is 0);
 *   - PBR Neutral and AgX match their published reference shaders (Khronos pbrNeutral.glsl;
 *     Wrensch's Minimal AgX, its GLSL column-major matrices kept as columns here) written out
 *     again below in double precision, on greys and colours, and AgX's 18% grey lands on the
 *     well-known ~0.5 of its encoded output (0.496745 before the display step);
 *   - OCIO: with $OCIO naming a two-view config written here (Raw: identity; Gamma: an
 *     ExponentTransform, x^(1/2.2)), both names are views, a ramp maps as the config says,
 *     exposure comes first, and an unknown name's reason lists the config's views (skipped when
 *     OpenImageIO lacks OpenColorIO);
 *   - writing: a PNG through a view stores round(255 * display) with no second encoding; the
 *     default view (and NULL) writes the same bytes as rs_image_write_layers; an .exr through a
 *     view keeps linear pixels and records raystream:view and raystream:exposure. */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/image_io.h"
#include "core/srgb.h"
#include "core/view.h"

static char tmpdir[256];

static uint32_t bits(float x)
{
    uint32_t u;
    memcpy(&u, &x, sizeof u);
    return u;
}

static rs_view make(const char *name, float ev)
{
    rs_view v;
    char why[512];
    if (!rs_view_from_name(name, ev, &v, why, sizeof why))
        fail_msg("view %s at %g EV refused: %s", name ? name : "(null)", (double)ev, why);
    return v;
}

/* ---- references, in double, from the published shaders ------------------------------------ */

static double ref_srgb(double x)
{
    x = x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
    return x <= 0.0031308 ? 12.92 * x : 1.055 * pow(x, 1.0 / 2.4) - 0.055;
}

/* Khronos PBR Neutral, PBR_Neutral/pbrNeutral.glsl, line for line; then sRGB. */
static void ref_pbr_neutral(const double in[3], double out[3])
{
    const double startCompression = 0.8 - 0.04;
    const double desaturation = 0.15;
    double color[3] = {in[0], in[1], in[2]};
    double x = fmin(color[0], fmin(color[1], color[2]));
    double offset = x < 0.08 ? x - 6.25 * x * x : 0.04;
    double peak, d, newPeak, g;
    int i;
    for (i = 0; i < 3; ++i)
        color[i] -= offset;
    peak = fmax(color[0], fmax(color[1], color[2]));
    if (peak >= startCompression) {
        d = 1. - startCompression;
        newPeak = 1. - d * d / (peak + d - startCompression);
        for (i = 0; i < 3; ++i)
            color[i] *= newPeak / peak;
        g = 1. - 1. / (desaturation * (peak - newPeak) + 1.);
        for (i = 0; i < 3; ++i) /* mix(color, newPeak * vec3(1), g) */
            color[i] = color[i] + (newPeak - color[i]) * g;
    }
    for (i = 0; i < 3; ++i)
        out[i] = ref_srgb(color[i]);
}

/* Minimal AgX (Wrensch): GLSL mat3(c0, c1, c2) takes columns; kept as columns here, so a
 * transposition slip in core/view.c's rows shows. */
static const double agx_mat_cols[3][3] = {
    {0.842479062253094, 0.0423282422610123, 0.0423756549057051},
    {0.0784335999999992, 0.878468636469772, 0.0784336},
    {0.0792237451477643, 0.0791661274605434, 0.879142973793104},
};
static const double agx_mat_inv_cols[3][3] = {
    {1.19687900512017, -0.0528968517574562, -0.0529716355144438},
    {-0.0980208811401368, 1.15190312990417, -0.0980434501171241},
    {-0.0990297440797205, -0.0989611768448433, 1.15107367264116},
};

static void mat_cols_mul(const double m[3][3], const double v[3], double out[3])
{
    int i;
    for (i = 0; i < 3; ++i)
        out[i] = m[0][i] * v[0] + m[1][i] * v[1] + m[2][i] * v[2];
}

static double agx_default_contrast_approx(double x)
{
    double x2 = x * x, x4 = x2 * x2;
    return +15.5 * x4 * x2 - 40.14 * x4 * x + 31.96 * x4 - 6.868 * x2 * x + 0.4298 * x2 +
           0.1191 * x - 0.00232;
}

/* agx() then agxEotf() (pow 2.2) then the sRGB render target's encoding; `outset` gets the
 * value before the display step. */
static void ref_agx(const double in[3], double out[3], double outset[3])
{
    const double min_ev = -12.47393, max_ev = 4.026069;
    double v[3], s[3];
    int i;
    mat_cols_mul(agx_mat_cols, in, v);
    for (i = 0; i < 3; ++i) {
        double e = log2(fmax(v[i], 1e-10));
        e = e < min_ev ? min_ev : e > max_ev ? max_ev : e;
        s[i] = agx_default_contrast_approx((e - min_ev) / (max_ev - min_ev));
    }
    mat_cols_mul(agx_mat_inv_cols, s, v);
    for (i = 0; i < 3; ++i) {
        if (outset)
            outset[i] = v[i];
        out[i] = ref_srgb(pow(fmax(v[i], 0.0), 2.2));
    }
}

/* ---- tests --------------------------------------------------------------------------------- */

static void test_names(void **state)
{
    rs_view v;
    char why[512];
    (void)state;
    v = make(NULL, 0.0f);
    assert_int_equal(v.kind, RS_VIEW_STANDARD);
    assert_string_equal(v.name, "standard");
    assert_true(rs_view_is_default(&v));
    v = make("standard", 1.0f);
    assert_int_equal(v.kind, RS_VIEW_STANDARD);
    assert_false(rs_view_is_default(&v));
    v = make("filmic", -2.5f);
    assert_int_equal(v.kind, RS_VIEW_FILMIC);
    assert_true(v.exposure == -2.5f);
    v = make("agx", 0.0f);
    assert_int_equal(v.kind, RS_VIEW_FILMIC);
    assert_string_equal(v.name, "filmic");
    v = make("pbr-neutral", 3.0f);
    assert_int_equal(v.kind, RS_VIEW_PBR_NEUTRAL);

    assert_false(rs_view_from_name("no-such-view", 0.0f, &v, why, sizeof why));
    assert_non_null(strstr(why, "no-such-view"));
    assert_non_null(strstr(why, "standard, filmic (or agx), pbr-neutral"));
    /* a view whose LUT is missing: refused when the view is named, before any render (issue
     * 39: found when the image was written, after the render, in several lines) */
    assert_false(rs_view_from_name("Lut", 0.0f, &v, why, sizeof why));
    printf("Lut: %s\n", why);
    assert_non_null(strstr(why, "view 'Lut'"));
    assert_non_null(strstr(why, "missing-lut.spi1d"));
    assert_null(strchr(why, '\n'));
    assert_null(strchr(why, '\n'));
    assert_false(rs_view_from_name("Filmic", 0.0f, &v, why, sizeof why)); /* exact names */
    assert_false(rs_view_from_name("", 0.0f, &v, why, sizeof why));
    assert_false(rs_view_from_name("filmic", 65.0f, &v, why, sizeof why));
    assert_non_null(strstr(why, "exposure"));
    assert_false(rs_view_from_name("filmic", NAN, &v, why, sizeof why));
    assert_false(rs_view_from_name("filmic", INFINITY, &v, why, sizeof why));
}

#define RAMP_N 4097

/* greys: 0, then 2^-20 .. 2^12 evenly in log2, then 0 .. 1 evenly (sorted afterwards not
 * needed: each part is checked on its own) */
static void ramp_log(float *x, size_t n)
{
    size_t i;
    x[0] = 0.0f;
    for (i = 1; i < n; ++i)
        x[i] = exp2f(-20.0f + 32.0f * (float)(i - 1) / (float)(n - 2));
}

static void test_exposure_exact(void **state)
{
    static const char *names[] = {"standard", "filmic", "pbr-neutral"};
    static const float evs[] = {-6.0f, -1.0f, 1.0f, 3.0f, 10.0f};
    float x[RAMP_N * 3], xs[RAMP_N * 3], a[RAMP_N * 3], b[RAMP_N * 3];
    size_t i, k, e;
    (void)state;
    for (i = 0; i < RAMP_N; ++i) { /* colours: three different ramps per pixel */
        x[3 * i] = exp2f(-14.0f + 20.0f * (float)i / RAMP_N);
        x[3 * i + 1] = 0.5f * x[3 * i];
        x[3 * i + 2] = (float)i / RAMP_N;
    }
    for (k = 0; k < 3; ++k)
        for (e = 0; e < sizeof evs / sizeof evs[0]; ++e) {
            rs_view v = make(names[k], evs[e]), v0 = make(names[k], 0.0f);
            for (i = 0; i < RAMP_N * 3; ++i)
                xs[i] = ldexpf(x[i], (int)evs[e]); /* exact: powers of two */
            assert_int_equal(rs_view_apply(&v, x, RAMP_N, a), RS_OK);
            assert_int_equal(rs_view_apply(&v0, xs, RAMP_N, b), RS_OK);
            for (i = 0; i < RAMP_N * 3; ++i)
                if (bits(a[i]) != bits(b[i]))
                    fail_msg("%s at %g EV: %.9g gives %.9g, at 0 EV %.9g gives %.9g", names[k],
                             (double)evs[e], (double)x[i], (double)a[i], (double)xs[i],
                             (double)b[i]);
        }
    { /* fractional: 2^0.5 */
        rs_view v = make("standard", 0.5f);
        float in[3] = {0.1f, 0.2f, 0.3f}, out[3];
        assert_int_equal(rs_view_apply(&v, in, 1, out), RS_OK);
        for (i = 0; i < 3; ++i)
            assert_float_equal(out[i], ref_srgb(in[i] * sqrt(2.0)), 2e-6);
    }
}

static void test_standard_is_srgb(void **state)
{
    float x[RAMP_N * 3], d[RAMP_N * 3];
    size_t i;
    rs_view v = make(NULL, 0.0f);
    (void)state;
    for (i = 0; i < RAMP_N * 3; ++i)
        x[i] = -0.25f + 1.5f * (float)i / (RAMP_N * 3);
    x[0] = NAN, x[1] = INFINITY, x[2] = -INFINITY, x[3] = 1e-30f;
    assert_int_equal(rs_view_apply(&v, x, RAMP_N, d), RS_OK);
    for (i = 0; i < RAMP_N * 3; ++i)
        assert_int_equal(bits(d[i]), bits(rs_srgb_encode(x[i])));
}

static void check_monotone(const char *name, const float *x, size_t n)
{
    static float in[RAMP_N * 3], out[RAMP_N * 3];
    rs_view v = make(name, 0.0f);
    size_t i, c;
    for (i = 0; i < n; ++i)
        in[3 * i] = in[3 * i + 1] = in[3 * i + 2] = x[i];
    assert_int_equal(rs_view_apply(&v, in, n, out), RS_OK);
    for (i = 0; i < n; ++i)
        for (c = 0; c < 3; ++c) {
            float o = out[3 * i + c];
            if (!(o >= 0.0f && o <= 1.0f))
                fail_msg("%s: %.9g gives %.9g, outside [0, 1]", name, (double)x[i], (double)o);
            if (i > 0 && x[i] >= x[i - 1] && o < out[3 * (i - 1) + c])
                fail_msg("%s channel %zu: %.9g gives %.9g, less than %.9g gives (%.9g)", name, c,
                         (double)x[i], (double)o, (double)x[i - 1], (double)out[3 * (i - 1) + c]);
        }
}

static void test_monotone_black(void **state)
{
    static const char *names[] = {"standard", "filmic", "pbr-neutral"};
    float x[RAMP_N], zero[3] = {0, 0, 0}, d[3];
    size_t k, i;
    (void)state;
    for (k = 0; k < 3; ++k) {
        rs_view v = make(names[k], 0.0f);
        ramp_log(x, RAMP_N);
        check_monotone(names[k], x, RAMP_N);
        for (i = 0; i < RAMP_N; ++i)
            x[i] = (float)i / (RAMP_N - 1);
        check_monotone(names[k], x, RAMP_N);
        assert_int_equal(rs_view_apply(&v, zero, 1, d), RS_OK);
        for (i = 0; i < 3; ++i)
            assert_true(d[i] == 0.0f);
    }
}

static const double samples[][3] = {
    {0.001, 0.001, 0.001}, {0.01, 0.01, 0.01}, {0.05, 0.05, 0.05}, {0.18, 0.18, 0.18},
    {0.5, 0.5, 0.5},       {0.76, 0.76, 0.76}, {1, 1, 1},          {4, 4, 4},
    {16, 16, 16},          {100, 100, 100},    {1, 0.5, 0.1},      {4, 2, 0.5},
    {0.02, 0.3, 0.9},      {16, 1, 0.25},      {0.07, 0.09, 0.2},  {0.9, 0.01, 0.0},
};

static void test_pbr_neutral_reference(void **state)
{
    size_t s, c;
    rs_view v = make("pbr-neutral", 0.0f);
    (void)state;
    for (s = 0; s < sizeof samples / sizeof samples[0]; ++s) {
        float in[3] = {(float)samples[s][0], (float)samples[s][1], (float)samples[s][2]}, out[3];
        double ref[3];
        ref_pbr_neutral(samples[s], ref);
        assert_int_equal(rs_view_apply(&v, in, 1, out), RS_OK);
        for (c = 0; c < 3; ++c)
            if (fabs(out[c] - ref[c]) > 2e-6)
                fail_msg("pbr-neutral (%g %g %g) channel %zu: %.7f, the reference %.7f",
                         samples[s][0], samples[s][1], samples[s][2], c, (double)out[c], ref[c]);
    }
    { /* two values by hand: 0.18 grey is below the shoulder (0.18 - 0.04 = 0.14 linear); 1.0
         grey: peak 0.96, new peak 1 - 0.24^2/(0.96 + 0.24 - 0.76) = 0.869091 */
        double g18[3] = {0.18, 0.18, 0.18}, g1[3] = {1, 1, 1}, r[3];
        ref_pbr_neutral(g18, r);
        assert_float_equal(r[0], ref_srgb(0.14), 1e-12);
        ref_pbr_neutral(g1, r);
        assert_float_equal(r[0], ref_srgb(1.0 - 0.24 * 0.24 / 0.44), 1e-12);
    }
}

static void test_agx_reference(void **state)
{
    size_t s, c;
    rs_view v = make("filmic", 0.0f);
    double grey[3] = {0.18, 0.18, 0.18}, r[3], outset[3];
    (void)state;
    for (s = 0; s < sizeof samples / sizeof samples[0]; ++s) {
        float in[3] = {(float)samples[s][0], (float)samples[s][1], (float)samples[s][2]}, out[3];
        double ref[3];
        ref_agx(samples[s], ref, NULL);
        assert_int_equal(rs_view_apply(&v, in, 1, out), RS_OK);
        for (c = 0; c < 3; ++c)
            if (fabs(out[c] - ref[c]) > 1e-5)
                fail_msg("filmic (%g %g %g) channel %zu: %.7f, the reference %.7f", samples[s][0],
                         samples[s][1], samples[s][2], c, (double)out[c], ref[c]);
    }
    /* the published implementation's numbers, its green channel (a grey's three differ in the
     * 5th digit: the inset's rows do not sum to exactly 1): 18% grey to 0.4967 (AgX puts middle
     * grey near 0.5 of its encoded range), 1.0 to 0.7869, the top of the range to 0.9986 */
    ref_agx(grey, r, outset);
    assert_float_equal(outset[1], 0.496745, 1e-6);
    assert_float_equal(r[1], 0.500531, 1e-6);
    grey[0] = grey[1] = grey[2] = 1.0;
    ref_agx(grey, r, outset);
    assert_float_equal(outset[1], 0.786885, 1e-6);
    grey[0] = grey[1] = grey[2] = 64.0;
    ref_agx(grey, r, outset);
    assert_float_equal(outset[1], 0.998625, 1e-6);
    /* highlights desaturate instead of clipping: a saturated orange 16x over white keeps its
     * blue channel well above 0 and its red below 1 */
    {
        float in[3] = {16.0f, 4.0f, 0.25f}, out[3];
        assert_int_equal(rs_view_apply(&v, in, 1, out), RS_OK);
        assert_true(out[2] > 0.5f);
        assert_true(out[0] > out[1] && out[1] > out[2]);
    }
}

static const char ocio_config[] =
    "ocio_profile_version: 1\n"
    "\n"
    "roles:\n"
    "  default: linear\n"
    "  scene_linear: linear\n"
    "\n"
    "displays:\n"
    "  TestDisplay:\n"
    "    - !<View> {name: Raw, colorspace: linear}\n"
    "    - !<View> {name: Gamma, colorspace: gamma22}\n"
    "    - !<View> {name: Lut, colorspace: lut}\n"
    "\n"
    "colorspaces:\n"
    "  - !<ColorSpace>\n"
    "    name: linear\n"
    "    bitdepth: 32f\n"
    "    isdata: false\n"
    "    allocation: uniform\n"
    "\n"
    "  - !<ColorSpace>\n"
    "    name: gamma22\n"
    "    bitdepth: 32f\n"
    "    isdata: false\n"
    "    allocation: uniform\n"
    "    to_reference: !<ExponentTransform> {value: [2.2, 2.2, 2.2, 1]}\n"
    "\n"
    "  - !<ColorSpace>\n"
    "    name: lut\n"
    "    bitdepth: 32f\n"
    "    isdata: false\n"
    "    allocation: uniform\n"
    "    from_reference: !<FileTransform> {src: missing-lut.spi1d, interpolation: linear}\n";

static void test_ocio(void **state)
{
    rs_view raw, gamma, v;
    char why[512];
    float x[RAMP_N * 3], d[RAMP_N * 3];
    size_t i;
    (void)state;
    if (!rs_view_ocio_available()) {
        printf("skipped: this build's OpenImageIO has no OpenColorIO\n");
        skip();
    }
    if (!rs_view_from_name("Raw", 0.0f, &raw, why, sizeof why))
        fail_msg("Raw: %s", why);
    assert_int_equal(raw.kind, RS_VIEW_OCIO);
    assert_string_equal(raw.name, "Raw");
    if (!rs_view_from_name("Gamma", 0.0f, &gamma, why, sizeof why))
        fail_msg("Gamma: %s", why);
    assert_int_equal(gamma.kind, RS_VIEW_OCIO);
    /* built-ins first; unknown names list the config's views */
    assert_true(rs_view_from_name("filmic", 0.0f, &v, why, sizeof why));
    assert_int_equal(v.kind, RS_VIEW_FILMIC);
    assert_false(rs_view_from_name("Log", 0.0f, &v, why, sizeof why));
    assert_non_null(strstr(why, "Raw, Gamma, Lut"));
    assert_non_null(strstr(why, "standard, filmic (or agx), pbr-neutral"));

    for (i = 0; i < RAMP_N * 3; ++i)
        x[i] = 1.25f * (float)i / (RAMP_N * 3);
    assert_int_equal(rs_view_apply(&raw, x, RAMP_N, d), RS_OK);
    for (i = 0; i < RAMP_N * 3; ++i)
        assert_float_equal(d[i], fmin(x[i], 1.0), 1e-6);
    assert_int_equal(rs_view_apply(&gamma, x, RAMP_N, d), RS_OK);
    for (i = 0; i < RAMP_N * 3; ++i)
        if (fabs(d[i] - fmin(pow(x[i], 1.0 / 2.2), 1.0)) > 2e-4)
            fail_msg("Gamma: %.7g gives %.7g, the config says %.7g", (double)x[i], (double)d[i],
                     fmin(pow(x[i], 1.0 / 2.2), 1.0));
    for (i = 1; i < RAMP_N * 3; ++i)
        assert_true(d[i] >= d[i - 1]);
    /* exposure before the view */
    v = raw;
    v.exposure = -2.0f;
    assert_int_equal(rs_view_apply(&v, x, RAMP_N, d), RS_OK);
    for (i = 0; i < RAMP_N * 3; ++i)
        assert_float_equal(d[i], x[i] * 0.25, 1e-6);
}

static unsigned char *slurp(const char *path, size_t *n)
{
    FILE *f = fopen(path, "rb");
    unsigned char *b;
    long len;
    assert_non_null(f);
    fseek(f, 0, SEEK_END);
    len = ftell(f);
    fseek(f, 0, SEEK_SET);
    b = malloc((size_t)len + 1);
    assert_non_null(b);
    assert_int_equal(fread(b, 1, (size_t)len, f), (size_t)len);
    fclose(f);
    *n = (size_t)len;
    return b;
}

static void same_bytes(const char *a, const char *b)
{
    size_t na, nb;
    unsigned char *x = slurp(a, &na), *y = slurp(b, &nb);
    assert_int_equal(na, nb);
    assert_memory_equal(x, y, na);
    free(x);
    free(y);
}

static void test_write(void **state)
{
    enum { W = 64, H = 8 };
    static float rgb[W * H * 3], disp[W * H * 3];
    char p_old[300], p_null[300], p_std[300], p_film[300], p_exr[300], value[64];
    rs_view std0 = make("standard", 0.0f), film = make("filmic", 2.0f);
    uint32_t w, h;
    float *back = NULL;
    size_t i;
    (void)state;
    snprintf(p_old, sizeof p_old, "%s/old.png", tmpdir);
    snprintf(p_null, sizeof p_null, "%s/null.png", tmpdir);
    snprintf(p_std, sizeof p_std, "%s/std.png", tmpdir);
    snprintf(p_film, sizeof p_film, "%s/film.png", tmpdir);
    snprintf(p_exr, sizeof p_exr, "%s/film.exr", tmpdir);
    if (rs_image_check_output(p_old) != RS_OK) {
        printf("skipped: this build writes no PNG\n");
        skip();
    }
    for (i = 0; i < W * H * 3; ++i)
        rgb[i] = exp2f(-12.0f + 16.0f * (float)i / (W * H * 3)) * (i % 3 == 1 ? 0.5f : 1.0f);
    rgb[0] = -1.0f, rgb[1] = NAN;

    assert_int_equal(rs_image_write_layers(p_old, W, H, rgb, NULL, 0, NULL, 0), RS_OK);
    assert_int_equal(rs_image_write_view(p_null, W, H, rgb, NULL, 0, NULL, 0, NULL), RS_OK);
    assert_int_equal(rs_image_write_view(p_std, W, H, rgb, NULL, 0, NULL, 0, &std0), RS_OK);
    same_bytes(p_old, p_null);
    same_bytes(p_old, p_std);

    assert_int_equal(rs_image_write_view(p_film, W, H, rgb, NULL, 0, NULL, 0, &film), RS_OK);
    assert_int_equal(rs_view_apply(&film, rgb, W * H, disp), RS_OK);
    assert_int_equal(rs_image_read(p_film, &w, &h, &back), RS_OK);
    assert_int_equal(w, W);
    assert_int_equal(h, H);
    for (i = 0; i < W * H * 3; ++i)
        assert_int_equal(lroundf(back[i] * 255.0f), lroundf(disp[i] * 255.0f));
    rs_free(back);

    assert_int_equal(rs_image_write_view(p_exr, W, H, rgb, NULL, 0, NULL, 0, &film), RS_OK);
    assert_int_equal(rs_image_read(p_exr, &w, &h, &back), RS_OK);
    for (i = 2; i < W * H * 3; ++i) /* linear, untouched */
        assert_int_equal(bits(back[i]), bits(rgb[i]));
    rs_free(back);
    assert_int_equal(rs_image_read_meta(p_exr, "raystream:view", value, sizeof value), RS_OK);
    assert_string_equal(value, "filmic");
    assert_int_equal(rs_image_read_meta(p_exr, "raystream:exposure", value, sizeof value), RS_OK);
    assert_string_equal(value, "2");
    /* the default view records nothing */
    assert_int_equal(rs_image_write_view(p_exr, W, H, rgb, NULL, 0, NULL, 0, &std0), RS_OK);
    assert_int_not_equal(rs_image_read_meta(p_exr, "raystream:view", value, sizeof value), RS_OK);

    remove(p_old), remove(p_null), remove(p_std), remove(p_film), remove(p_exr);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_names),
        cmocka_unit_test(test_exposure_exact),
        cmocka_unit_test(test_standard_is_srgb),
        cmocka_unit_test(test_monotone_black),
        cmocka_unit_test(test_pbr_neutral_reference),
        cmocka_unit_test(test_agx_reference),
        cmocka_unit_test(test_ocio),
        cmocka_unit_test(test_write),
    };
    char cfg[320];
    int rc;
    /* the OCIO config is read once per process, on first use: $OCIO is set before any test */
    snprintf(tmpdir, sizeof tmpdir, "/tmp/rs_view_test_XXXXXX");
    if (!mkdtemp(tmpdir)) {
        perror("mkdtemp");
        return 1;
    }
    snprintf(cfg, sizeof cfg, "%s/config.ocio", tmpdir);
    {
        FILE *f = fopen(cfg, "w");
        if (!f)
            return 1;
        fputs(ocio_config, f);
        fclose(f);
    }
    setenv("OCIO", cfg, 1);
    rc = cmocka_run_group_tests(tests, NULL, NULL);
    remove(cfg);
    rmdir(tmpdir);
    return rc;
}
