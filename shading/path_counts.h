/* shading/path_counts.h — the rays a megakernel traced, summed over host threads (C11 atomics:
 * host code only; the CUDA kernel reduces per warp instead).  A device's render_pass adds each
 * thread's rs_path_counts with rs_path_counts_atomic_add and hands the total on with
 * rs_path_counts_atomic_drain. */
#ifndef RS_SHADING_PATH_COUNTS_H
#define RS_SHADING_PATH_COUNTS_H

#include <stdatomic.h>

#include "shading/path.h"

typedef struct rs_path_counts_atomic {
    _Atomic uint64_t closest, shadow;
    _Atomic uint32_t max_bounce;
} rs_path_counts_atomic;

static inline void rs_path_counts_atomic_init(rs_path_counts_atomic *a)
{
    atomic_init(&a->closest, 0);
    atomic_init(&a->shadow, 0);
    atomic_init(&a->max_bounce, 0);
}

/* From any thread: one thread's counts into the total. */
static inline void rs_path_counts_atomic_add(rs_path_counts_atomic *a, const rs_path_counts *n)
{
    uint32_t seen = atomic_load(&a->max_bounce);
    atomic_fetch_add(&a->closest, n->closest);
    atomic_fetch_add(&a->shadow, n->shadow);
    while (n->max_bounce > seen &&
           !atomic_compare_exchange_weak(&a->max_bounce, &seen, n->max_bounce)) {
    }
}

/* After the threads are done: the total added to *out (max_bounce: the larger). */
static inline void rs_path_counts_atomic_drain(rs_path_counts_atomic *a, rs_path_counts *out)
{
    uint32_t mb = atomic_load(&a->max_bounce);
    out->closest += atomic_load(&a->closest);
    out->shadow += atomic_load(&a->shadow);
    if (mb > out->max_bounce)
        out->max_bounce = mb;
}

#endif
