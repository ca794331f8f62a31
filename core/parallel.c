/* core/parallel.c — see parallel.h. */
#include "core/parallel.h"

#include <string.h>

void rs_parallel_range(rs_par_strategy s, int threads, uint32_t begin, uint32_t end, uint32_t grain,
                       rs_par_body body, void *ctx)
{
    uint32_t n = end > begin ? end - begin : 0, blocks;
    long b;
    if (grain < 1)
        grain = 1;
    blocks = (uint32_t)(((uint64_t)n + grain - 1) / grain);
    if (n == 0)
        return;
    if (threads <= 1 || (blocks <= 1 && s != RS_PAR_COLUMNS) || n == 1) {
        body(ctx, begin, end);
        return;
    }
    (void)b;
    switch (s) {
    case RS_PAR_COLUMNS:
#pragma omp parallel num_threads(threads)
    {
#if defined(_OPENMP)
        uint32_t id = (uint32_t)omp_get_thread_num(), nt = (uint32_t)omp_get_num_threads();
#else
        uint32_t id = 0, nt = 1;
#endif
        uint32_t lo = begin + (uint32_t)((uint64_t)n * id / nt);
        uint32_t hi = begin + (uint32_t)((uint64_t)n * (id + 1) / nt);
        if (lo < hi)
            body(ctx, lo, hi);
    } break;
    case RS_PAR_TASKS:
#pragma omp parallel num_threads(threads)
#pragma omp single
        for (b = 0; b < (long)blocks; ++b) {
#pragma omp task firstprivate(b)
            {
                uint32_t lo = begin + (uint32_t)b * grain;
                body(ctx, lo, end - lo > grain ? lo + grain : end);
            }
        }
        break;
    default:
#pragma omp parallel for num_threads(threads) schedule(dynamic, 1)
        for (b = 0; b < (long)blocks; ++b) {
            uint32_t lo = begin + (uint32_t)b * grain;
            body(ctx, lo, end - lo > grain ? lo + grain : end);
        }
        break;
    }
}

static const char *const names[] = {"for-dynamic", "columns", "tasks"};

int rs_par_strategy_parse(const char *name, rs_par_strategy *out)
{
    int i;
    for (i = 0; i < 3; ++i)
        if (strcmp(name, names[i]) == 0) {
            *out = (rs_par_strategy)i;
            return 1;
        }
    return 0;
}

const char *rs_par_strategy_name(rs_par_strategy s) { return (unsigned)s < 3u ? names[s] : "?"; }
