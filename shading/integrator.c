/* shading/integrator.c — raygen, shade and shadow-resolve stages (see integrator.h).
 *
 * Estimators, per sampling mode, at a non-delta vertex with BSDF f and its sampling pdf p_b:
 *   mis      next-event: light sample with pdf p_l, weight w_l = p_l^2 / (p_l^2 + p_b^2),
 *            adds beta f cos Le w_l / p_l if the shadow ray is free; then a BSDF sample,
 *            beta *= f cos / p_b; an emitter that ray hits adds beta Le w_b with
 *            w_b = p_b^2 / (p_b^2 + p_l^2)  (Veach 1998, power heuristic).
 *   mixture  one direction from p = 1/2 p_light + 1/2 p_b; beta *= f cos / p; emitters add
 *            beta Le in full (the thesis's radiance_mixture).
 *   bsdf     BSDF sample; emitters add beta Le.
 *   uniform  uniform hemisphere, p = 1 / 2pi; emitters add beta Le.
 * Delta materials (mirror, glass) are always sampled by their BSDF, and the emitter their ray
 * hits counts in full.  All four estimate the same integral (tested). */
#include "shading/integrator.h"

#include <float.h>
#include <string.h>

#include "core/alloc.h"
#include "core/rng.h"
#include "shading/bsdf.h"
#include "shading/dims.h"
#include "shading/lights.h"
#include "shading/texture.h"

const char *rs_sampling_name(rs_sampling s)
{
    switch (s) {
    case RS_SAMPLING_MIS: return "mis";
    case RS_SAMPLING_MIXTURE: return "mixture";
    case RS_SAMPLING_BSDF: return "bsdf";
    case RS_SAMPLING_UNIFORM: return "uniform";
    }
    return "?";
}

int rs_sampling_parse(const char *text, rs_sampling *out)
{
    int i;
    for (i = 0; i <= RS_SAMPLING_UNIFORM; ++i)
        if (strcmp(text, rs_sampling_name((rs_sampling)i)) == 0) {
            *out = (rs_sampling)i;
            return 1;
        }
    return 0;
}

rs_status rs_paths_init(rs_paths *p, uint32_t capacity)
{
    memset(p, 0, sizeof *p);
    p->throughput = (rs_vec3 *)rs_alloc_aligned(capacity, sizeof(rs_vec3));
    p->radiance = (rs_vec3 *)rs_alloc_aligned(capacity, sizeof(rs_vec3));
    p->pending = (rs_vec3 *)rs_alloc_aligned(capacity, sizeof(rs_vec3));
    p->bsdf_pdf = (float *)rs_alloc_aligned(capacity, sizeof(float));
    p->time = (float *)rs_alloc_aligned(capacity, sizeof(float));
    p->flags = (uint8_t *)rs_alloc_aligned(capacity, 1);
    if (!p->throughput || !p->radiance || !p->pending || !p->bsdf_pdf || !p->time || !p->flags) {
        rs_paths_free(p);
        return rs_error_set(RS_ERR_NOMEM, "out of memory for %u paths", capacity);
    }
    p->capacity = capacity;
    return RS_OK;
}

void rs_paths_free(rs_paths *p)
{
    rs_free(p->throughput);
    rs_free(p->radiance);
    rs_free(p->pending);
    rs_free(p->bsdf_pdf);
    rs_free(p->time);
    rs_free(p->flags);
    memset(p, 0, sizeof *p);
}

void rs_integrator_raygen(const rs_integrator *it, uint64_t wave_start, uint32_t count,
                          rs_paths *paths, rs_ray_soa *out)
{
    const rs_camera_desc *cd = &it->scene->camera;
    long i;
#pragma omp parallel for num_threads(it->threads) schedule(static) if (it->threads > 1)
    for (i = 0; i < (long)count; ++i) {
        uint64_t g = wave_start + (uint64_t)i;
        uint32_t pixel = (uint32_t)(g % it->npix), sample = (uint32_t)(g / it->npix);
        rs_rng_f4 r = rs_rng_float4(it->seed, pixel, sample, 0, RS_DIM_CAMERA);
        rs_ray ray = rs_camera_ray(&it->camera, pixel % it->width, pixel / it->width, r.v[0],
                                   r.v[1], r.v[2], r.v[3]);
        float time = cd->shutter_open;
        if (cd->shutter_close != cd->shutter_open) {
            rs_rng_f4 rt = rs_rng_float4(it->seed, pixel, sample, 0, RS_DIM_TIME);
            time += rt.v[0] * (cd->shutter_close - cd->shutter_open);
        }
        ray.time = time;
        rs_ray_soa_set(out, (uint32_t)i, &ray, (uint32_t)i);
        paths->throughput[i] = rs_v3_splat(1.0f);
        paths->radiance[i] = rs_v3_splat(0.0f);
        paths->pending[i] = rs_v3_splat(0.0f);
        paths->bsdf_pdf[i] = 0.0f;
        paths->time[i] = time;
        paths->flags[i] = RS_PATH_SPECULAR;
    }
    out->count = count;
}

