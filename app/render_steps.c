/* app/render_steps.c — the steps of one render that the render command (render_cmd.c) and the
 * MPI glue (dist_glue.c) share (app/render_run.h): the settings, the outputs checked before the
 * render, the film, the BVH, the devices, the --checkpoint of the film, and the release of what
 * they made.  Both callers call down into this file; it calls nothing of theirs. */
#include <stdio.h>
#include <string.h>

#include "accel/bvh8.h"
#include "app/devices.h"
#include "app/render_run.h"
#include "core/alloc.h"
#include "core/denoise.h"
#include "core/image_io.h"
#include "gpu/gpu_device.h"
#include "shading/aov.h"

/* The image size from the options and the scene's own size. */
static void settings_size(const rs_cli_options *o, const rs_scene *scene, rs_image_settings *st)
{
    st->width = o->width ? o->width : scene->width;
    st->height = o->height ? o->height : scene->height;
    if (o->width && !o->height)
        st->height = (uint32_t)(0.5 + (double)o->width * scene->height / scene->width);
    if (!o->width && o->height)
        st->width = (uint32_t)(0.5 + (double)o->height * scene->width / scene->height);
    if (st->width < 1)
        st->width = 1;
    if (st->height < 1)
        st->height = 1;
}

/* What decides the image, once, from the options and the scene's own size (the one place an
 * image-defining option is read; app/image_settings.h). */
static void image_settings(const rs_cli_options *o, render_run *r)
{
    rs_image_settings *img = &r->img;
    memset(img, 0, sizeof *img);
    settings_size(o, r->scene, img);
    img->spp = o->spp;
    img->max_depth = o->max_depth;
    img->rr_depth = 3;
    img->seed = o->seed;
    img->sampling = o->sampling;
    img->sampler = o->sampler;
    img->filter = o->filter;
    img->texture_filter = o->texture_filter;
    img->light_sampler = o->light_sampler;
    img->isect_sphere = o->isect_sphere;
    img->isect_tri = o->isect_tri;
    img->isect_aabb = o->isect_aabb;
    if (o->adaptive > 0) {
        img->adaptive = o->adaptive;
        img->adaptive_min_spp = o->adaptive_min_spp;
    }
}

/* The engine's settings: the image's (r->img) and how it runs. */
static void engine_settings(const rs_image_settings *img, rs_render_settings *st)
{
    st->width = img->width;
    st->height = img->height;
    st->spp = img->spp;
    st->max_depth = img->max_depth;
    st->rr_depth = img->rr_depth;
    st->seed = img->seed;
    st->sampling = img->sampling;
    st->sampler = img->sampler;
    st->filter = img->filter;
    st->texture_filter = img->texture_filter;
    st->light_sampler = img->light_sampler;
}

/* The render settings from the options and the scene's own size. */
void rs_run_settings(const rs_cli_options *o, render_run *r)
{
    rs_render_settings *st = &r->st;
    memset(st, 0, sizeof *st);
    image_settings(o, r);
    engine_settings(&r->img, st);
    /* the devices write the passes the outputs read: the --aov layers, --denoise's guides */
    st->passes = (o->aovs & (RS_AOV_ALBEDO | RS_AOV_NORMAL | RS_AOV_DEPTH)) || o->denoise;
    st->wave_paths = o->wave_paths;
    st->waves_in_flight = o->waves;
    r->threads = o->threads ? o->threads : rs_cpu_count();
    /* ranks on one machine share its cores */
    if (!o->threads && r->local_ranks > 1)
        r->threads = r->threads / r->local_ranks > 0 ? r->threads / r->local_ranks : 1;
    /* --integrator megakernel --devices cpu:N runs on N threads */
    if (o->megakernel && !o->devices_auto && !o->devices[0].is_gpu && o->devices[0].threads)
        r->threads = o->devices[0].threads;
    st->threads = r->threads;
    /* the CPU devices and the shading share `threads` cores (core/cores.h) */
    rs_cores_init(&r->cores, r->threads);
    st->cores = &r->cores;
    st->strategy = o->strategy;
}

/* Every output is checked before any work (app/outputs.h): a folder, a file that cannot be
 * written, a missing or read-only folder, two outputs on one file, an output over an input; then
 * the image's format.  Returns an exit code: RS_EXIT_USAGE, nothing written, for all of them. */
