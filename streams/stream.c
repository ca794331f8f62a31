/* streams/stream.c — allocation of SoA streams (see stream.h).  Both stream types expand from
 * one definition over their field lists. */
#include "streams/stream.h"

#include <string.h>

#include "core/alloc.h"

#define RS_ALLOC_FIELD(type, name)                                                                 \
  s->name = (type *)rs_alloc_aligned(capacity ? capacity : 1, sizeof(type));                       \
  ok = ok && s->name != NULL;
#define RS_FREE_FIELD(type, name) rs_free(s->name);

/* Defines rs_<kind>_soa_init / rs_<kind>_soa_free for a stream type and its field list. */
#define RS_DEFINE_SOA(kind, FIELDS, what)                                                          \
  void rs_##kind##_soa_free(rs_##kind##_soa *s)                                                    \
  {                                                                                                \
    FIELDS(RS_FREE_FIELD)                                                                          \
    memset(s, 0, sizeof *s);                                                                       \
  }                                                                                                \
  rs_status rs_##kind##_soa_init(rs_##kind##_soa *s, uint32_t capacity)                            \
  {                                                                                                \
    int ok = 1;                                                                                    \
    memset(s, 0, sizeof *s);                                                                       \
    FIELDS(RS_ALLOC_FIELD)                                                                         \
    if (!ok) {                                                                                     \
      rs_##kind##_soa_free(s);                                                                     \
      return rs_error_set(RS_ERR_NOMEM, "out of memory allocating a stream of %u " what,           \
                          capacity);                                                               \
    }                                                                                              \
    s->capacity = capacity;                                                                        \
    return RS_OK;                                                                                  \
  }

RS_DEFINE_SOA(ray, RS_RAY_FIELDS, "rays")
RS_DEFINE_SOA(hit, RS_HIT_FIELDS, "hits")

void rs_ray_soa_copy(rs_ray_soa *dst, uint32_t to, const rs_ray_soa *src, uint32_t from)
{
#define COPY_FIELD(type, name) dst->name[to] = src->name[from];
    RS_RAY_FIELDS(COPY_FIELD)
#undef COPY_FIELD
}
