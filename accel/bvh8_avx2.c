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
#  include <float.h>
#  include <immintrin.h>
#  include <string.h>

typedef struct ray8 {
    __m256 o[3], d[3], inv[3];
    size_t near[3], far[3]; /* offsets in floats into rs_bvh8_node.b: each axis's near and far
                               plane's row */
    __m256 near_m[3], far_m[3], margin; /* walk8_ray_widen's: the margin with each plane's sign */
    int general;              /* some 1 / d is not finite: the slab test's min / max form */

} ray8;

/* The ray broadcast, with inv_d = rs_bvh_inv_dir(d) already made. */
static inline void walk8_ray_init_inv(ray8 *r, rs_vec3 o, rs_vec3 d, rs_vec3 inv_d)
{
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

static inline void walk8_ray_init(ray8 *r, rs_vec3 o, rs_vec3 d)
{
    walk8_ray_init_inv(r, o, d, rs_bvh_inv_dir(d));
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

/* rs_isect_tri's operations in its order on eight (triangle, ray) pairs: lane i tests triangle
 * (v0, e1, e2)[i] against ray (o, d)[i] inside (tmin, tmax)[i].  A block against one ray
 * broadcasts the ray, a packet against one triangle broadcasts the triangle: the same arithmetic
 * either way, so the same bits.  The mask of lanes hit, and t, u, v per lane. */
static inline uint32_t tri_test8(const __m256 v0[3], const __m256 e1[3], const __m256 e2[3],
                                 const __m256 o[3], const __m256 d[3], __m256 tmin, __m256 tmax,
                                 __m256 *t, __m256 *u, __m256 *v)
{
    __m256 e1x = e1[0], e1y = e1[1], e1z = e1[2], e2x = e2[0], e2y = e2[1], e2z = e2[2];
    __m256 dx = d[0], dy = d[1], dz = d[2];
    __m256 px = SUB(MUL(dy, e2z), MUL(dz, e2y));
    __m256 py = SUB(MUL(dz, e2x), MUL(dx, e2z));
    __m256 pz = SUB(MUL(dx, e2y), MUL(dy, e2x));
    __m256 det = ADD(ADD(MUL(e1x, px), MUL(e1y, py)), MUL(e1z, pz));
    __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    __m256 inv = _mm256_div_ps(one, det);
    __m256 sx = SUB(o[0], v0[0]);
    __m256 sy = SUB(o[1], v0[1]);
    __m256 sz = SUB(o[2], v0[2]);
    __m256 bu = MUL(ADD(ADD(MUL(sx, px), MUL(sy, py)), MUL(sz, pz)), inv);
    __m256 qx = SUB(MUL(sy, e1z), MUL(sz, e1y));
    __m256 qy = SUB(MUL(sz, e1x), MUL(sx, e1z));
    __m256 qz = SUB(MUL(sx, e1y), MUL(sy, e1x));
    __m256 bv = MUL(ADD(ADD(MUL(dx, qx), MUL(dy, qy)), MUL(dz, qz)), inv);
    __m256 tt = MUL(ADD(ADD(MUL(e2x, qx), MUL(e2y, qy)), MUL(e2z, qz)), inv);
    __m256 ok = CMP_NE(det, zero);
    ok = AND(ok, AND(CMP_GE(bu, zero), CMP_LE(bu, one)));
    ok = AND(ok, AND(CMP_GE(bv, zero), CMP_LE(ADD(bu, bv), one)));
    ok = AND(ok, AND(CMP_GT(tt, tmin), CMP_LT(tt, tmax)));
    *t = tt;
    *u = bu;
    *v = bv;
    return (uint32_t)_mm256_movemask_ps(ok);
}

/* rs_isect_quad's operations in its order on eight (parallelogram, ray) pairs, as tri_test8:
 * parallelogram (q, u, v, w)[i] against ray (o, d)[i].  The mask of lanes hit, t, a, b. */
static inline uint32_t quad_test8(const __m256 q[3], const __m256 u[3], const __m256 v[3],
                                  const __m256 w[3], const __m256 o[3], const __m256 d[3],
                                  __m256 tmin, __m256 tmax, __m256 *t, __m256 *a, __m256 *bb)
{
    __m256 wx = w[0], wy = w[1], wz = w[2];
    __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
    __m256 denom = ADD(ADD(MUL(wx, d[0]), MUL(wy, d[1])), MUL(wz, d[2]));
    __m256 ox = SUB(q[0], o[0]), oy = SUB(q[1], o[1]), oz = SUB(q[2], o[2]);
    __m256 num = ADD(ADD(MUL(wx, ox), MUL(wy, oy)), MUL(wz, oz));
    __m256 tt = _mm256_div_ps(num, denom);
    __m256 ok = AND(CMP_NE(denom, zero), AND(CMP_GT(tt, tmin), CMP_LT(tt, tmax)));
    __m256 hx, hy, hz, cx, cy, cz, al, ex, ey, ez, be;
    if (_mm256_movemask_ps(ok) == 0)
        return 0;
    hx = SUB(MUL(d[0], tt), ox);
    hy = SUB(MUL(d[1], tt), oy);
    hz = SUB(MUL(d[2], tt), oz);
    cx = SUB(MUL(hy, v[2]), MUL(hz, v[1]));
    cy = SUB(MUL(hz, v[0]), MUL(hx, v[2]));
    cz = SUB(MUL(hx, v[1]), MUL(hy, v[0]));
    al = ADD(ADD(MUL(wx, cx), MUL(wy, cy)), MUL(wz, cz));
    ex = SUB(MUL(u[1], hz), MUL(u[2], hy));
    ey = SUB(MUL(u[2], hx), MUL(u[0], hz));
    ez = SUB(MUL(u[0], hy), MUL(u[1], hx));
    be = ADD(ADD(MUL(wx, ex), MUL(wy, ey)), MUL(wz, ez));
    ok = AND(ok, AND(CMP_GE(al, zero), CMP_LE(al, one)));
    ok = AND(ok, AND(CMP_GE(be, zero), CMP_LE(be, one)));
    *t = tt;
    *a = al;
    *bb = be;
    return (uint32_t)_mm256_movemask_ps(ok);
}

/* Three rows of a block's lanes: LD3(b->v0) is {v0[0], v0[1], v0[2]} as vectors. */
#  define LD3(x)       {LD((x)[0]), LD((x)[1]), LD((x)[2])}
/* Lane k of three rows, broadcast. */
#  define BC3(x, k)    {_mm256_broadcast_ss(&(x)[0][k]), _mm256_broadcast_ss(&(x)[1][k]), \
                        _mm256_broadcast_ss(&(x)[2][k])}

/* rs_bvh4_tri4_hit on eight triangles: one ray against a block. */
static inline uint32_t tri8_hit(const rs_bvh8_tri8 *b, const ray8 *r, float tmin, float tmax,
                                float t[8], float u[8], float v[8])
{
    const __m256 v0[3] = LD3(b->v0), e1[3] = LD3(b->e1), e2[3] = LD3(b->e2);
    __m256 tv, uv, vv;
    uint32_t m = tri_test8(v0, e1, e2, r->o, r->d, _mm256_set1_ps(tmin), _mm256_set1_ps(tmax),
                           &tv, &uv, &vv);
    _mm256_storeu_ps(t, tv);
    _mm256_storeu_ps(u, uv);
    _mm256_storeu_ps(v, vv);
    return m;
}

/* rs_bvh4_quad4_hit on eight parallelograms: one ray against a block. */
static inline uint32_t quad8_hit(const rs_bvh8_quad8 *b, const ray8 *r, float tmin, float tmax,
                                 float t[8], float a[8], float bb[8])
{
    const __m256 q[3] = LD3(b->q), u[3] = LD3(b->u), v[3] = LD3(b->v), w[3] = LD3(b->w);
    __m256 tv, av, bv;
    uint32_t m = quad_test8(q, u, v, w, r->o, r->d, _mm256_set1_ps(tmin), _mm256_set1_ps(tmax),
                            &tv, &av, &bv);
    if (m == 0)
        return 0;
    _mm256_storeu_ps(t, tv);
    _mm256_storeu_ps(a, av);
    _mm256_storeu_ps(bb, bv);
    return m;
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

/* RS_WIDE_PREFETCH: what lane l of node n leads to, asked for as soon as the box test finds the
 * lane hit (Embree's traverser prefetches each child it takes the same way): five cache lines
 * from an inner node's start (its 256 bytes and the next node's first line) or from a packed
 * leaf's first block (a tri8's 320 bytes; the first 320 of a quad8, a sphere8 and the next).  The
 * closest-hit walk then orders and pushes the lanes while the lines come in from L2 or L3: on the
 * interior's recorded bounce and shadow rays its closest hits run 3-7% faster (docs/performance.md,
 * "A render's own rays, and prefetching the lanes hit").  Always five lines: a count that varied
 * with the kind would be a branch mispredicted as often as the kinds alternate. */
static inline void walk8_prefetch(const rs_bvh8 *b, const rs_bvh8_node *n, uint32_t l)
{
    uint32_t count = n->count[l], c = n->child[l];
    const char *p;
    if (count == 0)
        p = (const char *)&b->nodes[c];
    else if (!(count & RS_WIDE_PACKED))
        return; /* a leaf tested a primitive at a time: nothing in one place to ask for */
    else if (!(count & (RS_WIDE_QUADS | RS_WIDE_SPHERES)))
        p = (const char *)&b->tri8[c];
    else
        p = count & RS_WIDE_QUADS ? (const char *)&b->quad8[c] : (const char *)&b->sphere8[c];
    /* asm, not _mm_prefetch: GCC deletes a loop whose only work is __builtin_prefetch */
    __asm__ volatile("prefetcht0 (%0)\n\tprefetcht0 64(%0)\n\tprefetcht0 128(%0)\n\t"
                     "prefetcht0 192(%0)\n\tprefetcht0 256(%0)"
                     :
                     : "r"(p));
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
#  define RS_WIDE_PREFETCH(b, n, l)                 walk8_prefetch(b, n, l)
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

/* ---- Packets: eight rays walked through the tree together ----
 *
 * Rays that start close together and point the same way (a row of camera rays, the first
 * bounce off one surface) visit mostly the same nodes.  Walked one at a time each pays for the
 * walk: loading a node, the eight-lane box test, sorting and pushing the lanes hit, mispredicted
 * branches.  Walked as a packet (Embree's "hybrid" traversal, Wald et al. 2001) the rays are the
 * lanes: a node's child is tested against all eight rays at once, and a leaf's triangle too, so
 * the walk's bookkeeping is paid once for eight rays where they agree.
 *
 * The same answers, bit for bit, as walk8_closest and walk8_occluded: each ray's box tests and
 * primitive tests are the single-ray walk's operations in its order (a ray's slab distances are
 * the near and far plane's, which min and max of the two planes' pick exactly when 1 / d is
 * finite and nonzero; rays with another direction are walked alone), and the closest hit is the
 * least (t, prim) by rs_hit_better whatever the order of the visit (accel/wide_walk.h). */

/* The stack entry for lane `lane` of node `n`, number `node` (wide_walk.h's RS_WIDE_REF). */
#  define RS_WIDE_LEAF_OR_NODE(n, node, lane)                                                      \
    ((n)->count[lane] ? RS_WIDE_LEAF | (node) << 3 | (lane) : (n)->child[lane])

/* A packet entry with this many lanes or fewer left is walked one lane at a time from there:
 * rays that have parted ways share nothing more (on the living room's diffuse rays, 3 and 4
 * were the fastest of 0 to 6; docs/performance.md). */
#  define PK8_ALONE 3

typedef struct pk8 {
    __m256 o[3], d[3], inv[3], tmin;
    int octant; /* the lanes' directions all have the same signs: near and far planes known */
    uint32_t near[3], far[3]; /* then each axis's near and far plane's row of rs_bvh8_node.b */
    float tmax[8];            /* per lane, cut just past each hit (closest) */
    rs_ray ray[8];            /* each lane's ray, for the leaves walked one lane at a time */
    /* closest hit: the lanes' best hits and tmax in registers while the packet walks (pk8_out
     * puts them in hit[] and tmax[] for the steps that walk one lane at a time, pk8_in back) */
    __m256 ht, hu, hv, tmaxv;
    __m256i hprim;
} pk8;

/* The lanes' hits and tmax from registers to hit[] and p->tmax (an 8x4 transpose). */
static inline void pk8_out(pk8 *p, rs_hit *hit)
{
    __m256 pr = _mm256_castsi256_ps(p->hprim);
    __m256 t0 = _mm256_unpacklo_ps(p->ht, p->hu), t1 = _mm256_unpacklo_ps(p->hv, pr);
    __m256 t2 = _mm256_unpackhi_ps(p->ht, p->hu), t3 = _mm256_unpackhi_ps(p->hv, pr);
    __m256 r0 = _mm256_shuffle_ps(t0, t1, 0x44), r1 = _mm256_shuffle_ps(t0, t1, 0xee);
    __m256 r2 = _mm256_shuffle_ps(t2, t3, 0x44), r3 = _mm256_shuffle_ps(t2, t3, 0xee);
    float *h = &hit[0].t;
    typedef char hit_floats[sizeof(rs_hit) == 16 ? 1 : -1];
    (void)sizeof(hit_floats);
    /* r0 = lanes 0 | 4, r1 = 1 | 5, r2 = 2 | 6, r3 = 3 | 7 */
    _mm_storeu_ps(h + 0, _mm256_castps256_ps128(r0));
    _mm_storeu_ps(h + 4, _mm256_castps256_ps128(r1));
    _mm_storeu_ps(h + 8, _mm256_castps256_ps128(r2));
    _mm_storeu_ps(h + 12, _mm256_castps256_ps128(r3));
    _mm_storeu_ps(h + 16, _mm256_extractf128_ps(r0, 1));
    _mm_storeu_ps(h + 20, _mm256_extractf128_ps(r1, 1));
    _mm_storeu_ps(h + 24, _mm256_extractf128_ps(r2, 1));
    _mm_storeu_ps(h + 28, _mm256_extractf128_ps(r3, 1));
    _mm256_storeu_ps(p->tmax, p->tmaxv);
}

/* hit[] and p->tmax back into registers. */
static inline void pk8_in(pk8 *p, const rs_hit *hit)
{
    const float *h = &hit[0].t;
    __m256 r0 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(h)), _mm_loadu_ps(h + 16), 1);
    __m256 r1 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(h + 4)), _mm_loadu_ps(h + 20), 1);
    __m256 r2 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(h + 8)), _mm_loadu_ps(h + 24), 1);
    __m256 r3 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(h + 12)), _mm_loadu_ps(h + 28), 1);
    __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpacklo_ps(r2, r3);
    __m256 t2 = _mm256_unpackhi_ps(r0, r1), t3 = _mm256_unpackhi_ps(r2, r3);
    p->ht = _mm256_shuffle_ps(t0, t1, 0x44);
    p->hu = _mm256_shuffle_ps(t0, t1, 0xee);
    p->hv = _mm256_shuffle_ps(t2, t3, 0x44);
    p->hprim = _mm256_castps_si256(_mm256_shuffle_ps(t2, t3, 0xee));
    p->tmaxv = _mm256_loadu_ps(p->tmax);
}

