/* scheduler/sched.h — hands traversal work to devices.
 *
 * Each device gets a dispatch thread (pthreads).  Callers submit jobs (one batch of rays each)
 * to one shared bounded queue; each dispatch thread cuts its next chunk off the oldest job that
 * still has rays to hand out (work pulling: a faster device simply takes more chunks).  A job is
 * done when every ray of its batch has been answered exactly once.
 *
 * Chunk sizes.  A fixed `chunk_size` cuts every chunk to that size.  With 0 (adaptive, the
 * default) each device's chunk size follows its measured throughput: rays/s (a running mean
 * over its chunks) times a target chunk time, RS_SCHED_TARGET_HOST_S for devices that run on host
 * threads and RS_SCHED_TARGET_GPU_S for a GPU, between RS_SCHED_MIN_CHUNK and RS_SCHED_MAX_CHUNK.
 * Near the end of the queued work a chunk is also capped at the device's share of what is left
 * (left × its rays/s ÷ the sum over live devices), so that the devices finish together instead
 * of the slow one holding a large last chunk (guided self-scheduling, weighted by speed).
 *
 * Faults.  A device whose trace fails is retired, its chunk goes back to be taken first by the
 * others, and the remaining devices finish the work; only when no device is left does a job fail
 * (RS_ERR_DEVICE_LOST).
 *
 * Thread safety: any one thread may submit and wait; the job must stay alive, and its batch
 * unchanged, until rs_sched_wait returns.  Every submitted job must be waited for before
 * rs_sched_destroy. */
#ifndef RS_SCHEDULER_SCHED_H
#define RS_SCHEDULER_SCHED_H

#include "scheduler/device.h"

typedef struct rs_sched rs_sched;

typedef struct rs_timeline rs_timeline; /* scheduler/timeline.h */

typedef struct rs_sched_config {
    uint32_t chunk_size;     /* rays per chunk; 0: adaptive per device (above) */
    uint32_t queue_capacity; /* jobs the queue holds (>= 1); 0 means 8 */
    rs_timeline *timeline;   /* where each chunk traced is logged (lane = device index); NULL */
} rs_sched_config;

#define RS_SCHED_MIN_CHUNK     256u
#define RS_SCHED_MAX_CHUNK     (1u << 20)
#define RS_SCHED_FIRST_HOST    4096u  /* first chunk of a host device, before any measurement */
#define RS_SCHED_FIRST_GPU     65536u /* first chunk of a GPU */
#define RS_SCHED_TARGET_HOST_S 0.004
#define RS_SCHED_TARGET_GPU_S  0.020

/* A submitted batch.  Owned by the caller; the fields are the scheduler's. */
typedef struct rs_sched_job {
    const rs_trace_batch *batch;
    uint32_t next;      /* first ray not handed out yet */
    uint32_t remaining; /* rays not answered yet */
    int failed;
} rs_sched_job;

/* Starts one dispatch thread per device.  The devices must already hold the scene (upload);
 * they stay owned by the caller and must outlive the scheduler. */
rs_status rs_sched_create(rs_device *const *devices, int n_devices, const rs_sched_config *cfg,
                          rs_sched **out);
/* Queues `batch` as `job` and returns at once (after waiting for room in the queue). */
void rs_sched_submit(rs_sched *s, const rs_trace_batch *batch, rs_sched_job *job);
/* Blocks until every ray of `job` is answered: RS_OK, or RS_ERR_DEVICE_LOST when no device is
 * left (the job's rays are then withdrawn and its answers undefined). */
rs_status rs_sched_wait(rs_sched *s, rs_sched_job *job);
/* Submit and wait. */
rs_status rs_sched_trace(rs_sched *s, const rs_trace_batch *batch);
/* Stops and joins the dispatch threads.  NULL is a no-op. */
void rs_sched_destroy(rs_sched *s);

int rs_sched_device_count(const rs_sched *s);
rs_device *rs_sched_device(const rs_sched *s, int i);
/* A consistent copy of device i's counters; *alive is 0 once the device has been retired. */
void rs_sched_device_stats(rs_sched *s, int i, rs_device_stats *out, int *alive);
/* Totals over every job so far: rays submitted and rays answered (equal when nothing was lost).
 */
void rs_sched_totals(rs_sched *s, uint64_t *submitted, uint64_t *answered);

#endif
