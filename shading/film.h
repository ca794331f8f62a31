/* shading/film.h — the image being accumulated: per pixel, the sum of sample radiances and the
 * number of samples.  A pixel's value is the mean of its samples: the pixel filter is applied by
 * the camera, which draws each sample's position from the filter's own shape (filter importance
 * sampling, shading/filter.h; a sample under a negative lobe counts negated), so the film adds
 * no weights.
 *
 * The sums are exact integers: each sample's radiance is rounded once to a multiple of
 * 1 / RS_FILM_SCALE and added into a 128-bit integer.  Integer addition is associative, so a
 * pixel's sum depends only on which samples it got, never on their order or grouping: a film
 * rendered in pieces (waves, passes, ranks of an MPI job, a resumed checkpoint) and combined
 * with rs_film_merge in any order equals the one film of the same samples bit for bit
 * (tests/render_determinism_test.c).  The quantum 2^-40 (9.1e-13) is far below a float's
 * resolution of any pixel value above 1e-5; a sample beyond +-2^48 (2.8e14) is counted as
 * non-finite, so 2^32 samples of the largest still fit in 2^127. */
#ifndef RS_SHADING_FILM_H
#define RS_SHADING_FILM_H

#include "core/status.h"
#include "core/vec3.h"
#include "streams/paths.h"

#define RS_FILM_SCALE      0x1p40 /* film units per unit of radiance (2^40) */
#define RS_FILM_MAX_SAMPLE 0x1p48 /* larger radiances count as non-finite */

/* A pixel channel's sum in units of 1 / RS_FILM_SCALE (host only: the devices hand the host
 * radiances, which the host adds). */
__extension__ typedef __int128 rs_film_sum;

/* A pixel's sum of squared luminances l^2, exact like rs_film_sum so that merged films do not
 * depend on the order (an MPI job's adaptive rounds are decided from merged films): each l^2
 * (l is a luminance within +-RS_FILM_MAX_SAMPLE, so l^2 < 2^96) rounded once to a multiple of
 * 2^-64, added into a 192-bit integer, w[0] its lowest 64 bits; 2^32 samples of the largest
 * still fit. */
typedef struct rs_film_sq {
    uint64_t w[3];
} rs_film_sq;

typedef struct rs_film {
    uint32_t width, height;
    rs_film_sum *sum;   /* 3 per pixel, row-major from the top-left */
    uint32_t *count;    /* samples per pixel */
    rs_film_sq *sum_l2; /* per pixel, the sum of the samples' squared luminance (adaptive
                           sampling's error estimate), exact as `sum` is; NULL unless
                           rs_film_track_variance asked for it */
    uint64_t nonfinite; /* samples that were NaN, infinite or beyond RS_FILM_MAX_SAMPLE:
                           counted, contributed zero */
    /* The passes (NULL unless rs_film_keep_passes asked for them): what each sample's camera
     * ray showed at its first hit (streams/paths.h rs_path_aux), written by the devices as they
     * render, exact sums as `sum` is, so that they merge in any order too.  RS_FILM_PASSES per
     * pixel: albedo (RS_FILM_PASS_ALBEDO, 3), shading normal (RS_FILM_PASS_NORMAL, 3), the
     * direct emission (RS_FILM_PASS_EMISSION, 3: rs_path_first_emission, its share of the
     * pixel) and the distance (RS_FILM_PASS_DEPTH, 1; misses add nothing); pass_hits: per
     * pixel, the samples whose camera ray hit something (the distance's divisor). */
    rs_film_sum *pass;
    uint32_t *pass_hits;
} rs_film;

#define RS_FILM_PASS_ALBEDO   0
#define RS_FILM_PASS_NORMAL   3
#define RS_FILM_PASS_EMISSION 6
#define RS_FILM_PASS_DEPTH    9
#define RS_FILM_PASSES        10

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
/* Adds every sample of `src` (the same size) to `dst`: sums, counts and the non-finite count;
 * the squared-luminance sums only where both films keep them.  RS_ERR_ARG on a size mismatch.
 * The passes likewise where both films keep them; RS_ERR_ARG where only `dst` does.  Exact: merging films in any order gives the
 * same film. */
rs_status rs_film_merge(rs_film *dst, const rs_film *src);
/* Clears every sum and count (and the non-finite count), the passes too. */
void rs_film_clear(rs_film *f);
/* Pixel `pixel`'s channel sums as doubles (rounded once). */
void rs_film_pixel_sum(const rs_film *f, uint32_t pixel, double out[3]);
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
/* Pixel `pixel`'s sum of squared luminances as a double (rounded; 0 without
 * rs_film_track_variance). */
double rs_film_pixel_sq(const rs_film *f, uint32_t pixel);
/* From now on keep the passes (`pass`, `pass_hits`): on an empty film. */
rs_status rs_film_keep_passes(rs_film *f);
/* Adds one sample's passes to pixel `pixel` (a film that keeps them; the sample itself is added
 * by rs_film_add): components beyond +-RS_FILM_MAX_SAMPLE or not finite add zero, a depth that
 * is not finite (a miss) adds nothing. */
void rs_film_add_pass(rs_film *f, uint32_t pixel, const rs_path_aux *a);
/* rs_film_add_pass for every pixel, aux[pixel] (the megakernel's pass), on `threads` threads. */
void rs_film_add_pass_image(rs_film *f, const rs_path_aux *aux, int threads);
/* The passes as images (each NULL when not wanted; a film without passes writes zeros):
 * albedo, normal and emission 3 floats a pixel, depth 1; row-major from the top-left.  Each the
 * mean over the pixel's samples, but the normal: the mean's direction (zero where every sample
 * missed), and the depth: the mean over the samples that hit (infinity where none did). */
void rs_film_resolve_passes(const rs_film *f, float *albedo, float *normal, float *emission,
                            float *depth);
/* Fewest samples any pixel has. */
uint32_t rs_film_min_count(const rs_film *f);
/* The samples on the film, every pixel's together. */
uint64_t rs_film_samples(const rs_film *f);
#ifdef __cplusplus
}
#endif

#endif