int rs_run_check_outputs(const rs_cli_options *o, render_run *r)
{
    const char *inputs[3];
    rs_output *out = r->outs;
    int n = 0, rc;
    if (o->output) {
        r->out = o->output;
    } else {
        snprintf(r->out_default, sizeof r->out_default, "%s.%s", r->name, o->aovs ? "exr" : "png");
        r->out = r->out_default;
    }
    memset(r->outs, 0, sizeof r->outs);
    out[n].option = o->output ? "-o" : "the image";
    out[n++].path = r->out;
    if (o->stats_json) {
        out[n].option = "--stats-json";
        out[n].path = o->stats_json;
        out[n].may_be_special = 1; /* /dev/stdout */
        r->stats_out = &out[n++];
    }
    if (o->timeline) {
        out[n].option = "--timeline";
        out[n].path = o->timeline;
        r->timeline_out = &out[n++];
    }
    if (o->checkpoint) {
        out[n].option = "--checkpoint";
        out[n].path = o->checkpoint;
        out[n].may_replace = o->resume; /* checkpointing on into the file it continues */
        r->ckpt_out = &out[n++];
    }
    r->n_outs = n;
    inputs[0] = strncmp(o->scene, "builtin:", 8) == 0 ? NULL : o->scene;
    inputs[1] = o->mesh;
    inputs[2] = o->resume;
    if ((rc = rs_outputs_check(out, n, inputs, 3)) != RS_EXIT_OK)
        return rc;
    if (rs_image_check_output(r->out) != RS_OK)
        return rs_app_fail(RS_EXIT_USAGE, NULL);
    return rs_run_check_denoise(o);
}

int rs_run_check_denoise(const rs_cli_options *o)
{
    char why[400];
    /* OIDN is loaded at run time: its absence stops the run here, as does a library that cannot
     * make a CPU device and its filter */
    if (o->denoise && !rs_denoise_probe(why, sizeof why)) {
        rs_app_print("raystream: --denoise: %s\n", why);
        return RS_EXIT_RUNTIME;
    }
    return RS_EXIT_OK;
}

int rs_run_prepare(const rs_cli_options *o, render_run *r)
{
    int code;
    rs_run_settings(o, r);
    /* the library writes no file of the command's: it checks the denoiser alone */
    if ((code = r->library ? rs_run_check_denoise(o) : rs_run_check_outputs(o, r)) == RS_EXIT_OK &&
        (code = rs_run_make_film(o, r)) == RS_EXIT_OK &&
        (code = rs_run_build_bvh(o, r)) == RS_EXIT_OK)
        code = rs_run_start_devices(o, r);
    return code;
}

/* A --resume whose ranges all end on whole samples: RS_EXIT_OK, else one line ending in
 * `what` and RS_EXIT_USAGE. */
int rs_run_resume_whole_samples(const rs_cli_options *o, const render_run *r, const char *what)
{
    uint64_t npix = (uint64_t)r->st.width * r->st.height;
    uint32_t i;
    for (i = 0; i < r->held.n; ++i)
        if (r->held.r[i][1] % npix != 0) {
            rs_app_print("raystream: --resume %s: stopped within a sample (%llu paths of %ux%u "
                         "pixels); %s\n",
                         o->resume, (unsigned long long)r->held.r[i][1], r->st.width, r->st.height,
                         what);
            return RS_EXIT_USAGE;
        }
    return RS_EXIT_OK;
}

/* What decides the image, for --checkpoint and --resume. */
static void make_key(const rs_cli_options *o, render_run *r)
{
    rs_checkpoint_key *k = &r->key;
    memset(k, 0, sizeof *k);
    /* hashing every byte of a large scene takes a tenth of a second (the living room's 143k
     * triangles and 5 MB of textures): only where a checkpoint is written or read */
    if (o->checkpoint || o->resume)
        k->scene_hash = r->scene_hash ? r->scene_hash : rs_checkpoint_scene_hash(r->scene);
    k->img = r->img;
    k->scene = o->scene;
}

rs_status rs_run_new_film(const render_run *r, rs_film **out)
{
    rs_status st = rs_film_create(r->st.width, r->st.height, out);
    if (st == RS_OK && r->st.passes && (st = rs_film_keep_passes(*out)) != RS_OK) {
        rs_film_destroy(*out);
        *out = NULL;
    }
    return st;
}

/* The film: a fresh one, or with --resume the checkpoint's (app/checkpoint.h), checked against
 * these settings before any work; the render then starts at the first path it does not hold.
 * --resume without --spp continues to the spp the checkpoint was started with.  Returns an exit
 * code. */
int rs_run_make_film(const rs_cli_options *o, render_run *r)
{
    int rc;
    make_key(o, r);
    if (rs_run_new_film(r, &r->film) != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "starting the render");
    if (!o->resume)
        return RS_EXIT_OK;
    if (!o->spp_given)
        r->key.img.spp = 0; /* the file's */
    if (r->img.adaptive > 0) { /* the film's first samples, and where adaptive sampling stood */
        if ((rc = rs_checkpoint_read_adaptive(o->resume, &r->key, r->film, &r->ad)) != RS_EXIT_OK)
            return rc;
        r->img.spp = r->st.spp = r->key.img.spp;
        r->resumed = rs_film_samples(r->film);
        return RS_EXIT_OK;
    }
    if ((rc = rs_checkpoint_read(o->resume, &r->key, r->film, &r->held)) != RS_EXIT_OK)
        return rc;
    r->img.spp = r->st.spp = r->key.img.spp;
    r->resumed = rs_path_ranges_total(&r->held);
    if (o->megakernel)
        return rs_run_resume_whole_samples(o, r,
                                           "the megakernel continues whole passes only (use "
                                           "--integrator stream)");
    return RS_EXIT_OK;
}

