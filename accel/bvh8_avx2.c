/* accel/bvh8_avx2.c — closest-hit and any-hit traversal of the 8-wide BVH (accel/bvh8.h) with
 * AVX2.  Everything in this file is compiled for AVX2 (a target pragma, so the build runs on
 * any x86-64); it is called only where rs_bvh8_supported() says so.  The pragma names avx2
 * alone, never fma: with -ffp-contract=off no product and sum is fused, so each box and
 * triangle test rounds as the scalar code does. */
#include "accel/bvh8.h"

#if defined(__x86_64__) && defined(__GNUC__) && defined(RS_BVH4_SSE)

#  if defined(__clang__)
#    pragma clang attribute push(__attribute__((target("avx2"))), apply_to = function)
#  else
#    pragma GCC push_options
#    pragma GCC target("avx2")
#  endif
#  include <immintrin.h>
#  include <string.h>

typedef struct ray8 {
    __m256 o[3], d[3], inv[3];
    size_t near[3], far[3]; /* offsets in floats into rs_bvh8_node.b: each axis's near and far
                               plane's row */
    __m256 near_m[3], far_m[3], margin; /* walk8_ray_widen's: the margin with each plane's sign */
    int general;              /* some 1 / d is not finite: the slab test's min / max form */

} ray8;

static inline void walk8_ray_init(ray8 *r, rs_vec3 o, rs_vec3 d)
{
    rs_vec3 inv_d = rs_bvh_inv_dir(d);
    float iv[3], ov[3];
    int a;
    iv[0] = inv_d.x;
    iv[1] = inv_d.y;
    iv[2] = inv_d.z;
    ov[0] = o.x;
    ov[1] = o.y;
    ov[2] = o.z;
    r->general = 0;
    for (a = 0; a < 3; ++a) {
        r->o[a] = _mm256_set1_ps(ov[a]);
        r->d[a] = _mm256_set1_ps(a == 0 ? d.x : a == 1 ? d.y : d.z);
        r->inv[a] = _mm256_set1_ps(iv[a]);
        r->near[a] = 8u * ((size_t)a + (iv[a] < 0.0f ? 3u : 0u));
        r->far[a] = 8u * ((size_t)a + (iv[a] < 0.0f ? 0u : 3u));
        /* 1 / d finite and nonzero: no 0 * inf, and the planes order as the signs say */
        r->general |= !(iv[a] - iv[a] == 0.0f) || iv[a] == 0.0f;
    }
}

/* An instance's bottom level: its boxes widened by `margin` (lo - margin, hi + margin, as
 * rs_blas_node_hit; x + (-m) is x - m exactly). */
static inline void walk8_ray_widen(ray8 *r, float margin)
{
    int a;
    r->margin = _mm256_set1_ps(margin);
    for (a = 0; a < 3; ++a) {
        int flip = r->near[a] >= 24u; /* the near plane is hi */
        r->near_m[a] = _mm256_set1_ps(flip ? margin : -margin);
        r->far_m[a] = _mm256_set1_ps(flip ? -margin : margin);
    }
}

/* The slab test of the eight lanes of `n` (widened for a bottom level where `widen`, a constant
 * where it is inlined): the mask of lanes hit, their entry distances in *tn. */
