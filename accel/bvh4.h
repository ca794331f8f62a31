/* accel/bvh4.h — the CPU's 4-wide BVH: the binary tree collapsed so that each node holds up to
 * four children's boxes side by side, tested against one ray with SSE (Wald et al. 2008, "Getting
 * rid of packets"; Dammertz et al. 2008; Embree's BVH4).  Host only: the CUDA kernels and the GPU
 * fallback keep the binary tree (accel/bvh_traverse.h), whose 32-byte nodes suit one ray per GPU
 * thread.
 *
 * Same answers as the binary traversal, bit for bit: the 4-wide tree holds the binary tree's own
 * boxes (a subset of them) and its leaves' primitive ranges, each box test is the scalar slab
 * test's arithmetic lane by lane (rs_bvh_slab: (bound - o) * inv_d, NaN slabs skipped, the same
 * conservative margin RS_BVH_SLACK), and the
 * closest hit follows the same rule (rs_hit_better: smallest t, then lowest primitive number),
 * whatever order the children are visited in.
 *
 * Node layout (128 bytes, two cache lines, 64-byte aligned):
 *   lo[3][4], hi[3][4]  the children's boxes, axis-major (x of all four lanes, then y, then z)
 *   child[4]            interior lane: index of the child node; leaf lane: first prim_ids entry,
 *                       or for a packed leaf the first of its tri4 or quad4 blocks
 *   count[4]            0 for an interior lane, else the leaf's primitive count, or for a packed
 *                       leaf RS_WIDE_PACKED | its number of blocks, with RS_WIDE_QUADS for quad4
 *                       (accel/wide.h)
 *   n_lanes             lanes in use (1 to 4), packed from lane 0
 *
 * Packed leaves (SSE builds): a leaf of triangles only (with Möller-Trumbore geometry) keeps
 * copies of them, four to a block, as v0 and the edges e1 = v1 - v0, e2 = v2 - v0 side by side,
 * and tests the four at once with the scalar rs_isect_tri's operations in its order (unused lanes
 * are all zero: det = 0, never a hit); a leaf of parallelograms only keeps their q, u, v, w the
 * same way and repeats rs_isect_quad (unused lanes: w = 0, denominator 0, never a hit).  So t, u
 * and v come out the same bit for bit. */
#ifndef RS_ACCEL_BVH4_H
#define RS_ACCEL_BVH4_H

#include "accel/bvh.h"
#include "accel/trace.h"
#include "accel/wide.h"

#include <string.h>

#if defined(__SSE2__) || defined(_M_X64)
#  include <emmintrin.h>
#  define RS_BVH4_SSE 1
#endif

typedef struct rs_bvh4_node {
    float lo[3][4];
    float hi[3][4];
    uint32_t child[4];
    uint16_t count[4];
    uint32_t n_lanes;
    uint32_t leaf_mask; /* bit i: lane i is a leaf (count[i] != 0) */
} rs_bvh4_node;

typedef struct rs_bvh4_tri4 {
    float v0[3][4], e1[3][4], e2[3][4];
    uint32_t prim[4]; /* global primitive numbers; RS_NO_HIT in unused lanes */
} rs_bvh4_tri4;

typedef struct rs_bvh4_quad4 {
    float q[3][4], u[3][4], v[3][4], w[3][4];
    uint32_t prim[4]; /* global primitive numbers; RS_NO_HIT in unused lanes */
} rs_bvh4_quad4;

typedef struct rs_bvh4 {
    rs_bvh4_node *nodes;      /* node 0 is the root; none for an empty scene */
    rs_bvh4_tri4 *tri4;       /* the packed leaves' triangles */
    rs_bvh4_quad4 *quad4;     /* the packed leaves' parallelograms */
    const uint32_t *prim_ids; /* the binary BVH's, borrowed: it must outlive this tree */
    uint32_t *inst_root;      /* per instance: its prototype's bottom level, collapsed like the
                                 top tree into nodes after the top tree's; NULL without instances */
    uint32_t n_nodes, n_tri4, n_quad4;
    uint32_t depth;    /* in nodes; at most the binary tree's */
    uint32_t n_packed; /* leaves packed as tri4 or quad4 blocks */
} rs_bvh4;

