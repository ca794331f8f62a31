/* core/pfm.h — Portable Float Maps (.pfm: linear RGB floats, bottom row first) by our own code.
 * Every build writes them here (OpenImageIO 2.4 reads them but cannot write them); the build
 * without OpenImageIO reads them here too (the OpenImageIO build reads them through the library,
 * which also takes big-endian and greyscale ones).  Writes go through a temporary file renamed
 * into place, as every image write. */
#ifndef RS_CORE_PFM_H
#define RS_CORE_PFM_H

#include <stdint.h>

#include "core/status.h"

#ifdef __cplusplus
extern "C" {
#endif

/* 1 when `path` ends in .pfm (either case). */
int rs_pfm_is_path(const char *path);
/* RS_OK when the folder `path` would be written in exists and is writable. */
rs_status rs_pfm_check_output(const char *path);
rs_status rs_pfm_write(const char *path, uint32_t w, uint32_t h, const float *rgb);
/* A little-endian RGB .pfm; `*rgb` from rs_alloc, top row first. */
rs_status rs_pfm_read(const char *path, uint32_t *w, uint32_t *h, float **rgb);
/* One of R, G or B of a .pfm. */
rs_status rs_pfm_read_channel(const char *path, const char *channel, uint32_t *w, uint32_t *h,
                              float **data);

#ifdef __cplusplus
}
#endif

#endif
