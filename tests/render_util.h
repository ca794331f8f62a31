/* tests/render_util.h — renders a built-in scene through the public API for tests:
 * scene -> BVH -> devices -> scheduler -> rs_render -> resolved film.  Test-only helper. */
#ifndef RS_TESTS_RENDER_UTIL_H
#define RS_TESTS_RENDER_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "accel/bvh8.h" /* rs_bvh_wide_leaf_size */
#include "core/alloc.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"
#include "scenes/builtin.h"
#include "scheduler/fault.h"
#include "scheduler/adaptive.h"
#include "scheduler/render.h"

typedef struct rt_args {
    const char *scene; /* built-in name */
    uint32_t width, height, spp, max_depth;
    uint64_t seed;
    rs_sampling sampling;
    rs_sampler sampler;       /* zeroed: independent */
    int threads;              /* CPU device and shading threads */
    uint32_t chunk_size;      /* 0: default */
    uint32_t wave_paths;      /* 0: default */
    int with_fallback;        /* add a second, one-thread "gpu-fallback" device */
    int fallback_only;        /* the "gpu-fallback" device alone, with `threads` threads */
    uint32_t waves;           /* waves in flight; 0: auto */
    int real_gpu;             /* CUDA device 0 instead of the fallback in the two options above */
    rs_par_strategy strategy; /* the CPU device's, the shading's and the megakernel's */
    int megakernel;     /* the per-pixel integrator (scheduler/passes.c, on devs[0]) instead of the
                           stream */
    int no_bvh;         /* one leaf holding every primitive: brute force */
    rs_bvh_method bvh;  /* the builder (zeroed: median) */
    int fail_after;     /* > 0: the second device fails after this many chunks (RS_FAULT) */
    int shared_cores;   /* devices and shading share a budget of `threads` cores */
    uint32_t bvh_width; /* the CPU device's traversal: 2, 4 or 8 (0: 4) */
    rs_cpu_walk cpu_walk; /* how the CPU device's own waves walk the 8-wide tree (zeroed: auto) */
    int cli_bvh;        /* the CLI's tree instead: the widest traversal this CPU runs (bvh_width is
                           ignored) over leaves the size of its blocks (rs_bvh_wide_leaf_size) */
    rs_adaptive adaptive;            /* threshold > 0: rs_render_adaptive (the stream integrator) */
    rs_adaptive_stats *adaptive_out; /* its statistics, where not NULL */
    uint32_t *counts_out;            /* where not NULL: each pixel's samples (width * height) */
    float *passes_out; /* where not NULL: the render writes the film's passes, resolved here as
                          four planes of n = width * height pixels: albedo [0, 3n), normal
                          [3n, 6n), emission [6n, 9n) (3 floats a pixel), depth [9n, 10n) */
    const rs_filter *filter;         /* the pixel filter; NULL: box, 1 pixel */
    uint32_t light_sampler;          /* rs_light_sampler; zeroed: by power */
    int wavefront; /* the GPU device (fallback_only: alone; with_fallback: beside the CPU device,
                      which runs the stream engine) runs its paths whole (render_paths, its
                      wavefront: rs_engine_create_paths) instead of tracing for the host */
} rt_args;

static inline rt_args rt_defaults(const char *scene, uint32_t size, uint32_t spp)
{
    rt_args a;
    memset(&a, 0, sizeof a);
    a.scene = scene;
    a.width = a.height = size;
    a.spp = spp;
    a.max_depth = 50;
    a.seed = 1;
    a.sampling = RS_SAMPLING_MIS;
    a.threads = 1;
    return a;
}

/* The engine's settings for `a` (sizes, depth, seed, sampling, sampler, one thread, its wave
 * size): the tests that drive the engine themselves. */
static inline rs_render_settings rt_settings(const rt_args *a)
{
    rs_render_settings st;
    memset(&st, 0, sizeof st);
    st.width = a->width;
    st.height = a->height;
    st.spp = a->spp;
    st.max_depth = a->max_depth;
    st.seed = a->seed;
    st.sampling = a->sampling;
    st.sampler = a->sampler;
    st.threads = 1;
    st.wave_paths = a->wave_paths;
    if (a->filter)
        st.filter = *a->filter;
    st.light_sampler = a->light_sampler;
    return st;
}