/* Moves a ray origin off the surface along n (the side the new ray leaves from); the offset
 * scales with the coordinates so that it stays far above float rounding (~1e-7 relative) at any
 * scene scale. */
static rs_vec3 offset_origin(rs_vec3 x, rs_vec3 n, float prim_scale)
{
    float scale = fmaxf(fmaxf(fabsf(x.x), fabsf(x.y)), fmaxf(fabsf(x.z), 1e-2f));
    return rs_v3_madd(x, n, fmaxf(1e-4f * scale, 1e-6f * prim_scale));
}

/* The size of the numbers a primitive's intersection test works with, which bounds the error of
 * its hit points: for a sphere, its centre's coordinates and its radius (the ground sphere of
 * rtiow-final, radius 1000 centred 1000 below the origin, puts hit points near the origin with
 * errors of ~1e-4: offset by the hit point's own size only, a bounce ray there could find the
 * ground again at t ~ 1e-5, a hit outside the ground's bounding box that a BVH culls and brute
 * force does not).  The origin moves by 1e-6 of it (~17 float ulps; 2e-3 for that ground).
 * Triangles and quads: their hit points' own size, 0 here. */
static float prim_scale(const rs_scene *sc, uint32_t prim)
{
    const rs_sphere *s;
    if (prim >= sc->n_spheres)
        return 0.0f;
    s = &sc->spheres[prim];
    return fmaxf(fmaxf(fabsf(s->center.x), fabsf(s->center.y)), fabsf(s->center.z)) + s->radius;
}

static float power_heuristic(float a, float b)
{
    float a2 = a * a, b2 = b * b;
    return a2 + b2 > 0.0f ? a2 / (a2 + b2) : 0.0f;
}

/* Surface coordinates at a hit: spheres by longitude/latitude (RTIOW), quads by their planar
 * coordinates, triangles by interpolating their UVs (or the barycentrics). */
static void surface_uv(const rs_scene *sc, uint32_t prim, float hu, float hv, rs_vec3 n_out,
                       float *u, float *v)
{
    if (prim < sc->n_spheres) {
        float theta = acosf(fminf(1.0f, fmaxf(-1.0f, -n_out.y)));
        float phi = atan2f(-n_out.z, n_out.x) + RS_PI;
        *u = phi * (0.5f * RS_INV_PI);
        *v = theta * RS_INV_PI;
        return;
    }
    prim -= sc->n_spheres;
    if (prim < sc->n_quads || !sc->tri_uv) {
        *u = hu;
        *v = hv;
        return;
    }
    {
        const float *uv = &sc->tri_uv[6 * (size_t)(prim - sc->n_quads)];
        float b0 = 1.0f - hu - hv;
        *u = b0 * uv[0] + hu * uv[2] + hv * uv[4];
        *v = b0 * uv[1] + hu * uv[3] + hv * uv[5];
    }
}

static rs_vec3 surface_albedo(const rs_scene *sc, const rs_material *m, uint32_t prim, float hu,
                              float hv, rs_vec3 x, rs_vec3 ng)
{
    float u, v;
    if (m->albedo_tex == RS_NO_TEXTURE)
        return m->albedo;
    surface_uv(sc, prim, hu, hv, ng, &u, &v);
    return rs_texture_eval(&sc->textures[m->albedo_tex], sc->images, u, v, x);
}

/* The shading normal at a hit: the interpolated vertex normal of a triangle that has them,
 * turned to the side of n_geo (the geometric normal on the incoming side); n_geo otherwise, or
 * where the vertex normal would face away from wo. */