#define RS_BVH4_MAX_NODES (1u << 29)
/* Each level of the tree pushes at most 3 entries (closest) or 4 (any hit), and the tree is at
 * most RS_BVH_MAX_DEPTH deep. */
#define RS_BVH4_STACK (4 * RS_BVH_STACK)

#ifdef __cplusplus
extern "C" {
#endif
/* Collapses `b`, built over `g`, into a 4-wide tree: each node takes its binary node's two
 * children and then keeps opening the interior child of largest surface area until it has four;
 * leaves of triangles are packed when g->tri_algo is Möller-Trumbore, leaves of parallelograms
 * always (SSE builds).  RS_ERR_ARG for a leaf of
 * more than 32767 primitives or a tree of more than 2^29 nodes, RS_ERR_NOMEM when memory runs out
 * (*out is NULL then). */
rs_status rs_bvh4_build(const rs_bvh *b, const rs_geom *g, rs_bvh4 **out);
void rs_bvh4_destroy(rs_bvh4 *b);
#ifdef __cplusplus
}
#endif

/* The 4-wide primitives accel/wide_walk.h takes: the ray broadcast to four lanes
 * (rs_bvh4_ray_init; rs_bvh4_ray_widen for an instance's bottom level, whose boxes are widened
 * by its margin as rs_blas_node_hit widens them), and the slab test of the four lanes of `n`
 * (rs_bvh4_lanes: the mask of lanes hit, bit i for lane i, and their entry distances, which
 * rs_bvh4_tn_store spills; `widen` a constant where it is inlined). */
#ifdef RS_BVH4_SSE
typedef struct rs_bvh4_ray {
    __m128 o[3], d[3], inv[3];
    __m128 margin;     /* rs_bvh4_ray_widen's */
    int axis_parallel; /* a direction component is 0 (or NaN): slabs may give NaN */
} rs_bvh4_ray;

typedef __m128 rs_bvh4_tn;

static inline void rs_bvh4_ray_init(rs_bvh4_ray *r, rs_vec3 o, rs_vec3 d)
{
    rs_vec3 inv_d = rs_bvh_inv_dir(d);
    r->o[0] = _mm_set1_ps(o.x);
    r->o[1] = _mm_set1_ps(o.y);
    r->o[2] = _mm_set1_ps(o.z);
    r->d[0] = _mm_set1_ps(d.x);
    r->d[1] = _mm_set1_ps(d.y);
    r->d[2] = _mm_set1_ps(d.z);
    r->inv[0] = _mm_set1_ps(inv_d.x);
    r->inv[1] = _mm_set1_ps(inv_d.y);
    r->inv[2] = _mm_set1_ps(inv_d.z);
    r->axis_parallel = !(d.x != 0.0f && d.y != 0.0f && d.z != 0.0f);
}

static inline void rs_bvh4_ray_widen(rs_bvh4_ray *r, float margin)
{
    r->margin = _mm_set1_ps(margin);
}

static inline void rs_bvh4_tn_store(float tn[4], const rs_bvh4_tn *v) { _mm_storeu_ps(tn, *v); }

RS_HD_HOT uint32_t rs_bvh4_lanes(const rs_bvh4_node *n, const rs_bvh4_ray *r, int widen, float tmin,
                                 float tmax, rs_bvh4_tn *tn_out)
{
    __m128 tn = _mm_set1_ps(tmin), tf = _mm_set1_ps(tmax);
    int a;
    for (a = 0; a < 3; ++a) {
        __m128 lo = _mm_load_ps(n->lo[a]), hi = _mm_load_ps(n->hi[a]), t0, t1;
        if (widen) {
            lo = _mm_sub_ps(lo, r->margin);
            hi = _mm_add_ps(hi, r->margin);
        }
        t0 = _mm_mul_ps(_mm_sub_ps(lo, r->o[a]), r->inv[a]);
        t1 = _mm_mul_ps(_mm_sub_ps(hi, r->o[a]), r->inv[a]);
        /* _mm_min_ps(a, b) is a < b ? a : b, exactly rs_minf */
        __m128 n_tn = _mm_max_ps(_mm_min_ps(t0, t1), tn);
        __m128 n_tf = _mm_min_ps(_mm_max_ps(t0, t1), tf);
        if (r->axis_parallel) {
            /* (bound - o) * inf = NaN for a ray in a slab's plane: that slab is skipped */
            __m128 ok = _mm_cmpord_ps(t0, t1);
            tn = _mm_or_ps(_mm_and_ps(ok, n_tn), _mm_andnot_ps(ok, tn));
            tf = _mm_or_ps(_mm_and_ps(ok, n_tf), _mm_andnot_ps(ok, tf));
        } else {
            /* both NaN only for a NaN direction, when min / max keep tn, tf as the skip does */
            tn = n_tn;
            tf = n_tf;
        }
    }
    *tn_out = tn;
    tf = _mm_mul_ps(tf, _mm_set1_ps(RS_BVH_SLACK));
    return (uint32_t)_mm_movemask_ps(_mm_cmple_ps(tn, tf)) & ((1u << n->n_lanes) - 1u);
}
#else
typedef struct rs_bvh4_ray {
    rs_vec3 o, inv;
    float margin;
} rs_bvh4_ray;

