/* app/main.c — the `raystream` command: parses options, builds the scene, BVH, devices and
 * scheduler, runs the render with a progress bar, writes the image and prints a summary.
 * The only place that calls exit() (by returning from main) and that handles signals. */
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "app/options.h"
#include "app/progress.h"
#include "core/alloc.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "cpu/cpu_device.h"
#include "cpu/megakernel.h"
#include "gpu/gpu_device.h"
#include "scheduler/fault.h"
#include "scenes/builtin.h"
#include "scenes/scene_json.h"
#include "scheduler/render.h"

#ifndef RS_VERSION
#  define RS_VERSION "0.0.0"
#endif

static atomic_int g_cancel;

static void on_sigint(int sig)
{
    (void)sig;
    atomic_store(&g_cancel, 1);
}

static void install_sigint(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_sigint;
    sigemptyset(&sa.sa_mask);
    /* the first Ctrl-C asks for a clean stop; a second one kills as usual */
    sa.sa_flags = SA_RESETHAND;
    sigaction(SIGINT, &sa, NULL);
}

static int fail(int code, const char *what)
{
    const char *msg = rs_error_message();
    fprintf(stderr, "raystream: %s%s%s\n", what ? what : "", what && *msg ? ": " : "", msg);
    return code;
}

static int cmd_version(void)
{
    const char *why = "";
    int n;
    printf("raystream %s\n", RS_VERSION);
    if (rs_gpu_compiled()) {
        n = rs_gpu_count(&why);
        if (n > 0)
            printf("  CUDA:        yes (%d device%s)\n", n, n == 1 ? "" : "s");
        else
            printf("  CUDA:        yes, built in; no usable device (%s)\n", why);
    } else {
        printf("  CUDA:        no (built without the CUDA toolkit)\n");
    }
    if (RS_HAVE_OPENMP)
        printf("  OpenMP:      yes, %d threads available\n", rs_default_threads());
    else
        printf("  OpenMP:      no (compiled out for ThreadSanitizer); %d cores\n", rs_cpu_count());
    printf("  OpenImageIO: %s\n", rs_image_library_version());
    return RS_EXIT_OK;
}

static int cmd_scenes(void)
{
    int i;
    const char *name, *desc;
    for (i = 0; (name = rs_builtin_name(i, &desc)) != NULL; ++i)
        printf("builtin:%-12s %s\n", name, desc);
    return RS_EXIT_OK;
}

static void human(double v, char *buf, size_t n)
{
    if (v >= 1e9)
        snprintf(buf, n, "%.2f G", v / 1e9);
    else if (v >= 1e6)
        snprintf(buf, n, "%.2f M", v / 1e6);
    else if (v >= 1e3)
        snprintf(buf, n, "%.2f k", v / 1e3);
    else
        snprintf(buf, n, "%.0f ", v);
}

/* Creates the devices named on the command line (--devices auto: the CPU and every CUDA
 * device).  A gpu that cannot be used becomes the CPU fallback device (one warning line).  The
 * cores are shared out without oversubscription: each fallback takes one thread when a cpu
 * device is beside it (every core when it is alone), and a cpu device without an explicit
 * thread count gets the rest.  RS_FAULT (scheduler/fault.h) wraps devices that should fail.
 * Returns the count, or -1 after printing an error. */