static rs_vec3 shading_normal(const rs_scene *sc, uint32_t prim, float hu, float hv, rs_vec3 n_geo,
                              rs_vec3 wo)
{
    uint32_t t = prim - sc->n_spheres - sc->n_quads;
    const float *vn;
    rs_vec3 ns;
    float len;
    if (!sc->tri_normal || prim < sc->n_spheres + sc->n_quads)
        return n_geo;
    vn = &sc->tri_normal[9 * (size_t)t];
    ns = rs_v3_add(rs_v3_add(rs_v3_scale(rs_v3(vn[0], vn[1], vn[2]), 1.0f - hu - hv),
                             rs_v3_scale(rs_v3(vn[3], vn[4], vn[5]), hu)),
                   rs_v3_scale(rs_v3(vn[6], vn[7], vn[8]), hv));
    len = rs_v3_length(ns);
    if (!(len > 1e-6f))
        return n_geo;
    ns = rs_v3_scale(ns, 1.0f / len);
    if (rs_v3_dot(ns, n_geo) < 0.0f)
        ns = rs_v3_neg(ns);
    return rs_v3_dot(ns, wo) > 0.0f ? ns : n_geo;
}

static void shade_one(const rs_integrator *it, uint64_t wave_start, uint32_t bounce,
                      const rs_ray_soa *rays, const rs_hit_soa *hits, uint32_t j, rs_paths *paths,
                      rs_ray_soa *next, uint8_t *next_valid, rs_ray_soa *shadow,
                      uint8_t *shadow_valid)
{
    const rs_scene *sc = it->scene;
    uint32_t p = rays->path[j], prim = hits->prim[j];
    uint64_t g = wave_start + p;
    uint32_t pixel = (uint32_t)(g % it->npix), sample = (uint32_t)(g / it->npix);
    rs_ray r = rs_ray_soa_get(rays, j);
    rs_vec3 beta = paths->throughput[p];
    const rs_material *m;
    rs_vec3 x, ng, n, n_geo, wo, wi, albedo, origin;
    rs_rng_f4 rb;
    float t = hits->t[j], pdf = 0.0f;
    int front, specular = 0;

    next_valid[j] = 0;
    shadow_valid[j] = 0;
    if (prim == RS_NO_HIT) {
        rs_vec3 bg = rs_scene_background(sc, r.d);
        paths->radiance[p] = rs_v3_add(paths->radiance[p], rs_v3_mul(beta, bg));
        return;
    }
    m = rs_scene_prim_material(sc, prim);
    x = rs_ray_at(&r, t);
    ng = rs_prim_normal(sc, prim, x, r.time);

    if (m->type == RS_MAT_DIFFUSE_LIGHT) {
        rs_vec3 le = rs_emitted(m, ng, r.d);
        float w = 1.0f;
        int32_t l = sc->prim_light[prim];
        /* a light reached by BSDF sampling: MIS against the light sampling that could also
         * have found it (not after a delta bounce or from the camera, where none could) */
        if (it->sampling == RS_SAMPLING_MIS && !(paths->flags[p] & RS_PATH_SPECULAR) && l >= 0)
            w = power_heuristic(paths->bsdf_pdf[p],
                                rs_light_pdf_hit(sc, (uint32_t)l, r.o, r.time, r.d, t, ng));
        paths->radiance[p] = rs_v3_add(paths->radiance[p], rs_v3_scale(rs_v3_mul(beta, le), w));
        return; /* emitters reflect nothing */
    }

    /* The segment after this vertex would be number bounce + 1. */
    if (bounce + 1 >= it->max_depth)
        return;
    front = rs_v3_dot(ng, r.d) < 0.0f;
    n_geo = front ? ng : rs_v3_neg(ng); /* the geometric normal on the incoming ray's side */
    wo = rs_v3_neg(r.d);
    n = shading_normal(sc, prim, hits->u[j], hits->v[j], n_geo, wo);
    albedo = surface_albedo(sc, m, prim, hits->u[j], hits->v[j], x, ng);
    rb = rs_rng_float4(it->seed, pixel, sample, bounce, RS_DIM_BSDF);

    if (rs_material_is_delta(m)) {
        /* mirror or glass: the only direction that carries light is the sampled one */
        rs_scatter bs;
        if (!rs_bsdf_sample(m, albedo, n, wo, front, rb.v[0], rb.v[1], rb.v[2], &bs))
            return;
        wi = bs.wi;
        /* with a shading normal, a direction can land on the wrong side of the real surface */
        if ((rs_v3_dot(wi, n_geo) > 0.0f) == (bs.transmit != 0))
            return;
        beta = rs_v3_mul(beta, bs.weight);
        origin = offset_origin(x, bs.transmit ? rs_v3_neg(n_geo) : n_geo, prim_scale(sc, prim));
        specular = 1;
    } else {
        rs_rng_f4 rl = rs_rng_float4(it->seed, pixel, sample, bounce, RS_DIM_LIGHT);
        float ci;
        rs_vec3 f;
        origin = offset_origin(x, n_geo, prim_scale(sc, prim));

        if (it->sampling == RS_SAMPLING_MIS && sc->n_lights > 0) {
            /* next-event estimation: a shadow ray toward a sampled point on a light */
            rs_light_sample ls;
            if (rs_light_sample_at(sc, origin, r.time, rl.v[0], rl.v[1], rl.v[2], &ls)) {
                float c = rs_v3_dot(n, ls.wi);
                rs_vec3 fl = rs_bsdf_eval(m, albedo, n, wo, ls.wi);
                if (c > 0.0f && rs_v3_dot(n_geo, ls.wi) > 0.0f && !rs_v3_is_zero(ls.le) &&
                    !rs_v3_is_zero(fl)) {
                    float w = power_heuristic(ls.pdf, rs_bsdf_pdf(m, albedo, n, wo, ls.wi));
                    rs_ray sr;
                    paths->pending[p] =
                        rs_v3_scale(rs_v3_mul(rs_v3_mul(beta, fl), ls.le), c * w / ls.pdf);
                    sr.o = origin;
                    sr.d = rs_v3_sub(ls.point, origin); /* unnormalised: the light is at t = 1 */
                    sr.tmin = 0.0f;
                    sr.tmax = 1.0f - 1e-4f;
                    sr.time = r.time;
                    rs_ray_soa_set(shadow, j, &sr, p);
                    shadow_valid[j] = 1;
                }
            }
        }

        if (it->sampling == RS_SAMPLING_UNIFORM) {
            /* no importance sampling at all: uniform hemisphere, f cos / (1 / 2pi) */
            rs_onb frame = rs_onb_from_normal(n);
            wi = rs_onb_to_world(&frame, rs_sample_uniform_hemisphere(rb.v[0], rb.v[1]));
            ci = rs_v3_dot(n, wi);
            pdf = rs_pdf_uniform_hemisphere(ci);
            f = rs_bsdf_eval(m, albedo, n, wo, wi);
            if (!(pdf > 0.0f))
                return;
            beta = rs_v3_mul(beta, rs_v3_scale(f, ci / pdf));
        } else if (it->sampling == RS_SAMPLING_MIXTURE && sc->n_lights > 0) {
            /* the thesis's radiance_mixture: one direction from 1/2 light pdf + 1/2 BSDF pdf */
            if (rl.v[3] < 0.5f) {
                rs_light_sample ls;
                if (!rs_light_sample_at(sc, origin, r.time, rl.v[0], rl.v[1], rl.v[2], &ls))
                    return;
                wi = ls.wi;
            } else {
                rs_scatter bs;
                if (!rs_bsdf_sample(m, albedo, n, wo, front, rb.v[0], rb.v[1], rb.v[2], &bs))
                    return;
                wi = bs.wi;
            }
            ci = rs_v3_dot(n, wi);
            if (!(ci > 0.0f))
                return; /* f = 0 below the surface: the path carries nothing further */
            pdf = 0.5f * rs_lights_pdf_dir(sc, origin, r.time, wi) +
                  0.5f * rs_bsdf_pdf(m, albedo, n, wo, wi);
            f = rs_bsdf_eval(m, albedo, n, wo, wi);
            if (!(pdf > 0.0f))
                return;
            beta = rs_v3_mul(beta, rs_v3_scale(f, ci / pdf));
        } else {
            /* mis, bsdf, and mixture without lights: the material's own sampling */
            rs_scatter bs;
            if (!rs_bsdf_sample(m, albedo, n, wo, front, rb.v[0], rb.v[1], rb.v[2], &bs))
                return;
            wi = bs.wi;
            pdf = bs.pdf;
            beta = rs_v3_mul(beta, bs.weight);
        }
    }

    if (!specular && !(rs_v3_dot(wi, n_geo) > 0.0f))
        return; /* below the real surface (a shading-normal artefact): nothing comes back */
    if (bounce + 1 >= it->rr_depth) {
        float q = fminf(rs_v3_max_comp(beta), 0.95f);
        if (!(rb.v[3] < q))
            return;
        beta = rs_v3_scale(beta, 1.0f / q);
    }
    if (rs_v3_is_zero(beta) || !(rs_v3_max_comp(beta) > 0.0f))
        return;
    {
        rs_ray nr;
        nr.o = origin;
        nr.d = wi;
        nr.tmin = 0.0f;
        nr.tmax = FLT_MAX;
        nr.time = r.time;
        rs_ray_soa_set(next, j, &nr, p);
        next_valid[j] = 1;
    }
    paths->throughput[p] = beta;
    paths->bsdf_pdf[p] = pdf;
    paths->flags[p] = specular ? RS_PATH_SPECULAR : 0;
}

