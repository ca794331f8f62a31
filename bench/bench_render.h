/* bench/bench_render.h — one render of a scene the way a benchmark row describes it: the stream
 * engine on a CPU device (and, optionally, a GPU or its fallback beside it) or the per-pixel
 * megakernel, with a thread count and an OpenMP strategy (benchmark-only helper). */
#ifndef RS_BENCH_BENCH_RENDER_H
#define RS_BENCH_BENCH_RENDER_H

#include <stdio.h>
#include <string.h>

#include "accel/bvh8.h"
#include "core/cores.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"
#include "scenes/builtin.h"
#include "scheduler/render.h"

typedef struct br_config {
    uint32_t width, height, spp;
    rs_sampling sampling;
    int threads;
    int megakernel;
    rs_par_strategy strategy;
    uint32_t bvh_width; /* 2, 4, 8, or 0: the widest this CPU runs */
    int with_gpu;       /* stream: a CUDA device beside the CPU device; megakernel: on CUDA */
    rs_sampler sampler; /* zeroed: independent */
    uint32_t light_sampler; /* rs_light_sampler; zeroed: by power */
    uint64_t seed;      /* 0: 1 */
} br_config;

/* A benchmark's scene: a built-in one by name, or "cornell-mesh:FILE" (FILE under the models
 * folder `models`, NULL: the default) dropped into the Cornell box; with its geometry and a SAH
 * BVH as the CLI builds it: leaves sized to the CPU's wide tree for a CPU-only device set
 * (gpu_too 0), the classic SAH leaves when a GPU (or its fallback) traces too.  Returns 1; 0 when the scene cannot be made (a missing model: "NAME: skipped: why" is
 * printed and the caller goes on); -1 when the BVH fails (printed). */
static inline int br_load_scene(const char *prog, const char *spec, const char *models,
                                int gpu_too, rs_scene **scene, rs_geom *g, rs_bvh **bvh)
{
    rs_builtin_opts o;
    rs_bvh_build_opts bo;
    char path[4096];
    rs_status st;
    memset(&o, 0, sizeof o);
    o.models_dir = models;
    if (strncmp(spec, "cornell-mesh:", 13) == 0) {
        snprintf(path, sizeof path, "%s/%s", rs_builtin_models_dir(models), spec + 13);
        o.mesh_file = path;
        st = rs_builtin_create_ex("cornell-mesh", &o, scene);
    } else {
        st = rs_builtin_create_ex(spec, &o, scene);
    }
    if (st != RS_OK) {
        printf("%s: skipped: %s\n\n", spec, rs_error_message());
        rs_error_clear();
        return 0;
    }
    *g = rs_scene_geom(*scene);
    memset(&bo, 0, sizeof bo);
    bo.builder.method = RS_BVH_SAH;
    if (!gpu_too)
        bo.leaf_block = bo.max_leaf = rs_bvh_wide_leaf_size(0, g);
    if (rs_bvh_build(g, &bo, bvh) != RS_OK) {
        fprintf(stderr, "%s: %s\n", prog, rs_error_message());
        rs_scene_destroy(*scene);
        *scene = NULL;
        return -1;
    }
    return 1;
}

/* Renders; fills *stats and, when rgb is not NULL, the image.  Returns 0 after printing why. */
static inline int br_render(const char *prog, const rs_scene *scene, const rs_geom *g,
                            const rs_bvh *bvh, const br_config *c, float *rgb,
                            rs_render_stats *stats)
{
    rs_device *devs[2] = {NULL, NULL};
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_cpu_device_opts co;
    rs_cores cores;
    int n = 1, i, ok = 0;
    rs_status rst;
    memset(&st, 0, sizeof st);
    st.width = c->width;
    st.height = c->height;
    st.spp = c->spp;
    st.max_depth = 50;
    st.seed = c->seed ? c->seed : 1;
    st.sampling = c->sampling;
    st.sampler = c->sampler;
    st.light_sampler = c->light_sampler;
    st.threads = c->threads;
    st.strategy = c->strategy;
    rs_cores_init(&cores, c->threads);
    st.cores = &cores;
    if (rs_film_create(c->width, c->height, &film) != RS_OK)
        goto out;
    if (c->megakernel) {
        /* one device: CUDA device 0, or the CPU device with every thread */
        if (c->with_gpu) {
            if (rs_gpu_device_create(0, &devs[0]) != RS_OK)
                goto out;
        } else {
            memset(&co, 0, sizeof co);
            co.threads = c->threads;
            co.bvh_width = c->bvh_width;
            co.strategy = c->strategy;
            if (rs_cpu_device_create_opts(&co, &devs[0]) != RS_OK)
                goto out;
        }
        if (rs_device_upload(devs[0], g, bvh) != RS_OK)
            goto out;
        rst = rs_render_passes(scene, devs[0], &st, NULL, film, stats);
    } else {
        memset(&co, 0, sizeof co);
        co.threads = c->with_gpu && c->threads > 1 ? c->threads - 1 : c->threads;
        co.bvh_width = c->bvh_width;
        co.strategy = c->strategy;
        co.cores = &cores;
        if (rs_cpu_device_create_opts(&co, &devs[0]) != RS_OK)
            goto out;
        if (c->with_gpu) {
            if (rs_gpu_device_create(0, &devs[1]) != RS_OK)
                goto out;
            n = 2;
        }
        for (i = 0; i < n; ++i)
            if (rs_device_upload(devs[i], g, bvh) != RS_OK)
                goto out;
        if (rs_sched_create(devs, n, NULL, &sched) != RS_OK)
            goto out;
        rst = rs_render(scene, sched, &st, NULL, film, stats);
    }
    if (rst != RS_OK)
        goto out;
    if (rgb)
        rs_film_resolve(film, rgb);
    ok = 1;
out:
    if (!ok)
        fprintf(stderr, "%s: %s\n", prog, rs_error_message());
    rs_sched_destroy(sched);
    for (i = 0; i < n; ++i)
        rs_device_destroy(devs[i]);
    rs_film_destroy(film);
    return ok;
}

/* Runs fn(name, ctx) for each name of the comma-separated `list` (empty names skipped): 1 when
 * every call returned 1, 0 when one returned 0 (a failed check: the others still run), -1 at
 * the first that returned -1 (an error). */
static inline int br_each_name(const char *list, int (*fn)(const char *name, const void *ctx),
                               const void *ctx)
{
    char name[128];
    const char *p, *end;
    int ok = 1;
    for (p = list; *p; p = *end ? end + 1 : end) {
        int r;
        end = strchr(p, ',');
        if (!end)
            end = p + strlen(p);
        snprintf(name, sizeof name, "%.*s", (int)(end - p), p);
        if (!name[0])
            continue;
        r = fn(name, ctx);
        if (r < 0)
            return -1;
        if (r == 0)
            ok = 0;
    }
    return ok;
}

#endif
