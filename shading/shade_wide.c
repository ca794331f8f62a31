/* shading/shade_wide.c — see shade_wide.h.
 *
 * Each function below restates one RS_HD function of the scalar shading on eight lanes (GCC's
 * vector extensions, compiled for AVX2 alone, so the build runs on any x86-64 and picks this at
 * run time); the comment names it.  Operations are written in the scalar code's order with its
 * operands (a * b + c as (a * b) + c, left to right; the build never contracts to FMA), min and
 * max with the host's rs_fminf / rs_fmaxf NaN rules, selects for the scalar code's branches.
 * Lanes past the entries are copies of the first and are never stored.  The stream, path and
 * scene arrays come into lanes by vector loads, gathers and transposed rows (shade8), and the
 * results go back by vector stores where eight entries make eight rays, else lane by lane. */
#include "shading/shade_wide.h"

#include <float.h>
#include <stddef.h>
#include <stdatomic.h>

static atomic_int wide_off;         /* forced off (rs_shade_wide_use(0)) */
static _Atomic uint64_t wide_count; /* entries shaded here (rs_shade_wide_count) */

/* The most lights the per-render check walks (beyond it the scalar code shades). */
#define WIDE_MAX_LIGHTS 256u

#if defined(__x86_64__) && defined(__GNUC__)
#  define RS_WIDE_HAVE_AVX2 1
#  include <immintrin.h>
#else
#  define RS_WIDE_HAVE_AVX2 0
#endif

static int cpu_ok(void)
{
#if RS_WIDE_HAVE_AVX2
    return __builtin_cpu_supports("avx2");
#else
    return 0;
#endif
}

int rs_shade_wide_use(int on)
{
    atomic_store(&wide_off, !on);
    return on && cpu_ok();
}

uint64_t rs_shade_wide_count(void)
{
    return atomic_load_explicit(&wide_count, memory_order_relaxed);
}

int rs_shade_wide_ready(const rs_render_consts *it, uint32_t bounce)
{
    const rs_scene *sc = it->scene;
    uint32_t l;
    if (atomic_load_explicit(&wide_off, memory_order_relaxed) || !cpu_ok())
        return 0;
    if (bounce + 1 >= it->max_depth || it->sampling != RS_SAMPLING_MIS ||
        it->light_sampler == RS_LIGHT_SAMPLER_BVH)
        return 0;
    /* no punctual or directional lights, a sky only if uniform */
    if (sc->n_lights != sc->n_area_lights || sc->n_lights > WIDE_MAX_LIGHTS ||
        (sc->env_pick > 0.0f && !sc->env_uniform))
        return 0;
    for (l = 0; l < sc->n_lights; ++l) {
        uint32_t prim = sc->lights[l].prim;
        if ((prim & RS_LIGHT_PUNCTUAL) || prim < sc->n_spheres ||
            prim - sc->n_spheres >= sc->n_quads + sc->n_tris ||
            rs_scene_prim_material(sc, prim)->type != RS_MAT_DIFFUSE_LIGHT)
            return 0;
    }
    return 1;
}

#if RS_WIDE_HAVE_AVX2

typedef float f8 __attribute__((vector_size(32)));
typedef uint32_t u8 __attribute__((vector_size(32)));
typedef int32_t i8 __attribute__((vector_size(32)));

typedef struct v3 {
    f8 x, y, z;
} v3;

/* every function below is compiled for AVX2 (an attribute each: GCC and Clang both take it) */
#  define WIDE static inline __attribute__((always_inline, target("avx2")))

WIDE f8 splat(float s) { return (f8){s, s, s, s, s, s, s, s}; }
WIDE u8 usplat(uint32_t s) { return (u8){s, s, s, s, s, s, s, s}; }
WIDE f8 load8(const float *p) { return (f8)_mm256_loadu_ps(p); }
WIDE void store8(float *p, f8 a) { _mm256_storeu_ps(p, (__m256)a); }

/* masks are lanes of all ones (comparisons give them as signed integers) */
WIDE f8 sel(u8 m, f8 a, f8 b) { return (f8)((m & (u8)a) | (~m & (u8)b)); }
WIDE v3 sel3(u8 m, v3 a, v3 b)
{
    v3 r = {sel(m, a.x, b.x), sel(m, a.y, b.y), sel(m, a.z, b.z)};
    return r;
}
WIDE f8 vsqrt(f8 a) { return (f8)_mm256_sqrt_ps((__m256)a); }
WIDE f8 vabs(f8 a) { return (f8)((u8)a & usplat(0x7fffffffu)); }
/* rs_fmaxf, rs_fminf (host) */
WIDE f8 vmax(f8 a, f8 b) { return sel((u8)(a > b), a, sel((u8)(b != b), a, b)); }
WIDE f8 vmin(f8 a, f8 b) { return sel((u8)(a < b), a, sel((u8)(b != b), a, b)); }

