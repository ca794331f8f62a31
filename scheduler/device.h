/* scheduler/device.h — what the render loops know of a device: a table of functions.
 *
 * One device model serves both integrators.  The CPU device (cpu/), the CUDA device and its CPU
 * fallback (gpu/) each fill this table; the engine's stream runs (scheduler/stream_engine.c) and
 * megakernel runs (scheduler/passes.c) see nothing else, and cpu/ and gpu/ never include
 * each other.
 *
 * Life cycle: create (device-specific constructor) -> upload once -> trace many chunks (from
 * exactly one dispatch thread at a time) and/or upload_scene once per render (the engine's
 * creation, scheduler/render.h), render_pass many times (from the render thread, for every plan
 * the engine runs) -> destroy.
 *
 * Memory.  A device with RS_DEVICE_OWN_MEMORY traces in memory of its own (a CUDA device): the
 * geometry is copied at upload and every chunk is copied in and out.  Where it offers host_alloc,
 * the wave buffers are allocated with it (page-locked memory that the device reads and writes by
 * DMA), and it copies a chunk straight from the caller's arrays without staging.  A host device
 * borrows the caller's arrays: they must outlive it.
 *
 * Thread safety: `trace` is only called from the device's dispatch thread, `upload_scene` and
 * `render_pass` only from the render thread, never both in one render.  `stats` is written by
 * the scheduler under its lock (rays, chunks, busy and idle time) and by the device itself
 * inside the calls above (the bytes it copied: the GPU devices and the fallback, from the one
 * thread that calls them); read it after rs_sched_destroy or through rs_sched_device_stats
 * (scheduler/sched.h). */
#ifndef RS_SCHEDULER_DEVICE_H
#define RS_SCHEDULER_DEVICE_H

#include "accel/bvh.h"
#include "accel/trace.h"
#include "core/parallel.h"
#include "shading/film.h"
#include "shading/path.h"

typedef struct rs_device rs_device;

/* Device flags. */
#define RS_DEVICE_OWN_MEMORY 1u /* traces in memory of its own (a GPU), not on host threads */
/* Its render_paths runs the host's own stages on host threads (the CPU device): where another
 * device can only trace, it stays with that one in the stream engine instead (somebody must
 * shade for it, and it traces too). */
#define RS_DEVICE_HOST_PATHS 2u

/* One call of the megakernel's pass loop: what render_pass needs besides its sample range. */
typedef struct rs_pass_job {
    const rs_render_consts *it; /* the render's constants; it->scene is the host scene */
    rs_film *film;            /* each pixel's samples are added in sample order */
    rs_par_strategy strategy; /* how host threads split the pixels */
    /* Polled between pixels (host devices) or passes (GPUs); NULL: never.  Non-zero: stop and
     * return RS_OK with the samples finished so far on the film. */
    int (*cancelled)(void *user);
    /* `paths` more paths are on the film; called from one thread at a time.  May be NULL. */
    void (*progress)(void *user, uint64_t paths);
    void *user;
} rs_pass_job;

/* One call of render_paths: what a device needs to run paths whole (the wavefront). */
typedef struct rs_paths_job {
    const rs_render_consts *it; /* the render's constants; it->scene is the host scene */
    /* The plan's pixels (shading/integrator.h's rs_path_map): path g is pixel
     * pixel_of[g mod n_active] (NULL: g mod n_active itself), sample g div n_active.  Host
     * memory; `plan_id` changes whenever the plan does, so a device may keep a copy. */
    const uint32_t *pixel_of;
    uint32_t n_active;
    uint64_t plan_id;
    rs_film *film; /* the paths' samples are added to it (exact sums: in any order) */
    /* Polled between waves; non-zero: stop, and put only the waves finished on the film. */
    int (*cancelled)(void *user);
    void *user;
} rs_paths_job;

