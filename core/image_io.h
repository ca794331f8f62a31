/* core/image_io.h — image files through OpenImageIO, behind a small C API.
 *
 * The format follows the file extension.  Float formats (.exr, .hdr, .pfm) get linear radiance;
 * 8-bit formats (.png, .jpg, .jpeg, .tif, .tiff, .bmp, .tga) get the sRGB transfer curve after
 * clamping to [0, 1], or a view's display values (rs_image_write_view, core/view.h).  Writes go
 * to a temporary file beside the target that is renamed over it only once complete, so a failed
 * or interrupted write never leaves a partial file and never clobbers a good one.  C++ exceptions
 * stop at this API's edge. */
#ifndef RS_CORE_IMAGE_IO_H
#define RS_CORE_IMAGE_IO_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"
#include "core/view.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Checks, before any work, that `path` has a supported extension and that its folder exists
 * and accepts new files (by creating and removing a probe file). */
rs_status rs_image_check_output(const char *path);

/* Writes width x height RGB (3 floats a pixel, row-major from the top-left, linear). */
rs_status rs_image_write(const char *path, uint32_t width, uint32_t height, const float *rgb);

/* A string attribute of an image file's header ("raystream:spp" = "64"). */
typedef struct rs_image_meta {
    const char *key, *value;
} rs_image_meta;

/* rs_image_write with n_meta header attributes, kept where the format has a header for them
 * (.exr only: the other formats are written as rs_image_write writes them, byte for byte). */
rs_status rs_image_write_meta(const char *path, uint32_t width, uint32_t height, const float *rgb,
                              const rs_image_meta *meta, size_t n_meta);

/* An extra layer of an EXR file: channels "<name>.<c>" for each letter c of `channels`
 * ("albedo" + "RGB": albedo.R, albedo.G, albedo.B), `data` holding strlen(channels) floats a
 * pixel. */
typedef struct rs_image_layer {
    const char *name;
    const char *channels;
    const float *data;
} rs_image_layer;

/* rs_image_write_meta with n_layers extra layers after R, G, B (only an .exr can hold them:
 * RS_ERR_ARG for another format when n_layers > 0). */
rs_status rs_image_write_layers(const char *path, uint32_t width, uint32_t height,
                                const float *rgb, const rs_image_layer *layers, size_t n_layers,
                                const rs_image_meta *meta, size_t n_meta);

/* rs_image_write_layers through a view (core/view.h).  An 8-bit format stores the view's
 * display values (rs_view_apply, then round(255 v)) with no second sRGB encoding; a float format
 * (.exr, .hdr, .pfm) stays scene-linear, neither exposed nor tone mapped, and an .exr records
 * the view as the attributes "raystream:view" (its name) and "raystream:exposure" (EV, "%g").
 * `view` NULL or the default view (rs_view_is_default: standard at 0 EV) writes exactly what
 * rs_image_write_layers writes, byte for byte, with no attribute added. */
rs_status rs_image_write_view(const char *path, uint32_t width, uint32_t height, const float *rgb,
                              const rs_image_layer *layers, size_t n_layers,
                              const rs_image_meta *meta, size_t n_meta, const rs_view *view);

/* 1 when `path`'s extension is an 8-bit display format (.png .jpg .jpeg .tif .tiff .bmp .tga,
 * any case): the files a view applies to. */
int rs_image_is_display_format(const char *path);

/* Channel `channel` ("R", "albedo.G", "depth.Z") of image `path`: width * height floats
 * (rs_alloc).  RS_ERR_ARG when the file has no such channel. */
rs_status rs_image_read_channel(const char *path, const char *channel, uint32_t *width,
                                uint32_t *height, float **data);

/* The string attribute `key` of image `path` into value[n] (NUL-terminated, cut to fit).
 * RS_ERR_ARG when the file has no such attribute or cannot be read. */
rs_status rs_image_read_meta(const char *path, const char *key, char *value, size_t n);

/* Read images are bounded: the file must be a regular file of at most RS_FILE_MAX_IMAGE_BYTES
 * (core/file.h) and the image at most this many pixels, each side at most RS_IMAGE_MAX_SIDE. */
#define RS_IMAGE_MAX_SIDE   65536
#define RS_IMAGE_MAX_PIXELS ((uint64_t)1 << 28)

/* Reads any image OpenImageIO knows as RGB floats in the file's own encoding (8-bit files give
 * their code values / 255, not decoded).  *rgb is allocated with rs_alloc; free with rs_free. */
rs_status rs_image_read(const char *path, uint32_t *width, uint32_t *height, float **rgb);

/* Reads an image as linear RGB: files stored as integers (8/16-bit PNG, JPEG, ...) are taken
 * as sRGB-encoded and decoded; float files (EXR, HDR) are already linear.  For textures. */
rs_status rs_image_read_linear(const char *path, uint32_t *width, uint32_t *height, float **rgb);

/* Reads an image's alpha channel (OpenImageIO's alpha channel, or the second of two channels,
 * or the fourth of four), as stored (8-bit: code / 255): width * height floats, rows from the top.
 * An image without one gives RS_OK and *alpha NULL.  Free with rs_free. */
rs_status rs_image_read_alpha(const char *path, uint32_t *width, uint32_t *height, float **alpha);

/* A w2 x h2 copy of the w x h RGB float image rgb (rows from the top) into out (w2 * h2 * 3
 * floats, the caller's), filtered by OpenImageIO's resize with a box one output pixel wide: a
 * 2:1 reduction averages each 2x2 block.  w2 <= w, h2 <= h.  For texture mip levels. */
rs_status rs_image_downsample(const float *rgb, uint32_t w, uint32_t h, float *out, uint32_t w2,
                              uint32_t h2);
/* 1 where rs_image_downsample works (OpenImageIO is built in), 0 in the PFM-only build. */
int rs_image_can_downsample(void);

/* "2.4.7" */
const char *rs_image_library_version(void);

#ifdef __cplusplus
}
#endif
#endif
