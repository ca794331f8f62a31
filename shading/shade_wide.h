/* shading/shade_wide.h — eight path vertices shaded at once on the CPU (AVX2), for the commonest
 * vertex: a Lambertian surface without textures on a parallelogram or a triangle of the scene's
 * own, under MIS with lights picked by power among parallelogram and triangle emitters and a
 * uniform sky.
 *
 * The scalar shading (shading/path.h: rs_path_shade_at) spends most of its time on one path's
 * chains of dependent operations (a square root, then a division, then the products that need
 * it): here the same operations run on eight paths in the lanes of one vector, in the same order
 * and on the same operands, so each lane rounds exactly as the scalar code does and the image is
 * the scalar shading's bit for bit (tests/shading_wide_test.c compares every output of every
 * entry).  Whatever else a wave holds (misses, emitters, other materials, spheres, instances,
 * textures) is shaded by rs_path_shade_at as before; the stage (shading/integrator.c) writes
 * each batch's rays from this code first, straight into the streams, then the others' (a ray's
 * place in a stream changes no answer).
 *
 * Host only: the CUDA device and the megakernels shade with rs_path_shade_at. */
#ifndef RS_SHADING_SHADE_WIDE_H
#define RS_SHADING_SHADE_WIDE_H

#include "shading/path.h"
#include "streams/stream.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Whether the wide shading runs at all: 1 where the CPU has AVX2 (the default), 0 forced off
 * (tests and benchmarks compare the two).  Returns whether it will run from now on. */
int rs_shade_wide_use(int on);

/* Entries shaded by rs_shade_wide so far, in this process (the tests check that it ran). */
uint64_t rs_shade_wide_count(void);

/* Whether vertices of segment `bounce` of this render may be shaded wide: the sampling, the
 * light sampler and every light are of the kinds above, and the vertex draws a next ray. */
int rs_shade_wide_ready(const rs_render_consts *it, uint32_t bounce);

/* Whether a hit on global primitive `prim` (RS_NO_HIT: none) is a vertex the wide code shades. */
static inline int rs_shade_wide_entry(const rs_scene *sc, uint32_t prim)
{
    const rs_material *m;
    uint32_t p = prim - sc->n_spheres;
    if (prim == RS_NO_HIT || prim < sc->n_spheres || p >= sc->n_quads + sc->n_tris)
        return 0;
    m = rs_scene_prim_material(sc, prim);
    return m->type == RS_MAT_LAMBERTIAN && m->albedo_tex == RS_NO_TEXTURE &&
           !(m->flags & RS_MAT_UNIFORM_SAMPLING) && rs_v3_is_zero(m->sigma_a);
}

/* Shades entries entry[0..n) of the stream (rays, hits), segment `bounce`, as rs_path_shade_at
 * would with the numbers rb[k] (group RS_DIM_BSDF) and rl[k] (RS_DIM_LIGHT), k = entry[i] -
 * rng_base: each entry's path
 * state in `paths` is updated, and the rays it makes are written to the streams, a next ray at
 * next[*on] and a shadow ray at shadow[*os] (each count then advanced), in the entries' order.
 * Every entry must pass rs_shade_wide_entry, after rs_shade_wide_ready. */
void rs_shade_wide(const rs_render_consts *it, uint32_t bounce, const rs_ray_soa *rays,
                   const rs_hit_soa *hits, const uint32_t *entry, uint32_t n, const rs_rng_f4 *rb,
                   const rs_rng_f4 *rl, uint32_t rng_base, rs_paths *paths, rs_ray_soa *next,
                   uint32_t *on, rs_ray_soa *shadow, uint32_t *os);

#ifdef __cplusplus
}
#endif

#endif
