/* core/pfm.c — Portable Float Maps by our own code (core/pfm.h). */
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/image_io.h"
#include "core/pfm.h"

int rs_pfm_is_path(const char *path)
{
    size_t n = strlen(path);
    return n > 4 && (strcmp(path + n - 4, ".pfm") == 0 || strcmp(path + n - 4, ".PFM") == 0);
}

rs_status rs_pfm_check_output(const char *path)
{
    char dir[4096];
    const char *slash = strrchr(path, '/');
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1,
             slash ? (slash == path ? "/" : path) : ".");
    if (access(dir, W_OK) != 0)
        return rs_error_set(RS_ERR_IO, "%s: the folder %s does not exist or is not writable", path,
                            dir);
    return RS_OK;
}

rs_status rs_pfm_write(const char *path, uint32_t w, uint32_t h, const float *rgb)
{
    char tmp[4200];
    FILE *f;
    uint32_t y;
    int ok;
    rs_status st = rs_pfm_check_output(path);
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

rs_status rs_pfm_read(const char *path, uint32_t *w, uint32_t *h, float **rgb)
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
        return rs_error_set(RS_ERR_IO, "%s: not a little-endian RGB .pfm", path);
    }
    *w = ww;
    *h = hh;
    return RS_OK;
}

rs_status rs_pfm_read_channel(const char *path, const char *channel, uint32_t *w, uint32_t *h,
                              float **data)
{
    static const char names[] = "RGB";
    const char *c = strlen(channel) == 1 ? strchr(names, channel[0]) : NULL;
    float *rgb = NULL;
    size_t i, n;
    rs_status st;
    *data = NULL;
    if (!c || !*c)
        return rs_error_set(RS_ERR_ARG, "%s: no channel %s (a .pfm holds R, G and B only)", path,
                            channel);
    st = rs_pfm_read(path, w, h, &rgb);
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