static int create_devices(const rs_cli_options *o, int threads, rs_cores *cores, rs_device **devs)
{
    rs_device_spec specs[RS_MAX_DEVICES];
    int usable[RS_MAX_DEVICES];
    int i, n = 0, n_specs = 0, n_gpus, has_cpu = 0, fallback_threads = 0;
    const char *why = "";
    rs_fault_spec fault;

    if (rs_fault_parse(getenv("RS_FAULT"), &fault) != RS_OK) {
        fail(RS_EXIT_USAGE, NULL);
        return -1;
    }
    n_gpus = rs_gpu_count(&why);
    if (o->devices_auto) {
        memset(&specs[0], 0, sizeof specs[0]);
        n_specs = 1;
        for (i = 0; i < n_gpus && n_specs < RS_MAX_DEVICES; ++i) {
            memset(&specs[n_specs], 0, sizeof specs[0]);
            specs[n_specs].is_gpu = 1;
            specs[n_specs++].index = i;
        }
    } else {
        n_specs = o->n_devices;
        memcpy(specs, o->devices, (size_t)n_specs * sizeof specs[0]);
    }
    for (i = 0; i < n_specs; ++i)
        has_cpu |= !specs[i].is_gpu;
    for (i = 0; i < n_specs; ++i) {
        usable[i] = !specs[i].is_gpu || specs[i].index < n_gpus;
        if (!usable[i])
            fallback_threads += has_cpu ? 1 : threads;
    }
    for (i = 0; i < n_specs; ++i) {
        const rs_device_spec *d = &specs[i];
        rs_status st;
        if (!d->is_gpu) {
            rs_cpu_device_opts co;
            memset(&co, 0, sizeof co);
            co.threads = d->threads
                             ? d->threads
                             : (threads - fallback_threads > 1 ? threads - fallback_threads : 1);
            co.name = "cpu";
            co.bvh_width = o->no_bvh ? 2 : o->bvh_width; /* 4-wide leaves hold < 2^15 */
            co.cores = cores;
            co.strategy = o->strategy;
            st = rs_cpu_device_create_opts(&co, &devs[n]);
        } else {
            st = usable[i] ? rs_gpu_device_create(d->index, &devs[n]) : RS_ERR_DEVICE_LOST;
            if (st != RS_OK) {
                int ft = has_cpu ? 1 : threads;
                fprintf(stderr,
                        "raystream: warning: %s; gpu:%d runs on the CPU fallback (%d thread%s)\n",
                        usable[i] ? rs_error_message() : why, d->index, ft, ft == 1 ? "" : "s");
                rs_error_clear();
                st = rs_gpu_fallback_create(ft, d->index, cores, &devs[n]);
            }
        }
        if (st == RS_OK) {
            int after = d->is_gpu ? fault.gpu_after : fault.cpu_after;
            if (after >= 0)
                st = rs_fault_wrap(&devs[n], after);
            if (st != RS_OK)
                rs_device_destroy(devs[n]);
        }
        if (st != RS_OK) {
            while (n > 0)
                rs_device_destroy(devs[--n]);
            fail(RS_EXIT_RUNTIME, "creating devices");
            return -1;
        }
        n++;
    }
    return n;
}

/* Where --integrator megakernel runs: --devices cpu[:N] on the CPU (N threads); gpu[:INDEX] on that
 * CUDA device, or where it cannot be used on its host fallback (one warning); auto on CUDA device 0
 * where there is one, else the CPU. */
static void megakernel_device(const rs_cli_options *o, int threads, rs_megakernel_opts *mo)
{
    const char *why = "";
    int n_gpus = rs_gpu_count(&why);
    memset(mo, 0, sizeof *mo);
    mo->strategy = o->strategy;
    mo->bvh_width = o->no_bvh ? 2 : o->bvh_width;
    mo->device = RS_MK_CPU;
    if (o->devices_auto) {
        if (n_gpus > 0)
            mo->device = RS_MK_CUDA;
        return;
    }
    if (!o->devices[0].is_gpu)
        return;
    mo->gpu_index = o->devices[0].index;
    if (mo->gpu_index < n_gpus) {
        mo->device = RS_MK_CUDA;
        return;
    }
    fprintf(stderr,
            "raystream: warning: %s; the megakernel for gpu:%d runs on the CPU fallback (%d "
            "thread%s)\n",
            n_gpus == 0 ? why : "no such CUDA device", mo->gpu_index, threads,
            threads == 1 ? "" : "s");
    mo->device = RS_MK_GPU_FALLBACK;
}

/* The --stats table (stderr) and --stats-json file.  Returns 0 if the JSON file could not be
 * written (after printing why). */