/* Whether the render may trace on a GPU (or its fallback): --devices names one, or auto finds
 * one. */
static int any_gpu(const rs_cli_options *o)
{
    const char *why = "";
    int i;
    if (o->devices_auto)
        return rs_gpu_count(&why) > 0;
    for (i = 0; i < o->n_devices; ++i)
        if (o->devices[i].is_gpu)
            return 1;
    return 0;
}

/* The BVH over the geometry with the chosen intersection tests.  Returns an exit code. */
int rs_run_build_bvh(const rs_cli_options *o, render_run *r)
{
    rs_bvh_build_opts bo;
    double t0;
    r->geom = rs_scene_geom(r->scene);
    r->geom.sphere_algo = r->img.isect_sphere;
    r->geom.tri_algo = r->img.isect_tri;
    r->geom.aabb_algo = r->img.isect_aabb;
    memset(&bo, 0, sizeof bo);
    bo.builder = o->bvh;
    bo.threads = (uint32_t)r->threads;
    if (o->no_bvh) /* one leaf holding everything: each ray tests every primitive */
        bo.max_leaf = UINT32_MAX;
    else if (!any_gpu(o)) /* leaves the size of the CPU's wide tree's blocks, which test them
                             at once; a GPU's binary kernel keeps the classic SAH leaves */
        bo.leaf_block = bo.max_leaf = rs_bvh_wide_leaf_size(o->bvh_width, &r->geom);
    if (o->bvh_on_gpu) {
        const char *why = "";
        if (rs_gpu_count(&why) > 0)
            bo.lbvh_sort = rs_gpu_lbvh_sort; /* device 0 */
        else
            rs_app_print("raystream: warning: %s; the lbvh is built on the CPU\n", why);
    }
    t0 = rs_now_s();
    if (rs_bvh_build(&r->geom, &bo, &r->bvh) != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "building the BVH");
    rs_bvh_attach(r->bvh, &r->geom);
    r->bvh_ms = 1e3 * (rs_now_s() - t0);
    return RS_EXIT_OK;
}

/* The devices (one for the megakernel) with the scene uploaded to each.  Returns the count, or
 * -1 after a message. */
static int make_devices(const rs_cli_options *o, render_run *r)
{
    rs_device **devs = o->megakernel ? &r->mk : r->devs;
    int n = rs_devices_create(o, &r->fault, r->threads, o->megakernel ? NULL : &r->cores, devs);
    int i;
    if (n < 0)
        return -1;
    if (!o->megakernel)
        r->n_devs = n;
    for (i = 0; i < n; ++i)
        if (rs_device_upload(devs[i], &r->geom, r->bvh) != RS_OK) {
            char what[96];
            snprintf(what, sizeof what, "uploading the scene to %s", devs[i]->name);
            rs_app_fail(RS_EXIT_RUNTIME, what);
            return -1;
        }
    return n;
}

/* The devices, the scene uploaded to each, the timeline, the scheduler, the image, the engine.
 * Returns an exit code. */
