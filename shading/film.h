/* shading/film.h — the image being accumulated: per pixel, the sum of sample radiances (double)
 * and the number of samples.  A pixel's value is the mean (a box filter over the pixel, since
 * samples are jittered uniformly inside it).  Samples are added in a fixed order by one thread
 * (the render loop), so the sums are bit-reproducible. */
#ifndef RS_SHADING_FILM_H
#define RS_SHADING_FILM_H

#include "core/status.h"
#include "core/vec3.h"

typedef struct rs_film {
    uint32_t width, height;
    double *sum;        /* 3 per pixel, row-major from the top-left */
    uint32_t *count;    /* samples per pixel */
    double *sum_l2;     /* per pixel, the sum of the samples' squared luminance (adaptive
                           sampling's error estimate; not in checkpoints); NULL unless
                           rs_film_track_variance asked for it */
    uint64_t nonfinite; /* samples that were NaN or infinite: counted, contributed zero */
} rs_film;

#ifdef __cplusplus
extern "C" {
#endif
rs_status rs_film_create(uint32_t width, uint32_t height, rs_film **out);
void rs_film_destroy(rs_film *f);
void rs_film_add(rs_film *f, uint32_t pixel, rs_vec3 radiance);
/* One sample for every pixel: radiance[pixel] for pixel in [0, width * height), the pixels split
 * among `threads` host threads (a pass of the megakernel: each pixel still gets its samples in
 * the order of the calls). */
void rs_film_add_image(rs_film *f, const rs_vec3 *radiance, int threads);
/* Writes width * height * 3 floats of mean radiance (0 where a pixel has no sample yet). */
void rs_film_resolve(const rs_film *f, float *rgb);
/* From now on keep each pixel's sum of squared luminance (for rs_film_rel_error): on an empty
 * film, so that it covers every sample. */
rs_status rs_film_track_variance(rs_film *f);
/* The relative standard error of pixel `pixel`'s mean luminance: sqrt(var / n) / mean, the
 * sample variance from the sums, the mean held at least 1e-3 (dark pixels are not sampled for
 * ever); infinity below two samples or without rs_film_track_variance, 0 for a pixel whose
 * samples are all alike. */
double rs_film_rel_error(const rs_film *f, uint32_t pixel);
/* Fewest samples any pixel has. */
uint32_t rs_film_min_count(const rs_film *f);
#ifdef __cplusplus
}
#endif

#endif
