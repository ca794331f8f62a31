/* scenes/scene_env.c — the environment map's distribution (see scene_env.h, shading/envmap.h).
 *
 * Texel (i, j) of a W x H map covers the directions with theta in [j, j + 1) pi / H (from the
 * zenith down) and phi in [i, i + 1) 2 pi / W.  Sampling picks a row by the marginal CDF and a
 * texel in it by the row's conditional CDF, both over luminance times sin(theta) at the row's
 * centre, then a point uniform in the texel's (u, v) rectangle: the density over (u, v) is the
 * texel's probability times W H, and over solid angle that divided by 2 pi^2 sin(theta). */
#include "scenes/scene_env.h"

#include <float.h>
#include <math.h>
#include <string.h>

#include "core/alloc.h"

#define PI 3.14159265358979323846

rs_status rs_scene_set_environment(rs_scene *s, uint32_t image, rs_vec3 scale,
                                   const float *rot_world_to_map)
{
    static const float id[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    if (image >= s->n_images)
        return rs_error_set(RS_ERR_ARG, "environment map: no image %u", image);
    if (!(scale.x >= 0 && scale.y >= 0 && scale.z >= 0) || !isfinite(scale.x) ||
        !isfinite(scale.y) || !isfinite(scale.z))
        return rs_error_set(RS_ERR_ARG, "environment map: scale must be finite and >= 0");
    s->env_image = image;
    s->env_scale = scale;
    memcpy(s->env_rot, rot_world_to_map ? rot_world_to_map : id, sizeof s->env_rot);
    s->finalized = 0;
    return RS_OK;
}

static float luminance(const float *rgb)
{
    return 0.2126f * rgb[0] + 0.7152f * rgb[1] + 0.0722f * rgb[2];
}

double rs_scene_bound_radius(const rs_scene *s)
{
    rs_vec3 lo = rs_v3_splat(FLT_MAX), hi = rs_v3_splat(-FLT_MAX);
    uint32_t i;
    for (i = 0; i < s->n_spheres; ++i) {
        rs_vec3 r = rs_v3_splat(s->spheres[i].radius);
        lo = rs_v3_min(lo, rs_v3_sub(s->spheres[i].center, r));
        hi = rs_v3_max(hi, rs_v3_add(s->spheres[i].center, r));
    }
    for (i = 0; i < s->n_quads; ++i) {
        const rs_quad *q = &s->quads[i];
        rs_vec3 c[4];
        int k;
        c[0] = q->q, c[1] = rs_v3_add(q->q, q->u), c[2] = rs_v3_add(q->q, q->v);
        c[3] = rs_v3_add(c[1], q->v);
        for (k = 0; k < 4; ++k)
            lo = rs_v3_min(lo, c[k]), hi = rs_v3_max(hi, c[k]);
    }
    for (i = 0; i < s->n_tris; ++i) {
        lo = rs_v3_min(lo, rs_v3_min(s->tris[i].v0, rs_v3_min(s->tris[i].v1, s->tris[i].v2)));
        hi = rs_v3_max(hi, rs_v3_max(s->tris[i].v0, rs_v3_max(s->tris[i].v1, s->tris[i].v2)));
    }
    for (i = 0; i < s->n_instances; ++i) { /* the exact bounds of the placed triangles */
        lo = rs_v3_min(lo, s->instances[i].box.lo);
        hi = rs_v3_max(hi, s->instances[i].box.hi);
    }
    if (!(lo.x <= hi.x))
        return 1.0;
    {
        double dx = (double)hi.x - lo.x, dy = (double)hi.y - lo.y, dz = (double)hi.z - lo.z;
        double r = 0.5 * sqrt(dx * dx + dy * dy + dz * dz);
        return r > 0 ? r : 1.0;
    }
}

/* No map: a constant background colour is a uniform sky, light-sampled as one (over the
 * sphere, MIS-weighted against BSDF rays that escape), as pbrt's and Mitsuba's constant emitters
 * are; before, only BSDF rays that escaped saw it.  The RTIOW gradient (background_sky) is not
 * sampled.  Its power in *power (left 0 otherwise). */
static void constant_background(rs_scene *s, double *power)
{
    const rs_vec3 b = s->background;
    const float rgb[3] = {b.x, b.y, b.z};
    if (!s->background_sky && isfinite(b.x) && isfinite(b.y) && isfinite(b.z) && b.x >= 0 &&
        b.y >= 0 && b.z >= 0 && luminance(rgb) > 0) {
        double r = rs_scene_bound_radius(s);
        s->env_uniform = 1;
        s->env_uniform_le = b;
        *power = PI * r * r * (double)luminance(rgb) * 4.0 * PI;
    }
}

/* Each row's CDF over its texels (by luminance times the scale's, times sin theta) into
 * s->env_cond_cdf, each row's sum into row_sum; returns the sum of all. */
static double conditional_cdfs(rs_scene *s, const rs_image *im, double *row_sum)
{
    uint32_t w = im->width, h = im->height, i, j;
    double total = 0;
    /* the scale's luminance weights the distribution as it weights the radiance */
    const float sc[3] = {s->env_scale.x, s->env_scale.y, s->env_scale.z};
    for (j = 0; j < h; ++j) {
        double sin_t = sin(PI * (j + 0.5) / h), acc = 0;
        float *cdf = &s->env_cond_cdf[(size_t)j * (w + 1)];
        for (i = 0; i < w; ++i) {
            const float *t = &im->rgb[3 * ((size_t)j * w + i)];
            float rgb[3];
            rgb[0] = t[0] * sc[0], rgb[1] = t[1] * sc[1], rgb[2] = t[2] * sc[2];
            cdf[i] = (float)acc;
            acc += (double)luminance(rgb) * sin_t;
        }
        row_sum[j] = acc;
        total += acc;
        /* a black row is never picked; its CDF is made uniform so that it is well formed */
        for (i = 0; i <= w; ++i)
            cdf[i] = acc > 0 ? (i == w ? 1.0f : (float)(cdf[i] / acc)) : (float)i / (float)w;
        cdf[w] = 1.0f;
    }
    return total;
}

rs_status rs_scene_env_build(rs_scene *s, double *power)
{
    const rs_image *im;
    uint32_t w, h, i, j;
    double *row_sum, total = 0, lum_int = 0;
    *power = 0;
    rs_free(s->env_marg_cdf);
    rs_free(s->env_cond_cdf);
    s->env_marg_cdf = s->env_cond_cdf = NULL;
    s->env_pick = 0.0f;
    s->env_uniform = 0;
    s->env_uniform_le = rs_v3_splat(0.0f);
    if (s->env_image == RS_NO_TEXTURE) {
        constant_background(s, power);
        return RS_OK;
    }
    if (s->env_image >= s->n_images)
        return rs_error_set(RS_ERR_ARG, "environment map: no image %u", s->env_image);
    im = &s->images[s->env_image];
    w = im->width;
    h = im->height;
    for (i = 0; i < 3 * w * h; ++i)
        if (!isfinite(im->rgb[i]) || im->rgb[i] < 0)
            return rs_error_set(RS_ERR_ARG,
                                "environment map: texel (%u, %u) is %s (texels must be finite "
                                "and >= 0)",
                                (i / 3) % w, (i / 3) / w, isfinite(im->rgb[i]) ? "negative" : "not finite");
    /* a map whose texels are all alike lights the scene from every direction the same: sampled
     * uniformly over the sphere with no table search and no trigonometry per lookup */
    for (i = 3; i < 3 * w * h && im->rgb[i] == im->rgb[i % 3]; ++i)
        ;
    if (i == 3 * w * h) {
        s->env_uniform = 1;
        s->env_uniform_le = rs_v3_mul(rs_v3(im->rgb[0], im->rgb[1], im->rgb[2]), s->env_scale);
    }
    row_sum = (double *)rs_alloc(h, sizeof *row_sum);
    s->env_marg_cdf = (float *)rs_alloc((size_t)h + 1, sizeof *s->env_marg_cdf);
    s->env_cond_cdf = (float *)rs_alloc((size_t)h * ((size_t)w + 1), sizeof *s->env_cond_cdf);
    if (!row_sum || !s->env_marg_cdf || !s->env_cond_cdf) {
        rs_free(row_sum);
        rs_free(s->env_marg_cdf);
        rs_free(s->env_cond_cdf);
        s->env_marg_cdf = s->env_cond_cdf = NULL;
        return rs_error_set(RS_ERR_NOMEM, "out of memory for a %ux%u environment map", w, h);
    }
    total = conditional_cdfs(s, im, row_sum);
    {
        double acc = 0;
        for (j = 0; j < h; ++j) {
            s->env_marg_cdf[j] = total > 0 ? (float)(acc / total) : (float)j / (float)h;
            acc += row_sum[j];
        }
        s->env_marg_cdf[h] = 1.0f;
    }
    rs_free(row_sum);
    /* the integral of luminance over directions: each texel's solid angle is
     * (2 pi / W) (pi / H) sin(theta) */
    lum_int = total * (2.0 * PI / w) * (PI / h);
    if (total > 0) {
        double r = rs_scene_bound_radius(s);
        *power = PI * r * r * lum_int;
    }
    return RS_OK;
}