typedef struct rs_device_ops {
    /* Makes the scene geometry and BVH available to the device (a copy for a GPU; the host
     * arrays are only borrowed by host devices and must outlive the device). */
    rs_status (*upload)(rs_device *d, const rs_geom *g, const rs_bvh *bvh);
    /* Traces rays [begin, end) of `batch`, writing the matching answers.  Blocking.  On failure
     * the answers for the range are undefined and the scheduler hands the range to another
     * device. */
    rs_status (*trace)(rs_device *d, const rs_trace_batch *batch, uint32_t begin, uint32_t end);
    void (*destroy)(rs_device *d);
    /* Optional (NULL: malloc'd memory).  `bytes` of host memory the device copies to and from
     * without staging (page-locked on a GPU), 64-byte aligned; NULL when short.  Freed with
     * host_free. */
    void *(*host_alloc)(rs_device *d, size_t bytes);
    void (*host_free)(rs_device *d, void *p);
    /* Optional (NULL: the device reads the host scene in place; a device with memory of its own
     * must have it to run the megakernel).  After upload: copies the scene's shading data
     * (materials, textures, lights) and the constants `it` for render_pass, which reads only
     * these copies (`it` is plain device-safe data: shading/path.h).  A second call replaces
     * the first; destroy releases the copy. */
    rs_status (*upload_scene)(rs_device *d, const rs_scene *scene, const rs_render_consts *it);
    /* Samples [s0, s0 + n) of every pixel, each path traced by the device's own loop over
     * shading/path.h's rs_path_start / rs_path_step with its own traversal, added to job->film,
     * each pixel's samples in sample order; the rays traced are added to *counts.
     * Stops early, with RS_OK, when job->cancelled says so. */
    rs_status (*render_pass)(rs_device *d, const rs_pass_job *job, uint32_t s0, uint32_t n,
                             rs_path_counts *counts);
    /* Optional (NULL: the device only traces for the host's stages).  After upload_scene (where
     * the device has one; a host device reads the host scene in place, after upload): paths
     * [p0, p1) of job's plan run whole where the device is (the wavefront: camera rays, both
     * traversals, shading, shadow rays, compaction and the film, each a stage over the device's
     * own path state; per wave only counts cross to the host), in waves of consecutive paths,
     * then added to job->film.  *done: the paths on the film, p1 - p0 unless job->cancelled
     * stopped it (a prefix: the finished waves); the rays traced are added to *counts. */
    rs_status (*render_paths)(rs_device *d, const rs_paths_job *job, uint64_t p0, uint64_t p1,
                              uint64_t *done, rs_path_counts *counts);
} rs_device_ops;

typedef struct rs_device_stats {
    uint64_t rays;     /* rays answered by this device */
    uint64_t chunks;   /* chunks answered */
    uint64_t failures; /* failed trace calls (the device is retired after the first) */
    double busy_s;     /* seconds inside trace() */
    double idle_s;     /* seconds the dispatch thread waited for work */
    uint64_t bytes_to_device, bytes_from_device; /* transfers, for devices with own memory */
} rs_device_stats;

struct rs_device {
    const rs_device_ops *ops;
    char name[48];         /* "cpu", "cuda:0 (NVIDIA H100 ...)", "gpu-fallback:0", ... */
    uint32_t flags;        /* RS_DEVICE_* */
    int threads;           /* host threads the device uses (0 for a GPU) */
    uint32_t pass_samples; /* samples per render_pass call the pass loop hands it; 0: all */
    rs_device_stats stats;
    void *impl;
};

/* Convenience wrappers; rs_device_destroy(NULL) is a no-op. */
#ifdef __cplusplus
extern "C" {
#endif
rs_status rs_device_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh);
void rs_device_destroy(rs_device *d);
/* 1 if the device traces off the host (RS_DEVICE_OWN_MEMORY). */
int rs_device_owns_memory(const rs_device *d);
#ifdef __cplusplus
}
#endif

#endif