/* Child c of node n against the packet's rays: the lanes whose ray enters the box inside
 * (tmin, tmax), and their entry distances. */
static inline uint32_t pk8_child(const rs_bvh8_node *n, uint32_t c, const pk8 *p, __m256 tmaxv,
                                 __m256 *tn_out)
{
    if (p->octant) { /* walk8_lanes' planes: the same distances, no min and max to pick them */
        __m256 nx = MUL(SUB(_mm256_broadcast_ss(&n->b[p->near[0]][c]), p->o[0]), p->inv[0]);
        __m256 ny = MUL(SUB(_mm256_broadcast_ss(&n->b[p->near[1]][c]), p->o[1]), p->inv[1]);
        __m256 nz = MUL(SUB(_mm256_broadcast_ss(&n->b[p->near[2]][c]), p->o[2]), p->inv[2]);
        __m256 fx = MUL(SUB(_mm256_broadcast_ss(&n->b[p->far[0]][c]), p->o[0]), p->inv[0]);
        __m256 fy = MUL(SUB(_mm256_broadcast_ss(&n->b[p->far[1]][c]), p->o[1]), p->inv[1]);
        __m256 fz = MUL(SUB(_mm256_broadcast_ss(&n->b[p->far[2]][c]), p->o[2]), p->inv[2]);
        __m256 tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, p->tmin));
        __m256 tf = _mm256_min_ps(_mm256_min_ps(fx, fy), _mm256_min_ps(fz, tmaxv));
        *tn_out = tn;
        return (uint32_t)_mm256_movemask_ps(CMP_LE(tn, MUL(tf, _mm256_set1_ps(RS_BVH_SLACK))));
    }
    {
    __m256 t0x = MUL(SUB(_mm256_broadcast_ss(&n->b[0][c]), p->o[0]), p->inv[0]);
    __m256 t1x = MUL(SUB(_mm256_broadcast_ss(&n->b[3][c]), p->o[0]), p->inv[0]);
    __m256 t0y = MUL(SUB(_mm256_broadcast_ss(&n->b[1][c]), p->o[1]), p->inv[1]);
    __m256 t1y = MUL(SUB(_mm256_broadcast_ss(&n->b[4][c]), p->o[1]), p->inv[1]);
    __m256 t0z = MUL(SUB(_mm256_broadcast_ss(&n->b[2][c]), p->o[2]), p->inv[2]);
    __m256 t1z = MUL(SUB(_mm256_broadcast_ss(&n->b[5][c]), p->o[2]), p->inv[2]);
    __m256 tn = _mm256_max_ps(_mm256_max_ps(_mm256_min_ps(t0x, t1x), _mm256_min_ps(t0y, t1y)),
                              _mm256_max_ps(_mm256_min_ps(t0z, t1z), p->tmin));
    __m256 tf = _mm256_min_ps(_mm256_min_ps(_mm256_max_ps(t0x, t1x), _mm256_max_ps(t0y, t1y)),
                              _mm256_min_ps(_mm256_max_ps(t0z, t1z), tmaxv));
    *tn_out = tn;
    return (uint32_t)_mm256_movemask_ps(CMP_LE(tn, MUL(tf, _mm256_set1_ps(RS_BVH_SLACK))));
    }
}

