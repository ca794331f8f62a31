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

typedef struct ray8 {
    __m256 o[3], inv[3];
    size_t near[3], far[3]; /* offsets in floats into rs_bvh8_node.b: each axis's near and far
                               plane's row */
    int general;              /* some 1 / d is not finite: the slab test's min / max form */
    rs_bvh4_ray r4;           /* for the packed leaves */
} ray8;

static void ray8_init(ray8 *r, const rs_ray *ray)
{
    rs_vec3 inv_d = rs_bvh_inv_dir(ray->d);
    float iv[3], ov[3];
    int a;
    iv[0] = inv_d.x;
    iv[1] = inv_d.y;
    iv[2] = inv_d.z;
    ov[0] = ray->o.x;
    ov[1] = ray->o.y;
    ov[2] = ray->o.z;
    r->general = 0;
    for (a = 0; a < 3; ++a) {
        r->o[a] = _mm256_set1_ps(ov[a]);
        r->inv[a] = _mm256_set1_ps(iv[a]);
        r->near[a] = 8u * ((size_t)a + (iv[a] < 0.0f ? 3u : 0u));
        r->far[a] = 8u * ((size_t)a + (iv[a] < 0.0f ? 0u : 3u));
        /* 1 / d finite and nonzero: no 0 * inf, and the planes order as the signs say */
        r->general |= !(iv[a] - iv[a] == 0.0f) || iv[a] == 0.0f;
    }
    /* rs_bvh4_ray_of, without dividing again */
    r->r4.o[0] = _mm_set1_ps(ov[0]);
    r->r4.o[1] = _mm_set1_ps(ov[1]);
    r->r4.o[2] = _mm_set1_ps(ov[2]);
    r->r4.d[0] = _mm_set1_ps(ray->d.x);
    r->r4.d[1] = _mm_set1_ps(ray->d.y);
    r->r4.d[2] = _mm_set1_ps(ray->d.z);
    r->r4.inv[0] = _mm_set1_ps(iv[0]);
    r->r4.inv[1] = _mm_set1_ps(iv[1]);
    r->r4.inv[2] = _mm_set1_ps(iv[2]);
    r->r4.axis_parallel = !(ray->d.x != 0.0f && ray->d.y != 0.0f && ray->d.z != 0.0f);
}

/* The slab test of the eight lanes of `n`: the mask of lanes hit, their entry distances in *tn. */
static inline uint32_t lanes8(const rs_bvh8_node *n, const ray8 *r, float tmin, float tmax,
                              __m256 *tn_out)
{
    const float *b = &n->b[0][0];
    __m256 tn, tf;
    if (!r->general) {
        __m256 nx = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(b + r->near[0]), r->o[0]),
                                  r->inv[0]);
        __m256 ny = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(b + r->near[1]), r->o[1]),
                                  r->inv[1]);
        __m256 nz = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(b + r->near[2]), r->o[2]),
                                  r->inv[2]);
        __m256 fx = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(b + r->far[0]), r->o[0]),
                                  r->inv[0]);
        __m256 fy = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(b + r->far[1]), r->o[1]),
                                  r->inv[1]);
        __m256 fz = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(b + r->far[2]), r->o[2]),
                                  r->inv[2]);
        tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, _mm256_set1_ps(tmin)));
        tf = _mm256_min_ps(_mm256_min_ps(fx, fy), _mm256_min_ps(fz, _mm256_set1_ps(tmax)));
    } else {
        int a;
        tn = _mm256_set1_ps(tmin);
        tf = _mm256_set1_ps(tmax);
        for (a = 0; a < 3; ++a) {
            __m256 t0 = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n->b[a]), r->o[a]), r->inv[a]);
            __m256 t1 =
                _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(n->b[a + 3]), r->o[a]), r->inv[a]);
            /* rs_slab: a slab whose distances are NaN (0 * inf) is skipped */
            __m256 ok = _mm256_cmp_ps(t0, t1, _CMP_ORD_Q);
            tn = _mm256_blendv_ps(tn, _mm256_max_ps(_mm256_min_ps(t0, t1), tn), ok);
            tf = _mm256_blendv_ps(tf, _mm256_min_ps(_mm256_max_ps(t0, t1), tf), ok);
        }
    }
    *tn_out = tn;
    tf = _mm256_mul_ps(tf, _mm256_set1_ps(RS_BVH_SLACK));
    return (uint32_t)_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ)) &
           ((1u << n->n_lanes) - 1u);
}

static inline uint32_t ref8(const rs_bvh8_node *n, uint32_t node, uint32_t lane)
{
    return n->count[lane] ? RS_BVH8_LEAF | node << 3 | lane : n->child[lane];
}

static inline uint32_t lowest(uint32_t m) { return (uint32_t)__builtin_ctz(m); }

