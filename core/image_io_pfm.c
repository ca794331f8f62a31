/* core/image_io_pfm.c — image files without OpenImageIO (builds configured with
 * RS_DEPS=OPTIONAL where it is not installed, such as a bare GPU machine): Portable Float Maps
 * only (.pfm, linear RGB, written bottom row first as the format says), with the same
 * temporary-file-and-rename write as the OpenImageIO shim.  Every other extension is an error
 * that says why. */
#include <ctype.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/image_io.h"

static int is_pfm(const char *path)
{
    size_t n = strlen(path);
    return n > 4 && (strcmp(path + n - 4, ".pfm") == 0 || strcmp(path + n - 4, ".PFM") == 0);
}

rs_status rs_image_check_output(const char *path)
{
    char dir[4096];
    const char *slash = strrchr(path, '/');
    if (!is_pfm(path))
        return rs_error_set(RS_ERR_ARG,
                            "%s: this build has no OpenImageIO and writes .pfm files only", path);
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1,
             slash ? (slash == path ? "/" : path) : ".");
    if (access(dir, W_OK) != 0)
        return rs_error_set(RS_ERR_IO, "%s: the folder %s does not exist or is not writable", path,
                            dir);
    return RS_OK;
}

rs_status rs_image_write(const char *path, uint32_t w, uint32_t h, const float *rgb)
{
    char tmp[4200];
    FILE *f;
    uint32_t y;
    int ok;
    rs_status st = rs_image_check_output(path);
    if (st != RS_OK)
        return st;
    if (!rs_file_temp_name(path, tmp, sizeof tmp))
        return rs_error_set(RS_ERR_ARG, "%s: path too long", path);
    if (!(f = fopen(tmp, "wb")))
        return rs_error_set(RS_ERR_IO, "%s: cannot write", path);
    ok = fprintf(f, "PF\n%u %u\n-1.0\n", w, h) > 0; /* negative scale: little-endian floats */
    for (y = h; ok && y-- > 0;)
        ok = fwrite(rgb + (size_t)y * w * 3, sizeof(float), (size_t)w * 3, f) == (size_t)w * 3;
    ok = (fclose(f) == 0) && ok;
    if (!ok || rename(tmp, path) != 0) {
        remove(tmp);
        return rs_error_set(RS_ERR_IO, "%s: write failed", path);
    }
    return RS_OK;
}

rs_status rs_image_read(const char *path, uint32_t *w, uint32_t *h, float **rgb)
{
    FILE *f;
    unsigned ww, hh;
    float scale;
    uint32_t y;
    int ok;
    rs_status st;
    *rgb = NULL;
    /* a regular file of a sane size only (a FIFO would block, /dev/zero never end) */
    st = rs_file_open(path, RS_FILE_MAX_IMAGE_BYTES, &f, NULL);
    if (st != RS_OK)
        return st;
    ok = fscanf(f, "PF %u %u %f", &ww, &hh, &scale) == 3 && fgetc(f) != EOF && scale < 0.0f &&
         ww > 0 && hh > 0 && ww < 65536 && hh < 65536 && (uint64_t)ww * hh <= RS_IMAGE_MAX_PIXELS;
    if (ok)
        ok = (*rgb = (float *)rs_alloc((size_t)ww * hh * 3, sizeof(float))) != NULL;
    for (y = hh; ok && y-- > 0;)
        ok = fread(*rgb + (size_t)y * ww * 3, sizeof(float), (size_t)ww * 3, f) == (size_t)ww * 3;
    fclose(f);
    if (!ok) {
        rs_free(*rgb);
        *rgb = NULL;
        return rs_error_set(
            RS_ERR_IO, "%s: not a little-endian RGB .pfm (this build has no OpenImageIO)", path);
    }
    *w = ww;
    *h = hh;
    return RS_OK;
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

/* A .pfm holds R, G and B. */
rs_status rs_image_read_channel(const char *path, const char *channel, uint32_t *w, uint32_t *h,
                                float **data)
{
    static const char names[] = "RGB";
    const char *c = strlen(channel) == 1 ? strchr(names, channel[0]) : NULL;
    float *rgb = NULL;
    size_t i, n;
    rs_status st;
    *data = NULL;
    if (!c || !*c)
        return rs_error_set(RS_ERR_ARG, "%s: no channel %s (this build has no OpenImageIO: .pfm "
                                        "files hold R, G and B only)",
                            path, channel);
    st = rs_image_read(path, w, h, &rgb);
    if (st != RS_OK)
        return st;
    n = (size_t)*w * *h;
    if (!(*data = (float *)rs_alloc(n, sizeof(float)))) {
        rs_free(rgb);
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory reading channel %s", path, channel);
    }
    for (i = 0; i < n; ++i)
        (*data)[i] = rgb[3 * i + (size_t)(c - names)];
    rs_free(rgb);
    return RS_OK;
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
