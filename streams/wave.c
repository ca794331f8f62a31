/* streams/wave.c — see wave.h. */
#include "streams/wave.h"

#include <string.h>

#include "core/alloc.h"

void rs_wave_buffers_destroy(rs_wave_buffers *b)
{
    const rs_host_allocator *a = &b->alloc;
    rs_ray_soa_free_in(&b->ext[0], a);
    rs_ray_soa_free_in(&b->ext[1], a);
    rs_ray_soa_free_in(&b->shadow, a);
    rs_hit_soa_free_in(&b->hits, a);
    rs_free(b->runs.first);
    rs_free(b->runs.second);
    rs_free(b->runs.end);
    rs_host_free(a, b->occluded);
    rs_paths_free(&b->paths);
    memset(b, 0, sizeof *b);
}

rs_status rs_wave_buffers_create(uint32_t n, const rs_host_allocator *a, rs_wave_buffers *b)
{
    rs_status st;
    memset(b, 0, sizeof *b);
    if (a)
        b->alloc = *a;
    b->pinned = a && a->alloc;
    a = &b->alloc;
    if ((st = rs_ray_soa_init_in(&b->ext[0], n, a)) != RS_OK ||
        (st = rs_ray_soa_init_in(&b->ext[1], n, a)) != RS_OK ||
        (st = rs_ray_soa_init_in(&b->shadow, n, a)) != RS_OK ||
        (st = rs_hit_soa_init_in(&b->hits, n, a)) != RS_OK ||
        (st = rs_paths_init(&b->paths, n)) != RS_OK)
        goto fail;
    b->runs.first = (uint32_t *)rs_alloc_aligned(n ? n : 1, sizeof(uint32_t));
    b->runs.second = (uint32_t *)rs_alloc_aligned(n ? n : 1, sizeof(uint32_t));
    b->runs.end = (uint32_t *)rs_alloc_aligned(n ? n : 1, sizeof(uint32_t));
    b->occluded = (uint8_t *)rs_host_alloc(a, n ? n : 1, 1);
    if (!b->runs.first || !b->runs.second || !b->runs.end || !b->occluded) {
        st = rs_error_set(RS_ERR_NOMEM, "out of memory for a wave of %u paths", n);
        goto fail;
    }
    return RS_OK;
fail:
    rs_wave_buffers_destroy(b);
    return st;
}
