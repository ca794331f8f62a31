/* shading/texture.h — texture lookups (RS_HD: plain data in, a colour out).
 *
 *   solid     a
 *   checker   3D cells of size `scale` (RTNW v4): a where floor(x/s)+floor(y/s)+floor(z/s) is
 *             even, b where it is odd — so it needs no UVs and has no seams
 *   stripes   `scale` stripes across u: a, b, a, ...
 *   image     bilinear between the four nearest texels, wrapping in u and v; v = 0 is the bottom
 *             row (the image's last), as in RTNW and OBJ files; with a footprint (below),
 *             trilinear: bilinear on the two mip levels around the footprint's level of detail,
 *             blended linearly; first through the texture's UV transform (glTF's
 *             KHR_texture_transform) where it has one
 *
 * A footprint is the width, in UV units, of what one pixel covers at the hit (shading/path.h:
 * rs_texture_footprint, pbrt-v4's camera approximation, docs/textures.md); 0: level 0 only,
 * bilinear, exactly the lookup without mip-maps. */
#ifndef RS_SHADING_TEXTURE_H
#define RS_SHADING_TEXTURE_H

#include <float.h>

#include "scenes/scene.h"

RS_HD int rs_wrap_index(int i, int n)
{
    int r = i % n;
    return r < 0 ? r + n : r;
}

RS_HD rs_vec3 rs_texel(const rs_image *im, int x, int y)
{
    const float *p = &im->rgb[3 * ((size_t)y * im->width + (size_t)x)];
    return rs_v3(p[0], p[1], p[2]);
}

RS_HD rs_vec3 rs_image_bilinear(const rs_image *im, float u, float v)
{
    float x = u * (float)im->width - 0.5f, y = (1.0f - v) * (float)im->height - 0.5f;
    float fx0 = floorf(x), fy0 = floorf(y);
    float fx = x - fx0, fy = y - fy0;
    int w = (int)im->width, h = (int)im->height;
    int x0, y0, x1, y1;
    rs_vec3 top, bottom;
    if (!(x == x && y == y)) /* NaN coordinates: the first texel, not a crash */
        return rs_texel(im, 0, 0);
    x0 = rs_wrap_index((int)fmodf(fx0, (float)w), w);
    y0 = rs_wrap_index((int)fmodf(fy0, (float)h), h);
    x1 = rs_wrap_index(x0 + 1, w);
    y1 = rs_wrap_index(y0 + 1, h);
    top = rs_v3_add(rs_v3_scale(rs_texel(im, x0, y0), 1.0f - fx),
                    rs_v3_scale(rs_texel(im, x1, y0), fx));
    bottom = rs_v3_add(rs_v3_scale(rs_texel(im, x0, y1), 1.0f - fx),
                       rs_v3_scale(rs_texel(im, x1, y1), fx));
    return rs_v3_add(rs_v3_scale(top, 1.0f - fy), rs_v3_scale(bottom, fy));
}

/* How image textures are filtered (rs_render_settings.texture_filter, --texture-filter). */
typedef enum rs_texture_filter {
    RS_TEXTURE_TRILINEAR = 0, /* mip-mapped, a level of detail per lookup (the default) */
    RS_TEXTURE_BILINEAR = 1   /* level 0 only: the images before mip-maps, bit for bit */
} rs_texture_filter;

/* Level k (< the image's levels) of image im as a one-level image of its own. */
RS_HD rs_image rs_image_level(const rs_image *im, uint32_t k)
{
    rs_image l;
    uint32_t w = im->width, h = im->height, j;
    size_t off = 0;
    for (j = 0; j < k; ++j) {
        off += 3 * (size_t)w * h;
        w = w > 1 ? w / 2 : 1;
        h = h > 1 ? h / 2 : 1;
    }
    l.width = w;
    l.height = h;
    l.rgb = im->rgb + off;
    l.levels = 1;
    return l;
}

/* log2(x) for a finite x > 0, within 0.01: the float's exponent (frexpf, exact) plus a quadratic
 * in its mantissa that is continuous and increasing.  Only exact steps, + and *: the host and
 * CUDA agree bit for bit, where the libraries' log2f may differ in the last bits, and a level
 * of detail needs no more. */
