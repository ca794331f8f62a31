/* cpu/cpu_device.h — the CPU device: OpenMP workers tracing chunks with the shared RS_HD
 * traversal.  The same device, named "gpu-fallback", stands in for a GPU that is not there. */
#ifndef RS_CPU_CPU_DEVICE_H
#define RS_CPU_CPU_DEVICE_H

#include "scheduler/device.h"

/* `threads` >= 1 OpenMP threads per chunk; `name` is copied (e.g. "cpu", "gpu-fallback"). */
rs_status rs_cpu_device_create(int threads, const char *name, rs_device **out);

#endif