RS_HD_HOT uint32_t walk8_lanes(const rs_bvh8_node *n, const ray8 *r, int widen, float tmin,
                               float tmax, __m256 *tn_out)
{
    const float *b = &n->b[0][0];
    __m256 tn, tf;
    if (!r->general) {
        __m256 pn[3], pf[3], nx, ny, nz, fx, fy, fz;
        int a;
        for (a = 0; a < 3; ++a) {
            pn[a] = _mm256_load_ps(b + r->near[a]);
            pf[a] = _mm256_load_ps(b + r->far[a]);
            if (widen) {
                pn[a] = _mm256_add_ps(pn[a], r->near_m[a]);
                pf[a] = _mm256_add_ps(pf[a], r->far_m[a]);
            }
        }
        nx = _mm256_mul_ps(_mm256_sub_ps(pn[0], r->o[0]), r->inv[0]);
        ny = _mm256_mul_ps(_mm256_sub_ps(pn[1], r->o[1]), r->inv[1]);
        nz = _mm256_mul_ps(_mm256_sub_ps(pn[2], r->o[2]), r->inv[2]);
        fx = _mm256_mul_ps(_mm256_sub_ps(pf[0], r->o[0]), r->inv[0]);
        fy = _mm256_mul_ps(_mm256_sub_ps(pf[1], r->o[1]), r->inv[1]);
        fz = _mm256_mul_ps(_mm256_sub_ps(pf[2], r->o[2]), r->inv[2]);
        tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, _mm256_set1_ps(tmin)));
        tf = _mm256_min_ps(_mm256_min_ps(fx, fy), _mm256_min_ps(fz, _mm256_set1_ps(tmax)));
    } else {
        int a;
        tn = _mm256_set1_ps(tmin);
        tf = _mm256_set1_ps(tmax);
        for (a = 0; a < 3; ++a) {
            __m256 lo = _mm256_load_ps(n->b[a]), hi = _mm256_load_ps(n->b[a + 3]), t0, t1, ok;
            if (widen) {
                lo = _mm256_sub_ps(lo, r->margin);
                hi = _mm256_add_ps(hi, r->margin);
            }
            t0 = _mm256_mul_ps(_mm256_sub_ps(lo, r->o[a]), r->inv[a]);
            t1 = _mm256_mul_ps(_mm256_sub_ps(hi, r->o[a]), r->inv[a]);
            /* rs_slab: a slab whose distances are NaN (0 * inf) is skipped */
            ok = _mm256_cmp_ps(t0, t1, _CMP_ORD_Q);
            tn = _mm256_blendv_ps(tn, _mm256_max_ps(_mm256_min_ps(t0, t1), tn), ok);
            tf = _mm256_blendv_ps(tf, _mm256_min_ps(_mm256_max_ps(t0, t1), tf), ok);
        }
    }
    *tn_out = tn;
    tf = _mm256_mul_ps(tf, _mm256_set1_ps(RS_BVH_SLACK));
    return (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ)) &
           ((1u << n->n_lanes) - 1u);
}

static inline void walk8_tn_store(float tn[8], const __m256 *v) { _mm256_storeu_ps(tn, *v); }

/* AVX comparisons that match SSE's: cmpneq is unordered (true for NaN), the others ordered. */
#  define CMP_NE(a, b) _mm256_cmp_ps(a, b, _CMP_NEQ_UQ)
#  define CMP_GE(a, b) _mm256_cmp_ps(a, b, _CMP_GE_OQ)
#  define CMP_GT(a, b) _mm256_cmp_ps(a, b, _CMP_GT_OQ)
#  define CMP_LE(a, b) _mm256_cmp_ps(a, b, _CMP_LE_OQ)
#  define CMP_LT(a, b) _mm256_cmp_ps(a, b, _CMP_LT_OQ)
#  define LD(x)        _mm256_load_ps(x)
#  define ADD(a, b)    _mm256_add_ps(a, b)
#  define SUB(a, b)    _mm256_sub_ps(a, b)
#  define MUL(a, b)    _mm256_mul_ps(a, b)
#  define AND(a, b)    _mm256_and_ps(a, b)

/* rs_bvh4_tri4_hit on eight triangles: rs_isect_tri's operations in its order. */
static inline uint32_t tri8_hit(const rs_bvh8_tri8 *b, const ray8 *r, float tmin, float tmax,
                                float t[8], float u[8], float v[8])
{
    __m256 e1x = LD(b->e1[0]), e1y = LD(b->e1[1]), e1z = LD(b->e1[2]);
    __m256 e2x = LD(b->e2[0]), e2y = LD(b->e2[1]), e2z = LD(b->e2[2]);
    __m256 dx = r->d[0], dy = r->d[1], dz = r->d[2];
    __m256 px = SUB(MUL(dy, e2z), MUL(dz, e2y));
    __m256 py = SUB(MUL(dz, e2x), MUL(dx, e2z));
    __m256 pz = SUB(MUL(dx, e2y), MUL(dy, e2x));
    __m256 det = ADD(ADD(MUL(e1x, px), MUL(e1y, py)), MUL(e1z, pz));
    __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    __m256 inv = _mm256_div_ps(one, det);
    __m256 sx = SUB(r->o[0], LD(b->v0[0]));
    __m256 sy = SUB(r->o[1], LD(b->v0[1]));
    __m256 sz = SUB(r->o[2], LD(b->v0[2]));
    __m256 bu = MUL(ADD(ADD(MUL(sx, px), MUL(sy, py)), MUL(sz, pz)), inv);
    __m256 qx = SUB(MUL(sy, e1z), MUL(sz, e1y));
    __m256 qy = SUB(MUL(sz, e1x), MUL(sx, e1z));
    __m256 qz = SUB(MUL(sx, e1y), MUL(sy, e1x));
    __m256 bv = MUL(ADD(ADD(MUL(dx, qx), MUL(dy, qy)), MUL(dz, qz)), inv);
    __m256 tt = MUL(ADD(ADD(MUL(e2x, qx), MUL(e2y, qy)), MUL(e2z, qz)), inv);
    __m256 ok = CMP_NE(det, zero);
    ok = AND(ok, AND(CMP_GE(bu, zero), CMP_LE(bu, one)));
    ok = AND(ok, AND(CMP_GE(bv, zero), CMP_LE(ADD(bu, bv), one)));
    ok = AND(ok, AND(CMP_GT(tt, _mm256_set1_ps(tmin)), CMP_LT(tt, _mm256_set1_ps(tmax))));
    _mm256_storeu_ps(t, tt);
    _mm256_storeu_ps(u, bu);
    _mm256_storeu_ps(v, bv);
    return (uint32_t)_mm256_movemask_ps(ok);
}