int rs_run_start_devices(const rs_cli_options *o, render_run *r)
{
    int n = make_devices(o, r);
    rs_device *sched_devs[RS_MAX_DEVICES];
    int i, n_sched = 0, gpus = 0, trace_only = 0;
    if (n < 0)
        return RS_EXIT_RUNTIME;
    /* devices that run paths whole (a GPU, or its fallback; the CPU, each of its threads a wave
     * of its own) run the stream integrator's stages themselves, shading included, unless
     * --shade-on host keeps all shading on the host (the devices then only trace).  A device that
     * can only trace (one wrapped by RS_FAULT) needs the stream engine: the CPU then shades for
     * it and traces beside it there. */
    for (i = 0; !o->megakernel && i < n; ++i)
        trace_only += !r->devs[i]->ops->render_paths;
    for (i = 0; !o->megakernel && i < n; ++i) {
        rs_device *d = r->devs[i];
        if (!o->shade_host && d->ops->render_paths && r->n_pdev < RS_ENGINE_MAX_PATH_DEVICES &&
            !(trace_only && (d->flags & RS_DEVICE_HOST_PATHS)))
            r->pdev[r->n_pdev++] = d;
        else
            sched_devs[n_sched++] = d;
    }
    for (i = 0; i < r->n_pdev; ++i)
        gpus += !(r->pdev[i]->flags & RS_DEVICE_HOST_PATHS);
    if (gpus && (n_sched || gpus < r->n_pdev) && r->threads > 1) {
        /* each GPU's host thread waits on it with a core of its own; the CPU (the stream
         * engine, or the CPU device's own waves) has the rest */
        int left = r->threads - gpus > 0 ? r->threads - gpus : 1;
        rs_cores_init(&r->cores, left);
        r->st.threads = left;
    }
    /* about 200 spans per wave and device; the log never grows past this */
    if (o->timeline && rs_timeline_create(1u << 20, &r->timeline) != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "starting the timeline");
    r->st.timeline = r->timeline;
    r->st.timeline_lane = (uint16_t)(o->megakernel ? 1 : n);
    if (!o->megakernel && n_sched) {
        rs_sched_config cfg;
        memset(&cfg, 0, sizeof cfg);
        cfg.chunk_size = o->chunk_size;
        cfg.timeline = r->timeline;
        if (rs_sched_create(sched_devs, n_sched, &cfg, &r->sched) != RS_OK)
            return rs_app_fail(RS_EXIT_RUNTIME, "starting the render");
    }
    r->rgb = (float *)rs_alloc((size_t)r->st.width * r->st.height * 3, sizeof *r->rgb);
    if (!r->rgb) {
        rs_app_print("raystream: out of memory for a %ux%u image\n", r->st.width, r->st.height);
        return RS_EXIT_RUNTIME;
    }
    /* under mpirun the job's coordinator keeps the time (app/distributed.h) */
    r->st.time_limit_s = r->dist ? 0.0 : o->time_limit_s;
    if (r->n_pdev ? rs_engine_create_paths(r->scene, &r->st, r->sched, r->pdev, r->n_pdev,
                                           &r->engine) != RS_OK
                  : rs_engine_create(r->scene, &r->st, r->sched, r->mk, &r->engine) != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "starting the render");
    return RS_EXIT_OK;
}

rs_status rs_run_engine(render_run *r, const rs_render_hooks *hooks)
{
    rs_work_plan plan;
    rs_status rst;
    if (r->img.adaptive > 0) {
        rs_adaptive a;
        a.threshold = r->img.adaptive;
        a.min_spp = r->img.adaptive_min_spp;
        a.time_limit_s = r->st.time_limit_s;
        rst = rs_adaptive_run(r->engine, &a, &r->ad, hooks, r->film, &r->stats);
        r->adaptive = r->ad.stats;
        return rst;
    }
    memset(&plan, 0, sizeof plan);
    plan.time_limit_s = r->st.time_limit_s;
    if (!rs_path_ranges_complement(&r->held, (uint64_t)r->st.width * r->st.height * r->st.spp,
                                   &plan.todo))
        rst = rs_error_set(RS_ERR_NOMEM, "out of memory");
    else
        rst = rs_engine_run(r->engine, &plan, hooks, r->film, &r->stats);
    rs_work_plan_free(&plan);
    return rst;
}

void rs_run_release(render_run *r)
{
    int i;
    rs_tev_close(r->tev);
    rs_engine_destroy(r->engine);
    rs_sched_destroy(r->sched);
    for (i = 0; i < r->n_devs; ++i)
        rs_device_destroy(r->devs[i]);
    rs_device_destroy(r->mk);
    rs_timeline_destroy(r->timeline);
    rs_film_destroy(r->film);
    rs_free(r->rgb);
    rs_free(r->denoised);
    rs_bvh_destroy(r->bvh);
    rs_scene_destroy(r->scene);
    rs_path_ranges_free(&r->held);
    rs_adaptive_state_free(&r->ad);
}

/* What the film holds now: the paths held before and what the render under way added.  0 when
 * out of memory (after a message). */
static int film_ranges(const render_run *r, rs_path_ranges *out)
{
    memset(out, 0, sizeof *out);
    if (rs_path_ranges_union(out, &r->held) && (!r->done || rs_path_ranges_union(out, r->done)))
        return 1;
    rs_app_print("raystream: out of memory for the checkpoint's list of paths\n");
    rs_path_ranges_free(out);
    return 0;
}

int rs_run_write_checkpoint(const render_run *r, int rename_now)
{
    rs_path_ranges held;
    int ok;
    if (r->key.img.adaptive > 0) /* the film's counts and the adaptive state */
        return r->ad.running && rs_checkpoint_write_adaptive(r->ckpt_out->path, r->ckpt_out->staged,
                                                             rename_now, &r->key, r->film, &r->ad);
    if (!film_ranges(r, &held))
        return 0;
    ok = rs_checkpoint_write(r->ckpt_out->path, r->ckpt_out->staged, rename_now, &r->key, r->film,
                             &held);
    rs_path_ranges_free(&held);
    return ok;
}