typedef struct rs_bvh4_tn {
    float t[4];
} rs_bvh4_tn;

static inline void rs_bvh4_ray_init(rs_bvh4_ray *r, rs_vec3 o, rs_vec3 d)
{
    r->o = o;
    r->inv = rs_bvh_inv_dir(d);
}

static inline void rs_bvh4_ray_widen(rs_bvh4_ray *r, float margin) { r->margin = margin; }

static inline void rs_bvh4_tn_store(float tn[4], const rs_bvh4_tn *v)
{
    memcpy(tn, v->t, sizeof v->t);
}

RS_HD_HOT uint32_t rs_bvh4_lanes(const rs_bvh4_node *n, const rs_bvh4_ray *r, int widen, float tmin,
                                 float tmax, rs_bvh4_tn *tn_out)
{
    uint32_t i, mask = 0;
    for (i = 0; i < n->n_lanes; ++i) {
        float tn = tmin, tf = tmax, lo[3], hi[3];
        int a;
        for (a = 0; a < 3; ++a) {
            lo[a] = widen ? n->lo[a][i] - r->margin : n->lo[a][i];
            hi[a] = widen ? n->hi[a][i] + r->margin : n->hi[a][i];
        }
        rs_slab((lo[0] - r->o.x) * r->inv.x, (hi[0] - r->o.x) * r->inv.x, &tn, &tf);
        rs_slab((lo[1] - r->o.y) * r->inv.y, (hi[1] - r->o.y) * r->inv.y, &tn, &tf);
        rs_slab((lo[2] - r->o.z) * r->inv.z, (hi[2] - r->o.z) * r->inv.z, &tn, &tf);
        tn_out->t[i] = tn;
        mask |= (uint32_t)(tn <= tf * RS_BVH_SLACK) << i;
    }
    return mask;
}
#endif

#ifdef RS_BVH4_SSE
/* rs_isect_tri on the four triangles of a block: the mask of lanes hit inside (tmin, tmax), and
 * their t, u, v. */