/* core/vec3.h */
WIDE v3 add3(v3 a, v3 b)
{
    v3 r = {a.x + b.x, a.y + b.y, a.z + b.z};
    return r;
}
WIDE v3 sub3(v3 a, v3 b)
{
    v3 r = {a.x - b.x, a.y - b.y, a.z - b.z};
    return r;
}
WIDE v3 mul3(v3 a, v3 b)
{
    v3 r = {a.x * b.x, a.y * b.y, a.z * b.z};
    return r;
}
WIDE v3 scale3(v3 a, f8 s)
{
    v3 r = {a.x * s, a.y * s, a.z * s};
    return r;
}
WIDE v3 neg3(v3 a)
{
    v3 r = {-a.x, -a.y, -a.z};
    return r;
}
WIDE v3 abs3(v3 a)
{
    v3 r = {vabs(a.x), vabs(a.y), vabs(a.z)};
    return r;
}
WIDE v3 madd3(v3 a, v3 b, f8 s) /* rs_v3_madd: a + b s */
{
    v3 r = {a.x + b.x * s, a.y + b.y * s, a.z + b.z * s};
    return r;
}
WIDE v3 cross3(v3 a, v3 b)
{
    v3 r = {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
    return r;
}
WIDE f8 dot3(v3 a, v3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
WIDE f8 len3(v3 a) { return vsqrt(dot3(a, a)); }
WIDE f8 norm1(v3 a) { return vabs(a.x) + vabs(a.y) + vabs(a.z); }
WIDE f8 maxc3(v3 a) { return vmax(a.x, vmax(a.y, a.z)); }
WIDE u8 zero3(v3 a) { return (u8)(a.x == 0.0f) & (u8)(a.y == 0.0f) & (u8)(a.z == 0.0f); }
WIDE v3 splat3(rs_vec3 a)
{
    v3 r = {splat(a.x), splat(a.y), splat(a.z)};
    return r;
}

/* core/hdmath.h: rs_sincosf for |x| < 16 (Cody and Waite's reduction); *big marks lanes beyond,
 * which the caller takes from the scalar function */
WIDE void vsincos(f8 x, f8 *s, f8 *c, u8 *big)
{
    u8 u = (u8)x, sign = u & usplat(0x80000000u), ps, pc, odd, q;
    f8 ax = (f8)(u ^ sign), k, a, k1, k2, b, r, lo, z, hz, w, sp, cp;
    i8 ki;
    *big = ~(u8)(ax < 16.0f);
    ki = __builtin_convertvector(ax * 0.636619772f + 0.5f, i8);
    k = __builtin_convertvector(ki, f8);
    a = ax - k * RS_HDM_PIO2_0;
    k1 = k * RS_HDM_PIO2_1;
    k2 = k * RS_HDM_PIO2_2;
    b = a - k1;
    r = b - k2;
    lo = ((a - b) - k1) + ((b - r) - k2);
    q = (u8)ki & usplat(3u);
    /* rs_hdm_sin_poly, rs_hdm_cos_poly */
    z = r * r;
    sp = r +
         ((r * z) * (RS_HDM_SIN0 + z * (RS_HDM_SIN1 + z * RS_HDM_SIN2)) + lo * (1.0f - 0.5f * z));
    hz = 0.5f * z;
    w = 1.0f - hz;
    cp = w + ((((1.0f - w) - hz) - r * lo) +
              (z * z) * (RS_HDM_COS0 + z * (RS_HDM_COS1 + z * RS_HDM_COS2)));
    ps = (u8)sp;
    pc = (u8)cp;
    odd = usplat(0u) - (q & usplat(1u));
    *s = (f8)(((ps & ~odd) | (pc & odd)) ^ ((q & usplat(2u)) << 30) ^ sign);
    *c = (f8)(((pc & ~odd) | (ps & odd)) ^ (((q + usplat(1u)) & usplat(2u)) << 30));
}

/* core/sampling.h: rs_sample_cosine_hemisphere */
WIDE v3 cosine_hemisphere(f8 u1, f8 u2)
{
    f8 r = vsqrt(u1), s, c, arg = (2.0f * RS_PI) * u2;
    u8 big;
    v3 out;
    vsincos(arg, &s, &c, &big);
    if (_mm256_movemask_ps((__m256)big)) { /* never for u2 in [0, 1): the scalar function */
        float a[8], sa[8], ca[8];
        int i;
        store8(a, arg);
        store8(sa, s);
        store8(ca, c);
        for (i = 0; i < 8; ++i)
            if (!(a[i] < 16.0f && a[i] > -16.0f))
                rs_sincosf(a[i], &sa[i], &ca[i]);
        s = load8(sa);
        c = load8(ca);
    }
    out.x = r * c;
    out.y = r * s;
    out.z = vsqrt(vmax(splat(0.0f), 1.0f - u1));
    return out;
}

/* core/sampling.h: rs_onb_from_normal, then rs_onb_to_world of l */
WIDE v3 onb_to_world(v3 n, v3 l)
{
    f8 sign = (f8)(((u8)n.z & usplat(0x80000000u)) | usplat(0x3f800000u)); /* copysignf(1, z) */
    f8 a = -1.0f / (sign + n.z), b = n.x * n.y * a;
    v3 t = {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    v3 bb = {b, sign + n.y * n.y * a, -n.y};
    return add3(add3(scale3(t, l.x), scale3(bb, l.y)), scale3(n, l.z));
}

/* shading/spawn.h: rs_spawn_origin */
WIDE v3 spawn_origin(v3 p, v3 err, v3 n)
{
    f8 d = dot3(abs3(n), add3(err, scale3(abs3(p), splat(2.0f * RS_GAMMA(1)))));
    return madd3(p, n, d);
}

/* shading/spawn.h: rs_quad_point (quad lanes: o = q, a = u, b = v, w = w) and rs_tri_point
 * (o = v0, a = e1, b = e2, w = e1 x e2) at (s, t) */
WIDE void surface_point(u8 quad, v3 o, v3 ea, v3 eb, v3 w, f8 s, f8 t, v3 *p, v3 *err, v3 *ng)
{
    v3 ta = scale3(ea, s), tb = scale3(eb, t);
    f8 len = len3(w), l1 = norm1(ea), l2 = norm1(eb);
    f8 slim_q = vmin(l1 * l2 * len, splat(1024.0f));
    f8 slim_t = sel((u8)(len > 0.0f), vmin(l1 * l2 / len, splat(1024.0f)), splat(1024.0f));
    f8 slim = sel(quad, slim_q, slim_t);
    f8 g = sel(quad, splat(RS_GAMMA(3)), splat(RS_GAMMA(4)));
    f8 e = RS_GAMMA(12) * (l1 + l2) * slim;
    v3 sum = add3(abs3(o), add3(abs3(ta), abs3(tb)));
    *p = add3(o, add3(ta, tb));
    *ng = scale3(w, 1.0f / len);
    err->x = sum.x * g + e;
    err->y = sum.y * g + e;
    err->z = sum.z * g + e;
}

/* shading/path.h: rs_power_heuristic */
WIDE f8 power_heuristic(f8 a, f8 b)
{
    f8 a2 = a * a, b2 = b * b;
    return sel((u8)(a2 + b2 > 0.0f), a2 / (a2 + b2), splat(0.0f));
}

/* shading/bsdf.h for a Lambertian surface: rs_bsdf_pdf_side (== rs_bsdf_pdf) and
 * rs_bsdf_eval_side's mask (f = albedo / pi where it is set) */
WIDE f8 lambert_pdf(f8 ci, f8 co)
{
    u8 ok = (u8)(ci > 0.0f) & (u8)(co > 0.0f);
    return sel(ok, sel((u8)(ci > 0.0f), ci * RS_INV_PI, splat(0.0f)), splat(0.0f));
}

/* One primitive per lane, as surface_point takes it. */
typedef struct lane_prims {
    float o[3][8], a[3][8], b[3][8], w[3][8];
    uint32_t quad[8];
} lane_prims;

WIDE void gather_prim(const rs_scene *sc, uint32_t prim, lane_prims *lp, int i)
{
    uint32_t p = prim - sc->n_spheres, c;
    rs_vec3 o, a, b, w;
    if (p < sc->n_quads) {
        const rs_quad *q = &sc->quads[p];
        o = q->q;
        a = q->u;
        b = q->v;
        w = q->w;
        lp->quad[i] = 0xffffffffu;
    } else {
        const rs_tri *t = &sc->tris[p - sc->n_quads];
        o = t->v0;
        a = rs_v3_sub(t->v1, t->v0);
        b = rs_v3_sub(t->v2, t->v0);
        w = rs_v3(0.0f, 0.0f, 0.0f); /* e1 x e2, made in the lanes */
        lp->quad[i] = 0u;
    }
    for (c = 0; c < 3; ++c) {
        lp->o[c][i] = c == 0 ? o.x : c == 1 ? o.y : o.z;
        lp->a[c][i] = c == 0 ? a.x : c == 1 ? a.y : a.z;
        lp->b[c][i] = c == 0 ? b.x : c == 1 ? b.y : b.z;
        lp->w[c][i] = c == 0 ? w.x : c == 1 ? w.y : w.z;
    }
}

WIDE v3 lane3(const float (*f)[8])
{
    v3 r = {load8(f[0]), load8(f[1]), load8(f[2])};
    return r;
}

WIDE void store3(float (*f)[8], v3 a)
{
    store8(f[0], a.x);
    store8(f[1], a.y);
    store8(f[2], a.z);
}

WIDE void prim_point(const lane_prims *lp, f8 s, f8 t, v3 *p, v3 *err, v3 *ng)
{
    u8 quad = (u8)_mm256_loadu_si256((const __m256i *)lp->quad);
    v3 o = lane3(lp->o), a = lane3(lp->a), b = lane3(lp->b);
    v3 w = sel3(quad, lane3(lp->w), cross3(a, b));
    surface_point(quad, o, a, b, w, s, t, p, err, ng);
}

/* Gathers (AVX2): lane i of the result is f[idx[i]]. */
WIDE f8 gatherf(const float *f, i8 idx) { return (f8)_mm256_i32gather_ps(f, (__m256i)idx, 4); }
WIDE u8 gatheru(const uint32_t *f, i8 idx)
{
    return (u8)_mm256_i32gather_epi32((const int *)(const void *)f, (__m256i)idx, 4);
}
/* Vectors stored `stride` floats apart, number idx[i] in lane i. */
WIDE v3 gather3(const float *base, i8 idx, int32_t stride)
{
    i8 k = idx * stride;
    v3 r = {gatherf(base, k), gatherf(base + 1, k), gatherf(base + 2, k)};
    return r;
}
/* A stream field at the lanes' entries j: one load where they are eight in a row (run). */
WIDE f8 field8(const float *f, i8 j, int run) { return run ? load8(f + j[0]) : gatherf(f, j); }
WIDE u8 ufield8(const uint32_t *f, i8 j, int run)
{
    return run ? (u8)_mm256_loadu_si256((const __m256i *)(const void *)(f + j[0])) : gatheru(f, j);
}

/* Four floats of each of eight lanes, p[i][0..3] in lane i: eight 16-byte loads, one 4x8
 * transpose (out[c] lane i = p[i][c]). */
WIDE void load8x4(const float *const p[8], f8 out[4])
{
    __m256 r0 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p[0])), _mm_loadu_ps(p[4]), 1);
    __m256 r1 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p[1])), _mm_loadu_ps(p[5]), 1);
    __m256 r2 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p[2])), _mm_loadu_ps(p[6]), 1);
    __m256 r3 = _mm256_insertf128_ps(_mm256_castps128_ps256(_mm_loadu_ps(p[3])), _mm_loadu_ps(p[7]), 1);
    __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpacklo_ps(r2, r3);
    __m256 t2 = _mm256_unpackhi_ps(r0, r1), t3 = _mm256_unpackhi_ps(r2, r3);
    out[0] = (f8)_mm256_shuffle_ps(t0, t1, 0x44);
    out[1] = (f8)_mm256_shuffle_ps(t0, t1, 0xee);
    out[2] = (f8)_mm256_shuffle_ps(t2, t3, 0x44);
    out[3] = (f8)_mm256_shuffle_ps(t2, t3, 0xee);
}

