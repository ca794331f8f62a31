/* scheduler/device.h — what the scheduler knows of a device: a table of functions.
 *
 * The CPU device, the CUDA device and the CUDA fallback all implement this interface; the
 * scheduler sees nothing else.  Life cycle: create (device-specific constructor) -> upload once
 * -> trace many chunks (from exactly one dispatch thread at a time) -> destroy.
 *
 * Thread safety: `trace` is only called from the device's dispatch thread.  `stats` is written
 * by the scheduler under its lock; read it after rs_sched_destroy or through rs_sched_stats. */
#ifndef RS_SCHEDULER_DEVICE_H
#define RS_SCHEDULER_DEVICE_H

#include "accel/bvh.h"
#include "accel/trace.h"

typedef struct rs_device rs_device;

typedef struct rs_device_ops {
    /* Makes the scene geometry and BVH available to the device (a copy for a GPU; the host
     * arrays are only borrowed by CPU devices and must outlive the device). */
    rs_status (*upload)(rs_device *d, const rs_geom *g, const rs_bvh *bvh);
    /* Traces rays [begin, end) of `batch`, writing the matching answers.  Blocking.  On failure
     * the answers for the range are undefined and the scheduler hands the range to another
     * device. */
    rs_status (*trace)(rs_device *d, const rs_trace_batch *batch, uint32_t begin, uint32_t end);
    void (*destroy)(rs_device *d);
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
    char name[48]; /* "cpu", "cuda:0 (NVIDIA H100 ...)", "gpu-fallback", ... */
    int threads;   /* host threads the device uses (0 for a GPU) */
    rs_device_stats stats;
    void *impl;
};

/* Convenience wrappers; rs_device_destroy(NULL) is a no-op. */
#ifdef __cplusplus
extern "C" {
#endif
rs_status rs_device_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh);
void rs_device_destroy(rs_device *d);
#ifdef __cplusplus
}
#endif

#endif