/* Triangle k of block b against the packet's eight rays. */
static inline uint32_t pk8_tri(const rs_bvh8_tri8 *b, uint32_t k, const pk8 *p, __m256 tmaxv,
                               __m256 *t, __m256 *u, __m256 *v)
{
    const __m256 v0[3] = BC3(b->v0, k), e1[3] = BC3(b->e1, k), e2[3] = BC3(b->e2, k);
    return tri_test8(v0, e1, e2, p->o, p->d, p->tmin, tmaxv, t, u, v);
}

/* Parallelogram k of block b against the packet's eight rays. */
static inline uint32_t pk8_quad(const rs_bvh8_quad8 *b, uint32_t k, const pk8 *p, __m256 tmaxv,
                                __m256 *t, __m256 *a, __m256 *bb)
{
    const __m256 q[3] = BC3(b->q, k), u[3] = BC3(b->u, k), v[3] = BC3(b->v, k),
                 w[3] = BC3(b->w, k);
    return quad_test8(q, u, v, w, p->o, p->d, p->tmin, tmaxv, t, a, bb);
}

/* Lanes `m` of a primitive test's answers, each taken if better (rs_hit_better), the lane's ray
 * cut just past it. */
/* Primitive k of packed block `block` (parallelograms where `count` says so, else triangles)
 * against the packet: pk8_quad's or pk8_tri's mask and answers. */
