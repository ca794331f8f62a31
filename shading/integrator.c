/* shading/integrator.c — raygen, shade and shadow-resolve stages (see integrator.h); the
 * estimators themselves are shading/path.h's. */
#include "shading/integrator.h"

#include <string.h>

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

const char *rs_sampler_name(rs_sampler s)
{
    switch (s) {
    case RS_SAMPLER_INDEPENDENT: return "independent";
    case RS_SAMPLER_SOBOL: return "sobol";
    case RS_SAMPLER_ZSOBOL: return "zsobol";
    }
    return "?";
}

int rs_sampler_parse(const char *text, rs_sampler *out)
{
    int i;
    for (i = 0; i <= RS_SAMPLER_ZSOBOL; ++i)
        if (strcmp(text, rs_sampler_name((rs_sampler)i)) == 0) {
            *out = (rs_sampler)i;
            return 1;
        }
    return 0;
}

void rs_integrator_raygen(const rs_integrator *it, const rs_stage_exec *ex, uint64_t wave_start,
                          uint32_t count, rs_paths *paths, rs_ray_soa *out)
{
    long i;
    int threads = ex->threads;
    (void)threads; /* read only by the OpenMP clauses (compiled out under ThreadSanitizer) */
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
    for (i = 0; i < (long)count; ++i) {
        rs_path_state ps;
        rs_ray ray = rs_path_begin(it, wave_start + (uint64_t)i, &ps);
        rs_ray_soa_set(out, (uint32_t)i, &ray, (uint32_t)i);
        rs_paths_store(paths, (uint32_t)i, &ps);
    }
    out->count = count;
}

/* Entry j of the stream: path p's state loaded from the SoA, shaded, stored back (rs_path_shade
 * changes only what the path's next stage reads). */
static void shade_one(const rs_integrator *it, uint64_t wave_start, uint32_t bounce,
                      const rs_ray_soa *rays, const rs_hit_soa *hits, uint32_t j, rs_paths *paths,
                      rs_ray_soa *next, uint8_t *next_valid, rs_ray_soa *shadow,
                      uint8_t *shadow_valid)
{
    uint32_t p = rays->path[j], made;
    rs_ray r = rs_ray_soa_get(rays, j), nr, sr;
    rs_hit h = rs_hit_soa_get(hits, j);
    rs_path_state ps = rs_paths_load(paths, p);
    made = rs_path_shade(it, wave_start + p, bounce, &r, &h, &ps, &nr, &sr);
    rs_paths_store(paths, p, &ps);
    next_valid[j] = (made & RS_SHADE_NEXT) != 0;
    shadow_valid[j] = (made & RS_SHADE_SHADOW) != 0;
    if (made & RS_SHADE_SHADOW)
        rs_ray_soa_set(shadow, j, &sr, p);
    if (made & RS_SHADE_NEXT)
        rs_ray_soa_set(next, j, &nr, p);
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

void rs_integrator_shade(const rs_integrator *it, const rs_stage_exec *ex, uint64_t wave_start,
                         uint32_t bounce, const rs_ray_soa *rays, const rs_hit_soa *hits,
                         uint32_t count, rs_paths *paths, rs_ray_soa *next, uint8_t *next_valid,
                         rs_ray_soa *shadow, uint8_t *shadow_valid)
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
    rs_parallel_range(ex->strategy, ex->threads, 0, count, 512, shade_range, &c);
}

void rs_integrator_resolve_shadows(const rs_stage_exec *ex, const rs_ray_soa *shadow,
                                   const uint8_t *occluded, uint32_t count, rs_paths *paths)
{
    long k;
    int threads = ex->threads;
    (void)threads; /* read only by the OpenMP clauses (compiled out under ThreadSanitizer) */
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
    for (k = 0; k < (long)count; ++k) {
        uint32_t p = shadow->path[k];
        if (!occluded[k])
            paths->radiance[p] = rs_v3_add(paths->radiance[p], paths->pending[p]);
    }
}
