/* core/image_io_pfm.c — image files without OpenImageIO (builds configured with
 * RS_DEPS=OPTIONAL where it is not installed, such as a bare GPU machine): Portable Float Maps
 * only (.pfm, linear RGB, written bottom row first as the format says), with the same
 * temporary-file-and-rename write as the OpenImageIO shim.  Every other extension is an error
 * that says why. */
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