RS_HD float rs_log2_approx(float x)
{
    int e;
    float t = 2.0f * frexpf(x, &e) - 1.0f; /* x = (1 + t) 2^(e - 1), t in [0, 1) */
    return (float)(e - 1) + t * (1.3465f - 0.3465f * t);
}

/* The level of detail of image im for a footprint `uvw` wide in UV units: log2 of the footprint
 * in texels, 0.5 log2(uvw^2 w h) (Akenine-Moller et al. 2021, eq. 34 with the UV-to-world area
 * ratio folded into uvw), held to [0, levels - 1]. */
RS_HD float rs_image_lod(const rs_image *im, float uvw)
{
    float x = uvw * uvw * (float)im->width * (float)im->height;
    float top = im->levels > 1 ? (float)(im->levels - 1) : 0.0f;
    float l;
    if (!(x > 1.0f)) /* a footprint within a texel, zero, or NaN */
        return 0.0f;
    if (!(x <= FLT_MAX))
        return top;
    l = 0.5f * rs_log2_approx(x);
    return l < top ? l : top;
}

/* Image im at (u, v) and level of detail `lod`: bilinear on level floor(lod) and the next,
 * mixed by lod's fraction; at a whole lod exactly the bilinear lookup on that level. */
RS_HD rs_vec3 rs_image_trilinear(const rs_image *im, float u, float v, float lod)
{
    uint32_t k;
    float f;
    rs_image a, b;
    rs_vec3 ca;
    if (im->levels <= 1 || !(lod > 0.0f))
        return rs_image_bilinear(im, u, v);
    if (lod > (float)(im->levels - 1))
        lod = (float)(im->levels - 1);
    k = (uint32_t)lod;
    f = lod - (float)k;
    a = rs_image_level(im, k);
    ca = rs_image_bilinear(&a, u, v);
    if (!(f > 0.0f) || k + 1 >= im->levels)
        return ca;
    b = rs_image_level(im, k + 1);
    return rs_v3_add(rs_v3_scale(ca, 1.0f - f), rs_v3_scale(rs_image_bilinear(&b, u, v), f));
}

/* The texture's colour at surface coordinates (u, v) and point p (an image: bilinear on level
 * 0, after its UV transform). */
RS_HD rs_vec3 rs_texture_eval(const rs_texture *t, const rs_image *images, float u, float v,
                              rs_vec3 p)
{
    switch (t->type) {
    case RS_TEX_CHECKER: {
        float inv = 1.0f / t->scale;
        long k = (long)floorf(p.x * inv) + (long)floorf(p.y * inv) + (long)floorf(p.z * inv);
        return (k & 1) ? t->b : t->a;
    }
    case RS_TEX_STRIPES: {
        long k = (long)floorf(u * t->scale);
        return (k & 1) ? t->b : t->a;
    }
    case RS_TEX_IMAGE:
        if (t->uv_xform) {
            const float *m = t->uv_m;
            float tu = m[0] * u + m[1] * v + m[2];
            v = m[3] * u + m[4] * v + m[5];
            u = tu;
        }
        return rs_image_bilinear(&images[t->image], u, v);
    default: return t->a;
    }
}

/* The texture's colour at surface coordinates (u, v) and point p, for a footprint `uvw` wide in
 * the surface's UV units (0: bilinear on level 0).  An image texture's UV transform maps (u, v)
 * first, and widens the footprint by sqrt|det| of its linear part. */
RS_HD rs_vec3 rs_texture_eval_lod(const rs_texture *t, const rs_image *images, float u, float v,
                                  rs_vec3 p, float uvw)
{
    if (t->type == RS_TEX_IMAGE) {
        const rs_image *im = &images[t->image];
        if (t->uv_xform) {
            const float *m = t->uv_m;
            float tu = m[0] * u + m[1] * v + m[2];
            v = m[3] * u + m[4] * v + m[5];
            u = tu;
            uvw *= sqrtf(fabsf(m[0] * m[4] - m[1] * m[3]));
        }
        if (!(uvw > 0.0f))
            return rs_image_bilinear(im, u, v);
        return rs_image_trilinear(im, u, v, rs_image_lod(im, uvw));
    }
    return rs_texture_eval(t, images, u, v, p);
}

#endif
