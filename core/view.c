/* core/view.c — the built-in view transforms and the view names (see view.h, docs/view.md).
 *
 * Every curve takes linear Rec.709 RGB after the exposure gain and gives display-encoded values
 * in [0, 1].  Each is monotone in grey and maps black to black; the standard view is
 * rs_srgb_encode itself, so an image written through it is byte for byte the pre-view one. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/srgb.h"
#include "core/view.h"

const char *rs_view_builtin_names(void) { return "standard, filmic (or agx), pbr-neutral"; }

int rs_view_is_default(const rs_view *v)
{
    return v->kind == RS_VIEW_STANDARD && v->exposure == 0.0f;
}

/* 2^ev, exactly a power of two when ev is a whole number (ldexpf scales the exponent only), so
 * the exposure gain never rounds a radiance; exp2f for fractional stops. */
static float exposure_gain(float ev)
{
    if (ev == floorf(ev))
        return ldexpf(1.0f, (int)ev);
    return exp2f(ev);
}

/* NaN and negative radiance count as black (a film never holds them; a curve must not see
 * them: log2 and the PBR Neutral offset are undefined there). */
static float nonneg(float x) { return x > 0.0f ? x : 0.0f; }

/* ---- filmic: AgX base -------------------------------------------------------------------
 * Troy Sobotka's AgX (github.com/sobotka/AgX, the base transform Blender 4 ships as "AgX"),
 * in the form of Benjamin Wrensch's reference "Minimal AgX implementation" (Missing Deadlines,
 * iolite-engine.com/blog_posts/minimal_agx_implementation, MIT licence): the inset matrix on
 * linear Rec.709, log2 encoding clamped to [min_ev, max_ev] and normalized to [0, 1], the
 * sigmoid as that page's 6th-order polynomial fit ("agxDefaultContrastApprox", mean squared
 * error 3.67e-6 against Troy's sigmoid; the exact sigmoid is not used), the outset (inverse
 * inset) matrix, and the reference's display step: pow(x, 2.2) back to linear light, then
 * stored as an sRGB render target stores it, with the sRGB curve.  The matrices are the
 * reference's GLSL column-major mat3s written out as rows (out = M in). */
static const float agx_inset[3][3] = {
    {0.842479062253094f, 0.0784335999999992f, 0.0792237451477643f},
    {0.0423282422610123f, 0.878468636469772f, 0.0791661274605434f},
    {0.0423756549057051f, 0.0784336f, 0.879142973793104f},
};
static const float agx_outset[3][3] = {
    {1.19687900512017f, -0.0980208811401368f, -0.0990297440797205f},
    {-0.0528968517574562f, 1.15190312990417f, -0.0989611768448433f},
    {-0.0529716355144438f, -0.0980434501171241f, 1.15107367264116f},
};
#define AGX_MIN_EV (-12.47393f)
#define AGX_MAX_EV 4.026069f

static float agx_sigmoid(float x)
{
    float x2 = x * x, x4 = x2 * x2;
    return 15.5f * x4 * x2 - 40.14f * x4 * x + 31.96f * x4 - 6.868f * x2 * x + 0.4298f * x2 +
           0.1191f * x - 0.00232f;
}

void rs_view_filmic_rgb(const float in[3], float out[3])
{
    float c[3] = {nonneg(in[0]), nonneg(in[1]), nonneg(in[2])}, s[3];
    int i;
    for (i = 0; i < 3; ++i) {
        float v = agx_inset[i][0] * c[0] + agx_inset[i][1] * c[1] + agx_inset[i][2] * c[2];
        float ev = v > 1e-10f ? log2f(v) : AGX_MIN_EV; /* log2(0) is -inf: the floor */
        ev = ev < AGX_MIN_EV ? AGX_MIN_EV : ev > AGX_MAX_EV ? AGX_MAX_EV : ev;
        s[i] = agx_sigmoid((ev - AGX_MIN_EV) / (AGX_MAX_EV - AGX_MIN_EV));
    }
    for (i = 0; i < 3; ++i) {
        /* the fit gives -0.00232 at the floor: below zero is black (the reference's pow of a
         * negative is undefined) */
        float d = agx_outset[i][0] * s[0] + agx_outset[i][1] * s[1] + agx_outset[i][2] * s[2];
        out[i] = rs_srgb_encode(d > 0.0f ? powf(d, 2.2f) : 0.0f);
    }
}

/* ---- pbr-neutral -------------------------------------------------------------------------
 * The Khronos PBR Neutral tone mapper, its reference GLSL
 * (github.com/KhronosGroup/ToneMapping, PBR_Neutral/pbrNeutral.glsl): a toe that removes a
 * small offset from the darkest channel, identity up to startCompression, then a rational
 * shoulder on the largest channel with a desaturation towards the new peak.  Its output is
 * linear; the sRGB curve encodes it. */
