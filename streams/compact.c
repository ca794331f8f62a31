/* streams/compact.c — rs_stream_compact (stream.h): the valid entries of a ray stream packed in
 * order, by a blocked two-pass scan whose blocks are fixed by the thread count alone, so the
 * result is the same for any schedule. */
#include "streams/stream.h"

#define COMPACT_MAX_BLOCKS 64

uint32_t rs_stream_compact(const rs_ray_soa *src, const uint8_t *valid, uint32_t count,
                           rs_ray_soa *dst, int threads)
{
    uint32_t offsets[COMPACT_MAX_BLOCKS + 1];
    int nb = threads < 1 ? 1 : (threads > COMPACT_MAX_BLOCKS ? COMPACT_MAX_BLOCKS : threads);
    int b;
    if (count < 4096)
        nb = 1;
        /* pass 1: count per block */
#pragma omp parallel for num_threads(nb) schedule(static, 1) if (nb > 1)
    for (b = 0; b < nb; ++b) {
        uint32_t lo = (uint32_t)((uint64_t)count * b / nb),
                 hi = (uint32_t)((uint64_t)count * (b + 1) / nb);
        uint32_t c = 0, i;
        for (i = lo; i < hi; ++i)
            c += valid[i] != 0;
        offsets[b + 1] = c;
    }
    offsets[0] = 0;
    for (b = 0; b < nb; ++b)
        offsets[b + 1] += offsets[b];
        /* pass 2: copy, each block from its prefix offset */
#pragma omp parallel for num_threads(nb) schedule(static, 1) if (nb > 1)
    for (b = 0; b < nb; ++b) {
        uint32_t lo = (uint32_t)((uint64_t)count * b / nb),
                 hi = (uint32_t)((uint64_t)count * (b + 1) / nb);
        uint32_t o = offsets[b], i;
        for (i = lo; i < hi; ++i)
            if (valid[i]) {
                /* each field inline (rs_ray_soa_copy is a call into stream.c) */
#define COPY_FIELD(type, name) dst->name[o] = src->name[i];
                RS_RAY_FIELDS(COPY_FIELD)
#undef COPY_FIELD
                o++;
            }
    }
    dst->count = offsets[nb];
    return offsets[nb];
}
