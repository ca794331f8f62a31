/* shading/integrator.c — raygen, shade and shadow-resolve stages (see integrator.h); the
 * estimators themselves are shading/path.h's. */
#include "shading/integrator.h"

#include <string.h>

#include "core/alloc.h"

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
    long i;
#pragma omp parallel for num_threads(it->threads) schedule(static) if (it->threads > 1)
    for (i = 0; i < (long)count; ++i) {
        rs_path_state ps;
        rs_ray ray = rs_path_begin(it, wave_start + (uint64_t)i, &ps);
        rs_ray_soa_set(out, (uint32_t)i, &ray, (uint32_t)i);
        paths->throughput[i] = ps.throughput;
        paths->radiance[i] = ps.radiance;
        paths->pending[i] = ps.pending;
        paths->bsdf_pdf[i] = ps.bsdf_pdf;
        paths->time[i] = ps.time;
        paths->flags[i] = (uint8_t)ps.flags;
    }
    out->count = count;
}

/* Entry j of the stream: path p's state in and out of the SoA around rs_path_shade, writing
 * only what it changed. */
static void shade_one(const rs_integrator *it, uint64_t wave_start, uint32_t bounce,
                      const rs_ray_soa *rays, const rs_hit_soa *hits, uint32_t j, rs_paths *paths,
                      rs_ray_soa *next, uint8_t *next_valid, rs_ray_soa *shadow,
                      uint8_t *shadow_valid)
{
    uint32_t p = rays->path[j], made;
    rs_ray r = rs_ray_soa_get(rays, j), nr, sr;
    rs_hit h;
    rs_path_state ps;
    h.t = hits->t[j];
    h.u = hits->u[j];
    h.v = hits->v[j];
    h.prim = hits->prim[j];
    ps.throughput = paths->throughput[p];
    ps.radiance = paths->radiance[p];
    ps.bsdf_pdf = paths->bsdf_pdf[p];
    ps.flags = paths->flags[p];
    made = rs_path_shade(it, wave_start + p, bounce, &r, &h, &ps, &nr, &sr);
    paths->radiance[p] = ps.radiance;
    next_valid[j] = (made & RS_SHADE_NEXT) != 0;
    shadow_valid[j] = (made & RS_SHADE_SHADOW) != 0;
    if (made & RS_SHADE_SHADOW) {
        paths->pending[p] = ps.pending;
        rs_ray_soa_set(shadow, j, &sr, p);
    }
    if (made & RS_SHADE_NEXT) {
        paths->throughput[p] = ps.throughput;
        paths->bsdf_pdf[p] = ps.bsdf_pdf;
        paths->flags[p] = (uint8_t)ps.flags;
        rs_ray_soa_set(next, j, &nr, p);
    }
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
