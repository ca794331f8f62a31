/* shading/integrator.c — the stream engine's raygen, shade and shadow-resolve stages (see
 * integrator.h); the
 * estimators themselves are shading/path.h's. */
#include "shading/integrator.h"
#include "shading/aov.h"
#include "shading/shade_wide.h"

#include <string.h>

#include "core/rand_batch.h"

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

/* The stages make their paths' random numbers BATCH at a time (core/rand_batch.h: vectors of
 * eight on AVX2): 64 paths' worth of numbers is 2 KB per group, well inside the L1 cache. */
#define BATCH 64

/* Pixel and sample of paths wave_start + p, for p = path[i] (or p0 + i where path is NULL),
 * i < n.  A stream keeps its paths in increasing order, so after one division each entry is a
 * step from the one before (a step back or past a whole image divides again); the numbers are
 * those of g mod n_active and g div n_active (mapped through map->pixel_of for a plan over some
 * pixels). */
static void locate(const rs_path_map *map, uint64_t wave_start, const uint32_t *path, uint32_t p0,
                   uint32_t n, uint32_t *pixel, uint32_t *sample)
{
    uint32_t i, prev = 0, px = 0, sm = 0, npix = map->n_active;
    for (i = 0; i < n; ++i) {
        uint32_t p = path ? path[i] : p0 + i, step = p - prev;
        if (i == 0 || p < prev || step >= npix) {
            uint64_t g = wave_start + p;
            px = (uint32_t)(g % npix);
            sm = (uint32_t)(g / npix);
        } else if (step >= npix - px) {
            px = step - (npix - px);
            sm++;
        } else {
            px += step;
        }
        prev = p;
        pixel[i] = px;
        sample[i] = sm;
    }
    /* a plan over some pixels only (adaptive sampling): their indices */
    if (map->pixel_of)
        for (i = 0; i < n; ++i)
            pixel[i] = map->pixel_of[pixel[i]];
}

/* out[i] = rs_path_rand(it, pixel[i], sample[i], bounce, group), i < n. */
static void path_rand_batch(const rs_render_consts *it, const uint32_t *pixel,
                            const uint32_t *sample, uint32_t bounce, uint32_t group, uint32_t n,
                            rs_rng_f4 *out)
{
    uint32_t i;
    if (it->sampler == RS_SAMPLER_SOBOL) {
        rs_rand_batch_sobol(it->seed, pixel, sample, bounce, group, n, out);
        if (group == RS_DIM_LIGHT)
            for (i = 0; i < n; ++i)
                out[i] = rs_path_sobol_order(out[i], group);
    } else if (it->sampler == RS_SAMPLER_INDEPENDENT) {
        rs_rand_batch_philox(it->seed, pixel, sample, bounce, group, n, out);
    } else {
        for (i = 0; i < n; ++i) /* zsobol: no batched form yet */
            out[i] = rs_path_rand(it, pixel[i], sample[i], bounce, group);
    }
}

void rs_stage_raygen(const rs_render_consts *it, const rs_path_map *map, const rs_stage_exec *ex,
                     uint64_t wave_start, uint32_t count, rs_paths *paths, rs_ray_soa *out)
{
    long blk;
    int threads = ex->threads;
    int shutter = it->scene->camera.shutter_close != it->scene->camera.shutter_open;
    (void)threads; /* read only by the OpenMP clauses (compiled out under ThreadSanitizer) */
#pragma omp parallel for num_threads(threads) schedule(static) if (threads > 1)
    for (blk = 0; blk < (long)((count + BATCH - 1) / BATCH); ++blk) {
        uint32_t b = (uint32_t)blk * BATCH, n = count - b < BATCH ? count - b : BATCH, k;
        uint32_t pixel[BATCH], sample[BATCH];
        rs_rng_f4 cam[BATCH], tim[BATCH];
        locate(map, wave_start, NULL, b, n, pixel, sample);
        path_rand_batch(it, pixel, sample, 0, RS_DIM_CAMERA, n, cam);
        if (shutter)
            path_rand_batch(it, pixel, sample, 0, RS_DIM_TIME, n, tim);
        for (k = 0; k < n; ++k) {
            rs_path_state ps;
            rs_rng_f4 pre[2];
            rs_ray ray;
            pre[0] = cam[k];
            pre[1] = shutter ? tim[k] : cam[k];
            ray = rs_path_begin_at(it, pixel[k], sample[k], pre, &ps);
            rs_ray_soa_set(out, b + k, &ray, b + k);
            rs_paths_store(paths, b + k, &ps);
        }
    }
    out->count = count;
}

typedef struct shade_ctx {
    const rs_render_consts *it;
    const rs_path_map *map;
    uint64_t wave_start;
    uint32_t bounce;
    const rs_ray_soa *rays;
    const rs_hit_soa *hits;
    rs_paths *paths;
    rs_ray_soa *next, *shadow;
    const rs_stream_runs *runs;
    int wide;     /* rs_shade_wide_ready */
    int prefetch; /* the scene's triangles are more than the caches keep near (prefetch_hits) */
} shade_ctx;

#define RS_NO_WIDE 0xffffffffu

/* Entries [b, b + n) at the camera rays' hits: what each showed, for the film's passes, before
 * shading moves the paths on. */
static void record_passes(const shade_ctx *c, uint32_t b, uint32_t n)
{
    uint32_t j;
    for (j = b; j < b + n; ++j) {
        uint32_t p = c->rays->path[j];
        rs_ray r = rs_ray_soa_get(c->rays, j);
        rs_hit h = rs_hit_soa_get(c->hits, j);
        rs_path_state ps = rs_paths_load(c->paths, p);
        c->paths->aux[p] = rs_path_aux_at(c->it, &r, &h, &ps);
    }
}

