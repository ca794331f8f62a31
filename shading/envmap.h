/* shading/envmap.h — the environment map as a light: its radiance along a direction, a direction
 * sampled in proportion to luminance times sin(theta), and that sampling's pdf (RS_HD: the CUDA
 * megakernel lights its paths with this very code).
 *
 * Directions d are turned into the map's frame by the scene's rotation, m = R d, then
 *   theta = acos(m.y)                          v = theta / pi        (v = 0: the top row, +y)
 *   phi   = atan2(m.x, -m.z), in (-pi, pi]     u = 1/2 + phi / 2 pi  (u = 1/2: the -z direction)
 * so the middle of the image lies straight ahead of a camera looking down -z, +x to its right.
 * The radiance is the texel's (nearest, no filtering: the pdf is constant over a texel, and so
 * the estimate is exact for any map), times the scene's env_scale.
 * The distribution is built by rs_scene_finalize (scenes/scene_env.c).  A map whose texels are
 * all alike (a uniform sky, env_uniform) is sampled uniformly over the sphere, pdf 1 / 4 pi, and
 * its radiance and pdf are constants: no table search, no trigonometry but the sample's own.  A
 * constant background colour (no map) is such a uniform sky too, sampled the same way. */
#ifndef RS_SHADING_ENVMAP_H
#define RS_SHADING_ENVMAP_H

#include "core/sampling.h"
#include "scenes/scene.h"

/* Whether rays that leave the scene see a light: a map, or a constant background colour, which
 * finalize makes a uniform sky (env_uniform without an image). */
RS_HD int rs_env_present(const rs_scene *s)
{
    return s->env_image != RS_NO_TEXTURE || s->env_uniform;
}

/* Whether light sampling has anything to pick: an emitter or a map that is not black. */
RS_HD int rs_scene_has_lights(const rs_scene *s) { return s->n_lights > 0 || s->env_pick > 0.0f; }

RS_HD rs_vec3 rs_env_rot(const float *r, rs_vec3 d)
{
    return rs_v3(r[0] * d.x + r[1] * d.y + r[2] * d.z, r[3] * d.x + r[4] * d.y + r[5] * d.z,
                 r[6] * d.x + r[7] * d.y + r[8] * d.z);
}

RS_HD rs_vec3 rs_env_rot_inv(const float *r, rs_vec3 d)
{
    return rs_v3(r[0] * d.x + r[3] * d.y + r[6] * d.z, r[1] * d.x + r[4] * d.y + r[7] * d.z,
                 r[2] * d.x + r[5] * d.y + r[8] * d.z);
}

/* The texel (i, j) that direction m (in the map's frame, unit) falls in; *sin_t = sin(theta). */
RS_HD void rs_env_texel_of(const rs_image *im, rs_vec3 m, uint32_t *i, uint32_t *j, float *sin_t)
{
    float y = rs_fminf(1.0f, rs_fmaxf(-1.0f, m.y));
    float u = 0.5f + rs_atan2f(m.x, -m.z) * (0.5f * RS_INV_PI), v = rs_acosf(y) * RS_INV_PI;
    float fi = u * (float)im->width, fj = v * (float)im->height;
    *i = fi >= (float)im->width ? im->width - 1 : fi > 0.0f ? (uint32_t)fi : 0u;
    *j = fj >= (float)im->height ? im->height - 1 : fj > 0.0f ? (uint32_t)fj : 0u;
    *sin_t = sqrtf(rs_fmaxf(0.0f, 1.0f - y * y));
}

/* Radiance arriving along -d from the map, d unit (not necessarily: it is normalised). */
RS_HD_COLD rs_vec3 rs_env_radiance(const rs_scene *s, rs_vec3 d)
{
    const rs_image *im;
    rs_vec3 m;
    uint32_t i, j;
    float st;
    const float *t;
    if (s->env_uniform) /* first: a constant background has no image */
        return s->env_uniform_le;
    im = &s->images[s->env_image];
    m = rs_env_rot(s->env_rot, rs_v3_normalize(d));
    rs_env_texel_of(im, m, &i, &j, &st);
    t = &im->rgb[3 * ((size_t)j * im->width + i)];
    return rs_v3_mul(rs_v3(t[0], t[1], t[2]), s->env_scale);
}

/* The largest k in [0, n) with cdf[k] <= u (cdf[0] = 0, cdf[n] = 1, u in [0, 1)): an entry of
 * zero probability is never returned. */
RS_HD uint32_t rs_env_cdf_find(const float *cdf, uint32_t n, float u)
{
    uint32_t lo = 0, hi = n;
    while (hi - lo > 1) {
        uint32_t mid = (lo + hi) / 2;
        if (cdf[mid] <= u)
            lo = mid;
        else
            hi = mid;
    }
    return lo;
}

/* The density over (u, v) of texel (i, j): its probability times W H. */
RS_HD float rs_env_texel_pdf(const rs_scene *s, uint32_t i, uint32_t j)
{
    const rs_image *im = &s->images[s->env_image];
    const float *row = &s->env_cond_cdf[(size_t)j * (im->width + 1)];
    float pr = s->env_marg_cdf[j + 1] - s->env_marg_cdf[j], pc = row[i + 1] - row[i];
    return pr * pc * (float)im->width * (float)im->height;
}