static inline uint32_t pk8_prim(const rs_bvh8 *b, uint32_t count, uint32_t block, uint32_t k,
                                const pk8 *p, __m256 tmaxv, __m256 *t, __m256 *u, __m256 *v)
{
    return count & RS_WIDE_QUADS ? pk8_quad(&b->quad8[block], k, p, tmaxv, t, u, v)
                                 : pk8_tri(&b->tri8[block], k, p, tmaxv, t, u, v);
}

/* Lanes `m` of a primitive test's answers, each taken where better (rs_hit_better: nearer, or as
 * near with a lower number), the lane's ray cut just past it (rs_float_next_up): lane by lane the
 * scalar rules, all lanes at once. */
static inline void pk8_take(pk8 *p, uint32_t m, __m256 tv, __m256 uv, __m256 vv, uint32_t prim)
{
    const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
    const __m256i sign = _mm256_set1_epi32((int)0x80000000u), one = _mm256_set1_epi32(1);
    __m256i mv = _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32((int)m), bit), bit);
    __m256i pv = _mm256_set1_epi32((int)prim);
    __m256i lower = _mm256_cmpgt_epi32(_mm256_xor_si256(p->hprim, sign), _mm256_xor_si256(pv, sign));
    __m256 better = _mm256_or_ps(_mm256_cmp_ps(tv, p->ht, _CMP_LT_OQ),
                                 _mm256_and_ps(_mm256_cmp_ps(tv, p->ht, _CMP_EQ_OQ),
                                               _mm256_castsi256_ps(lower)));
    __m256i u = _mm256_castps_si256(tv), up;
    __m256 zero = _mm256_setzero_ps();
    better = _mm256_and_ps(better, _mm256_castsi256_ps(mv));
    /* rs_float_next_up: 0 -> the smallest denormal, finite > 0 -> one up, < 0 -> one down */
    up = _mm256_blendv_epi8(u, _mm256_add_epi32(u, one),
                            _mm256_and_si256(_mm256_castps_si256(_mm256_cmp_ps(tv, zero, _CMP_GT_OQ)),
                                             _mm256_cmpgt_epi32(_mm256_set1_epi32(0x7f800000), u)));
    up = _mm256_blendv_epi8(up, _mm256_sub_epi32(u, one),
                            _mm256_castps_si256(_mm256_cmp_ps(tv, zero, _CMP_LT_OQ)));
    up = _mm256_blendv_epi8(up, one, _mm256_castps_si256(_mm256_cmp_ps(tv, zero, _CMP_EQ_OQ)));
    p->tmaxv = _mm256_blendv_ps(p->tmaxv, _mm256_castsi256_ps(up), better);
    p->ht = _mm256_blendv_ps(p->ht, tv, better);
    p->hu = _mm256_blendv_ps(p->hu, uv, better);
    p->hv = _mm256_blendv_ps(p->hv, vv, better);
    p->hprim = _mm256_castps_si256(
        _mm256_blendv_ps(_mm256_castsi256_ps(p->hprim), _mm256_castsi256_ps(pv), better));
}