/* rs_bvh4_quad4_hit on eight parallelograms: rs_isect_quad's operations in its order. */
static inline uint32_t quad8_hit(const rs_bvh8_quad8 *b, const ray8 *r, float tmin, float tmax,
                                 float t[8], float a[8], float bb[8])
{
    __m256 wx = LD(b->w[0]), wy = LD(b->w[1]), wz = LD(b->w[2]);
    __m256 qx = LD(b->q[0]), qy = LD(b->q[1]), qz = LD(b->q[2]);
    __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    __m256 denom = ADD(ADD(MUL(wx, r->d[0]), MUL(wy, r->d[1])), MUL(wz, r->d[2]));
    __m256 ox = SUB(qx, r->o[0]), oy = SUB(qy, r->o[1]), oz = SUB(qz, r->o[2]);
    __m256 num = ADD(ADD(MUL(wx, ox), MUL(wy, oy)), MUL(wz, oz));
    __m256 tt = _mm256_div_ps(num, denom);
    __m256 ok = AND(CMP_NE(denom, zero),
                    AND(CMP_GT(tt, _mm256_set1_ps(tmin)), CMP_LT(tt, _mm256_set1_ps(tmax))));
    if (_mm256_movemask_ps(ok) == 0)
        return 0;
    {
        __m256 ux = LD(b->u[0]), uy = LD(b->u[1]), uz = LD(b->u[2]);
        __m256 vx = LD(b->v[0]), vy = LD(b->v[1]), vz = LD(b->v[2]);
        __m256 hx = SUB(MUL(r->d[0], tt), ox);
        __m256 hy = SUB(MUL(r->d[1], tt), oy);
        __m256 hz = SUB(MUL(r->d[2], tt), oz);
        __m256 cx = SUB(MUL(hy, vz), MUL(hz, vy));
        __m256 cy = SUB(MUL(hz, vx), MUL(hx, vz));
        __m256 cz = SUB(MUL(hx, vy), MUL(hy, vx));
        __m256 al = ADD(ADD(MUL(wx, cx), MUL(wy, cy)), MUL(wz, cz));
        __m256 ex = SUB(MUL(uy, hz), MUL(uz, hy));
        __m256 ey = SUB(MUL(uz, hx), MUL(ux, hz));
        __m256 ez = SUB(MUL(ux, hy), MUL(uy, hx));
        __m256 be = ADD(ADD(MUL(wx, ex), MUL(wy, ey)), MUL(wz, ez));
        ok = AND(ok, AND(CMP_GE(al, zero), CMP_LE(al, one)));
        ok = AND(ok, AND(CMP_GE(be, zero), CMP_LE(be, one)));
        _mm256_storeu_ps(t, tt);
        _mm256_storeu_ps(a, al);
        _mm256_storeu_ps(bb, be);
    }
    return (uint32_t)_mm256_movemask_ps(ok);
}

/* rs_isect_sphere on eight spheres: its operations in its order (sqrt and division are
 * correctly rounded in SSE/AVX as in sqrtf and '/'). */