static inline uint32_t rs_bvh4_tri4_hit(const rs_bvh4_tri4 *b, const rs_bvh4_ray *r, float tmin,
                                        float tmax, float t[4], float u[4], float v[4])
{
#  define RS_LD(a) _mm_load_ps(a)
    __m128 e1x = RS_LD(b->e1[0]), e1y = RS_LD(b->e1[1]), e1z = RS_LD(b->e1[2]);
    __m128 e2x = RS_LD(b->e2[0]), e2y = RS_LD(b->e2[1]), e2z = RS_LD(b->e2[2]);
    __m128 dx = r->d[0], dy = r->d[1], dz = r->d[2];
    /* p = d x e2, det = e1 . p */
    __m128 px = _mm_sub_ps(_mm_mul_ps(dy, e2z), _mm_mul_ps(dz, e2y));
    __m128 py = _mm_sub_ps(_mm_mul_ps(dz, e2x), _mm_mul_ps(dx, e2z));
    __m128 pz = _mm_sub_ps(_mm_mul_ps(dx, e2y), _mm_mul_ps(dy, e2x));
    __m128 det =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(e1x, px), _mm_mul_ps(e1y, py)), _mm_mul_ps(e1z, pz));
    __m128 inv = _mm_div_ps(_mm_set1_ps(1.0f), det);
    /* s = o - v0, u = (s . p) inv */
    __m128 sx = _mm_sub_ps(r->o[0], RS_LD(b->v0[0]));
    __m128 sy = _mm_sub_ps(r->o[1], RS_LD(b->v0[1]));
    __m128 sz = _mm_sub_ps(r->o[2], RS_LD(b->v0[2]));
    __m128 bu = _mm_mul_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(sx, px), _mm_mul_ps(sy, py)), _mm_mul_ps(sz, pz)), inv);
    /* q = s x e1, v = (d . q) inv, t = (e2 . q) inv */
    __m128 qx = _mm_sub_ps(_mm_mul_ps(sy, e1z), _mm_mul_ps(sz, e1y));
    __m128 qy = _mm_sub_ps(_mm_mul_ps(sz, e1x), _mm_mul_ps(sx, e1z));
    __m128 qz = _mm_sub_ps(_mm_mul_ps(sx, e1y), _mm_mul_ps(sy, e1x));
    __m128 bv = _mm_mul_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, qx), _mm_mul_ps(dy, qy)), _mm_mul_ps(dz, qz)), inv);
    __m128 tt = _mm_mul_ps(
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(e2x, qx), _mm_mul_ps(e2y, qy)), _mm_mul_ps(e2z, qz)), inv);
    __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    __m128 ok = _mm_cmpneq_ps(det, zero);
    ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpge_ps(bu, zero), _mm_cmple_ps(bu, one)));
    ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpge_ps(bv, zero), _mm_cmple_ps(_mm_add_ps(bu, bv), one)));
    ok = _mm_and_ps(
        ok, _mm_and_ps(_mm_cmpgt_ps(tt, _mm_set1_ps(tmin)), _mm_cmplt_ps(tt, _mm_set1_ps(tmax))));
#  undef RS_LD
    _mm_storeu_ps(t, tt);
    _mm_storeu_ps(u, bu);
    _mm_storeu_ps(v, bv);
    return (uint32_t)_mm_movemask_ps(ok);
}
#endif

#ifdef RS_BVH4_SSE
/* rs_isect_quad on the four parallelograms of a block: the mask of lanes hit inside (tmin, tmax),
 * and their t and planar coordinates a, b. */
