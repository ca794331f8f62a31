/* shading/texture.h — texture lookups (RS_HD: plain data in, a colour out).
 *
 *   solid     a
 *   checker   3D cells of size `scale` (RTNW v4): a where floor(x/s)+floor(y/s)+floor(z/s) is
 *             even, b where it is odd — so it needs no UVs and has no seams
 *   stripes   `scale` stripes across u: a, b, a, ...
 *   image     bilinear between the four nearest texels, wrapping in u and v; v = 0 is the bottom
 *             row (the image's last), as in RTNW and OBJ files */
#ifndef RS_SHADING_TEXTURE_H
#define RS_SHADING_TEXTURE_H

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

/* The texture's colour at surface coordinates (u, v) and point p. */
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
    case RS_TEX_IMAGE: return rs_image_bilinear(&images[t->image], u, v);
    default: return t->a;
    }
}

#endif
