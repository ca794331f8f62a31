/* streams/stream.h — ray and hit streams as structures of arrays.
 *
 * Each field is declared once in an X-macro list; the struct, the allocation and the copies all
 * expand from it, so adding a field touches one line.  Byte budgets per entry:
 *   ray  40 B  ox oy oz dx dy dz tmin tmax time (float) + path (uint32: index into the wave's
 *              paths)
 *   hit  16 B  t u v (float) + prim (uint32, RS_NO_HIT for a miss)
 *   occlusion 1 B per shadow ray (1 = blocked)
 * A view holds plain pointers (host or device) and is what RS_HD code and devices take. */
#ifndef RS_STREAMS_STREAM_H
#define RS_STREAMS_STREAM_H

#include <stddef.h>

#include "core/ray.h"
#include "core/status.h"

/* clang-format off */
#define RS_RAY_FIELDS(X)                                                      \
    X(float, ox) X(float, oy) X(float, oz)                                    \
    X(float, dx) X(float, dy) X(float, dz)                                    \
    X(float, tmin) X(float, tmax) X(float, time)                              \
    X(uint32_t, path)
/* clang-format on */

#define RS_HIT_FIELDS(X) X(float, t) X(float, u) X(float, v) X(uint32_t, prim)

#define RS_STREAM_DECLARE_FIELD(type, name) type *name;

typedef struct rs_ray_soa {
    RS_RAY_FIELDS(RS_STREAM_DECLARE_FIELD)
    uint32_t count;
    uint32_t capacity;
} rs_ray_soa;

typedef struct rs_hit_soa {
    RS_HIT_FIELDS(RS_STREAM_DECLARE_FIELD)
    uint32_t capacity;
} rs_hit_soa;

/* Bytes one entry of each stream takes, summed over its fields. */
#define RS_STREAM_FIELD_SIZE(type, name) +sizeof(type)
#define RS_RAY_BYTES                     (0 RS_RAY_FIELDS(RS_STREAM_FIELD_SIZE))
#define RS_HIT_BYTES                     (0 RS_HIT_FIELDS(RS_STREAM_FIELD_SIZE))

RS_HD rs_ray rs_ray_soa_get(const rs_ray_soa *s, uint32_t i)
{
    rs_ray r;
    r.o = rs_v3(s->ox[i], s->oy[i], s->oz[i]);
    r.d = rs_v3(s->dx[i], s->dy[i], s->dz[i]);
    r.tmin = s->tmin[i];
    r.tmax = s->tmax[i];
    r.time = s->time[i];
    return r;
}

RS_HD void rs_ray_soa_set(const rs_ray_soa *s, uint32_t i, const rs_ray *r, uint32_t path)
{
    s->ox[i] = r->o.x;
    s->oy[i] = r->o.y;
    s->oz[i] = r->o.z;
    s->dx[i] = r->d.x;
    s->dy[i] = r->d.y;
    s->dz[i] = r->d.z;
    s->tmin[i] = r->tmin;
    s->tmax[i] = r->tmax;
    s->time[i] = r->time;
    s->path[i] = path;
}

RS_HD void rs_hit_soa_set(const rs_hit_soa *s, uint32_t i, const rs_hit *h)
{
    s->t[i] = h->t;
    s->u[i] = h->u;
    s->v[i] = h->v;
    s->prim[i] = h->prim;
}

RS_HD rs_hit rs_hit_soa_get(const rs_hit_soa *s, uint32_t i)
{
    rs_hit h;
    h.t = s->t[i];
    h.u = s->u[i];
    h.v = s->v[i];
    h.prim = s->prim[i];
    return h;
}

/* Where a stream's arrays come from: NULL means rs_alloc_aligned / rs_free; a device's
 * host_alloc (scheduler/device.h) gives page-locked memory a GPU copies by DMA. */
typedef struct rs_host_allocator {
    void *(*alloc)(void *user, size_t bytes); /* 64-byte aligned, or NULL */
    void (*release)(void *user, void *p);
    void *user;
} rs_host_allocator;

#ifdef __cplusplus
extern "C" {
#endif
/* Allocates every field for `capacity` entries (64-byte aligned); count starts at 0. */
rs_status rs_ray_soa_init(rs_ray_soa *s, uint32_t capacity);
void rs_ray_soa_free(rs_ray_soa *s);
/* The same with the arrays from `a` (NULL: as above); free with the same `a`. */
rs_status rs_ray_soa_init_in(rs_ray_soa *s, uint32_t capacity, const rs_host_allocator *a);
void rs_ray_soa_free_in(rs_ray_soa *s, const rs_host_allocator *a);
rs_status rs_hit_soa_init_in(rs_hit_soa *s, uint32_t capacity, const rs_host_allocator *a);
void rs_hit_soa_free_in(rs_hit_soa *s, const rs_host_allocator *a);
/* One array of n * size bytes from `a` (NULL: rs_alloc_aligned), and its release. */
void *rs_host_alloc(const rs_host_allocator *a, size_t n, size_t size);
void rs_host_free(const rs_host_allocator *a, void *p);
/* Copies entry `from` of `src` to entry `to` of `dst`. */
void rs_ray_soa_copy(rs_ray_soa *dst, uint32_t to, const rs_ray_soa *src, uint32_t from);
rs_status rs_hit_soa_init(rs_hit_soa *s, uint32_t capacity);
void rs_hit_soa_free(rs_hit_soa *s);
/* How a stage that split a stream of `count` entries into ranges left its output: for the range
 * that starts at slot b, end[b] is its end and first[b], second[b] how many entries of each of
 * its two output streams it wrote packed from slot b (the next rays and the shadow rays). */
typedef struct rs_stream_runs {
    uint32_t *first, *second, *end;
} rs_stream_runs;
/* Moves the runs of output stream `which` (0: first, 1: second) of `s` down into one packed
 * stream from slot 0, keeping their order; sets s->count and returns it.  In place and serial:
 * memmoves of whole runs, no test per entry (streams/compact.c). */
uint32_t rs_stream_pack_runs(rs_ray_soa *s, const rs_stream_runs *runs, int which, uint32_t count);
#ifdef __cplusplus
}
#endif

#endif
