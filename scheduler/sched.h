/* scheduler/sched.h — hands traversal work to devices.
 *
 * Each device gets a dispatch thread (pthreads) that pulls chunks from one shared bounded queue:
 * work pulling, so a faster device simply takes more chunks.  A batch of rays is cut into chunks
 * of `chunk_size` rays; rs_sched_trace returns when every ray of the batch has been answered
 * exactly once.  A device whose trace fails is retired, its chunk goes back to the front of the
 * queue, and the remaining devices finish the batch; only when no device is left does a trace
 * fail (RS_ERR_DEVICE_LOST).
 *
 * Thread safety: one caller thread drives rs_sched_trace; stats may be read with
 * rs_sched_device_stats from that thread at any time. */
#ifndef RS_SCHEDULER_SCHED_H
#define RS_SCHEDULER_SCHED_H

#include "scheduler/device.h"

typedef struct rs_sched rs_sched;

typedef struct rs_sched_config {
    uint32_t chunk_size;     /* rays per chunk (>= 1); 0 means RS_SCHED_DEFAULT_CHUNK */
    uint32_t queue_capacity; /* chunks the queue holds (>= 1); 0 means 256 */
} rs_sched_config;

#define RS_SCHED_DEFAULT_CHUNK 65536u

/* Starts one dispatch thread per device.  The devices must already hold the scene (upload);
 * they stay owned by the caller and must outlive the scheduler. */
rs_status rs_sched_create(rs_device *const *devices, int n_devices, const rs_sched_config *cfg,
                          rs_sched **out);
/* Traces every ray of `batch` and blocks until all are answered. */
rs_status rs_sched_trace(rs_sched *s, const rs_trace_batch *batch);
/* Stops and joins the dispatch threads.  NULL is a no-op. */
void rs_sched_destroy(rs_sched *s);

int rs_sched_device_count(const rs_sched *s);
rs_device *rs_sched_device(const rs_sched *s, int i);
/* A consistent copy of device i's counters; *alive is 0 once the device has been retired. */
void rs_sched_device_stats(rs_sched *s, int i, rs_device_stats *out, int *alive);
/* Totals over every batch so far: rays submitted and rays answered (equal when nothing was lost).
 */
void rs_sched_totals(rs_sched *s, uint64_t *submitted, uint64_t *answered);

#endif