static inline uint32_t sphere8_hit(const rs_bvh8_sphere8 *b, const ray8 *r, float tmin, float tmax,
                                   float t[8])
{
    __m256 dx = r->d[0], dy = r->d[1], dz = r->d[2];
    __m256 ox = SUB(LD(b->c[0]), r->o[0]), oy = SUB(LD(b->c[1]), r->o[1]);
    __m256 oz = SUB(LD(b->c[2]), r->o[2]);
    __m256 a = ADD(ADD(MUL(dx, dx), MUL(dy, dy)), MUL(dz, dz));
    __m256 h = ADD(ADD(MUL(dx, ox), MUL(dy, oy)), MUL(dz, oz));
    __m256 ha = _mm256_div_ps(h, a);
    __m256 lx = SUB(ox, MUL(dx, ha)), ly = SUB(oy, MUL(dy, ha)), lz = SUB(oz, MUL(dz, ha));
    __m256 rad = LD(b->r);
    __m256 disc = MUL(a, SUB(MUL(rad, rad), ADD(ADD(MUL(lx, lx), MUL(ly, ly)), MUL(lz, lz))));
    __m256 ok = CMP_GE(disc, _mm256_setzero_ps()), lo = _mm256_set1_ps(tmin);
    __m256 hi = _mm256_set1_ps(tmax), sq, near, far, in_near;
    if (_mm256_movemask_ps(ok) == 0)
        return 0;
    sq = _mm256_sqrt_ps(disc);
    near = _mm256_div_ps(SUB(h, sq), a);
    far = _mm256_div_ps(ADD(h, sq), a);
    in_near = AND(CMP_GT(near, lo), CMP_LT(near, hi));
    /* the near root where it lies inside (tmin, tmax), else the far one */
    near = _mm256_blendv_ps(far, near, in_near);
    ok = AND(ok, AND(CMP_GT(near, lo), CMP_LT(near, hi)));
    _mm256_storeu_ps(t, near);
    return (uint32_t)_mm256_movemask_ps(ok);
}

/* The walks, from accel/wide_walk.h (walk8_closest, walk8_occluded). */
#  define RS_WIDE_W                                 8
#  define RS_WIDE_SHIFT                             3
#  define RS_WIDE_TREE                              rs_bvh8
#  define RS_WIDE_NODE                              rs_bvh8_node
#  define RS_WIDE_STACK                             RS_BVH8_STACK
#  define RS_WIDE_FN(x)                             walk8_##x
#  define RS_WIDE_ENTRY                             RS_HD_HOT
#  define RS_WIDE_RAY                               ray8
#  define RS_WIDE_TN                                __m256
#  define RS_WIDE_TRIS(b)                           ((b)->tri8)
#  define RS_WIDE_TRI_HIT(blk, r, t0, t1, t, u, v)  tri8_hit(blk, r, t0, t1, t, u, v)
#  define RS_WIDE_QUADS_OF(b)                       ((b)->quad8)
#  define RS_WIDE_QUAD_HIT(blk, r, t0, t1, t, u, v) quad8_hit(blk, r, t0, t1, t, u, v)
#  define RS_WIDE_SPHERES_OF(b)                     ((b)->sphere8)
#  define RS_WIDE_SPHERE_HIT(blk, r, t0, t1, t)     sphere8_hit(blk, r, t0, t1, t)
#  include "accel/wide_walk.h"

int rs_bvh8_closest(const rs_bvh8 *b, const rs_geom *g, rs_ray ray, rs_hit *hit)
{
    return walk8_closest(b, g, ray, hit);
}

int rs_bvh8_occluded(const rs_bvh8 *b, const rs_geom *g, rs_ray ray)
{
    return walk8_occluded(b, g, ray);
}

void rs_bvh8_trace(const rs_bvh8 *b, const rs_geom *g, const rs_trace_batch *batch,
                   uint32_t begin, uint32_t end)
{
    uint32_t i;
    for (i = begin; i < end; ++i) {
        rs_ray r = rs_ray_soa_get(&batch->rays, i);
        if (batch->kind == RS_TRACE_CLOSEST) {
            rs_hit h;
            rs_bvh8_closest(b, g, r, &h);
            rs_hit_soa_set(&batch->hits, i, &h);
        } else {
            batch->occluded[i] = (uint8_t)rs_bvh8_occluded(b, g, r);
        }
    }
}

#  if defined(__clang__)
#    pragma clang attribute pop
#  else
#    pragma GCC pop_options
#  endif

#else /* no AVX2 build: rs_bvh8_supported() is 0 and these are never called */

int rs_bvh8_closest(const rs_bvh8 *b, const rs_geom *g, rs_ray ray, rs_hit *hit)
{
    (void)b;
    (void)g;
    (void)ray;
    hit->prim = RS_NO_HIT;
    RS_ASSERT(0);
    return 0;
}

int rs_bvh8_occluded(const rs_bvh8 *b, const rs_geom *g, rs_ray ray)
{
    (void)b;
    (void)g;
    (void)ray;
    RS_ASSERT(0);
    return 0;
}

void rs_bvh8_trace(const rs_bvh8 *b, const rs_geom *g, const rs_trace_batch *batch,
                   uint32_t begin, uint32_t end)
{
    (void)b;
    (void)g;
    (void)batch;
    (void)begin;
    (void)end;
    RS_ASSERT(0);
}

#endif