/* A leaf for closest hit, lanes `m` of the packet: packed triangles and parallelograms against
 * the packet, anything else (spheres, unpacked leaves, instances) one lane at a time through
 * the single-ray walk's own leaf steps. */
static void pk8_leaf_closest(const rs_bvh8 *b, const rs_geom *g, uint32_t first, uint32_t count,
                             pk8 *p, rs_hit *hit, uint32_t m)
{
    uint32_t i, k;
    if ((count & RS_WIDE_PACKED) && !(count & RS_WIDE_SPHERES)) {
        for (i = 0; i < (count & RS_WIDE_BLOCKS); ++i) {
            const uint32_t *prim = count & RS_WIDE_QUADS ? b->quad8[first + i].prim
                                                         : b->tri8[first + i].prim;
            for (k = 0; k < 8; ++k) {
                __m256 t, u, v;
                uint32_t got;
                if (prim[k] == RS_NO_HIT)
                    continue;
                got = pk8_prim(b, count, first + i, k, p, p->tmaxv, &t, &u, &v) & m;
                if (got)
                    pk8_take(p, got, t, u, v, prim[k]);
            }
        }
        return;
    }
    pk8_out(p, hit);
    while (m) {
        uint32_t l = (uint32_t)__builtin_ctz(m);
        rs_ray r = p->ray[l];
        m &= m - 1;
        r.tmax = p->tmax[l];
        if (count & RS_WIDE_PACKED) {
            ray8 r8;
            walk8_ray_init(&r8, r.o, r.d);
            walk8_packed_closest(b, first, count, &r8, &r, &hit[l]);
        } else {
            for (i = 0; i < count; ++i)
                walk8_leaf_closest(b, g, first + i, &r, &hit[l], NULL);
        }
        p->tmax[l] = r.tmax;
    }
    pk8_in(p, hit);
}