/* A built-in scene, its BVH, one one-thread CPU device with it uploaded and a scheduler over it:
 * what the tests that drive the engine themselves start from. */
typedef struct rt_rig {
    rs_scene *scene;
    rs_bvh *bvh;
    rs_device *dev;
    rs_sched *sched;
} rt_rig;

/* 0 after printing why. */
static inline int rt_rig_up(rt_rig *g, const char *scene)
{
    rs_geom geom;
    memset(g, 0, sizeof *g);
    if (rs_builtin_create(scene, &g->scene) != RS_OK)
        goto fail;
    geom = rs_scene_geom(g->scene);
    if (rs_bvh_build(&geom, NULL, &g->bvh) != RS_OK ||
        rs_cpu_device_create(1, "cpu", &g->dev) != RS_OK ||
        rs_device_upload(g->dev, &geom, g->bvh) != RS_OK ||
        rs_sched_create(&g->dev, 1, NULL, &g->sched) != RS_OK)
        goto fail;
    return 1;
fail:
    fprintf(stderr, "rt_rig_up(%s): %s\n", scene, rs_error_message());
    return 0;
}

static inline void rt_rig_down(rt_rig *g)
{
    rs_sched_destroy(g->sched);
    rs_device_destroy(g->dev);
    rs_bvh_destroy(g->bvh);
    rs_scene_destroy(g->scene);
    memset(g, 0, sizeof *g);
}

/* Renders a finalized scene the caller owns (a->scene is ignored).  Returns width * height * 3
 * floats (free with free()), or NULL after printing why. */
