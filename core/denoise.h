/* core/denoise.h — denoising a rendered image with Intel Open Image Denoise 2.x (OIDN), loaded
 * at run time with dlopen: raystream builds and runs without it (docs/denoise.md).
 *
 * Where the library comes from, in order:
 *   1. $RS_OIDN_LIBRARY, a path to libOpenImageDenoise.so.2 (when set and not empty, it is the
 *      only place tried: a library named by hand that cannot be loaded is an error, not a reason
 *      to take another one);
 *   2. /opt/raystream/oidn/lib/libOpenImageDenoise.so.2 (sh scripts/install-deps.sh puts it
 *      there, from PyPI's pyoidn wheel);
 *   3. libOpenImageDenoise.so.2 on the loader's usual path.
 * The first successful load is kept for the life of the process; a failed one is retried on the
 * next call (so a test may point RS_OIDN_LIBRARY elsewhere and call again).
 *
 * Images are w*h*3 floats, rows top to bottom, packed RGB (the film's layout).  OIDN never writes
 * to stderr through these calls: its messages come back through rs_error_set.
 *
 * Thread safety: both functions may be called from any thread; the library is loaded once under
 * a lock.  Each rs_denoise makes and releases its own OIDN device and filter (a denoise is done
 * once per render, so nothing is cached between calls). */
#ifndef RS_CORE_DENOISE_H
#define RS_CORE_DENOISE_H

#include <stddef.h>
#include <stdint.h>

#include "core/status.h"

/* The default install location (scripts/install-deps.sh). */
#define RS_DENOISE_DEFAULT_LIBRARY "/opt/raystream/oidn/lib/libOpenImageDenoise.so.2"

#ifdef __cplusplus
extern "C" {
#endif
/* 1 when OIDN 2.x can be loaded (why[0] = '\0'); else 0 with one line in why[n] (when why is not
 * NULL) saying what is missing and how to get it (sh scripts/install-deps.sh, or
 * RS_OIDN_LIBRARY=PATH).  Loads the library if it is not loaded yet; makes no device. */
int rs_denoise_available(char *why, size_t n);
/* rs_denoise_available, then a CPU device and its RT filter made and released: what a denoise
 * needs first, tried before a render (an OIDN that loads without its CPU device library failed
 * only after the render).  1, or 0 with why[n]. */
int rs_denoise_probe(char *why, size_t n);

/* Denoises `beauty` (w*h*3 floats, linear HDR radiance) into `out` (w*h*3 floats; may be
 * `beauty` itself) with OIDN's "RT" filter, hdr on.
 *   albedo, normal: first-hit AOVs (w*h*3 floats each) or NULL; albedo alone, or albedo and
 *     normal, or neither (beauty only): OIDN's RT filter takes no normal without an albedo, so
 *     normal without albedo is RS_ERR_ARG.  Albedo in [0,1], normals in [-1,1] (any space).
 *   clean_aux: 1 when the aux images are noise-free (OIDN's "cleanAux": it then trusts them
 *     fully, which keeps more detail; with noisy aux images pass 0).
 *   use_gpu: 1 tries OIDN's CUDA device first and falls back to its CPU device; 0 uses the CPU.
 *   device_used[n] (may be NULL): the device that ran, e.g. "CPU (OIDN 2.5.1)" or
 *     "CUDA (OIDN 2.5.1)"; after a fallback, "CPU (OIDN 2.5.1; CUDA: <why not>)".
 * Returns RS_OK; RS_ERR_ARG for w or h zero, a size that overflows, NULL beauty/out or normal
 * without albedo; RS_ERR_DEVICE_LOST when OIDN is missing, too old, or no device could be made
 * or the filter failed; RS_ERR_NOMEM when OIDN ran out of memory.  The message (rs_error_set)
 * is OIDN's own text, prefixed with what was being done.  `out` is unspecified on failure. */
rs_status rs_denoise(const float *beauty, const float *albedo, const float *normal, uint32_t w,
                     uint32_t h, int clean_aux, int use_gpu, float *out, char *device_used,
                     size_t n);

/* rs_denoise with what the camera sees emitted kept out of the denoiser: beauty - direct (the
 * light that arrived by reflection) is denoised, and direct_fine added back to the result.
 * direct: per pixel, the share of `beauty` that its camera rays' first hits emitted (an
 * emitter, the background), from the render's own samples; direct_fine: the same, estimated
 * better (the film's emission pass and shading/aov.h rs_aov_refine).  A light seen at 16 samples a pixel has a
 * noisy outline 15 times brighter than the wall beside it, which the denoiser cannot tell from
 * noise it should smooth; this way it never sees it.  direct or direct_fine NULL: rs_denoise.
 * Same arguments and results otherwise (`out` may be `beauty`). */
rs_status rs_denoise_split(const float *beauty, const float *direct, const float *direct_fine,
                           const float *albedo, const float *normal, uint32_t w, uint32_t h,
                           int clean_aux, int use_gpu, float *out, char *device_used, size_t n);
#ifdef __cplusplus
}
#endif
#endif
