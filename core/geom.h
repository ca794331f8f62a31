/* core/geom.h — the scene's geometry as traversal sees it: flat arrays of each primitive type and
 * one global primitive numbering over them (spheres first, then quads, then triangles):
 *
 *   prim in [0, ns)              sphere  prim
 *   prim in [ns, ns + nq)        quad    prim - ns
 *   prim in [ns + nq, ns+nq+nt)  tri     prim - ns - nq
 *   prim in [ns+nq+nt, +ni)      instance prim - ns - nq - nt (BVH leaves only, see below)
 *
 * Instances (the two-level BVH).  An instance places a shared set of triangles, the prototype
 * inst_tris[first_tri, first_tri + n_tris) in object space, by an affine transform.  The scene's
 * BVH (the top level) holds each instance as one primitive with its world bounds; its bottom
 * level is a binary BVH over the prototype, in object space, shared by every instance of it
 * (blas_nodes, built by accel/bvh.c and attached with rs_bvh_attach).  A hit on an instance's
 * triangle k reports the primitive number prim_base + k: the number the triangle has when the
 * instances are flattened (copied, after the scene's own triangles, in instance order:
 * rs_scene_flatten_instances).  The bottom level's boxes are tested in object space, but each
 * triangle is tested in world space, transformed by rs_instance_tri exactly as flattening
 * transforms it; the closest-hit rule (rs_hit_better) makes the visit order irrelevant, so an
 * instanced scene and its flattened twin give the same hits bit for bit.
 *
 * The same struct holds host pointers on the CPU and device pointers on the GPU. */
#ifndef RS_CORE_GEOM_H
#define RS_CORE_GEOM_H

#include "core/intersect.h"

/* A node of a binary BVH (accel/bvh_traverse.h describes the layout; the bottom levels of
 * instances use it too, so the geometry can hold them). */
typedef struct rs_bvh_node {
    rs_vec3 lo;
    uint32_t left_first;
    rs_vec3 hi;
    uint32_t count;
} rs_bvh_node;

/* One placement of a prototype.  The transform is kept in double precision, as the scene file's
 * transforms are (scenes/transform.h), and applied by rs_instance_point. */
typedef struct rs_instance {
    double m[12];       /* object -> world, row-major 3x4: x'_i = m[4i] x + m[4i+1] y + m[4i+2] z
                           + m[4i+3] */
    double inv[12];     /* world -> object, the same layout (the bottom level's box tests) */
    double cof[9];      /* the cofactor matrix of the linear part (normals), row-major */
    rs_aabb box;        /* world bounds of the placed triangles, slightly widened */
    float margin;       /* object-space widening of the bottom level's boxes (rounding of the
                           transforms; rs_instance_margin) */
    uint32_t mirror;    /* det < 0: v1 and v2 (and their UVs and normals) swap, as flattening
                           swaps them so that normals keep pointing out */
    uint32_t first_tri; /* the prototype: inst_tris[first_tri, first_tri + n_tris) */
    uint32_t n_tris;
    uint32_t prim_base; /* global number of the instance's first triangle */
    uint32_t root;      /* the prototype's bottom-level root in blas_nodes (rs_bvh_attach) */
} rs_instance;

/* No padding (the checkpoint's scene hash reads every byte of the instance table). */
typedef char rs_instance_unpadded[sizeof(rs_instance) == 33 * 8 + 24 + 4 * 6 ? 1 : -1];

/* Point p of an instance's object space in world space: each coordinate computed in double and
 * rounded to float once (what scenes/transform.c does to a copied object). */
RS_HD rs_vec3 rs_instance_point(const rs_instance *in, rs_vec3 p)
{
    double x = p.x, y = p.y, z = p.z;
    return rs_v3((float)(in->m[0] * x + in->m[1] * y + in->m[2] * z + in->m[3]),
                 (float)(in->m[4] * x + in->m[5] * y + in->m[6] * z + in->m[7]),
                 (float)(in->m[8] * x + in->m[9] * y + in->m[10] * z + in->m[11]));
}

/* A prototype triangle placed by instance `in` (v1 and v2 swapped under a mirror). */
RS_HD rs_tri rs_instance_tri(const rs_instance *in, const rs_tri *t)
{
    rs_tri w;
    w.v0 = rs_instance_point(in, t->v0);
    w.v1 = rs_instance_point(in, in->mirror ? t->v2 : t->v1);
    w.v2 = rs_instance_point(in, in->mirror ? t->v1 : t->v2);
    return w;
}

/* An alpha cut-out (glTF's alphaMode MASK): one byte per texel, 1 where the surface is there,
 * 0 where rays pass through it (the texture's alpha times the factor against the cutoff,
 * decided when the scene is made).  Looked up at the hit's UVs by the nearest texel, wrapping,
 * v = 0 at the bottom row, as the image textures are. */
