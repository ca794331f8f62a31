/* streams/stream.c — allocation of SoA streams (see stream.h and paths.h).  Every stream type
 * expands from one definition over its field list. */
#include "streams/stream.h"

#include <string.h>

#include "core/alloc.h"
#include "streams/paths.h"

void *rs_host_alloc(const rs_host_allocator *a, size_t n, size_t size)
{
    size_t bytes;
    if (!a || !a->alloc)
        return rs_alloc_aligned(n, size);
    if (!rs_mul_size(n, size, &bytes))
        return NULL;
    return a->alloc(a->user, bytes ? bytes : 1);
}

void rs_host_free(const rs_host_allocator *a, void *p)
{
    if (!p)
        return;
    if (!a || !a->release)
        rs_free(p);
    else
        a->release(a->user, p);
}

#define RS_ALLOC_FIELD(type, name)                                                                 \
  s->name = (type *)rs_host_alloc(a, capacity ? capacity : 1, sizeof(type));                       \
  ok = ok && s->name != NULL;
#define RS_FREE_FIELD(type, name) rs_host_free(a, s->name);

/* Defines rs_<kind>_init_in / rs_<kind>_free_in (and the plain ones, from rs_alloc) for a
 * stream type and its field list. */
#define RS_DEFINE_SOA(kind, type_name, FIELDS, what)                                               \
  void rs_##kind##_free_in(type_name *s, const rs_host_allocator *a)                               \
  {                                                                                                \
    FIELDS(RS_FREE_FIELD)                                                                          \
    memset(s, 0, sizeof *s);                                                                       \
  }                                                                                                \
  rs_status rs_##kind##_init_in(type_name *s, uint32_t capacity, const rs_host_allocator *a)       \
  {                                                                                                \
    int ok = 1;                                                                                    \
    memset(s, 0, sizeof *s);                                                                       \
    FIELDS(RS_ALLOC_FIELD)                                                                         \
    if (!ok) {                                                                                     \
      rs_##kind##_free_in(s, a);                                                                   \
      return rs_error_set(RS_ERR_NOMEM, "out of memory allocating a stream of %u " what,           \
                          capacity);                                                               \
    }                                                                                              \
    s->capacity = capacity;                                                                        \
    return RS_OK;                                                                                  \
  }                                                                                                \
  rs_status rs_##kind##_init(type_name *s, uint32_t capacity)                                      \
  {                                                                                                \
    return rs_##kind##_init_in(s, capacity, NULL);                                                 \
  }                                                                                                \
  void rs_##kind##_free(type_name *s) { rs_##kind##_free_in(s, NULL); }

RS_DEFINE_SOA(ray_soa, rs_ray_soa, RS_RAY_FIELDS, "rays")
RS_DEFINE_SOA(hit_soa, rs_hit_soa, RS_HIT_FIELDS, "hits")
/* path state: rs_paths_init_in / rs_paths_free_in are internal, the plain pair is paths.h's */
RS_DEFINE_SOA(paths, rs_paths, RS_PATH_ALL_FIELDS, "paths")

void rs_ray_soa_copy(rs_ray_soa *dst, uint32_t to, const rs_ray_soa *src, uint32_t from)
{
#define COPY_FIELD(type, name) dst->name[to] = src->name[from];
    RS_RAY_FIELDS(COPY_FIELD)
#undef COPY_FIELD
}