static int report_stats(const rs_cli_options *o, rs_sched *sched, rs_device *const *devs,
                        int n_devs, const rs_render_stats *rstats, const rs_megakernel_opts *mk)
{
    rs_device_stats ds[RS_MAX_DEVICES];
    const char *names[RS_MAX_DEVICES];
    int alive[RS_MAX_DEVICES], threads[RS_MAX_DEVICES], i;
    uint64_t total = 0;
    double wall = rstats->seconds > 0 ? rstats->seconds : 1e-9;
    for (i = 0; i < n_devs; ++i) {
        rs_sched_device_stats(sched, i, &ds[i], &alive[i]);
        names[i] = devs[i]->name;
        threads[i] = devs[i]->threads;
        total += ds[i].rays;
    }
    if (!sched) { /* the megakernel: one device traced everything, one path at a time */
        static char name[128];
        memset(&ds[0], 0, sizeof ds[0]);
        ds[0].rays = total = rstats->rays_closest + rstats->rays_shadow;
        ds[0].busy_s = rstats->seconds;
        ds[0].bytes_to_device = mk->bytes_to_device;
        snprintf(name, sizeof name, "%s (megakernel)", mk->device_name);
        names[0] = name;
        threads[0] = mk->device == RS_MK_CUDA ? 0
                     : !o->devices_auto && !o->devices[0].is_gpu && o->devices[0].threads
                         ? o->devices[0].threads
                     : o->threads ? o->threads
                                  : rs_cpu_count();
        alive[0] = 1;
        n_devs = 1;
    }
    if (o->stats) {
        fprintf(stderr, "%-24s %14s %8s %9s %9s %9s %7s %12s %12s %s\n", "device", "rays", "chunks",
                "busy s", "idle s", "Mrays/s", "share", "bytes in", "bytes out", "state");
        for (i = 0; i < n_devs; ++i)
            fprintf(stderr, "%-24s %14llu %8llu %9.3f %9.3f %9.2f %6.1f%% %12llu %12llu %s\n",
                    names[i], (unsigned long long)ds[i].rays, (unsigned long long)ds[i].chunks,
                    ds[i].busy_s, ds[i].idle_s,
                    ds[i].busy_s > 0 ? (double)ds[i].rays / ds[i].busy_s / 1e6 : 0.0,
                    total ? 100.0 * (double)ds[i].rays / (double)total : 0.0,
                    (unsigned long long)ds[i].bytes_to_device,
                    (unsigned long long)ds[i].bytes_from_device, alive[i] ? "ok" : "failed");
    }
    if (o->stats_json) {
        FILE *f = fopen(o->stats_json, "w");
        if (!f) {
            fprintf(stderr, "raystream: %s: cannot write the stats\n", o->stats_json);
            return 0;
        }
        fprintf(f, "{\n  \"seconds\": %.6f,\n  \"rays\": %llu,\n  \"devices\": [\n", wall,
                (unsigned long long)total);
        for (i = 0; i < n_devs; ++i) {
            const char *c;
            fprintf(f, "    {\"name\": \"");
            for (c = names[i]; *c; ++c)
                if (*c == '"' || *c == '\\')
                    fprintf(f, "\\%c", *c);
                else if ((unsigned char)*c >= 0x20)
                    fputc(*c, f);
            fprintf(f,
                    "\", \"threads\": %d, \"rays\": %llu, \"chunks\": %llu, \"busy_s\": %.6f, "
                    "\"idle_s\": %.6f, \"mrays_per_s\": %.4f, \"share\": %.6f, "
                    "\"bytes_to_device\": %llu, \"bytes_from_device\": %llu, \"failures\": %llu, "
                    "\"failed\": %s}%s\n",
                    threads[i], (unsigned long long)ds[i].rays, (unsigned long long)ds[i].chunks,
                    ds[i].busy_s, ds[i].idle_s,
                    ds[i].busy_s > 0 ? (double)ds[i].rays / ds[i].busy_s / 1e6 : 0.0,
                    total ? (double)ds[i].rays / (double)total : 0.0,
                    (unsigned long long)ds[i].bytes_to_device,
                    (unsigned long long)ds[i].bytes_from_device, (unsigned long long)ds[i].failures,
                    alive[i] ? "false" : "true", i + 1 < n_devs ? "," : "");
        }
        fprintf(f, "  ]\n}\n");
        if (fclose(f) != 0) {
            fprintf(stderr, "raystream: %s: cannot write the stats\n", o->stats_json);
            return 0;
        }
    }
    return 1;
}