typedef struct rs_alpha_mask {
    uint32_t width, height;
    uint32_t offset; /* of its first texel in mask_bits, rows from the top */
} rs_alpha_mask;

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
    /* instances (NULL / 0 without): the table, the prototypes' triangles, and the bottom levels
     * (from the scene's BVH: rs_bvh_attach; node indices and prim ids into these arrays) */
    const rs_instance *instances;
    const rs_tri *inst_tris;
    const rs_bvh_node *blas_nodes;
    const uint32_t *blas_prim_ids; /* indices into inst_tris */
    uint32_t n_instances, n_inst_tris, n_blas_nodes;
    /* alpha cut-outs (NULL / 0 without): per triangle 1 + its mask's index, or 0 (opaque), and
     * the triangles' UVs where the scene has them */
    const uint32_t *tri_mask;
    const rs_alpha_mask *masks;
    const uint8_t *mask_bits;
    const float *tri_uv;
    uint32_t n_masks, n_mask_bits;
} rs_geom;

/* Every array of rs_geom, with its element count (`g` a pointer to the geometry; the element
 * size is the field's own; a NULL array is copied as NULL).  A device's copy of the geometry
 * (scheduler/device_copy.h) is made from this list: a new array of rs_geom goes here. */
#define RS_GEOM_ARRAYS(X, g)                                                                       \
  X(spheres, (size_t)(g)->n_spheres)                                                               \
  X(sphere_motion, (size_t)(g)->n_spheres)                                                         \
  X(quads, (size_t)(g)->n_quads)                                                                   \
  X(tris, (size_t)(g)->n_tris)                                                                     \
  X(instances, (size_t)(g)->n_instances)                                                           \
  X(inst_tris, (size_t)(g)->n_inst_tris)                                                           \
  X(blas_nodes, (size_t)(g)->n_blas_nodes)                                                         \
  X(blas_prim_ids, (size_t)(g)->n_inst_tris)                                                      \
  X(tri_mask, (g)->tri_mask ? (size_t)(g)->n_tris : 0)                                             \
  X(masks, (size_t)(g)->n_masks)                                                                   \
  X(mask_bits, (size_t)(g)->n_mask_bits)                                                           \
  X(tri_uv, (g)->tri_mask ? 6 * (size_t)(g)->n_tris : 0)

/* Centre of sphere i at `time`. */
RS_HD rs_vec3 rs_geom_sphere_center(const rs_geom *g, uint32_t i, float time)
{
    return g->sphere_motion ? rs_v3_madd(g->spheres[i].center, g->sphere_motion[i], time)
                            : g->spheres[i].center;
}

/* The primitives the scene's BVH is built over: the scene's own, then one per instance. */
RS_HD uint32_t rs_geom_prim_count(const rs_geom *g)
{
    return g->n_spheres + g->n_quads + g->n_tris + g->n_instances;
}

/* The scene's own primitives (not instances): those rs_geom_intersect takes. */
RS_HD uint32_t rs_geom_own_count(const rs_geom *g) { return g->n_spheres + g->n_quads + g->n_tris; }

/* Whether own triangle t (0-based among triangles), cut out by its mask, is there at the hit's
 * barycentrics (u, v): its UVs interpolated as shading interpolates them (the barycentrics
 * themselves without UVs), the nearest texel of the mask. */
RS_HD_COLD int rs_geom_mask_opaque(const rs_geom *g, uint32_t t, float hu, float hv)
{
    const rs_alpha_mask *m = &g->masks[g->tri_mask[t] - 1];
    float u = hu, v = hv, x, y;
    uint32_t col, row;
    if (g->tri_uv) {
        const float *uv = &g->tri_uv[6 * (size_t)t];
        float b0 = 1.0f - hu - hv;
        u = b0 * uv[0] + hu * uv[2] + hv * uv[4];
        v = b0 * uv[1] + hu * uv[3] + hv * uv[5];
    }
    x = u - floorf(u);
    y = v - floorf(v);
    if (!(x >= 0.0f && y >= 0.0f)) /* a NaN UV: keep the hit */
        return 1;
    col = (uint32_t)(x * (float)m->width);
    row = (uint32_t)(y * (float)m->height);
    col = col < m->width ? col : m->width - 1;
    row = row < m->height ? row : m->height - 1;
    return g->mask_bits[m->offset + (size_t)(m->height - 1 - row) * m->width + col] != 0;
}

/* Own triangle t with an alpha cut-out: hit where the test hits and the mask is there. */
RS_HD_COLD int rs_geom_tri_masked(const rs_geom *g, uint32_t t, const rs_ray *r, float *th,
                                  float *u, float *v)
{
    return rs_isect_tri_by(g->tri_algo, &g->tris[t], r, th, u, v) &&
           rs_geom_mask_opaque(g, t, *u, *v);
}

/* Intersects global primitive `prim` (one of the scene's own, < rs_geom_own_count; an instance's
 * triangles are accel/bvh_traverse.h's); on a hit writes t, u, v and returns 1. */
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
    if (g->tri_mask && g->tri_mask[prim]) /* a tail call: the common path keeps no frame */
        return rs_geom_tri_masked(g, prim, r, t, u, v);
    return rs_isect_tri_by(g->tri_algo, &g->tris[prim], r, t, u, v);
}

#endif
