/* scheduler/passes.h — the megakernel's pass loop, beside the wavefront loop (render.h).
 *
 * The thesis's classic integrator: each sample's path traced from the camera to its end
 * (rs_path_radiance, shading/path.h: the wavefront's own per-path code with the same random
 * numbers) on ONE device, through its render_pass entry (scheduler/device.h).  The loop hands
 * the device its samples in calls of d->pass_samples samples (all of them for the CPU device,
 * whose pixel loop adds each pixel's samples one after the other; a few per call for a GPU,
 * which runs one pass over every pixel per sample), checks Ctrl-C and reports progress between
 * calls.  Each pixel gets its samples in sample order, so the image is the wavefront's bit for
 * bit on the host devices (and up to the GPU's arithmetic on CUDA).
 *
 * With a time limit or a film_ready hook (render.h) the film must end every call on whole
 * samples: the CPU device then gets one sample per call and is not told of a cancel (it would
 * stop within a sample), which the loop checks between calls instead.  settings->path_begin
 * must be a whole number of passes. */
#ifndef RS_SCHEDULER_PASSES_H
#define RS_SCHEDULER_PASSES_H

#include "scheduler/render.h"

/* Renders like rs_render on device `d` (already uploaded with the scene's geometry and BVH; it
 * must have render_pass).  Waves, chunks and cores of `settings` are ignored: the device uses its
 * own threads.  On cancel the samples not started are left out and RS_ERR_CANCELLED returned. */
rs_status rs_render_passes(const rs_scene *scene, rs_device *d, const rs_render_settings *settings,
                           const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats);

#endif