static inline uint32_t rs_bvh4_quad4_hit(const rs_bvh4_quad4 *b, const rs_bvh4_ray *r, float tmin,
                                         float tmax, float t[4], float a[4], float bb[4])
{
#  define RS_LD(x) _mm_load_ps(x)
    __m128 wx = RS_LD(b->w[0]), wy = RS_LD(b->w[1]), wz = RS_LD(b->w[2]);
    __m128 qx = RS_LD(b->q[0]), qy = RS_LD(b->q[1]), qz = RS_LD(b->q[2]);
    __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
    /* denom = w . d, t = w . (q - o) / denom */
    __m128 denom = _mm_add_ps(_mm_add_ps(_mm_mul_ps(wx, r->d[0]), _mm_mul_ps(wy, r->d[1])),
                              _mm_mul_ps(wz, r->d[2]));
    __m128 ox = _mm_sub_ps(qx, r->o[0]), oy = _mm_sub_ps(qy, r->o[1]);
    __m128 oz = _mm_sub_ps(qz, r->o[2]);
    __m128 num = _mm_add_ps(_mm_add_ps(_mm_mul_ps(wx, ox), _mm_mul_ps(wy, oy)),
                            _mm_mul_ps(wz, oz));
    __m128 tt = _mm_div_ps(num, denom);
    __m128 ok = _mm_and_ps(_mm_cmpneq_ps(denom, zero),
                           _mm_and_ps(_mm_cmpgt_ps(tt, _mm_set1_ps(tmin)),
                                      _mm_cmplt_ps(tt, _mm_set1_ps(tmax))));
    if (_mm_movemask_ps(ok) == 0)
        return 0;
    {
        /* ph = d t - (q - o); alpha = w . (ph x v), beta = w . (u x ph) */
        __m128 ux = RS_LD(b->u[0]), uy = RS_LD(b->u[1]), uz = RS_LD(b->u[2]);
        __m128 vx = RS_LD(b->v[0]), vy = RS_LD(b->v[1]), vz = RS_LD(b->v[2]);
        __m128 hx = _mm_sub_ps(_mm_mul_ps(r->d[0], tt), ox);
        __m128 hy = _mm_sub_ps(_mm_mul_ps(r->d[1], tt), oy);
        __m128 hz = _mm_sub_ps(_mm_mul_ps(r->d[2], tt), oz);
        __m128 cx = _mm_sub_ps(_mm_mul_ps(hy, vz), _mm_mul_ps(hz, vy));
        __m128 cy = _mm_sub_ps(_mm_mul_ps(hz, vx), _mm_mul_ps(hx, vz));
        __m128 cz = _mm_sub_ps(_mm_mul_ps(hx, vy), _mm_mul_ps(hy, vx));
        __m128 al = _mm_add_ps(_mm_add_ps(_mm_mul_ps(wx, cx), _mm_mul_ps(wy, cy)),
                               _mm_mul_ps(wz, cz));
        __m128 dx = _mm_sub_ps(_mm_mul_ps(uy, hz), _mm_mul_ps(uz, hy));
        __m128 dy = _mm_sub_ps(_mm_mul_ps(uz, hx), _mm_mul_ps(ux, hz));
        __m128 dz = _mm_sub_ps(_mm_mul_ps(ux, hy), _mm_mul_ps(uy, hx));
        __m128 be = _mm_add_ps(_mm_add_ps(_mm_mul_ps(wx, dx), _mm_mul_ps(wy, dy)),
                               _mm_mul_ps(wz, dz));
        ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpge_ps(al, zero), _mm_cmple_ps(al, one)));
        ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpge_ps(be, zero), _mm_cmple_ps(be, one)));
        _mm_storeu_ps(t, tt);
        _mm_storeu_ps(a, al);
        _mm_storeu_ps(bb, be);
    }
#  undef RS_LD
    return (uint32_t)_mm_movemask_ps(ok);
}

#endif

/* The walks, from accel/wide_walk.h: rs_bvh4_closest (closest hit, as rs_bvh_closest: 1 and
 * *hit on a hit, else hit->prim = RS_NO_HIT and 0) and rs_bvh4_occluded (any hit inside (tmin,
 * tmax), as rs_bvh_occluded), with rs_bvh4_packed_closest / _occluded for packed leaves. */
#define RS_WIDE_W     4
#define RS_WIDE_SHIFT 2
#define RS_WIDE_TREE  rs_bvh4
#define RS_WIDE_NODE  rs_bvh4_node
#define RS_WIDE_STACK RS_BVH4_STACK
#define RS_WIDE_FN(x) rs_bvh4_##x
#define RS_WIDE_RAY   rs_bvh4_ray
#define RS_WIDE_TN    rs_bvh4_tn
#ifdef RS_BVH4_SSE
#  define RS_WIDE_TRIS(b)                         ((b)->tri4)
#  define RS_WIDE_TRI_HIT(blk, r, t0, t1, t, u, v) rs_bvh4_tri4_hit(blk, r, t0, t1, t, u, v)
#  define RS_WIDE_QUADS_OF(b)                     ((b)->quad4)
#  define RS_WIDE_QUAD_HIT(blk, r, t0, t1, t, u, v) rs_bvh4_quad4_hit(blk, r, t0, t1, t, u, v)
#endif
#include "accel/wide_walk.h"

/* rs_trace_one (accel/trace.h) on the 4-wide tree. */
static inline void rs_bvh4_trace_one(const rs_bvh4 *b, const rs_geom *g,
                                     const rs_trace_batch *batch, uint32_t i)
{
    rs_ray r = rs_ray_soa_get(&batch->rays, i);
    if (batch->kind == RS_TRACE_CLOSEST) {
        rs_hit h;
        rs_bvh4_closest(b, g, r, &h);
        rs_hit_soa_set(&batch->hits, i, &h);
    } else {
        batch->occluded[i] = (uint8_t)rs_bvh4_occluded(b, g, r);
    }
}

#endif