/* The closest hits of the packet's lanes `active` (hit[] set up as walk8_closest does, and
 * loaded into the packet by pk8_in; pk8_out puts the answers back). */
static void pk8_closest(const rs_bvh8 *b, const rs_geom *g, pk8 *p, rs_hit *hit, uint32_t active)
{
    uint32_t stack[RS_BVH8_STACK];
    uint8_t stack_m[RS_BVH8_STACK];
    __m256 stack_tn[RS_BVH8_STACK];
    uint32_t sp = 0;
    stack[0] = 0;
    stack_m[0] = (uint8_t)active;
    stack_tn[0] = _mm256_set1_ps(-FLT_MAX);
    sp = 1;
    while (sp > 0) {
        __m256 tmaxv = p->tmaxv;
        uint32_t ref, m;
        --sp;
        ref = stack[sp];
        /* the lanes that can still find a hit no farther than their best so far */
        m = stack_m[sp] &
            (uint32_t)_mm256_movemask_ps(
                CMP_LE(stack_tn[sp], MUL(tmaxv, _mm256_set1_ps(RS_BVH_SLACK))));
        if (m == 0)
            continue;
        if (!(ref & RS_WIDE_LEAF) && __builtin_popcount(m) <= PK8_ALONE) {
            /* too few lanes left to share the walk: each walks this subtree alone */
            pk8_out(p, hit);
            while (m) {
                uint32_t l = (uint32_t)__builtin_ctz(m);
                rs_ray r = p->ray[l];
                ray8 r8;
                m &= m - 1;
                r.tmax = p->tmax[l];
                walk8_ray_init(&r8, r.o, r.d);
                walk8_walk_closest(b, g, ref, &r8, &r, &hit[l], NULL);
                p->tmax[l] = r.tmax;
            }
            pk8_in(p, hit);
            continue;
        }
        if (!(ref & RS_WIDE_LEAF)) {
            const rs_bvh8_node *n = &b->nodes[ref];
            uint32_t c, k = 0, order[8], cm[8], j;
            float near[8];
            __m256 tn[8];
            for (c = 0; c < n->n_lanes; ++c) {
                uint32_t hm = pk8_child(n, c, p, tmaxv, &tn[k]) & m;
                float t8[8], best;
                if (hm == 0)
                    continue;
                _mm256_storeu_ps(t8, tn[k]);
                best = t8[__builtin_ctz(hm)];
                /* insertion by the first lane's entry distance, far first */
                for (j = k; j > 0 && near[j - 1] < best; --j) {
                    near[j] = near[j - 1];
                    order[j] = order[j - 1];
                    cm[j] = cm[j - 1];
                }
                near[j] = best;
                order[j] = c | k << 8;
                cm[j] = hm;
                ++k;
            }
            for (j = 0; j < k; ++j) {
                RS_ASSERT(sp < RS_BVH8_STACK);
                stack[sp] = RS_WIDE_LEAF_OR_NODE(n, ref, order[j] & 0xffu);
                stack_m[sp] = (uint8_t)cm[j];
                stack_tn[sp++] = tn[order[j] >> 8];
            }
        } else {
            const rs_bvh8_node *n = &b->nodes[(ref & ~RS_WIDE_LEAF) >> 3];
            uint32_t lane = ref & 7u;
            pk8_leaf_closest(b, g, n->child[lane], n->count[lane], p, hit, m);
        }
    }
}

/* A leaf for any hit, lanes `m` of the packet: the mask of those it blocks.  Packed triangles and
 * parallelograms against the packet, anything else one lane at a time (walk8_leaf_run_occluded). */
static uint32_t pk8_leaf_occluded(const rs_bvh8 *b, const rs_geom *g, uint32_t first,
                                  uint32_t count, pk8 *p, __m256 tmaxv, uint32_t m)
{
    uint32_t i, k, done = 0;
    if ((count & RS_WIDE_PACKED) && !(count & RS_WIDE_SPHERES)) {
        for (i = 0; i < (count & RS_WIDE_BLOCKS) && m; ++i) {
            const uint32_t *prim =
                count & RS_WIDE_QUADS ? b->quad8[first + i].prim : b->tri8[first + i].prim;
            for (k = 0; k < 8 && m; ++k) {
                __m256 t, u, v;
                uint32_t got;
                if (prim[k] == RS_NO_HIT)
                    continue;
                got = pk8_prim(b, count, first + i, k, p, tmaxv, &t, &u, &v) & m;
                done |= got;
                m &= ~got;
            }
        }
        return done;
    }
    while (m) {
        uint32_t l = (uint32_t)__builtin_ctz(m);
        ray8 r8;
        m &= m - 1;
        walk8_ray_init(&r8, p->ray[l].o, p->ray[l].d);
        if (walk8_leaf_run_occluded(b, g, first, count, &r8, &p->ray[l], NULL))
            done |= 1u << l;
    }
    return done;
}