typedef struct shade_ctx {
    const rs_integrator *it;
    uint64_t wave_start;
    uint32_t bounce;
    const rs_ray_soa *rays;
    const rs_hit_soa *hits;
    rs_paths *paths;
    rs_ray_soa *next, *shadow;
    uint8_t *next_valid, *shadow_valid;
} shade_ctx;

static void shade_range(void *ctx, uint32_t begin, uint32_t end)
{
    const shade_ctx *c = (const shade_ctx *)ctx;
    uint32_t j;
    for (j = begin; j < end; ++j)
        shade_one(c->it, c->wave_start, c->bounce, c->rays, c->hits, j, c->paths, c->next,
                  c->next_valid, c->shadow, c->shadow_valid);
}

void rs_integrator_shade(const rs_integrator *it, uint64_t wave_start, uint32_t bounce,
                         const rs_ray_soa *rays, const rs_hit_soa *hits, uint32_t count,
                         rs_paths *paths, rs_ray_soa *next, uint8_t *next_valid, rs_ray_soa *shadow,
                         uint8_t *shadow_valid)
{
    shade_ctx c;
    c.it = it;
    c.wave_start = wave_start;
    c.bounce = bounce;
    c.rays = rays;
    c.hits = hits;
    c.paths = paths;
    c.next = next;
    c.shadow = shadow;
    c.next_valid = next_valid;
    c.shadow_valid = shadow_valid;
    /* shading costs vary by material and by hit or miss: blocks of 512 paths, split as the
     * strategy says */
    rs_parallel_range(it->strategy, it->threads, 0, count, 512, shade_range, &c);
}