/* Beyond this many triangles (36 bytes each, and their normals) a scene's triangles no longer
 * stay in a core's L2 cache between bounces; below it the loop only costs (the Cornell box: 1.5%
 * of its time). */
#define RS_PREFETCH_TRIS 16384u

/* Asks for the scene data shading will read at these hits (a triangle's corners, its vertex
 * normals and material number) while the batch's random numbers are made: in a scene larger than
 * the caches each hit's triangle is a miss, the first load of the shading that followed stalled
 * on it (perf on the living room: a quarter of shade8's samples).  Only the speed changes.
 * Forced inline: out of line GCC finds the function without effects and drops its calls. */
RS_HD_HOT void prefetch_hits(const rs_scene *sc, const uint32_t *prim, uint32_t n)
{
    uint32_t k;
    for (k = 0; k < n; ++k) {
        uint32_t t = prim[k] - sc->n_spheres - sc->n_quads;
        if (prim[k] == RS_NO_HIT || prim[k] < sc->n_spheres + sc->n_quads || t >= sc->n_tris)
            continue;
        __builtin_prefetch(&sc->tris[t]);
        __builtin_prefetch(&sc->tri_mat[t]);
        if (sc->tri_normal)
            __builtin_prefetch(&sc->tri_normal[9 * (size_t)t]);
    }
}

/* Shades the entries [begin, end); their next rays go packed to next[begin ...] and their shadow
 * rays to shadow[begin ...] (each batch's eight-lane entries first), the counts to the range's
 * run record. */
static void shade_range(void *ctx, uint32_t begin, uint32_t end)
{
    const shade_ctx *c = (const shade_ctx *)ctx;
    /* a vertex at the last segment only gathers light: it draws no numbers */
    int draws = c->bounce + 1 < c->it->max_depth;
    uint32_t b, k, on = begin, os = begin;
    for (b = begin; b < end; b += BATCH) {
        uint32_t n = end - b < BATCH ? end - b : BATCH;
        uint32_t pixel[BATCH], sample[BATCH], wide_j[BATCH], nw = 0;
        rs_rng_f4 rb[BATCH], rl[BATCH], pre[2];
        uint8_t wide[BATCH];
        locate(c->map, c->wave_start, c->rays->path + b, 0, n, pixel, sample);
        if (c->prefetch)
            prefetch_hits(c->it->scene, c->hits->prim + b, n);
        if (c->bounce == 0 && c->it->passes)
            record_passes(c, b, n);
        if (draws) {
            path_rand_batch(c->it, pixel, sample, c->bounce, RS_DIM_BSDF, n, rb);
            path_rand_batch(c->it, pixel, sample, c->bounce, RS_DIM_LIGHT, n, rl);
        }
        if (c->wide) {
            /* the common vertices eight at a time (shading/shade_wide.h), their rays first in
             * the streams (the order of a stream's rays changes no answer), the rest below */
            for (k = 0; k < n; ++k) {
                wide[k] = (uint8_t)rs_shade_wide_entry(c->it->scene, c->hits->prim[b + k]);
                if (wide[k])
                    wide_j[nw++] = b + k;
            }
            rs_shade_wide(c->it, c->bounce, c->rays, c->hits, wide_j, nw, rb, rl, b, c->paths,
                          c->next, &on, c->shadow, &os);
        }
        for (k = 0; k < n; ++k) {
            /* entry j: path p's state loaded from the SoA, shaded, stored back (rs_path_shade_at
             * changes only what the path's next stage reads) */
            uint32_t j = b + k, p = c->rays->path[j], made;
            rs_ray r, nr, sr;
            rs_hit h;
            rs_path_state ps;
            if (nw && wide[k])
                continue;
            r = rs_ray_soa_get(c->rays, j);
            h = rs_hit_soa_get(c->hits, j);
            ps = rs_paths_load(c->paths, p);
            if (draws) {
                pre[0] = rb[k];
                pre[1] = rl[k];
            }
            made = rs_path_shade_at(c->it, pixel[k], sample[k], c->bounce, draws ? pre : NULL, &r,
                                    &h, &ps, &nr, &sr);
            rs_paths_store(c->paths, p, &ps);
            if (made & RS_SHADE_SHADOW)
                rs_ray_soa_set(c->shadow, os++, &sr, p);
            if (made & RS_SHADE_NEXT)
                rs_ray_soa_set(c->next, on++, &nr, p);
        }
    }
    c->runs->first[begin] = on - begin;
    c->runs->second[begin] = os - begin;
    c->runs->end[begin] = end;
}

void rs_stage_shade(const rs_render_consts *it, const rs_path_map *map, const rs_stage_exec *ex,
                    uint64_t wave_start, uint32_t bounce, const rs_ray_soa *rays,
                    const rs_hit_soa *hits, uint32_t count, rs_paths *paths, rs_ray_soa *next,
                    rs_ray_soa *shadow, const rs_stream_runs *runs)
{
    shade_ctx c;
    c.it = it;
    c.map = map;
    c.wave_start = wave_start;
    c.bounce = bounce;
    c.rays = rays;
    c.hits = hits;
    c.paths = paths;
    c.next = next;
    c.shadow = shadow;
    c.runs = runs;
    c.wide = rs_shade_wide_ready(it, bounce);
    c.prefetch = it->scene->n_tris > RS_PREFETCH_TRIS;
    /* shading costs vary by material and by hit or miss: blocks of 512 paths, split as the
     * strategy says */
    rs_parallel_range(ex->strategy, ex->threads, 0, count, 512, shade_range, &c);
}

void rs_stage_resolve_shadows(const rs_stage_exec *ex, const rs_ray_soa *shadow,
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