/* Floats `off` .. off + 3 of records `stride` floats long, record idx[i] in lane i. */
WIDE void rec8x4(const float *base, i8 idx, uint32_t stride, uint32_t off, f8 out[4])
{
    const float *p[8];
    int i;
    for (i = 0; i < 8; ++i)
        p[i] = base + (size_t)(uint32_t)idx[i] * stride + off;
    load8x4(p, out);
}

/* Nine floats of records `stride` >= 9 floats long (triangles: three corners; vertex normals),
 * record idx[i] in lane i, as three vectors: floats 0..3, 4..7 and 5..8 loaded, none past the
 * ninth. */
WIDE void rec8x9(const float *base, i8 idx, uint32_t stride, v3 *a, v3 *b, v3 *c)
{
    f8 x[4], y[4], z[4];
    rec8x4(base, idx, stride, 0, x);
    rec8x4(base, idx, stride, 4, y);
    rec8x4(base, idx, stride, 5, z);
    a->x = x[0], a->y = x[1], a->z = x[2];
    b->x = x[3], b->y = y[0], b->z = y[1];
    c->x = y[2], c->y = y[3], c->z = z[3];
}

/* A rs_vec3 (and the float after it, which is read too) of records `stride` floats long. */
WIDE v3 rec8v3(const float *base, i8 idx, uint32_t stride)
{
    f8 x[4];
    v3 r;
    rec8x4(base, idx, stride, 0, x);
    r.x = x[0], r.y = x[1], r.z = x[2];
    return r;
}

