/* core/image_io_pfm.c — image files without OpenImageIO (builds configured with
 * RS_DEPS=OPTIONAL where it is not installed, such as a bare GPU machine): Portable Float Maps
 * only (.pfm, linear RGB: core/pfm.c, which the OpenImageIO build uses for them too).  Every
 * other extension is an error that says why. */
#include <ctype.h>
#include <string.h>

#include "core/alloc.h"
#include "core/image_io.h"
#include "core/pfm.h"

rs_status rs_image_check_output(const char *path)
{
    if (!rs_pfm_is_path(path))
        return rs_error_set(RS_ERR_ARG,
                            "%s: this build has no OpenImageIO and writes .pfm files only", path);
    return rs_pfm_check_output(path);
}

rs_status rs_image_write(const char *path, uint32_t w, uint32_t h, const float *rgb)
{
    rs_status st = rs_image_check_output(path);
    return st != RS_OK ? st : rs_pfm_write(path, w, h, rgb);
}

rs_status rs_image_read(const char *path, uint32_t *w, uint32_t *h, float **rgb)
{
    return rs_pfm_read(path, w, h, rgb);
}

rs_status rs_image_read_linear(const char *path, uint32_t *w, uint32_t *h, float **rgb)
{
    return rs_image_read(path, w, h, rgb); /* PFM is linear */
}

rs_status rs_image_write_meta(const char *path, uint32_t w, uint32_t h, const float *rgb,
                              const rs_image_meta *meta, size_t n_meta)
{
    (void)meta; /* a .pfm has no header for them */
    (void)n_meta;
    return rs_image_write(path, w, h, rgb);
}

/* Extra layers need an .exr, which needs OpenImageIO; without layers a .pfm as rs_image_write. */
rs_status rs_image_write_layers(const char *path, uint32_t w, uint32_t h, const float *rgb,
                                const rs_image_layer *layers, size_t n_layers,
                                const rs_image_meta *meta, size_t n_meta)
{
    (void)layers;
    if (n_layers > 0)
        return rs_error_set(RS_ERR_ARG,
                            "%s: extra layers (AOVs) need an .exr file, and this build has no "
                            "OpenImageIO",
                            path);
    return rs_image_write_meta(path, w, h, rgb, meta, n_meta);
}

/* A .pfm is a float format: the view leaves its pixels linear, as in the OpenImageIO build, and
 * the format has no header to record the view in. */
rs_status rs_image_write_view(const char *path, uint32_t w, uint32_t h, const float *rgb,
                              const rs_image_layer *layers, size_t n_layers,
                              const rs_image_meta *meta, size_t n_meta, const rs_view *view)
{
    (void)view;
    return rs_image_write_layers(path, w, h, rgb, layers, n_layers, meta, n_meta);
}

int rs_image_is_display_format(const char *path)
{
    static const char *const exts[] = {"png", "jpg", "jpeg", "tif", "tiff", "bmp", "tga"};
    const char *slash = strrchr(path, '/'), *dot = strrchr(path, '.');
    char e[8];
    size_t i, n;
    if (!dot || (slash && dot < slash) || (n = strlen(dot + 1)) >= sizeof e)
        return 0;
    for (i = 0; i <= n; ++i)
        e[i] = (char)tolower((unsigned char)dot[1 + i]);
    for (i = 0; i < sizeof exts / sizeof exts[0]; ++i)
        if (strcmp(e, exts[i]) == 0)
            return 1;
    return 0;
}

rs_status rs_image_read_channel(const char *path, const char *channel, uint32_t *w, uint32_t *h,
                                float **data)
{
    return rs_pfm_read_channel(path, channel, w, h, data);
}

/* A .pfm has no alpha: opaque (RS_OK, *alpha NULL) once the file reads as one. */
rs_status rs_image_read_alpha(const char *path, uint32_t *w, uint32_t *h, float **alpha)
{
    float *rgb = NULL;
    rs_status st = rs_image_read(path, w, h, &rgb);
    *alpha = NULL;
    rs_free(rgb);
    return st;
}

rs_status rs_image_read_meta(const char *path, const char *key, char *value, size_t n)
{
    (void)value;
    (void)n;
    return rs_error_set(RS_ERR_ARG, "%s: no attribute %s (this build has no OpenImageIO)", path,
                        key);
}

const char *rs_image_library_version(void) { return "none (PFM only)"; }

/* No resampler without OpenImageIO: image textures keep one level (bilinear lookups), which
 * scenes/scene.c learns from rs_image_can_downsample. */
int rs_image_can_downsample(void) { return 0; }

rs_status rs_image_downsample(const float *rgb, uint32_t w, uint32_t h, float *out, uint32_t w2,
                              uint32_t h2)
{
    (void)rgb;
    (void)out;
    return rs_error_set(RS_ERR_ARG, "downsampling a %ux%u image to %ux%u: this build has no "
                                    "OpenImageIO", w, h, w2, h2);
}