static int cmd_render(const rs_cli_options *o)
{
    rs_scene *scene = NULL;
    rs_bvh *bvh = NULL;
    rs_device *devs[RS_MAX_DEVICES];
    rs_sched *sched = NULL;
    rs_film *film = NULL;
    float *rgb = NULL;
    int n_devs = 0, i, code = RS_EXIT_OK, threads;
    char out_default[96], scene_stem[64];
    const char *out, *name;
    rs_render_settings st;
    rs_render_stats stats;
    rs_megakernel_opts mk;
    rs_render_hooks hooks;
    rs_progress progress;
    rs_sched_config cfg;
    rs_cores cores;
    rs_status rst;
    double t0, bvh_ms;
    rs_geom geom;
    rs_bvh_build_opts bvh_opts;
    char bvh_name[64];

    memset(&mk, 0, sizeof mk);
    /* ---- the scene ---- */
    if (strncmp(o->scene, "builtin:", 8) == 0) {
        rs_builtin_opts bo;
        rs_status bst;
        const char *slash, *dot;
        bo.models_dir = o->models;
        bo.mesh_file = o->mesh;
        name = o->scene + 8;
        bst = rs_builtin_create_ex(name, &bo, &scene);
        if (bst != RS_OK)
            return fail(bst == RS_ERR_ARG && !o->mesh ? RS_EXIT_USAGE : RS_EXIT_RUNTIME, NULL);
        if (o->mesh) {
            /* the default output is named after the mesh: bunny.ply -> bunny.png */
            slash = strrchr(o->mesh, '/');
            name = slash ? slash + 1 : o->mesh;
            dot = strrchr(name, '.');
            snprintf(scene_stem, sizeof scene_stem, "%.*s",
                     dot ? (int)(dot - name) : (int)strlen(name), name);
            name = scene_stem;
        }
    } else {
        struct stat sb;
        const char *slash = strrchr(o->scene, '/'), *dot;
        if (stat(o->scene, &sb) != 0) {
            fprintf(stderr,
                    "raystream: %s: no such scene file (built-in scenes are named "
                    "builtin:NAME; see 'raystream scenes')\n",
                    o->scene);
            return RS_EXIT_USAGE;
        }
        if (rs_scene_load_json(o->scene, &scene) != RS_OK)
            return fail(RS_EXIT_RUNTIME, NULL);
        /* the default output is named after the file: scenes/foo.json -> foo.png */
        name = slash ? slash + 1 : o->scene;
        dot = strrchr(name, '.');
        snprintf(scene_stem, sizeof scene_stem, "%.*s", dot ? (int)(dot - name) : (int)strlen(name),
                 name);
        name = scene_stem;
    }

    /* ---- settings ---- */
    memset(&st, 0, sizeof st);
    st.width = o->width ? o->width : scene->width;
    st.height = o->height ? o->height : scene->height;
    if (o->width && !o->height)
        st.height = (uint32_t)(0.5 + (double)o->width * scene->height / scene->width);
    if (!o->width && o->height)
        st.width = (uint32_t)(0.5 + (double)o->height * scene->width / scene->height);
    if (st.width < 1)
        st.width = 1;
    if (st.height < 1)
        st.height = 1;
    st.spp = o->spp;
    st.max_depth = o->max_depth;
    st.seed = o->seed;
    st.sampling = o->sampling;
    st.wave_paths = o->wave_paths;
    st.waves_in_flight = o->waves;
    threads = o->threads ? o->threads : rs_cpu_count();
    st.threads = threads;
    /* the CPU devices and the shading share `threads` cores (core/cores.h) */
    rs_cores_init(&cores, threads);
    st.cores = &cores;
    st.strategy = o->strategy;

    /* ---- the output is checked before any work ---- */
    if (o->output) {
        out = o->output;
    } else {
        snprintf(out_default, sizeof out_default, "%s.png", name);
        out = out_default;
    }
    rst = rs_image_check_output(out);
    if (rst != RS_OK) {
        rs_scene_destroy(scene);
        return fail(rst == RS_ERR_ARG ? RS_EXIT_USAGE : RS_EXIT_RUNTIME, NULL);
    }
    if (o->stats_json) {
        /* its folder must exist and be writable before the render starts */
        char dir[4096];
        const char *slash = strrchr(o->stats_json, '/');
        snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - o->stats_json) : 1,
                 slash ? (slash == o->stats_json ? "/" : o->stats_json) : ".");
        if (access(dir, W_OK) != 0) {
            fprintf(stderr,
                    "raystream: --stats-json %s: the folder %s does not exist or is not "
                    "writable\n",
                    o->stats_json, dir);
            rs_scene_destroy(scene);
            return RS_EXIT_USAGE;
        }
    }

    /* ---- BVH, devices, scheduler, film ---- */
    geom = rs_scene_geom(scene);
    geom.sphere_algo = o->isect_sphere;
    geom.tri_algo = o->isect_tri;
    geom.aabb_algo = o->isect_aabb;
    memset(&bvh_opts, 0, sizeof bvh_opts);
    bvh_opts.builder = o->bvh;
    bvh_opts.threads = (uint32_t)threads;
    if (o->no_bvh) /* one leaf holding everything: each ray tests every primitive */
        bvh_opts.max_leaf = UINT32_MAX;
    if (o->bvh_on_gpu) {
        const char *why = "";
        if (rs_gpu_count(&why) > 0) {
            bvh_opts.lbvh_sort = rs_gpu_lbvh_sort; /* device 0 */
        } else {
            fprintf(stderr, "raystream: warning: %s; the lbvh is built on the CPU\n", why);
        }
    }
    t0 = rs_now_s();
    if (rs_bvh_build(&geom, &bvh_opts, &bvh) != RS_OK) {
        code = fail(RS_EXIT_RUNTIME, "building the BVH");
        goto done;
    }
    bvh_ms = 1e3 * (rs_now_s() - t0);
    if (o->megakernel) {
        if (!o->devices_auto && !o->devices[0].is_gpu && o->devices[0].threads)
            st.threads = threads = o->devices[0].threads; /* --devices cpu:N */
        megakernel_device(o, threads, &mk);
        if (rs_film_create(st.width, st.height, &film) != RS_OK) {
            code = fail(RS_EXIT_RUNTIME, "starting the render");
            goto done;
        }
        goto render;
    }
    n_devs = create_devices(o, threads, &cores, devs);
    if (n_devs < 0) {
        n_devs = 0;
        code = RS_EXIT_RUNTIME;
        goto done;
    }
    for (i = 0; i < n_devs; ++i)
        if (rs_device_upload(devs[i], &geom, bvh) != RS_OK) {
            char what[96];
            snprintf(what, sizeof what, "uploading the scene to %s", devs[i]->name);
            code = fail(RS_EXIT_RUNTIME, what);
            goto done;
        }
    cfg.chunk_size = o->chunk_size;
    cfg.queue_capacity = 0;
    if (rs_sched_create(devs, n_devs, &cfg, &sched) != RS_OK ||
        rs_film_create(st.width, st.height, &film) != RS_OK) {
        code = fail(RS_EXIT_RUNTIME, "starting the render");
        goto done;
    }