int rs_bvh8_closest(const rs_bvh8 *b, const rs_geom *g, rs_ray ray, rs_hit *hit)
{
    uint32_t stack[RS_BVH8_STACK];
    float stack_t[RS_BVH8_STACK];
    uint32_t sp = 0, ref = 0;
    ray8 r;
    hit->prim = RS_NO_HIT;
    hit->t = ray.tmax;
    hit->u = hit->v = 0.0f;
    if (b->n_nodes == 0)
        return 0;
    ray8_init(&r, &ray);
    for (;;) {
        if (!(ref & RS_BVH8_LEAF)) {
            const rs_bvh8_node *n = &b->nodes[ref];
            __m256 tnv;
            uint32_t mask = lanes8(n, &r, ray.tmin, ray.tmax, &tnv);
            if (mask != 0) {
                float tn[8];
                uint32_t first = lowest(mask), second;
                mask &= mask - 1;
                if (mask == 0) {
                    ref = ref8(n, ref, first);
                    continue;
                }
                _mm256_storeu_ps(tn, tnv);
                second = lowest(mask);
                mask &= mask - 1;
                if (mask == 0) {
                    /* two lanes: the nearer next, the other pushed */
                    if (tn[second] < tn[first]) {
                        uint32_t s = first;
                        first = second;
                        second = s;
                    }
                    RS_ASSERT(sp < RS_BVH8_STACK);
                    stack[sp] = ref8(n, ref, second);
                    stack_t[sp++] = tn[second];
                    ref = ref8(n, ref, first);
                    continue;
                } else {
                    /* three to eight: insertion sort by entry distance, pushed far to near */
                    uint32_t lanes[8], k = 2, i, j;
                    if (tn[second] < tn[first]) {
                        lanes[0] = second;
                        lanes[1] = first;
                    } else {
                        lanes[0] = first;
                        lanes[1] = second;
                    }
                    while (mask) {
                        uint32_t l = lowest(mask);
                        mask &= mask - 1;
                        for (j = k; j > 0 && tn[lanes[j - 1]] > tn[l]; --j)
                            lanes[j] = lanes[j - 1];
                        lanes[j] = l;
                        ++k;
                    }
                    for (i = k - 1; i > 0; --i) {
                        RS_ASSERT(sp < RS_BVH8_STACK);
                        stack[sp] = ref8(n, ref, lanes[i]);
                        stack_t[sp++] = tn[lanes[i]];
                    }
                    ref = ref8(n, ref, lanes[0]);
                    continue;
                }
            }
        } else {
            const rs_bvh8_node *n = &b->nodes[(ref & ~RS_BVH8_LEAF) >> 3];
            uint32_t lane = ref & 7u, first = n->child[lane], count = n->count[lane], i;
            if (count & RS_BVH4_PACKED) {
                rs_bvh4_packed_closest(b->tri4, b->quad4, first, count, &r.r4, &ray, hit);
                count = 0;
            }
            for (i = 0; i < count; ++i)
                rs_bvh_leaf_closest(g, b->prim_ids[first + i], &ray, hit);
        }
        /* pop the next entry that can still hold a hit no farther than the best so far */
        for (;;) {
            if (sp == 0)
                return hit->prim != RS_NO_HIT;
            --sp;
            if (stack_t[sp] <= ray.tmax * RS_BVH_SLACK)
                break;
        }
        ref = stack[sp];
    }
}

int rs_bvh8_occluded(const rs_bvh8 *b, const rs_geom *g, rs_ray ray)
{
    uint32_t stack[RS_BVH8_STACK];
    uint32_t sp = 0;
    ray8 r;
    if (b->n_nodes == 0)
        return 0;
    ray8_init(&r, &ray);
    stack[sp++] = 0;
    while (sp > 0) {
        uint32_t ref = stack[--sp];
        if (!(ref & RS_BVH8_LEAF)) {
            const rs_bvh8_node *n = &b->nodes[ref];
            __m256 tnv;
            uint32_t mask = lanes8(n, &r, ray.tmin, ray.tmax, &tnv);
            while (mask) {
                uint32_t l = lowest(mask);
                mask &= mask - 1;
                RS_ASSERT(sp < RS_BVH8_STACK);
                stack[sp++] = ref8(n, ref, l);
            }
        } else {
            const rs_bvh8_node *n = &b->nodes[(ref & ~RS_BVH8_LEAF) >> 3];
            uint32_t lane = ref & 7u, first = n->child[lane], count = n->count[lane], i;
            if (count & RS_BVH4_PACKED) {
                if (rs_bvh4_packed_occluded(b->tri4, b->quad4, first, count, &r.r4, &ray))
                    return 1;
                continue;
            }
            for (i = 0; i < count; ++i) {
                float t, u, v;
                if (rs_geom_intersect(g, b->prim_ids[first + i], &ray, &t, &u, &v))
                    return 1;
            }
        }
    }
    return 0;
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
