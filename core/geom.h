/* core/geom.h — the scene's geometry as traversal sees it: flat arrays of each primitive type and
 * one global primitive numbering over them (spheres first, then quads, then triangles):
 *
 *   prim in [0, ns)              sphere  prim
 *   prim in [ns, ns + nq)        quad    prim - ns
 *   prim in [ns + nq, ns+nq+nt)  tri     prim - ns - nq
 *
 * The same struct holds host pointers on the CPU and device pointers on the GPU. */
#ifndef RS_CORE_GEOM_H
#define RS_CORE_GEOM_H

#include "core/intersect.h"

typedef struct rs_geom {
    const rs_sphere *spheres;
    const rs_vec3 *sphere_motion; /* per sphere: centre displacement per unit time; NULL: none */
    float time0, time1;           /* the times rays may carry (the shutter); bounds cover it */
    uint32_t sphere_algo;         /* rs_isect_sphere_algo (0: algebraic, the default) */
    uint32_t tri_algo;            /* rs_isect_tri_algo (0: Moller-Trumbore, the default) */
    uint32_t aabb_algo;           /* rs_isect_aabb_algo for BVH nodes (0: slab, the default) */
    const rs_quad *quads;
    const rs_tri *tris;
    uint32_t n_spheres, n_quads, n_tris;
} rs_geom;

/* Every array of rs_geom, with its element count (`g` a pointer to the geometry; the element
 * size is the field's own; a NULL array is copied as NULL).  A device's copy of the geometry
 * (scheduler/device_copy.h) is made from this list: a new array of rs_geom goes here. */
#define RS_GEOM_ARRAYS(X, g)                                                                       \
  X(spheres, (size_t)(g)->n_spheres)                                                               \
  X(sphere_motion, (size_t)(g)->n_spheres)                                                         \
  X(quads, (size_t)(g)->n_quads)                                                                   \
  X(tris, (size_t)(g)->n_tris)

/* Centre of sphere i at `time`. */
RS_HD rs_vec3 rs_geom_sphere_center(const rs_geom *g, uint32_t i, float time)
{
    return g->sphere_motion ? rs_v3_madd(g->spheres[i].center, g->sphere_motion[i], time)
                            : g->spheres[i].center;
}

RS_HD uint32_t rs_geom_prim_count(const rs_geom *g)
{
    return g->n_spheres + g->n_quads + g->n_tris;
}

/* Intersects global primitive `prim`; on a hit writes t, u, v and returns 1. */
RS_HD int rs_geom_intersect(const rs_geom *g, uint32_t prim, const rs_ray *r, float *t, float *u,
                            float *v)
{
    if (prim < g->n_spheres) {
        *u = 0.0f;
        *v = 0.0f;
        if (g->sphere_motion) {
            rs_sphere s = g->spheres[prim];
            s.center = rs_v3_madd(s.center, g->sphere_motion[prim], r->time);
            return rs_isect_sphere_by(g->sphere_algo, &s, r, t);
        }
        return rs_isect_sphere_by(g->sphere_algo, &g->spheres[prim], r, t);
    }
    prim -= g->n_spheres;
    if (prim < g->n_quads)
        return rs_isect_quad(&g->quads[prim], r, t, u, v);
    prim -= g->n_quads;
    return rs_isect_tri_by(g->tri_algo, &g->tris[prim], r, t, u, v);
}

#endif
