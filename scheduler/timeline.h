/* scheduler/timeline.h — what a render did when: busy spans per lane, for `--timeline FILE.svg`.
 *
 * Lanes 0 .. n_devices - 1 are the scheduler's devices (one span per chunk traced); lane
 * n_devices is the render thread (one span per stage it ran: raygen, shade, compact, ...).
 * Times are seconds since rs_timeline_create.  The log has a fixed capacity: spans past it are
 * counted in `dropped`, never allocated in the hot loop.  rs_timeline_add may be called from any
 * thread. */
#ifndef RS_SCHEDULER_TIMELINE_H
#define RS_SCHEDULER_TIMELINE_H

#include <stdint.h>

#include "core/status.h"

/* The render's named stages (scheduler/stream_engine.c runs them in this order for each wave). */
typedef enum rs_stage {
    RS_STAGE_RAYGEN = 0,      /* camera rays and fresh path state */
    RS_STAGE_TRACE_CLOSEST,   /* extension rays with the devices (closest hit) */
    RS_STAGE_SHADE,           /* emission, next-event shadow rays, the next extension rays */
    RS_STAGE_TRACE_SHADOW,    /* shadow rays with the devices (any hit) */
    RS_STAGE_RESOLVE_SHADOWS, /* unoccluded shadow rays add their contribution */
    RS_STAGE_COMPACT,         /* surviving paths' next rays packed for the next bounce */
    RS_STAGE_FILM,            /* the finished wave added to the film in path order */
    RS_STAGE_PASS,            /* the megakernel: one pass of samples over the image */
    RS_STAGE_COUNT
} rs_stage;

/* "raygen", "trace-closest", "shade", "trace-shadow", "resolve-shadows", "compact", "film",
 * "pass". */
const char *rs_stage_name(rs_stage s);

typedef struct rs_span {
    double t0, t1; /* seconds since the timeline's start */
    uint32_t wave; /* the wave the work belonged to */
    uint16_t lane; /* device index, or n_devices for the render thread */
    uint8_t stage; /* rs_stage */
    uint8_t unused;
} rs_span;

typedef struct rs_timeline rs_timeline;

/* A log of at most `capacity` spans, its clock started now. */
rs_status rs_timeline_create(uint32_t capacity, rs_timeline **out);
void rs_timeline_destroy(rs_timeline *t);
/* Seconds since the timeline's start (the clock spans are measured on). */
double rs_timeline_now(const rs_timeline *t);
/* Records a span; t == NULL is a no-op (no timeline asked for). */
void rs_timeline_add(rs_timeline *t, uint16_t lane, rs_stage stage, uint32_t wave, double t0,
                     double t1);
/* The spans recorded so far, in the order they were added, and how many did not fit. */
const rs_span *rs_timeline_spans(const rs_timeline *t, uint32_t *n, uint64_t *dropped);

#endif