WIDE int all8(u8 m) { return _mm256_movemask_ps((__m256)m) == 0xff; }

/* The rays of lanes `ok` among the first `count` (origin o, direction d, tmin 0) into stream s
 * from *at on, in lane order: eight vector stores where all eight make one.  The lanes written,
 * as bits. */
WIDE uint32_t put_rays(rs_ray_soa *s, uint32_t *at, u8 ok, uint32_t count, v3 o, v3 d, f8 tmax,
                       f8 time, u8 path)
{
    uint32_t m = (uint32_t)_mm256_movemask_ps((__m256)ok) & ((1u << count) - 1u), k = *at, i;
    if (m == 0xffu) {
        store8(s->ox + k, o.x);
        store8(s->oy + k, o.y);
        store8(s->oz + k, o.z);
        store8(s->dx + k, d.x);
        store8(s->dy + k, d.y);
        store8(s->dz + k, d.z);
        store8(s->tmin + k, splat(0.0f));
        store8(s->tmax + k, tmax);
        store8(s->time + k, time);
        _mm256_storeu_si256((__m256i *)(void *)(s->path + k), (__m256i)path);
        *at = k + 8;
    } else if (m) {
        float o_[3][8], d_[3][8], tmax_[8], time_[8];
        uint32_t path_[8];
        store3(o_, o);
        store3(d_, d);
        store8(tmax_, tmax);
        store8(time_, time);
        _mm256_storeu_si256((__m256i *)(void *)path_, (__m256i)path);
        for (i = 0; i < count; ++i) {
            rs_ray r;
            if (!(m >> i & 1u))
                continue;
            r.o = rs_v3(o_[0][i], o_[1][i], o_[2][i]);
            r.d = rs_v3(d_[0][i], d_[1][i], d_[2][i]);
            r.tmin = 0.0f;
            r.tmax = tmax_[i];
            r.time = time_[i];
            rs_ray_soa_set(s, (*at)++, &r, path_[i]);
        }
    }
    return m;
}
WIDE int any8(u8 m) { return _mm256_movemask_ps((__m256)m) != 0; }

