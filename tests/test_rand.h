/* tests/test_rand.h — random test inputs from a fixed seed (test-only helpers).
 * splitmix64 (Steele, Lea & Flood 2014): tiny, well mixed, and independent of the renderer's own
 * generator, so tests of the renderer do not feed it its own numbers. */
#ifndef RS_TESTS_TEST_RAND_H
#define RS_TESTS_TEST_RAND_H

#include <math.h>
#include <stdint.h>

#include "core/geom.h"

static inline uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/* Pearson's statistic of `bins` observed counts that each expect `expected`. */
static inline double chi_square(const double *observed, int bins, double expected)
{
    double c = 0.0;
    int i;
    for (i = 0; i < bins; ++i)
        c += (observed[i] - expected) * (observed[i] - expected) / expected;
    return c;
}

/* uniform double in [0, 1) from the top 53 bits */
static inline double rnd01(uint64_t *s) { return (double)(splitmix64(s) >> 11) * 0x1.0p-53; }

static inline float rnd_range(uint64_t *s, double lo, double hi)
{
    return (float)(lo + (hi - lo) * rnd01(s));
}

/* a point uniform in the cube [-h, h]^3 */
static inline rs_vec3 rnd_box(uint64_t *s, float h)
{
    return rs_v3(rnd_range(s, -h, h), rnd_range(s, -h, h), rnd_range(s, -h, h));
}

/* a uniformly distributed unit vector (z uniform in [-1, 1], phi uniform) */
static inline rs_vec3 rnd_unit(uint64_t *s)
{
    double z = 2.0 * rnd01(s) - 1.0, phi = 6.283185307179586 * rnd01(s);
    double r = sqrt(1.0 - z * z);
    return rs_v3((float)(r * cos(phi)), (float)(r * sin(phi)), (float)z);
}

static inline rs_ray mk_ray(rs_vec3 o, rs_vec3 d, float tmin, float tmax)
{
    rs_ray r;
    r.o = o;
    r.d = d;
    r.tmin = tmin;
    r.tmax = tmax;
    r.time = 0.0f;
    return r;
}

/* Closest hit by testing every primitive: the reference BVH tests compare against. */
static inline int brute_closest(const rs_geom *g, const rs_ray *r, rs_hit *hit)
{
    uint32_t n = rs_geom_prim_count(g), i;
    hit->prim = RS_NO_HIT;
    hit->t = r->tmax;
    hit->u = hit->v = 0.0f;
    for (i = 0; i < n; ++i) {
        float t, u, v;
        if (rs_geom_intersect(g, i, r, &t, &u, &v) && (hit->prim == RS_NO_HIT || t < hit->t)) {
            hit->t = t;
            hit->u = u;
            hit->v = v;
            hit->prim = i;
        }
    }
    return hit->prim != RS_NO_HIT;
}

/* Fills the arrays so that every primitive's bounds are centred exactly on c (spheres c +- r;
 * squares q = c - (u + v) / 2 with power-of-two sizes; triangles with bounds symmetric about c):
 * the identical-centroids case every builder must survive. */
static inline void fill_identical_centroids(rs_sphere *sp, uint32_t ns, rs_quad *qd, uint32_t nq,
                                            rs_tri *tr, uint32_t nt, rs_vec3 c)
{
    uint32_t i;
    for (i = 0; i < ns; ++i) {
        sp[i].center = c;
        sp[i].radius = (float)(i + 1) / 64.0f;
    }
    for (i = 0; i < nq; ++i) {
        float a = (float)(1u << (i % 4));
        rs_vec3 u = (i % 3 == 0) ? rs_v3(a, 0, 0) : rs_v3(0, a, 0);
        rs_vec3 v = (i % 3 == 2) ? rs_v3(a, 0, 0) : rs_v3(0, 0, a);
        qd[i] = rs_quad_make(rs_v3_sub(c, rs_v3_scale(rs_v3_add(u, v), 0.5f)), u, v);
    }
    for (i = 0; i < nt; ++i) {
        float a = 0.5f * (float)(1 + i % 5);
        tr[i].v0 = rs_v3(c.x - a, c.y - a, c.z);
        tr[i].v1 = rs_v3(c.x + a, c.y, c.z - a);
        tr[i].v2 = rs_v3(c.x, c.y + a, c.z + a);
    }
}

#endif