render:
    rgb = (float *)rs_alloc((size_t)st.width * st.height * 3, sizeof *rgb);
    if (!rgb) {
        fprintf(stderr, "raystream: out of memory for a %ux%u image\n", st.width, st.height);
        code = RS_EXIT_RUNTIME;
        goto done;
    }

    /* ---- render ---- */
    install_sigint();
    rs_progress_begin(&progress, !o->quiet);
    hooks.progress = rs_progress_update;
    hooks.user = &progress;
    hooks.cancel = &g_cancel;
    if (o->megakernel) {
        rst = rs_render_megakernel(scene, &geom, bvh, &st, &mk, &hooks, film, &stats);
    } else {
        rst = rs_render(scene, sched, &st, &hooks, film, &stats);
    }
    rs_progress_end(&progress);
    signal(SIGINT, SIG_DFL);
    if (rst != RS_OK && rst != RS_ERR_CANCELLED) {
        code = fail(RS_EXIT_RUNTIME, "render failed");
        goto done;
    }
    if (rst == RS_ERR_CANCELLED) {
        rs_error_clear();
        code = RS_EXIT_INTERRUPTED;
    }

    /* ---- output ---- */
    rs_film_resolve(film, rgb);
    if (rs_image_write(out, st.width, st.height, rgb) != RS_OK) {
        code = fail(RS_EXIT_RUNTIME, NULL);
        goto done;
    }
    if ((o->stats || o->stats_json) && !report_stats(o, sched, devs, n_devs, &stats, &mk))
        code = RS_EXIT_RUNTIME;

    if (!o->quiet) {
        char sps[32], rps[32], rays[32];
        double secs = stats.seconds > 0 ? stats.seconds : 1e-9;
        uint64_t rays_total = stats.rays_closest + stats.rays_shadow;
        human((double)stats.paths_done / secs, sps, sizeof sps);
        human((double)rays_total / secs, rps, sizeof rps);
        human((double)rays_total, rays, sizeof rays);
        fprintf(stderr,
                "%s %s at %ux%u, %u spp (%s sampling, max depth %u, seed %llu) in %.2f s: "
                "%ssamples/s, %srays/s (%srays: %llu camera/bounce + %llu shadow). "
                "BVH (%s, SAH cost %.1f): %u nodes over %u primitives, built in %.2f ms. ",
                code == RS_EXIT_INTERRUPTED ? "Partial render (interrupted):" : "Rendered",
                o->scene, st.width, st.height, st.spp, rs_sampling_name(st.sampling), st.max_depth,
                (unsigned long long)st.seed, stats.seconds, sps, rps, rays,
                (unsigned long long)stats.rays_closest, (unsigned long long)stats.rays_shadow,
                rs_bvh_builder_name(&bvh->builder, bvh_name, sizeof bvh_name), rs_bvh_sah_cost(bvh),
                bvh->n_nodes, bvh->n_prims, bvh_ms);
        for (i = 0; i < n_devs; ++i) {
            rs_device_stats ds;
            int alive;
            rs_sched_device_stats(sched, i, &ds, &alive);
            human((double)ds.rays, rays, sizeof rays);
            fprintf(stderr, "%s %s (%d thread%s) traced %srays in %llu chunks (%.0f%%)%s%s",
                    i == 0 ? "Devices:" : ";", devs[i]->name, devs[i]->threads,
                    devs[i]->threads == 1 ? "" : "s", rays, (unsigned long long)ds.chunks,
                    rays_total ? 100.0 * (double)ds.rays / (double)rays_total : 0.0,
                    alive ? "" : " and then failed", i + 1 == n_devs ? ". " : "");
        }
        if (o->megakernel) {
            if (mk.device == RS_MK_CUDA)
                fprintf(stderr, "Integrator: megakernel on %s. ", mk.device_name);
            else
                fprintf(stderr, "Integrator: megakernel on %s (%s, %d thread%s). ", mk.device_name,
                        rs_par_strategy_name(o->strategy), threads, threads == 1 ? "" : "s");
        } else
            fprintf(stderr, "Shading took %.2f s, tracing %.2f s. ", stats.shade_s, stats.trace_s);
        if (film->nonfinite)
            fprintf(stderr, "%llu non-finite samples were dropped. ",
                    (unsigned long long)film->nonfinite);
        if (code == RS_EXIT_INTERRUPTED)
            fprintf(stderr, "Wrote %s with %llu of %llu samples (at least %u per pixel).\n", out,
                    (unsigned long long)stats.paths_done, (unsigned long long)stats.paths_total,
                    rs_film_min_count(film));
        else
            fprintf(stderr, "Wrote %s.\n", out);
    } else if (code == RS_EXIT_INTERRUPTED) {
        fprintf(stderr,
                "raystream: interrupted; wrote a partial image (%llu of %llu samples) to %s\n",
                (unsigned long long)stats.paths_done, (unsigned long long)stats.paths_total, out);
    }

done:
    rs_sched_destroy(sched);
    for (i = 0; i < n_devs; ++i)
        rs_device_destroy(devs[i]);
    rs_film_destroy(film);
    rs_free(rgb);
    rs_bvh_destroy(bvh);
    rs_scene_destroy(scene);
    return code;
}

int main(int argc, char **argv)
{
    rs_cli_options o;
    int rc = rs_cli_parse(argc, argv, &o);
    if (rc != RS_EXIT_OK)
        return rc;
    switch (o.command) {
    case RS_CMD_HELP: rs_cli_print_help(o.scene); return RS_EXIT_OK;
    case RS_CMD_VERSION: return cmd_version();
    case RS_CMD_SCENES: return cmd_scenes();
    case RS_CMD_RENDER: return cmd_render(&o);
    }
    return RS_EXIT_OK;
}