/* Up to eight entries: rs_path_shade_at's path through a Lambertian vertex.  The lanes' stream
 * fields come in by vector loads where the entries are eight in a row, by gathers elsewhere; the
 * scene's triangles or parallelograms (where the lanes' are all of one kind: one loop over the
 * lanes for a mix), their albedos and the random numbers as rows of four floats turned into lanes
 * (load8x4); the rays go out by vector stores where all eight make one.  No lane is written to a
 * small array and read back as a vector: such a load waits for the eight stores to leave the
 * store buffer (perf put two thirds of this function's time there). */
__attribute__((target("avx2"))) static void
shade8(const rs_render_consts *it, uint32_t bounce, const rs_ray_soa *rays, const rs_hit_soa *hits,
       const uint32_t *entry, uint32_t count, const rs_rng_f4 *rb, const rs_rng_f4 *rl,
       uint32_t rng_base, rs_paths *paths, rs_ray_soa *next, uint32_t *on, rs_ray_soa *shadow,
       uint32_t *os)
{
    const rs_scene *sc = it->scene;
    const int nee = rs_scene_has_lights(sc);
    const float env_pick = sc->env_pick;
    const uint32_t mat_stride = (uint32_t)(sizeof(rs_material) / sizeof(float));
    lane_prims hp, lp;
    uint32_t env_[8], lok_[8], path_[8], k_[8], light_[8];
    float pend_[3][8], beta_[3][8], pdf_[8], envpdf_[8];
    uint32_t i, c, m;
    int run, one_light;
    f8 rbv[4], rlv[4], hu, hv, timev, pickv, areav, sh_tmax;
    u8 pathv, primv, quadv, lquad, twov, sh_okv, nx_okv;
    i8 jv, pv;
    v3 d, wo, x, err, ng, n_geo, n, origin, thr, alb, beta, po, pa, pb, pw, lo, la, lb, lw, emiv;
    v3 sh_dv, pendv, nx_d;
    u8 front;
    /* records read four floats at a time: a material's albedo and the float after it */
    typedef char material_floats[sizeof(rs_material) % sizeof(float) == 0 &&
                                         offsetof(rs_material, albedo) + 16 <= sizeof(rs_material)
                                     ? 1
                                     : -1];
    typedef char quad_floats[sizeof(rs_quad) == 12 * sizeof(float) ? 1 : -1];
    typedef char tri_floats[sizeof(rs_tri) == 9 * sizeof(float) ? 1 : -1];
    (void)sizeof(material_floats), (void)sizeof(quad_floats), (void)sizeof(tri_floats);

    /* ---- gather ---- */
    for (i = 0; i < 8; ++i) {
        uint32_t j = entry[i < count ? i : 0];
        jv[i] = (int32_t)j;
        k_[i] = j - rng_base;
    }
    /* eight in a row: entry[i] = entry[0] + i */
    run = count == 8 && all8((u8)(jv == (i8){0, 1, 2, 3, 4, 5, 6, 7} + (int32_t)entry[0]));
    d.x = field8(rays->dx, jv, run);
    d.y = field8(rays->dy, jv, run);
    d.z = field8(rays->dz, jv, run);
    timev = field8(rays->time, jv, run);
    hu = field8(hits->u, jv, run);
    hv = field8(hits->v, jv, run);
    pathv = ufield8(rays->path, jv, run);
    primv = ufield8(hits->prim, jv, run);
    rec8x4(rb[0].v, (i8)_mm256_loadu_si256((const __m256i *)k_), 4, 0, rbv);
    rec8x4(rl[0].v, (i8)_mm256_loadu_si256((const __m256i *)k_), 4, 0, rlv);
    _mm256_storeu_si256((__m256i *)path_, (__m256i)pathv);
    thr = gather3(&paths->throughput[0].x, (i8)pathv, 3);
    pv = (i8)(primv - usplat(sc->n_spheres)); /* wide entries: never a sphere */
    quadv = (u8)(pv < (i8)usplat(sc->n_quads));
    if (!any8(quadv)) {
        /* all triangles: corners, material numbers and vertex normals gathered */
        i8 t = pv - (i8)usplat(sc->n_quads);
        v3 v1, v2;
        rec8x9(&sc->tris[0].v0.x, t, 9, &po, &v1, &v2);
        pa = sub3(v1, po);
        pb = sub3(v2, po);
        pw = cross3(pa, pb);
        alb = rec8v3(&sc->materials[0].albedo.x, (i8)gatheru(sc->tri_mat, t), mat_stride);
        if (sc->tri_normal) {
            /* rs_shading_normal: a triangle of the scene's own with vertex normals */
            v3 n0, n1, n2;
            rec8x9(sc->tri_normal, t, 9, &n0, &n1, &n2);
            {
                v3 ns = add3(add3(scale3(n0, 1.0f - hu - hv), scale3(n1, hu)), scale3(n2, hv));
                f8 len = len3(ns);
                u8 ok = (u8)(len > 1e-6f);
                surface_point(usplat(0u), po, pa, pb, pw, hu, hv, &x, &err, &ng);
                front = (u8)(dot3(ng, d) < 0.0f);
                n_geo = sel3(front, ng, neg3(ng));
                wo = neg3(d);
                ns = scale3(ns, 1.0f / len);
                ns = sel3((u8)(dot3(ns, n_geo) < 0.0f), neg3(ns), ns);
                n = sel3(ok & (u8)(dot3(ns, wo) > 0.0f), ns, n_geo);
            }
        } else {
            surface_point(usplat(0u), po, pa, pb, pw, hu, hv, &x, &err, &ng);
            front = (u8)(dot3(ng, d) < 0.0f);
            n_geo = sel3(front, ng, neg3(ng));
            wo = neg3(d);
            n = n_geo;
        }
    } else if (all8(quadv)) {
        /* all parallelograms: no vertex normals */
        const float *qf = &sc->quads[0].q.x;
        f8 q0[4], q1[4], q2[4];
        rec8x4(qf, pv, 12, 0, q0);
        rec8x4(qf, pv, 12, 4, q1);
        rec8x4(qf, pv, 12, 8, q2);
        po.x = q0[0], po.y = q0[1], po.z = q0[2];
        pa.x = q0[3], pa.y = q1[0], pa.z = q1[1];
        pb.x = q1[2], pb.y = q1[3], pb.z = q2[0];
        pw.x = q2[1], pw.y = q2[2], pw.z = q2[3];
        alb = rec8v3(&sc->materials[0].albedo.x, (i8)gatheru(sc->quad_mat, pv), mat_stride);
        surface_point(quadv, po, pa, pb, pw, hu, hv, &x, &err, &ng);
        front = (u8)(dot3(ng, d) < 0.0f);
        n_geo = sel3(front, ng, neg3(ng));
        wo = neg3(d);
        n = n_geo;
    } else {
        /* a mix: one lane at a time */
        float alb_[3][8], vn_[9][8];
        uint32_t vn_on[8], any_vn = 0;
        for (i = 0; i < 8; ++i) {
            uint32_t prim = primv[i], t;
            const rs_material *m = rs_scene_prim_material(sc, prim);
            alb_[0][i] = m->albedo.x;
            alb_[1][i] = m->albedo.y;
            alb_[2][i] = m->albedo.z;
            gather_prim(sc, prim, &hp, (int)i);
            /* rs_shading_normal: a triangle of the scene's own with vertex normals */
            t = prim - sc->n_spheres - sc->n_quads;
            vn_on[i] = 0u;
            for (c = 0; c < 9; ++c)
                vn_[c][i] = 0.0f;
            if (prim >= sc->n_spheres + sc->n_quads && sc->tri_normal) {
                vn_on[i] = 0xffffffffu;
                any_vn = 1;
                for (c = 0; c < 9; ++c)
                    vn_[c][i] = sc->tri_normal[9 * (size_t)t + c];
            }
        }
        alb = lane3(alb_);
        prim_point(&hp, hu, hv, &x, &err, &ng);
        front = (u8)(dot3(ng, d) < 0.0f);
        n_geo = sel3(front, ng, neg3(ng));
        wo = neg3(d);
        n = n_geo;
        if (any_vn) {
            /* rs_shading_normal */
            v3 n0 = {load8(vn_[0]), load8(vn_[1]), load8(vn_[2])};
            v3 n1 = {load8(vn_[3]), load8(vn_[4]), load8(vn_[5])};
            v3 n2 = {load8(vn_[6]), load8(vn_[7]), load8(vn_[8])};
            v3 ns = add3(add3(scale3(n0, 1.0f - hu - hv), scale3(n1, hu)), scale3(n2, hv));
            f8 len = len3(ns);
            u8 ok = (u8)_mm256_loadu_si256((const __m256i *)vn_on) & (u8)(len > 1e-6f);
            ns = scale3(ns, 1.0f / len);
            ns = sel3((u8)(dot3(ns, n_geo) < 0.0f), neg3(ns), ns);
            n = sel3(ok & (u8)(dot3(ns, wo) > 0.0f), ns, n_geo);
        }
    }
    origin = spawn_origin(x, err, n_geo);
    beta = thr;

    /* ---- next-event estimation: rs_shade_next_event, rs_light_sample_from ---- */
    one_light = 1; /* every lane that samples a light samples the same one (light_[0] after) */
    light_[0] = RS_NO_HIT;
    for (i = 0; i < 8; ++i) {
        float u = rlv[0][i];
        env_[i] = 0u;
        lok_[i] = nee ? 0xffffffffu : 0u;
        light_[i] = RS_NO_HIT;
        if (nee && env_pick > 0.0f) {
            if (u < env_pick)
                env_[i] = 0xffffffffu;
            else
                u = (u - env_pick) / (1.0f - env_pick);
        }
        if (nee && !env_[i] && sc->n_lights == 0)
            lok_[i] = 0u;
        if (lok_[i] && !env_[i]) {
            light_[i] = sc->n_lights == 1 ? 0u : rs_light_pick_n(sc, u, sc->n_lights);
            if (light_[0] == RS_NO_HIT)
                light_[0] = light_[i];
            one_light &= light_[i] == light_[0];
        }
    }
    /* The lights' data, lanes without one (the sky, or no light) given any primitive: nothing
     * of theirs is kept.  One light for all: its data once, splat into every lane. */
    if (one_light) {
        uint32_t prim = light_[0] != RS_NO_HIT ? sc->lights[light_[0]].prim : primv[0];
        const rs_material *lm = rs_scene_prim_material(sc, prim);
        gather_prim(sc, prim, &lp, 0);
        lquad = usplat(lp.quad[0]);
        lo = splat3(rs_v3(lp.o[0][0], lp.o[1][0], lp.o[2][0]));
        la = splat3(rs_v3(lp.a[0][0], lp.a[1][0], lp.a[2][0]));
        lb = splat3(rs_v3(lp.b[0][0], lp.b[1][0], lp.b[2][0]));
        lw = splat3(rs_v3(lp.w[0][0], lp.w[1][0], lp.w[2][0]));
        if (light_[0] != RS_NO_HIT) {
            pickv = splat(sc->lights[light_[0]].pick_pdf);
            areav = splat(sc->lights[light_[0]].area);
            twov = usplat((lm->flags & RS_MAT_TWO_SIDED) ? 0xffffffffu : 0u);
            emiv = splat3(lm->emission);
        } else {
            pickv = areav = splat(1.0f);
            twov = usplat(0u);
            emiv = splat3(rs_v3(0.0f, 0.0f, 0.0f));
        }
    } else {
        float pick_[8], area_[8], emi_[3][8];
        uint32_t two_[8];
        for (i = 0; i < 8; ++i) {
            uint32_t l = light_[i];
            pick_[i] = area_[i] = 1.0f;
            two_[i] = 0u;
            emi_[0][i] = emi_[1][i] = emi_[2][i] = 0.0f;
            if (l != RS_NO_HIT) {
                uint32_t prim = sc->lights[l].prim;
                const rs_material *lm = rs_scene_prim_material(sc, prim);
                pick_[i] = sc->lights[l].pick_pdf;
                area_[i] = sc->lights[l].area;
                two_[i] = (lm->flags & RS_MAT_TWO_SIDED) ? 0xffffffffu : 0u;
                emi_[0][i] = lm->emission.x;
                emi_[1][i] = lm->emission.y;
                emi_[2][i] = lm->emission.z;
                gather_prim(sc, prim, &lp, (int)i);
            } else {
                gather_prim(sc, primv[0], &lp, (int)i); /* a valid primitive, unused */
            }
        }
        lquad = (u8)_mm256_loadu_si256((const __m256i *)lp.quad);
        lo = lane3(lp.o);
        la = lane3(lp.a);
        lb = lane3(lp.b);
        lw = lane3(lp.w);
        pickv = load8(pick_);
        areav = load8(area_);
        twov = (u8)_mm256_loadu_si256((const __m256i *)two_);
        emiv = lane3(emi_);
    }
    {
        u8 env = (u8)_mm256_loadu_si256((const __m256i *)env_);
        u8 ok = (u8)_mm256_loadu_si256((const __m256i *)lok_);
        f8 u1 = rlv[1], u2 = rlv[2], su = vsqrt(u1), pdf, cos_l, d2, dist, c_, w;
        v3 lpnt, lerr, ln, to, wi, le, fl, end, sd;
        /* the light's point: a parallelogram at (u1, u2), a triangle at rs_sample_triangle's */
        surface_point(lquad, lo, la, lb, sel3(lquad, lw, cross3(la, lb)),
                      sel(lquad, u1, su * (1.0f - u2)), sel(lquad, u2, su * u2), &lpnt, &lerr, &ln);
        to = sub3(lpnt, x);
        d2 = dot3(to, to);
        dist = vsqrt(d2);
        wi = scale3(to, 1.0f / dist);
        cos_l = vabs(dot3(ln, wi));
        pdf = pickv * d2 / (areav * cos_l);
        le = sel3(twov | (u8)(dot3(ln, wi) < 0.0f), emiv, splat3(rs_v3(0.0f, 0.0f, 0.0f)));
        ok &= env | ((u8)(d2 > 0.0f) & (u8)(cos_l > 1e-7f));
        if (_mm256_movemask_ps((__m256)env)) {
            /* rs_light_sample_env -> rs_env_sample_at, a uniform sky about n */
            v3 we = onb_to_world(n, cosine_hemisphere(u1, u2));
            f8 pe = vmax(splat(0.0f), dot3(n, we) / len3(we)) * RS_INV_PI;
            ok &= ~env | (u8)(pe > 0.0f);
            wi = sel3(env, we, wi);
            pdf = sel(env, pe * env_pick, pdf);
            le = sel3(env, splat3(sc->env_uniform_le), le);
        }
        c_ = dot3(n, wi);
        /* beyond the surface (a Lambertian one transmits nothing), or no light */
        ok &= (u8)(dot3(n_geo, wi) > 0.0f) & (u8)(c_ > 0.0f) & ~zero3(le);
        /* rs_bsdf_eval_side */
        fl = sel3((u8)(c_ > 0.0f) & (u8)(dot3(n, wo) > 0.0f), scale3(alb, splat(RS_INV_PI)),
                  splat3(rs_v3(0.0f, 0.0f, 0.0f)));
        ok &= ~zero3(fl);
        w = power_heuristic(pdf, lambert_pdf(c_, dot3(n, wo)));
        pendv = scale3(mul3(mul3(beta, fl), le), vabs(c_) * w / pdf);
        store3(pend_, pendv);
        /* rs_spawn_end toward the origin */
        end =
            spawn_origin(lpnt, lerr, sel3((u8)(dot3(ln, sub3(origin, lpnt)) < 0.0f), neg3(ln), ln));
        sd = sel3(env, wi, sub3(end, origin));
        sh_dv = sd;
        sh_okv = ok;
        sh_tmax = sel(env, splat(FLT_MAX), splat(1.0f - RS_SHADOW_EPS));
    }

    /* ---- the next direction: rs_shade_direction -> rs_bsdf_sample, then roulette ---- */
    {
        v3 wi = onb_to_world(n, cosine_hemisphere(rbv[0], rbv[1]));
        f8 ci = dot3(n, wi), co = dot3(n, wo), pdf = lambert_pdf(ci, co);
        u8 ok = (u8)(ci > 0.0f) & (u8)(pdf > 0.0f);
        v3 f = sel3((u8)(ci > 0.0f) & (u8)(co > 0.0f), scale3(alb, splat(RS_INV_PI)),
                    splat3(rs_v3(0.0f, 0.0f, 0.0f)));
        beta = mul3(beta, scale3(f, ci / pdf));
        /* below the real surface: the path ends (rs_vertex_side_ok, nothing transmitted) */
        ok &= (u8)(dot3(wi, n_geo) > 0.0f);
        if (bounce + 1 >= it->rr_depth) {
            /* rs_roulette_survival */
            f8 q = vmin(vmax(maxc3(mul3(thr, alb)), splat(0.05f)), splat(0.95f));
            ok &= (u8)(rbv[3] < q);
            beta = scale3(beta, 1.0f / q);
        }
        ok &= ~zero3(beta) & (u8)(maxc3(beta) > 0.0f);
        nx_d = wi;
        nx_okv = ok;
        store3(beta_, beta);
        store8(pdf_, pdf);
        if (sc->env_uniform) /* rs_env_pdf_at about n, times the sky's pick */
            store8(envpdf_, env_pick * (vmax(splat(0.0f), dot3(n, wi) / len3(wi)) * RS_INV_PI));
        else
            store8(envpdf_, splat(0.0f));
    }

    /* ---- scatter: the rays straight into the streams, the paths' state ---- */
    m = put_rays(shadow, os, sh_okv, count, origin, sh_dv, sh_tmax, timev, pathv);
    for (i = 0; i < count; ++i)
        if (m >> i & 1u)
            paths->pending[path_[i]] = rs_v3(pend_[0][i], pend_[1][i], pend_[2][i]);
    m = put_rays(next, on, nx_okv, count, origin, nx_d, splat(FLT_MAX), timev, pathv);
    for (i = 0; i < count; ++i)
        if (m >> i & 1u) {
            uint32_t p = path_[i];
            paths->throughput[p] = rs_v3(beta_[0][i], beta_[1][i], beta_[2][i]);
            paths->bsdf_pdf[p] = pdf_[i];
            paths->env_pdf[p] = envpdf_[i];
            paths->flags[p] = (uint8_t)(paths->flags[p] & RS_PATH_NEGATIVE);
        }
}

#endif

void rs_shade_wide(const rs_render_consts *it, uint32_t bounce, const rs_ray_soa *rays,
                   const rs_hit_soa *hits, const uint32_t *entry, uint32_t n, const rs_rng_f4 *rb,
                   const rs_rng_f4 *rl, uint32_t rng_base, rs_paths *paths, rs_ray_soa *next,
                   uint32_t *on, rs_ray_soa *shadow, uint32_t *os)
{
#if RS_WIDE_HAVE_AVX2
    uint32_t i;
    if (n)
        atomic_fetch_add_explicit(&wide_count, n, memory_order_relaxed);
    for (i = 0; i < n; i += 8)
        shade8(it, bounce, rays, hits, entry + i, n - i < 8 ? n - i : 8, rb, rl, rng_base, paths,
               next, on, shadow, os);
#else
    (void)it, (void)bounce, (void)rays, (void)hits, (void)entry, (void)n, (void)rb, (void)rl;
    (void)rng_base;
    (void)paths, (void)next, (void)on, (void)shadow, (void)os;
#endif
}
