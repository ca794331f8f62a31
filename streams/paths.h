/* streams/paths.h — the state a path carries from one vertex to the next, declared once.
 *
 * RS_PATH_FIELDS lists each field with its type; from it expand the one-path view that the
 * RS_HD path code works on (rs_path_state, shading/path.h), the structure of arrays a wave keeps
 * (rs_paths, one array per field, indexed by the path's slot in its wave), their allocation, and
 * the loads and stores between the two.  Adding a field is one line here (Cycles'
 * kernel/integrator/state_template.h is the model).  Byte budget per path: 49 B
 *   throughput, radiance, pending (3 x 12 B), bsdf_pdf, env_pdf, time (3 x 4 B), flags (1 B).  (flags
 *   as 4 bytes cost 1.3% of a 1-thread Cornell render in memory traffic.) */
#ifndef RS_STREAMS_PATHS_H
#define RS_STREAMS_PATHS_H

#include "core/status.h"
#include "core/vec3.h"

/* clang-format off */
#define RS_PATH_FIELDS(X)                                                                          \
    X(rs_vec3, throughput) /* product of f cos / pdf so far */                                    \
    X(rs_vec3, radiance)   /* light gathered so far */                                            \
    X(rs_vec3, pending)    /* next-event contribution waiting for its shadow ray */               \
    X(float, bsdf_pdf)     /* solid-angle pdf of the BSDF sample that made the current ray */     \
    X(float, env_pdf)      /* with a uniform sky: light sampling's pdf of that ray's direction */ \
                           /* at the vertex that made it (shading/envmap.h, env_pick included) */ \
    X(float, time)         /* the path's time in the shutter interval (its rays share it) */      \
    X(uint8_t, flags)      /* RS_PATH_* (shading/path.h) */
/* clang-format on */

/* What a path's camera ray showed at its first hit, for the film's passes (shading/film.h;
 * made by shading/aov.h rs_path_aux_at): kept beside the path's state, not in RS_PATH_FIELDS,
 * since it is written once (at the first hit, when the render keeps passes) and read once (by
 * the film), so the per-vertex loads and stores do not carry it. */
typedef struct rs_path_aux {
    rs_vec3 albedo;   /* the material's reflectance there, textured (held to [0, 1]) */
    rs_vec3 normal;   /* the shading normal, world space, toward the eye; zero for a miss */
    rs_vec3 emission; /* what the pixel's sample took there unweighted: the direct emission */
    float depth;      /* distance from the camera; infinity for a miss */
} rs_path_aux;

/* The arrays every wave's paths hold: the state, then the passes' record (one rs_path_aux a
 * path).  Allocation and the device copies' layouts go over this list. */
#define RS_PATH_ALL_FIELDS(X) RS_PATH_FIELDS(X) X(rs_path_aux, aux)

#define RS_PATH_DECLARE_FIELD(type, name) type name;
#define RS_PATH_DECLARE_ARRAY(type, name) type *name;

/* One path's state: what the RS_HD path code reads and writes. */
typedef struct rs_path_state {
    RS_PATH_FIELDS(RS_PATH_DECLARE_FIELD)
} rs_path_state;

/* The state of a wave's paths (SoA, indexed by path slot). */
typedef struct rs_paths {
    RS_PATH_ALL_FIELDS(RS_PATH_DECLARE_ARRAY)
    uint32_t capacity;
} rs_paths;

#define RS_PATH_BYTES                     (0 RS_PATH_FIELDS(RS_STREAM_FIELD_SIZE_))
#define RS_STREAM_FIELD_SIZE_(type, name) +sizeof(type)

RS_HD rs_path_state rs_paths_load(const rs_paths *p, uint32_t i)
{
    rs_path_state s;
#define RS_PATH_LOAD(type, name) s.name = p->name[i];
    RS_PATH_FIELDS(RS_PATH_LOAD)
#undef RS_PATH_LOAD
    return s;
}

RS_HD void rs_paths_store(const rs_paths *p, uint32_t i, const rs_path_state *s)
{
#define RS_PATH_STORE(type, name) p->name[i] = s->name;
    RS_PATH_FIELDS(RS_PATH_STORE)
#undef RS_PATH_STORE
}

#ifdef __cplusplus
extern "C" {
#endif
/* Allocates every field for `capacity` paths (64-byte aligned; the _in pair takes the arrays
 * from an allocator, streams/stream.h); RS_ERR_NOMEM leaves nothing allocated. */
rs_status rs_paths_init(rs_paths *p, uint32_t capacity);
void rs_paths_free(rs_paths *p);
struct rs_host_allocator;
rs_status rs_paths_init_in(rs_paths *p, uint32_t capacity, const struct rs_host_allocator *a);
void rs_paths_free_in(rs_paths *p, const struct rs_host_allocator *a);
#ifdef __cplusplus
}
#endif

#endif
