/* streams/stream.c — allocation of SoA streams (see stream.h). */
#include "streams/stream.h"

#include <string.h>

#include "core/alloc.h"

rs_status rs_ray_soa_init(rs_ray_soa *s, uint32_t capacity)
{
    int ok = 1;
    memset(s, 0, sizeof *s);
#define ALLOC_FIELD(type, name)                                                                    \
  s->name = (type *)rs_alloc_aligned(capacity ? capacity : 1, sizeof(type));                       \
  ok = ok && s->name != NULL;
    RS_RAY_FIELDS(ALLOC_FIELD)
#undef ALLOC_FIELD
    if (!ok) {
        rs_ray_soa_free(s);
        return rs_error_set(RS_ERR_NOMEM, "out of memory allocating a ray stream of %u rays",
                            capacity);
    }
    s->capacity = capacity;
    return RS_OK;
}

void rs_ray_soa_free(rs_ray_soa *s)
{
#define FREE_FIELD(type, name) rs_free(s->name);
    RS_RAY_FIELDS(FREE_FIELD)
#undef FREE_FIELD
    memset(s, 0, sizeof *s);
}

void rs_ray_soa_copy(rs_ray_soa *dst, uint32_t to, const rs_ray_soa *src, uint32_t from)
{
#define COPY_FIELD(type, name) dst->name[to] = src->name[from];
    RS_RAY_FIELDS(COPY_FIELD)
#undef COPY_FIELD
}

rs_status rs_hit_soa_init(rs_hit_soa *s, uint32_t capacity)
{
    int ok = 1;
    memset(s, 0, sizeof *s);
#define ALLOC_FIELD(type, name)                                                                    \
  s->name = (type *)rs_alloc_aligned(capacity ? capacity : 1, sizeof(type));                       \
  ok = ok && s->name != NULL;
    RS_HIT_FIELDS(ALLOC_FIELD)
#undef ALLOC_FIELD
    if (!ok) {
        rs_hit_soa_free(s);
        return rs_error_set(RS_ERR_NOMEM, "out of memory allocating a hit stream of %u hits",
                            capacity);
    }
    s->capacity = capacity;
    return RS_OK;
}

void rs_hit_soa_free(rs_hit_soa *s)
{
#define FREE_FIELD(type, name) rs_free(s->name);
    RS_HIT_FIELDS(FREE_FIELD)
#undef FREE_FIELD
    memset(s, 0, sizeof *s);
}