/* Any hit for the packet's lanes `active`: the mask of those blocked.  As walk8_occluded, the
 * leaves among a node's children hit are tested at once and the other children pushed. */
static uint32_t pk8_occluded(const rs_bvh8 *b, const rs_geom *g, pk8 *p, uint32_t active)
{
    uint32_t stack[RS_BVH8_STACK];
    uint8_t stack_m[RS_BVH8_STACK];
    uint32_t sp = 1, done = 0;
    __m256 tmaxv = _mm256_loadu_ps(p->tmax);
    stack[0] = 0;
    stack_m[0] = (uint8_t)active;
    while (sp > 0 && done != active) {
        uint32_t ref = stack[--sp], m = stack_m[sp] & ~done, c;
        const rs_bvh8_node *n = &b->nodes[ref];
        if (m == 0)
            continue;
        if (__builtin_popcount(m) <= PK8_ALONE) {
            while (m) {
                uint32_t l = (uint32_t)__builtin_ctz(m);
                ray8 r8;
                m &= m - 1;
                walk8_ray_init(&r8, p->ray[l].o, p->ray[l].d);
                if (walk8_walk_occluded(b, g, ref, &r8, &p->ray[l], NULL))
                    done |= 1u << l;
            }
            continue;
        }
        for (c = 0; c < n->n_lanes && m; ++c) {
            __m256 tn;
            uint32_t hm = pk8_child(n, c, p, tmaxv, &tn) & m;
            if (!hm)
                continue;
            if (n->count[c]) {
                uint32_t got = pk8_leaf_occluded(b, g, n->child[c], n->count[c], p, tmaxv, hm);
                done |= got;
                m &= ~got;
            } else {
                RS_ASSERT(sp < RS_BVH8_STACK);
                stack[sp] = n->child[c];
                stack_m[sp++] = (uint8_t)hm;
            }
        }
    }
    return done;
}

/* Eight lanes of one stream field from f (entries i .. i + n - 1 of it): lanes n .. 7 copies of
 * lane 0. */
static inline __m256 pk8_field(const float *f, uint32_t n)
{
    float x[8];
    uint32_t l;
    if (n == 8)
        return _mm256_loadu_ps(f);
    for (l = 0; l < 8; ++l)
        x[l] = f[l < n ? l : 0];
    return _mm256_loadu_ps(x);
}

/* Rays i .. i + n - 1 of the stream as eight lanes: v[0..2] the origins, v[3..5] the directions,
 * v[6] tmin (pk8_field). */
static inline void pk8_load(const rs_ray_soa *r, uint32_t i, uint32_t n, __m256 v[7])
{
    const float *f[7] = {r->ox + i, r->oy + i, r->oz + i, r->dx + i, r->dy + i, r->dz + i,
                         r->tmin + i};
    uint32_t k;
    for (k = 0; k < 7; ++k)
        v[k] = pk8_field(f[k], n);
}