static inline float *rt_render_scene(const rs_scene *scene, const rt_args *a,
                                     rs_render_stats *stats_out)
{
    rs_bvh *bvh = NULL;
    rs_device *devs[2] = {NULL, NULL};
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    rs_render_settings st;
    rs_render_stats stats;
    rs_sched_config cfg;
    rs_geom g;
    float *rgb = NULL;
    int n = a->with_fallback ? 2 : 1, i, ok = 0;
    rs_cpu_device_opts co;
    rs_cores cores, *budget = a->shared_cores ? &cores : NULL;
    rs_bvh_build_opts bo;

    g = rs_scene_geom(scene);
    rs_cores_init(&cores, a->threads);
    memset(&co, 0, sizeof co);
    co.threads = a->threads;
    co.cores = budget;
    co.strategy = a->strategy;
    co.walk = a->cpu_walk;
    co.bvh_width = a->no_bvh ? 2 : a->cli_bvh ? 0 : a->bvh_width ? a->bvh_width : 4;
    memset(&bo, 0, sizeof bo);
    bo.max_leaf = a->no_bvh ? UINT32_MAX : 0;
    if (a->cli_bvh && !a->no_bvh)
        bo.leaf_block = bo.max_leaf = rs_bvh_wide_leaf_size(0, &g);
    bo.builder.method = a->bvh;
    if (rs_bvh_build(&g, &bo, &bvh) != RS_OK ||
        (a->fallback_only ? (a->real_gpu ? rs_gpu_device_create(0, &devs[0])
                                         : rs_gpu_fallback_create(a->threads, 0, budget, &devs[0]))
                          : rs_cpu_device_create_opts(&co, &devs[0])) != RS_OK ||
        (n == 2 && (a->real_gpu ? rs_gpu_device_create(0, &devs[1])
                                : rs_gpu_fallback_create(1, 0, budget, &devs[1])) != RS_OK))
        goto out;
    if (n == 2 && a->fail_after > 0 && rs_fault_wrap(&devs[1], a->fail_after) != RS_OK)
        goto out;
    for (i = 0; i < n; ++i)
        if (rs_device_upload(devs[i], &g, bvh) != RS_OK)
            goto out;
    memset(&cfg, 0, sizeof cfg);
    cfg.chunk_size = a->chunk_size;
    /* with the wavefront beside it, the scheduler has the CPU device alone */
    if (rs_sched_create(devs, a->wavefront && n == 2 ? 1 : n, &cfg, &sched) != RS_OK ||
        rs_film_create(a->width, a->height, &film) != RS_OK ||
        (a->passes_out && rs_film_keep_passes(film) != RS_OK))
        goto out;
    st = rt_settings(a);
    st.passes = a->passes_out != NULL;
    st.waves_in_flight = a->waves;
    st.threads = a->threads;
    st.cores = budget;
    st.strategy = a->strategy;
    if (a->megakernel) {
        /* devs[0] runs it: the CPU device, or with fallback_only the GPU megakernel's passes
         * (on host threads / on CUDA with real_gpu) */
        if (rs_render_passes(scene, devs[0], &st, NULL, film, &stats) != RS_OK)
            goto out;
    } else if (a->wavefront) {
        rs_engine *e = NULL;
        rs_status rst = n == 2 ? rs_engine_create_paths(scene, &st, sched, &devs[1], 1, &e)
                               : rs_engine_create_paths(scene, &st, NULL, &devs[0], 1, &e);
        if (rst == RS_OK && a->adaptive.threshold > 0) {
            rs_adaptive_stats as;
            rst = rs_render_adaptive(e, &a->adaptive, NULL, film, &stats, &as);
            if (a->adaptive_out)
                *a->adaptive_out = as;
        } else if (rst == RS_OK) {
            rs_work_plan plan;
            memset(&plan, 0, sizeof plan);
            rst = rs_path_ranges_add(&plan.todo, 0, (uint64_t)a->width * a->height * a->spp)
                      ? rs_engine_run(e, &plan, NULL, film, &stats)
                      : RS_ERR_NOMEM;
            rs_work_plan_free(&plan);
        }
        rs_engine_destroy(e);
        if (rst != RS_OK)
            goto out;
    } else if (a->adaptive.threshold > 0) {
        rs_adaptive_stats as;
        rs_engine *e = NULL;
        rs_status rst = rs_engine_create(scene, &st, sched, NULL, &e);
        if (rst == RS_OK)
            rst = rs_render_adaptive(e, &a->adaptive, NULL, film, &stats, &as);
        rs_engine_destroy(e);
        if (rst != RS_OK)
            goto out;
        if (a->adaptive_out)
            *a->adaptive_out = as;
    } else if (rs_render(scene, sched, &st, NULL, film, &stats) != RS_OK) {
        goto out;
    }
    rgb = (float *)malloc((size_t)a->width * a->height * 3 * sizeof *rgb);
    if (!rgb)
        goto out;
    rs_film_resolve(film, rgb);
    if (a->counts_out)
        memcpy(a->counts_out, film->count, (size_t)a->width * a->height * sizeof *film->count);
    if (a->passes_out) {
        size_t np = (size_t)a->width * a->height;
        rs_film_resolve_passes(film, a->passes_out, a->passes_out + 3 * np,
                               a->passes_out + 6 * np, a->passes_out + 9 * np);
    }
    if (stats_out)
        *stats_out = stats;
    ok = 1;
out:
    if (!ok)
        fprintf(stderr, "rt_render(%s): %s\n", scene->name, rs_error_message());
    rs_sched_destroy(sched);
    for (i = 0; i < n; ++i)
        rs_device_destroy(devs[i]);
    rs_film_destroy(film);
    rs_bvh_destroy(bvh);
    return rgb;
}

/* Renders built-in scene a->scene.  Returns the image as rt_render_scene does, or NULL. */
static inline float *rt_render(const rt_args *a, rs_render_stats *stats_out)
{
    rs_scene *scene = NULL;
    float *rgb;
    if (rs_builtin_create(a->scene, &scene) != RS_OK) {
        fprintf(stderr, "rt_render(%s): %s\n", a->scene, rs_error_message());
        return NULL;
    }
    rgb = rt_render_scene(scene, a, stats_out);
    rs_scene_destroy(scene);
    return rgb;
}

static inline double rt_mean(const float *rgb, size_t n_floats)
{
    double s = 0.0;
    size_t i;
    for (i = 0; i < n_floats; ++i)
        s += rgb[i];
    return s / (double)n_floats;
}

#endif
