/* scheduler/fault.h — fault injection for the heterogeneous scheduler's failure path.
 *
 * RS_FAULT=KIND:after=N (KIND cpu or gpu; several specs comma-separated) makes every device of
 * that kind fail its trace call after N chunks answered: the trace returns RS_ERR_DEVICE_LOST
 * without touching the answers, as a lost GPU would.  The scheduler then retires the device,
 * puts the chunk back in the queue and the render finishes on the other devices.  A "gpu" is a
 * CUDA device or its CPU fallback.  Used by the tests and by anyone checking a render survives a
 * device loss; without RS_FAULT nothing is wrapped. */
#ifndef RS_SCHEDULER_FAULT_H
#define RS_SCHEDULER_FAULT_H

#include "scheduler/device.h"

typedef struct rs_fault_spec {
    int cpu_after; /* chunks before a cpu device fails; -1: never */
    int gpu_after; /* chunks before a gpu (or fallback) device fails; -1: never */
} rs_fault_spec;

#ifdef __cplusplus
extern "C" {
#endif
/* Parses `text` (the value of RS_FAULT; NULL or "" means no faults).  RS_ERR_ARG with a message
 * naming the bad part. */
rs_status rs_fault_parse(const char *text, rs_fault_spec *out);
/* Wraps *d in a device that fails after `after` chunks (after >= 0); the wrapper owns the inner
 * device and destroys it with itself.  On failure *d is left as it was. */
rs_status rs_fault_wrap(rs_device **d, int after);
#ifdef __cplusplus
}
#endif

#endif