/* The solid-angle pdf with which rs_env_sample draws direction d (unit), pick probability not
 * included. */
RS_HD_COLD float rs_env_pdf(const rs_scene *s, rs_vec3 d)
{
    uint32_t i, j;
    float st;
    if (s->env_uniform)
        return 0.25f * RS_INV_PI;
    if (!s->env_marg_cdf)
        return 0.0f;
    rs_env_texel_of(&s->images[s->env_image], rs_env_rot(s->env_rot, rs_v3_normalize(d)), &i, &j, &st);
    if (!(st > 0.0f))
        return 0.0f;
    return rs_env_texel_pdf(s, i, j) / (2.0f * RS_PI * RS_PI * st);
}

/* A direction *wi toward the map from (u1, u2), its pdf (pick probability not included) and the
 * radiance along it.  0: none (a black map, or the sample landed on a pole). */
RS_HD_COLD int rs_env_sample(const rs_scene *s, float u1, float u2, rs_vec3 *wi, float *pdf,
                             rs_vec3 *le)
{
    const rs_image *im;
    const float *row;
    uint32_t i, j;
    float du, dv, u, v, theta, phi, st, ct, sp, cp, span;
    rs_vec3 m;
    if (s->env_uniform) {
        /* a uniform map or a constant background: uniform over the sphere (the rotation
         * changes nothing) */
        *wi = rs_sample_uniform_sphere(u1, u2);
        *pdf = 0.25f * RS_INV_PI;
        *le = s->env_uniform_le;
        return 1;
    }
    if (!s->env_marg_cdf)
        return 0;
    im = &s->images[s->env_image];
    j = rs_env_cdf_find(s->env_marg_cdf, im->height, u1);
    span = s->env_marg_cdf[j + 1] - s->env_marg_cdf[j];
    if (!(span > 0.0f))
        return 0;
    dv = rs_fminf((u1 - s->env_marg_cdf[j]) / span, 0.99999994f);
    row = &s->env_cond_cdf[(size_t)j * (im->width + 1)];
    i = rs_env_cdf_find(row, im->width, u2);
    span = row[i + 1] - row[i];
    if (!(span > 0.0f))
        return 0;
    du = rs_fminf((u2 - row[i]) / span, 0.99999994f);
    u = ((float)i + du) / (float)im->width;
    v = ((float)j + dv) / (float)im->height;
    theta = v * RS_PI;
    phi = (u - 0.5f) * 2.0f * RS_PI;
    rs_sincosf(theta, &st, &ct);
    if (!(st > 0.0f))
        return 0;
    rs_sincosf(phi, &sp, &cp);
    /* the inverse of rs_env_texel_of's mapping: m.x = sin sin(phi), m.z = -sin cos(phi) */
    m = rs_v3(st * sp, ct, -st * cp);
    *wi = rs_env_rot_inv(s->env_rot, m);
    *pdf = rs_env_texel_pdf(s, i, j) / (2.0f * RS_PI * RS_PI * st);
    {
        const float *t = &im->rgb[3 * ((size_t)j * im->width + i)];
        *le = rs_v3_mul(rs_v3(t[0], t[1], t[2]), s->env_scale);
    }
    return *pdf > 0.0f;
}

/* A uniform sky seen from a surface point with unit normal n: sampled in proportion to cos
 * about n (the hemisphere light can arrive from through a reflecting surface), pdf max(0, n.w) /
 * pi, the very distribution a Lambertian BSDF samples, so that the MIS weights of the two are
 * 1/2 each and no light sample is spent below the surface (uniform over the sphere wasted half
 * of them).  A map, or n zero (no surface: the light tests), is sampled as rs_env_sample does,
 * and rs_env_pdf_at is rs_env_pdf there. */
RS_HD float rs_env_pdf_at(const rs_scene *s, rs_vec3 n, rs_vec3 d)
{
    if (s->env_uniform && !rs_v3_is_zero(n))
        return rs_fmaxf(0.0f, rs_v3_dot(n, d) / rs_v3_length(d)) * RS_INV_PI;
    return rs_env_pdf(s, d);
}

RS_HD int rs_env_sample_at(const rs_scene *s, rs_vec3 n, float u1, float u2, rs_vec3 *wi,
                           float *pdf, rs_vec3 *le)
{
    if (s->env_uniform && !rs_v3_is_zero(n)) {
        rs_onb f = rs_onb_from_normal(n);
        rs_vec3 l = rs_sample_cosine_hemisphere(u1, u2);
        *wi = rs_onb_to_world(&f, l);
        *pdf = rs_env_pdf_at(s, n, *wi); /* as a BSDF ray that escapes is weighed */
        *le = s->env_uniform_le;
        return *pdf > 0.0f;
    }
    return rs_env_sample(s, u1, u2, wi, pdf, le);
}

#endif