void rs_view_pbr_neutral_rgb(const float in[3], float out[3])
{
    const float start_compression = 0.8f - 0.04f;
    const float desaturation = 0.15f;
    float c[3] = {nonneg(in[0]), nonneg(in[1]), nonneg(in[2])};
    float x = fminf(c[0], fminf(c[1], c[2]));
    float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
    float peak;
    int i;
    for (i = 0; i < 3; ++i)
        c[i] -= offset;
    peak = fmaxf(c[0], fmaxf(c[1], c[2]));
    if (peak >= start_compression) {
        const float d = 1.0f - start_compression;
        float new_peak = 1.0f - d * d / (peak + d - start_compression);
        float g = 1.0f - 1.0f / (desaturation * (peak - new_peak) + 1.0f);
        for (i = 0; i < 3; ++i) {
            c[i] *= new_peak / peak;
            c[i] = c[i] * (1.0f - g) + new_peak * g; /* GLSL mix(color, newPeak, g) */
        }
    }
    for (i = 0; i < 3; ++i)
        out[i] = rs_srgb_encode(c[i]);
}

/* ---- names -------------------------------------------------------------------------------- */

static int builtin_kind(const char *name, rs_view_kind *kind, const char **canon)
{
    if (!name || strcmp(name, "standard") == 0)
        *kind = RS_VIEW_STANDARD, *canon = "standard";
    else if (strcmp(name, "filmic") == 0 || strcmp(name, "agx") == 0)
        *kind = RS_VIEW_FILMIC, *canon = "filmic";
    else if (strcmp(name, "pbr-neutral") == 0)
        *kind = RS_VIEW_PBR_NEUTRAL, *canon = "pbr-neutral";
    else
        return 0;
    return 1;
}

int rs_view_from_name(const char *name, float exposure_ev, rs_view *out, char *why, size_t n)
{
    rs_view v;
    const char *canon;
    char ocio_why[512];
    memset(&v, 0, sizeof v);
    if (!(exposure_ev >= -64.0f && exposure_ev <= 64.0f)) { /* NaN fails both */
        snprintf(why, n, "exposure %g EV is outside -64..64", (double)exposure_ev);
        return 0;
    }
    v.exposure = exposure_ev;
    if (builtin_kind(name, &v.kind, &canon)) {
        snprintf(v.name, sizeof v.name, "%s", canon);
        *out = v;
        return 1;
    }
    if (!*name) {
        snprintf(why, n, "empty view name (views: %s)", rs_view_builtin_names());
        return 0;
    }
    if (strlen(name) >= sizeof v.name) {
        snprintf(why, n, "view name '%.40s...' is longer than %d characters", name,
                 (int)sizeof v.name - 1);
        return 0;
    }
    switch (rs_view_ocio_find(name, ocio_why, sizeof ocio_why)) {
    case 1: break;
    case 0:
        snprintf(why, n, "unknown view '%s' (built-in views: %s; %s)", name,
                 rs_view_builtin_names(), ocio_why);
        return 0;
    default: snprintf(why, n, "%s", ocio_why); return 0;
    }
    v.kind = RS_VIEW_OCIO;
    snprintf(v.name, sizeof v.name, "%s", name);
    *out = v;
    return 1;
}

/* ---- applying ----------------------------------------------------------------------------- */

rs_status rs_view_apply(const rs_view *v, const float *linear_rgb, size_t npix, float *display_rgb)
{
    float gain = exposure_gain(v->exposure);
    size_t i, n = npix * 3;
    rs_status st;
    switch (v->kind) {
    case RS_VIEW_STANDARD:
        for (i = 0; i < n; ++i)
            display_rgb[i] = rs_srgb_encode(linear_rgb[i] * gain);
        return RS_OK;
    case RS_VIEW_FILMIC:
    case RS_VIEW_PBR_NEUTRAL:
#if defined(_OPENMP)
#  pragma omp parallel for schedule(static) if (npix > 65536)
#endif
        for (i = 0; i < npix; ++i) {
            float c[3] = {linear_rgb[3 * i] * gain, linear_rgb[3 * i + 1] * gain,
                          linear_rgb[3 * i + 2] * gain};
            if (v->kind == RS_VIEW_FILMIC)
                rs_view_filmic_rgb(c, display_rgb + 3 * i);
            else
                rs_view_pbr_neutral_rgb(c, display_rgb + 3 * i);
        }
        return RS_OK;
    case RS_VIEW_OCIO:
        for (i = 0; i < n; ++i)
            display_rgb[i] = nonneg(linear_rgb[i] * gain);
        st = rs_view_ocio_apply(v->name, display_rgb, npix);
        if (st != RS_OK)
            return st;
        for (i = 0; i < n; ++i) /* a display's code values: [0, 1], NaN as 0 */
            display_rgb[i] = display_rgb[i] > 0.0f ? fminf(display_rgb[i], 1.0f) : 0.0f;
        return RS_OK;
    }
    return rs_error_set(RS_ERR_ARG, "unknown view kind %d", (int)v->kind);
}