void rs_integrator_resolve_shadows(const rs_integrator *it, const rs_ray_soa *shadow,
                                   const uint8_t *occluded, uint32_t count, rs_paths *paths)
{
    long k;
    (void)it; /* read only by the OpenMP clauses (compiled out under ThreadSanitizer) */
#pragma omp parallel for num_threads(it->threads) schedule(static) if (it->threads > 1)
    for (k = 0; k < (long)count; ++k) {
        uint32_t p = shadow->path[k];
        if (!occluded[k])
            paths->radiance[p] = rs_v3_add(paths->radiance[p], paths->pending[p]);
    }
}

#define COMPACT_MAX_BLOCKS 64

uint32_t rs_stream_compact(const rs_ray_soa *src, const uint8_t *valid, uint32_t count,
                           rs_ray_soa *dst, int threads)
{
    uint32_t offsets[COMPACT_MAX_BLOCKS + 1];
    int nb = threads < 1 ? 1 : (threads > COMPACT_MAX_BLOCKS ? COMPACT_MAX_BLOCKS : threads);
    int b;
    if (count < 4096)
        nb = 1;
        /* pass 1: count per block */
#pragma omp parallel for num_threads(nb) schedule(static, 1) if (nb > 1)
    for (b = 0; b < nb; ++b) {
        uint32_t lo = (uint32_t)((uint64_t)count * b / nb),
                 hi = (uint32_t)((uint64_t)count * (b + 1) / nb);
        uint32_t c = 0, i;
        for (i = lo; i < hi; ++i)
            c += valid[i] != 0;
        offsets[b + 1] = c;
    }
    offsets[0] = 0;
    for (b = 0; b < nb; ++b)
        offsets[b + 1] += offsets[b];
        /* pass 2: copy, each block from its prefix offset */
#pragma omp parallel for num_threads(nb) schedule(static, 1) if (nb > 1)
    for (b = 0; b < nb; ++b) {
        uint32_t lo = (uint32_t)((uint64_t)count * b / nb),
                 hi = (uint32_t)((uint64_t)count * (b + 1) / nb);
        uint32_t o = offsets[b], i;
        for (i = lo; i < hi; ++i)
            if (valid[i])
                rs_ray_soa_copy(dst, o++, src, i);
    }
    dst->count = offsets[nb];
    return offsets[nb];
}