void rs_bvh8_trace_packets(const rs_bvh8 *b, const rs_geom *g, const rs_trace_batch *batch,
                           uint32_t begin, uint32_t end)
{
    uint32_t i, l;
    if (b->n_nodes == 0 || end - begin < 8) {
        rs_bvh8_trace(b, g, batch, begin, end);
        return;
    }
    for (i = begin; i < end; i += 8) {
        uint32_t n = end - i < 8 ? end - i : 8, active, neg[3], a;
        __m256 v[7], ok = _mm256_castsi256_ps(_mm256_set1_epi32(-1)), zero = _mm256_setzero_ps();
        pk8 p;
        rs_hit hit[8];
        /* the eight rays' fields, straight from the stream (a short packet's missing lanes take
         * its first ray, masked off) */
        pk8_load(&batch->rays, i, n, v);
        for (l = 0; l < 8; ++l) {
            p.ray[l] = rs_ray_soa_get(&batch->rays, i + (l < n ? l : 0));
            hit[l].prim = RS_NO_HIT;
            hit[l].t = p.ray[l].tmax;
            hit[l].u = hit[l].v = 0.0f;
            p.tmax[l] = p.ray[l].tmax;
        }
        for (a = 0; a < 3; ++a) {
            /* rs_bvh_inv_dir, eight at once (a division rounds as the scalar one); a lane whose
             * 1 / d is not finite or is zero is walked alone */
            p.o[a] = v[a];
            p.d[a] = v[3 + a];
            p.inv[a] = _mm256_div_ps(_mm256_set1_ps(1.0f), v[3 + a]);
            ok = AND(ok, AND(_mm256_cmp_ps(SUB(p.inv[a], p.inv[a]), zero, _CMP_EQ_OQ),
                             _mm256_cmp_ps(p.inv[a], zero, _CMP_NEQ_UQ)));
        }
        p.tmin = v[6];
        active = (uint32_t)_mm256_movemask_ps(ok) & ((1u << n) - 1u);
        if (__builtin_popcount(active) < 2) {
            rs_bvh8_trace(b, g, batch, i, i + n);
            continue;
        }
        /* the signs of the packet's directions, where they agree */
        for (a = 0; a < 3; ++a) {
            uint32_t below = (uint32_t)_mm256_movemask_ps(CMP_LT(p.inv[a], zero)) & active;
            neg[a] = (below != active ? 1u : 0u) | (below ? 2u : 0u);
        }
        p.octant = neg[0] != 3u && neg[1] != 3u && neg[2] != 3u;
        for (a = 0; a < 3; ++a) {
            p.near[a] = a + (neg[a] == 2u ? 3u : 0u);
            p.far[a] = a + (neg[a] == 2u ? 0u : 3u);
        }
        if (batch->kind == RS_TRACE_CLOSEST) {
            pk8_in(&p, hit);
            pk8_closest(b, g, &p, hit, active);
            pk8_out(&p, hit);
            for (l = 0; l < n; ++l) {
                if (active & (1u << l))
                    rs_hit_soa_set(&batch->hits, i + l, &hit[l]);
                else
                    rs_bvh8_trace(b, g, batch, i + l, i + l + 1);
            }
        } else {
            uint32_t blocked = pk8_occluded(b, g, &p, active);
            for (l = 0; l < n; ++l) {
                if (active & (1u << l))
                    batch->occluded[i + l] = (uint8_t)((blocked >> l) & 1u);
                else
                    rs_bvh8_trace(b, g, batch, i + l, i + l + 1);
            }
        }
    }
}

void rs_bvh8_trace(const rs_bvh8 *b, const rs_geom *g, const rs_trace_batch *batch,
                   uint32_t begin, uint32_t end)
{
    uint32_t i, l;
    if (b->n_nodes == 0) {
        for (i = begin; i < end; ++i) {
            rs_hit h;
            rs_ray r = rs_ray_soa_get(&batch->rays, i);
            if (batch->kind == RS_TRACE_CLOSEST) {
                rs_bvh8_closest(b, g, r, &h);
                rs_hit_soa_set(&batch->hits, i, &h);
            } else {
                batch->occluded[i] = 0;
            }
        }
        return;
    }
    for (i = begin; i < end; i += 8) {
        /* rs_bvh8_closest / rs_bvh8_occluded ray by ray, the eight rays' 1 / d made at once (a
         * vector division rounds as the scalar one): three scalar divisions a ray were a
         * tenth of the packet walk's setup */
        uint32_t n = end - i < 8 ? end - i : 8;
        const __m256 one = _mm256_set1_ps(1.0f);
        float iv[3][8];
        _mm256_storeu_ps(iv[0], _mm256_div_ps(one, pk8_field(batch->rays.dx + i, n)));
        _mm256_storeu_ps(iv[1], _mm256_div_ps(one, pk8_field(batch->rays.dy + i, n)));
        _mm256_storeu_ps(iv[2], _mm256_div_ps(one, pk8_field(batch->rays.dz + i, n)));
        for (l = 0; l < n; ++l) {
            rs_ray r = rs_ray_soa_get(&batch->rays, i + l);
            ray8 r8;
            walk8_ray_init_inv(&r8, r.o, r.d, rs_v3(iv[0][l], iv[1][l], iv[2][l]));
            if (batch->kind == RS_TRACE_CLOSEST) {
                rs_hit h;
                h.prim = RS_NO_HIT;
                h.t = r.tmax;
                h.u = h.v = 0.0f;
                walk8_walk_closest(b, g, 0, &r8, &r, &h, NULL);
                rs_hit_soa_set(&batch->hits, i + l, &h);
            } else {
                batch->occluded[i + l] = (uint8_t)walk8_walk_occluded(b, g, 0, &r8, &r, NULL);
            }
        }
    }
}

#  if defined(__clang__)
#    pragma clang attribute pop
#  else
#    pragma GCC pop_options
#  endif

#else /* no AVX2 build: rs_bvh8_supported() is 0 and these are never called */

void rs_bvh8_trace_packets(const rs_bvh8 *b, const rs_geom *g, const rs_trace_batch *batch,
                           uint32_t begin, uint32_t end)
{
    (void)b;
    (void)g;
    (void)batch;
    (void)begin;
    (void)end;
    RS_ASSERT(0);
}

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
