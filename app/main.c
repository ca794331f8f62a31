/* app/main.c — the `raystream` command: parses options, builds the scene, BVH, devices and
 * scheduler, runs the render with a progress bar, writes the image and prints a summary.
 * The only place that calls exit() (by returning from main) and that handles signals. */
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "accel/bvh8.h"
#include "app/checkpoint.h"
#include "app/distributed.h"
#include "app/options.h"
#include "scheduler/adaptive.h"
#include "shading/aov.h"
#include "app/outputs.h"
#include "app/progress.h"
#include "core/alloc.h"
#include "core/file.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"
#include "app/timeline_svg.h"
#include "scenes/builtin.h"
#include "scenes/gltf.h"
#include "scenes/scene_export.h"
#include "scenes/scene_json.h"
#include "scheduler/fault.h"
#include "scheduler/render.h"

#ifndef RS_VERSION
#  define RS_VERSION "0.0.0"
#endif

/* The stop signals (SIGINT, SIGTERM, SIGHUP).  The first one asks for a clean stop: g_cancel,
 * which the render loop polls, and g_signal, its number, for the exit status (128 + it).  A
 * second one stops at once: the files being written (app/outputs.h, tracked before the first is
 * created) are removed and the program dies of that signal, as it would without a handler.
 * The handler may run on any thread; it touches only lock-free atomics and calls only
 * async-signal-safe functions (unlink, signal, raise). */
static atomic_int g_cancel;
static atomic_int g_signal;

static void on_stop_signal(int sig)
{
    int none = 0, saved_errno = errno; /* unlink may set it under the interrupted code's feet */
    if (atomic_compare_exchange_strong(&g_signal, &none, sig)) {
        atomic_store(&g_cancel, 1);
        return;
    }
    rs_outputs_remove_tracked();
    signal(sig, SIG_DFL);
    raise(sig); /* pending until the handler returns (the signal is blocked in it), then fatal */
    errno = saved_errno;
}

static const int k_stop_signals[] = {SIGINT, SIGTERM, SIGHUP};

/* A signal the caller ignores (nohup, a background job of a script) stays ignored. */
static void install_stop_signals(void)
{
    struct sigaction sa, old;
    size_t i;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    for (i = 0; i < sizeof k_stop_signals / sizeof k_stop_signals[0]; ++i)
        sigaddset(&sa.sa_mask, k_stop_signals[i]); /* one handler at a time */
    sa.sa_flags = SA_RESTART;
    for (i = 0; i < sizeof k_stop_signals / sizeof k_stop_signals[0]; ++i)
        if (sigaction(k_stop_signals[i], NULL, &old) == 0 && old.sa_handler != SIG_IGN)
            sigaction(k_stop_signals[i], &sa, NULL);
}

static const char *signal_name(int sig)
{
    switch (sig) {
    case SIGINT: return "SIGINT";
    case SIGTERM: return "SIGTERM";
    case SIGHUP: return "SIGHUP";
    default: return "a signal";
    }
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
    if (rs_dist_built())
        printf("  MPI:         yes (mpirun -n N raystream render ...; docs/distributed.md)\n");
    else
        printf("  MPI:         no (built without MPI: RS_MPI, libopenmpi-dev)\n");
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
 * thread count gets the rest.  `fault` (RS_FAULT, scheduler/fault.h) wraps devices that should
 * fail.
 * Returns the count, or -1 after printing an error. */
static int create_devices(const rs_cli_options *o, const rs_fault_spec *fault, int threads,
                          rs_cores *cores, rs_device **devs)
{
    rs_device_spec specs[RS_MAX_DEVICES];
    int usable[RS_MAX_DEVICES];
    int i, n = 0, n_specs = 0, n_gpus, has_cpu = 0, fallback_threads = 0;
    const char *why = "";

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
            int after = d->is_gpu ? fault->gpu_after : fault->cpu_after;
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

/* The one device --integrator megakernel runs on: --devices cpu[:N] the CPU device (N threads);
 * gpu[:INDEX] that CUDA device, or where it cannot be used its host fallback (one warning); auto
 * CUDA device 0 where there is one, else the CPU.  Returns 0 after printing an error. */
static int create_megakernel_device(const rs_cli_options *o, int threads, rs_device **out)
{
    const char *why = "";
    int n_gpus = rs_gpu_count(&why), gpu = -1;
    rs_status st;
    if (o->devices_auto)
        gpu = n_gpus > 0 ? 0 : -1;
    else if (o->devices[0].is_gpu)
        gpu = o->devices[0].index;
    if (gpu < 0) {
        rs_cpu_device_opts co;
        memset(&co, 0, sizeof co);
        co.threads = threads;
        co.name = "cpu";
        co.bvh_width = o->no_bvh ? 2 : o->bvh_width;
        co.strategy = o->strategy;
        st = rs_cpu_device_create_opts(&co, out);
    } else if (gpu < n_gpus && (st = rs_gpu_device_create(gpu, out)) == RS_OK) {
        /* the CUDA device */
    } else {
        fprintf(stderr,
                "raystream: warning: %s; the megakernel for gpu:%d runs on the CPU fallback (%d "
                "thread%s)\n",
                gpu < n_gpus  ? rs_error_message()
                : n_gpus == 0 ? why
                              : "no such CUDA device",
                gpu, threads, threads == 1 ? "" : "s");
        rs_error_clear();
        st = rs_gpu_fallback_create(threads, gpu, NULL, out);
    }
    if (st != RS_OK) {
        fail(RS_EXIT_RUNTIME, "creating the device");
        return 0;
    }
    return 1;
}

/* Everything one `raystream render` makes, released by run_release. */
typedef struct render_run {
    rs_scene *scene;
    rs_bvh *bvh;
    rs_geom geom;
    double bvh_ms;
    rs_device *devs[RS_MAX_DEVICES]; /* the stream engine's devices */
    int n_devs;
    rs_device *mk; /* the megakernel's one device */
    rs_sched *sched;
    rs_engine *engine; /* set up once; every plan of the render runs on it */
    rs_film *film;
    rs_timeline *timeline;
    float *rgb;
    rs_cores cores;
    int threads;
    rs_render_settings st;
    rs_render_stats stats;
    rs_adaptive_stats adaptive; /* --adaptive: rounds, samples, pixels stopped */
    double adaptive_t;          /* --adaptive's threshold, 0: off */
    char name[64]; /* the scene's stem: default output name */
    char out_default[96];
    const char *out;
    rs_fault_spec fault;            /* RS_FAULT */
    rs_output outs[RS_OUTPUTS_MAX]; /* the image, then --stats-json and --timeline if asked */
    int n_outs;
    rs_output *stats_out, *timeline_out; /* into outs, or NULL */
    rs_output *ckpt_out;                 /* --checkpoint, into outs, or NULL */
    int interrupted;                     /* the signal that stopped the render, or 0 */
    rs_checkpoint_key key;               /* what decides the image, for --checkpoint/--resume */
    uint64_t resumed;                    /* paths the --resume file held */
    rs_path_ranges held;                 /* paths the film held before the render under way */
    const rs_path_ranges *done;          /* ... and what the render has added (the engine's) */
    double last_ckpt;                    /* when the last checkpoint was written (rs_now_s) */
    double ckpt_every_s;                 /* --checkpoint-interval */
    rs_progress progress;
    rs_dist *dist;        /* under mpirun (app/distributed.h), or NULL */
    int rank;             /* this process's rank (0 without MPI) */
    int local_ranks;      /* ranks on this machine: they share its cores */
    rs_dist_result dres;  /* rank 0: the job's result */
    rs_dist_fault dist_fault; /* RS_MPI_FAULT */
} render_run;

static void run_release(render_run *r)
{
    int i;
    rs_engine_destroy(r->engine);
    rs_sched_destroy(r->sched);
    for (i = 0; i < r->n_devs; ++i)
        rs_device_destroy(r->devs[i]);
    rs_device_destroy(r->mk);
    rs_timeline_destroy(r->timeline);
    rs_film_destroy(r->film);
    rs_free(r->rgb);
    rs_bvh_destroy(r->bvh);
    rs_scene_destroy(r->scene);
    rs_path_ranges_free(&r->held);
}

/* What the film holds now: the paths held before and what the render under way added.  0 when
 * out of memory (after a message). */
static int film_ranges(const render_run *r, rs_path_ranges *out)
{
    memset(out, 0, sizeof *out);
    if (rs_path_ranges_union(out, &r->held) && (!r->done || rs_path_ranges_union(out, r->done)))
        return 1;
    fprintf(stderr, "raystream: out of memory for the checkpoint's list of paths\n");
    rs_path_ranges_free(out);
    return 0;
}

/* Writes the checkpoint of the film as it is now (see film_ranges). */
static int write_checkpoint(const render_run *r, int rename_now)
{
    rs_path_ranges held;
    int ok;
    if (!film_ranges(r, &held))
        return 0;
    ok = rs_checkpoint_write(r->ckpt_out->path, r->ckpt_out->staged, rename_now, &r->key,
                             r->film, &held);
    rs_path_ranges_free(&held);
    return ok;
}

/* The stem of a file name: dir/bunny.ply -> bunny. */
static void file_stem(const char *path, char *out, size_t n)
{
    const char *slash = strrchr(path, '/'), *name = slash ? slash + 1 : path;
    const char *dot = strrchr(name, '.');
    snprintf(out, n, "%.*s", dot ? (int)(dot - name) : (int)strlen(name), name);
}

/* The scene: a built-in one (with --mesh, named after the mesh) or a JSON file.  Returns an
 * exit code. */
static int load_scene(const rs_cli_options *o, render_run *r)
{
    if (strncmp(o->scene, "builtin:", 8) == 0) {
        rs_builtin_opts bo;
        rs_status bst;
        struct stat sb;
        if (o->mesh && stat(o->mesh, &sb) == 0 && S_ISDIR(sb.st_mode)) {
            fprintf(stderr, "raystream: --mesh %s: is a folder, not a mesh file\n", o->mesh);
            return RS_EXIT_USAGE;
        }
        bo.models_dir = o->models;
        bo.mesh_file = o->mesh;
        bo.log = o->quiet ? NULL : stderr;
        bst = rs_builtin_create_ex(o->scene + 8, &bo, &r->scene);
        if (bst != RS_OK)
            return fail(bst == RS_ERR_ARG && !o->mesh ? RS_EXIT_USAGE : RS_EXIT_RUNTIME, NULL);
        if (o->mesh)
            file_stem(o->mesh, r->name, sizeof r->name);
        else
            snprintf(r->name, sizeof r->name, "%s", o->scene + 8);
        return RS_EXIT_OK;
    }
    {
        struct stat sb;
        if (stat(o->scene, &sb) != 0) {
            fprintf(stderr,
                    "raystream: %s: no such scene file (built-in scenes are named "
                    "builtin:NAME; see 'raystream scenes')\n",
                    o->scene);
            return RS_EXIT_USAGE;
        }
        if (S_ISDIR(sb.st_mode)) {
            fprintf(stderr, "raystream: %s: is a folder, not a scene file\n", o->scene);
            return RS_EXIT_USAGE;
        }
    }
    if (rs_is_gltf_path(o->scene)) {
        rs_gltf_opts go;
        go.camera = o->camera;
        go.log = o->quiet ? NULL : stderr;
        if (rs_scene_load_gltf(o->scene, &go, &r->scene) != RS_OK)
            return fail(RS_EXIT_RUNTIME, NULL);
    } else if (rs_scene_load_json_ex(o->scene, o->quiet ? NULL : stderr, &r->scene) != RS_OK) {
        return fail(RS_EXIT_RUNTIME, NULL);
    }
    if (o->flatten_instances && r->scene->n_instances &&
        (rs_scene_flatten_instances(r->scene) != RS_OK || rs_scene_finalize(r->scene) != RS_OK))
        return fail(RS_EXIT_RUNTIME, "flattening the instances");
    file_stem(o->scene, r->name, sizeof r->name);
    return RS_EXIT_OK;
}

/* --envmap FILE: the scene's background becomes the map, sampled as a light. */
static int apply_envmap(const rs_cli_options *o, render_run *r)
{
    uint32_t image;
    if (!o->envmap)
        return RS_EXIT_OK;
    if (rs_file_check(o->envmap, RS_FILE_MAX_IMAGE_BYTES, NULL) != RS_OK ||
        rs_scene_load_image(r->scene, o->envmap, &image) != RS_OK ||
        rs_scene_set_environment(r->scene, image, rs_v3_splat(o->envmap_scale), NULL) != RS_OK ||
        rs_scene_finalize(r->scene) != RS_OK) {
        char msg[600];
        snprintf(msg, sizeof msg, "%s", rs_error_message());
        rs_error_clear();
        if (strncmp(msg, o->envmap, strlen(o->envmap)) != 0)
            rs_error_set(RS_ERR_ARG, "--envmap %s: %s", o->envmap, msg);
        else
            rs_error_set(RS_ERR_ARG, "--envmap %s", msg);
        return fail(RS_EXIT_RUNTIME, NULL);
    }
    return RS_EXIT_OK;
}

/* A last bound on reading the inputs.  Every file is checked before it is opened (core/file.h)
 * and the one known spin of a library (Assimp on a cut PLY header) is caught before the file is
 * handed over, but a parser of some other format may still spin on a malformed file.  Should
 * loading take longer than this, the run ends with one line naming the input and exit status 1
 * instead of hanging; nothing has been written yet.  Far above any real load (the 100k-triangle
 * dragon loads in about a second here). */
#define LOAD_LIMIT_S 600

typedef struct load_watch {
    pthread_mutex_t mu;
    pthread_cond_t cv;
    int done;
    const char *what;
} load_watch;

static void *load_watch_main(void *arg)
{
    load_watch *w = (load_watch *)arg;
    struct timespec until;
    clock_gettime(CLOCK_MONOTONIC, &until);
    until.tv_sec += LOAD_LIMIT_S;
    pthread_mutex_lock(&w->mu);
    while (!w->done)
        if (pthread_cond_timedwait(&w->cv, &w->mu, &until) == ETIMEDOUT && !w->done) {
            fprintf(stderr,
                    "raystream: %s: still reading after %d s, giving up (a malformed file?)\n",
                    w->what, LOAD_LIMIT_S);
            _exit(RS_EXIT_RUNTIME); /* the loader may hold any lock: no exit handlers */
        }
    pthread_mutex_unlock(&w->mu);
    return NULL;
}

/* load_scene under the watch above (unwatched if the watch cannot be started). */
static int load_scene_bounded(const rs_cli_options *o, render_run *r)
{
    load_watch w;
    pthread_condattr_t ca;
    pthread_t t;
    int code, watching;
    memset(&w, 0, sizeof w);
    w.what = o->mesh ? o->mesh : o->scene;
    pthread_mutex_init(&w.mu, NULL);
    pthread_condattr_init(&ca);
    pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
    pthread_cond_init(&w.cv, &ca);
    pthread_condattr_destroy(&ca);
    watching = pthread_create(&t, NULL, load_watch_main, &w) == 0;
    code = load_scene(o, r);
    if (code == RS_EXIT_OK)
        code = apply_envmap(o, r);
    if (watching) {
        pthread_mutex_lock(&w.mu);
        w.done = 1;
        pthread_cond_signal(&w.cv);
        pthread_mutex_unlock(&w.mu);
        pthread_join(t, NULL);
    }
    pthread_cond_destroy(&w.cv);
    pthread_mutex_destroy(&w.mu);
    return code;
}

/* The render settings from the options and the scene's own size. */
static void make_settings(const rs_cli_options *o, render_run *r)
{
    rs_render_settings *st = &r->st;
    const rs_scene *scene = r->scene;
    memset(st, 0, sizeof *st);
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
    st->spp = o->spp;
    st->max_depth = o->max_depth;
    st->seed = o->seed;
    st->sampling = o->sampling;
    st->sampler = o->sampler;
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
static int check_outputs(const rs_cli_options *o, render_run *r)
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
        return fail(RS_EXIT_USAGE, NULL);
    return RS_EXIT_OK;
}

/* A --resume whose ranges all end on whole samples: RS_EXIT_OK, else one line ending in
 * `what` and RS_EXIT_USAGE. */
static int resume_whole_samples(const rs_cli_options *o, const render_run *r, const char *what)
{
    uint64_t npix = (uint64_t)r->st.width * r->st.height;
    uint32_t i;
    for (i = 0; i < r->held.n; ++i)
        if (r->held.r[i][1] % npix != 0) {
            fprintf(stderr,
                    "raystream: --resume %s: stopped within a sample (%llu paths of %ux%u "
                    "pixels); %s\n",
                    o->resume, (unsigned long long)r->held.r[i][1], r->st.width, r->st.height,
                    what);
            return RS_EXIT_USAGE;
        }
    return RS_EXIT_OK;
}

/* The film: a fresh one, or with --resume the checkpoint's (app/checkpoint.h), checked against
 * these settings before any work; the render then starts at the first path it does not hold.
 * --resume without --spp continues to the spp the checkpoint was started with.  Returns an exit
 * code. */
static int make_film(const rs_cli_options *o, render_run *r)
{
    rs_checkpoint_key *k = &r->key;
    int rc;
    memset(k, 0, sizeof *k);
    /* hashing every byte of a large scene takes a tenth of a second (the living room's 143k
     * triangles and 5 MB of textures): only where a checkpoint is written or read */
    if (o->checkpoint || o->resume)
        k->scene_hash = rs_checkpoint_scene_hash(r->scene);
    k->seed = r->st.seed;
    k->width = r->st.width;
    k->height = r->st.height;
    k->spp = r->st.spp;
    k->max_depth = r->st.max_depth;
    k->rr_depth = r->st.rr_depth ? r->st.rr_depth : 3;
    k->sampling = (uint32_t)r->st.sampling;
    k->sampler = (uint32_t)r->st.sampler;
    k->isect_sphere = o->isect_sphere;
    k->isect_tri = o->isect_tri;
    k->isect_aabb = o->isect_aabb;
    k->scene = o->scene;
    if (rs_film_create(r->st.width, r->st.height, &r->film) != RS_OK)
        return fail(RS_EXIT_RUNTIME, "starting the render");
    if (!o->resume)
        return RS_EXIT_OK;
    if (!o->spp_given)
        k->spp = 0; /* the file's */
    if ((rc = rs_checkpoint_read(o->resume, k, r->film, &r->held)) != RS_EXIT_OK)
        return rc;
    r->st.spp = k->spp;
    r->resumed = rs_path_ranges_total(&r->held);
    if (o->megakernel)
        return resume_whole_samples(o, r, "the megakernel continues whole passes only (use "
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
static int build_bvh(const rs_cli_options *o, render_run *r)
{
    rs_bvh_build_opts bo;
    double t0;
    r->geom = rs_scene_geom(r->scene);
    r->geom.sphere_algo = o->isect_sphere;
    r->geom.tri_algo = o->isect_tri;
    r->geom.aabb_algo = o->isect_aabb;
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
            fprintf(stderr, "raystream: warning: %s; the lbvh is built on the CPU\n", why);
    }
    t0 = rs_now_s();
    if (rs_bvh_build(&r->geom, &bo, &r->bvh) != RS_OK)
        return fail(RS_EXIT_RUNTIME, "building the BVH");
    rs_bvh_attach(r->bvh, &r->geom);
    r->bvh_ms = 1e3 * (rs_now_s() - t0);
    return RS_EXIT_OK;
}

/* The devices (one for the megakernel), the scene uploaded to each, the scheduler, the film,
 * the timeline.  Returns an exit code. */
static int start_devices(const rs_cli_options *o, render_run *r)
{
    rs_device **devs = o->megakernel ? &r->mk : r->devs;
    int n, i;
    if (o->megakernel) {
        if (!create_megakernel_device(o, r->threads, &r->mk))
            return RS_EXIT_RUNTIME;
        n = 1;
    } else {
        n = create_devices(o, &r->fault, r->threads, &r->cores, r->devs);
        if (n < 0)
            return RS_EXIT_RUNTIME;
        r->n_devs = n;
    }
    for (i = 0; i < n; ++i)
        if (rs_device_upload(devs[i], &r->geom, r->bvh) != RS_OK) {
            char what[96];
            snprintf(what, sizeof what, "uploading the scene to %s", devs[i]->name);
            return fail(RS_EXIT_RUNTIME, what);
        }
    /* about 200 spans per wave and device; the log never grows past this */
    if (o->timeline && rs_timeline_create(1u << 20, &r->timeline) != RS_OK)
        return fail(RS_EXIT_RUNTIME, "starting the timeline");
    r->st.timeline = r->timeline;
    r->st.timeline_lane = (uint16_t)(o->megakernel ? 1 : n);
    if (!o->megakernel) {
        rs_sched_config cfg;
        memset(&cfg, 0, sizeof cfg);
        cfg.chunk_size = o->chunk_size;
        cfg.timeline = r->timeline;
        if (rs_sched_create(r->devs, n, &cfg, &r->sched) != RS_OK)
            return fail(RS_EXIT_RUNTIME, "starting the render");
    }
    r->rgb = (float *)rs_alloc((size_t)r->st.width * r->st.height * 3, sizeof *r->rgb);
    if (!r->rgb) {
        fprintf(stderr, "raystream: out of memory for a %ux%u image\n", r->st.width, r->st.height);
        return RS_EXIT_RUNTIME;
    }
    /* under mpirun the job's coordinator keeps the time (app/distributed.h) */
    r->st.time_limit_s = r->dist ? 0.0 : o->time_limit_s;
    if (rs_engine_create(r->scene, &r->st, r->sched, r->mk, &r->engine) != RS_OK)
        return fail(RS_EXIT_RUNTIME, "starting the render");
    return RS_EXIT_OK;
}

/* The render itself, with the progress bar and the stop signals (which stay caught until the
 * program ends: a second one while the outputs are written removes their temporary files).
 * Returns an exit code: 128 + the signal for an interrupted render. */
static void on_progress(void *user, uint64_t done, uint64_t total)
{
    rs_progress_update(&((render_run *)user)->progress, done, total);
}

/* The render thread, whenever the film holds what it held plus `done`: a periodic checkpoint.
 * A failed one is reported and the render goes on (the last good file stays). */
static void on_film_ready(void *user, const rs_film *film, const rs_path_ranges *done)
{
    render_run *r = (render_run *)user;
    double now;
    (void)film;
    r->done = done;
    if (!r->ckpt_out || (now = rs_now_s()) - r->last_ckpt < r->ckpt_every_s ||
        rs_path_ranges_total(&r->held) + rs_path_ranges_total(done) ==
            (uint64_t)r->st.width * r->st.height * r->st.spp)
        return; /* the last is written at the end */
    r->last_ckpt = now;
    (void)write_checkpoint(r, 1);
}


static int run_render(const rs_cli_options *o, render_run *r)
{
    rs_render_hooks hooks;
    rs_status rst;
    install_stop_signals();
    rs_progress_begin(&r->progress, !o->quiet);
    memset(&hooks, 0, sizeof hooks);
    hooks.progress = on_progress;
    hooks.user = r;
    hooks.cancel = &g_cancel;
    r->ckpt_every_s = o->ckpt_every_s;
    r->last_ckpt = rs_now_s();
    if (r->ckpt_out) {
        hooks.film_ready = on_film_ready;
        rs_outputs_track(r->ckpt_out->staged); /* a second signal during a periodic write */
    }
    if (o->adaptive > 0) {
        rs_adaptive a;
        a.threshold = r->adaptive_t = o->adaptive;
        a.min_spp = o->adaptive_min_spp;
        rst = rs_render_adaptive(r->engine, &a, &hooks, r->film, &r->stats, &r->adaptive);
    } else {
        /* what the film lacks: everything, or the gaps of a --resume */
        rs_work_plan plan;
        memset(&plan, 0, sizeof plan);
        if (!rs_path_ranges_complement(&r->held, (uint64_t)r->st.width * r->st.height * r->st.spp,
                                       &plan.todo))
            rst = rs_error_set(RS_ERR_NOMEM, "out of memory");
        else
            rst = rs_engine_run(r->engine, &plan, &hooks, r->film, &r->stats);
        rs_work_plan_free(&plan);
    }
    r->done = rs_engine_done(r->engine);
    rs_progress_end(&r->progress);
    if (rst == RS_ERR_CANCELLED) {
        rs_error_clear();
        r->interrupted = atomic_load(&g_signal) ? atomic_load(&g_signal) : SIGINT;
        return RS_EXIT_SIGNALLED(r->interrupted);
    }
    if (rst != RS_OK)
        return fail(RS_EXIT_RUNTIME, "render failed");
    return RS_EXIT_OK;
}

/* Per device: its counters, name and threads, for --stats and --stats-json. */
typedef struct device_rows {
    rs_device_stats ds[RS_MAX_DEVICES];
    char names[RS_MAX_DEVICES][80];
    int alive[RS_MAX_DEVICES], threads[RS_MAX_DEVICES];
    int n;
    uint64_t total;
} device_rows;

static void collect_rows(const render_run *r, device_rows *t)
{
    int i;
    memset(t, 0, sizeof *t);
    if (r->mk) { /* the megakernel: one device traced everything, one path at a time */
        t->ds[0].rays = t->total = r->stats.rays_closest + r->stats.rays_shadow;
        t->ds[0].busy_s = r->stats.seconds;
        t->ds[0].chunks = r->stats.waves;
        t->ds[0].bytes_to_device = r->mk->stats.bytes_to_device;
        snprintf(t->names[0], sizeof t->names[0], "%s (megakernel)", r->mk->name);
        t->threads[0] = r->mk->threads;
        t->alive[0] = 1;
        t->n = 1;
        return;
    }
    for (i = 0; i < r->n_devs; ++i) {
        rs_sched_device_stats(r->sched, i, &t->ds[i], &t->alive[i]);
        snprintf(t->names[i], sizeof t->names[i], "%s", r->devs[i]->name);
        t->threads[i] = r->devs[i]->threads;
        t->total += t->ds[i].rays;
    }
    t->n = r->n_devs;
}

static void print_stats_table(const render_run *r, const device_rows *t)
{
    int i;
    fprintf(stderr, "%-24s %14s %8s %9s %9s %9s %7s %12s %12s %s\n", "device", "rays", "chunks",
            "busy s", "idle s", "Mrays/s", "share", "bytes in", "bytes out", "state");
    for (i = 0; i < t->n; ++i) {
        const rs_device_stats *d = &t->ds[i];
        fprintf(stderr, "%-24s %14llu %8llu %9.3f %9.3f %9.2f %6.1f%% %12llu %12llu %s\n",
                t->names[i], (unsigned long long)d->rays, (unsigned long long)d->chunks, d->busy_s,
                d->idle_s, d->busy_s > 0 ? (double)d->rays / d->busy_s / 1e6 : 0.0,
                t->total ? 100.0 * (double)d->rays / (double)t->total : 0.0,
                (unsigned long long)d->bytes_to_device, (unsigned long long)d->bytes_from_device,
                t->alive[i] ? "ok" : "failed");
    }
    if (r->dist) {
        const rs_dist_result *d = &r->dres;
        fprintf(stderr, "%-5s %-34s %7s %12s %9s %9s %10s %12s %s\n", "rank", "host: devices",
                "passes", "samples", "busy s", "idle", "samples/s", "film bytes", "state");
        for (i = 0; i < d->ranks; ++i) {
            const rs_dist_rank_stats *k = &d->rank[i];
            double idle = k->wall_s > 0 ? 1.0 - k->busy_s / k->wall_s : 0.0;
            fprintf(stderr, "%-5d %-34.34s %7u %12llu %9.3f %8.1f%% %10.0f %12llu %s\n", i,
                    k->desc, k->passes, (unsigned long long)k->paths, k->busy_s,
                    100.0 * (idle > 0 ? idle : 0.0),
                    k->busy_s > 0 ? (double)k->paths / k->busy_s : 0.0,
                    (unsigned long long)k->film_bytes,
                    !k->alive ? "lost" : k->failed ? "failed" : "ok");
        }
        fprintf(stderr, "(the device and stage rows are rank 0's)\n");
    }
    fprintf(stderr, "%-24s %9s %7s\n", "stage (render thread)", "s", "share");
    for (i = 0; i < RS_STAGE_COUNT; ++i)
        if (r->stats.stage_s[i] > 0)
            fprintf(stderr, "%-24s %9.3f %6.1f%%\n", rs_stage_name((rs_stage)i),
                    r->stats.stage_s[i],
                    r->stats.seconds > 0 ? 100.0 * r->stats.stage_s[i] / r->stats.seconds : 0.0);
}

static void json_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (; *s; ++s)
        if (*s == '"' || *s == '\\')
            fprintf(f, "\\%c", *s);
        else if ((unsigned char)*s >= 0x20)
            fputc(*s, f);
    fputc('"', f);
}

/* Writes the --stats-json text to `path` (named `shown` in messages).  Returns 0 after printing
 * why the file could not be written. */
static int write_stats_json(const char *path, const char *shown, const render_run *r,
                            const device_rows *t)
{
    double wall = r->stats.seconds > 0 ? r->stats.seconds : 1e-9;
    FILE *f = fopen(path, "w");
    int i, ok;
    if (!f) {
        fprintf(stderr, "raystream: %s: cannot write the stats (%s)\n", shown, strerror(errno));
        return 0;
    }
    /* spp: what every pixel has (the image's samples per pixel); samples: the film's total */
    fprintf(f,
            "{\n  \"seconds\": %.6f,\n  \"rays\": %llu,\n  \"spp\": %u,\n  \"spp_requested\": %u,\n"
            "  \"samples\": %llu,\n  \"resumed_samples\": %llu,\n  \"time_limited\": %s,\n"
            "  \"interrupted\": %s,\n  \"adaptive\": %g,\n  \"adaptive_rounds\": %u,\n"
            "  \"pixels_stopped_early\": %u,\n  \"stages\": {",
            wall, (unsigned long long)t->total, rs_film_min_count(r->film), r->st.spp,
            (unsigned long long)(r->resumed + r->stats.paths_done), (unsigned long long)r->resumed,
            r->stats.time_limited ? "true" : "false", r->interrupted ? "true" : "false",
            r->adaptive_t, r->adaptive.rounds, r->adaptive.stopped);
    for (i = 0; i < RS_STAGE_COUNT; ++i)
        fprintf(f, "%s\"%s\": %.9f", i ? ", " : "", rs_stage_name((rs_stage)i),
                r->stats.stage_s[i]);
    fprintf(f, "},\n  \"devices\": [\n");
    for (i = 0; i < t->n; ++i) {
        const rs_device_stats *d = &t->ds[i];
        fprintf(f, "    {\"name\": ");
        json_string(f, t->names[i]);
        fprintf(f,
                ", \"threads\": %d, \"rays\": %llu, \"chunks\": %llu, \"busy_s\": %.6f, "
                "\"idle_s\": %.6f, \"mrays_per_s\": %.4f, \"share\": %.6f, "
                "\"bytes_to_device\": %llu, \"bytes_from_device\": %llu, \"failures\": %llu, "
                "\"failed\": %s}%s\n",
                t->threads[i], (unsigned long long)d->rays, (unsigned long long)d->chunks,
                d->busy_s, d->idle_s, d->busy_s > 0 ? (double)d->rays / d->busy_s / 1e6 : 0.0,
                t->total ? (double)d->rays / (double)t->total : 0.0,
                (unsigned long long)d->bytes_to_device, (unsigned long long)d->bytes_from_device,
                (unsigned long long)d->failures, t->alive[i] ? "false" : "true",
                i + 1 < t->n ? "," : "");
    }
    fprintf(f, "  ]");
    if (r->dist) {
        const rs_dist_result *d = &r->dres;
        fprintf(f,
                ",\n  \"mpi\": {\"ranks\": %d, \"pass_spp\": %u, \"passes\": %u, "
                "\"reissued\": %u, \"ranks_lost\": %d, \"bytes_received\": %llu, "
                "\"messages\": %llu, \"message_bytes\": %llu, "
                "\"rays\": %llu, \"complete\": %s, \"flushes\": %u,\n    \"per_rank\": [\n",
                d->ranks, d->pass_spp, d->passes_total, d->reissued, d->dead,
                (unsigned long long)d->bytes_received, (unsigned long long)d->messages,
                (unsigned long long)d->message_bytes,
                (unsigned long long)(d->rays_closest + d->rays_shadow),
                d->complete ? "true" : "false", d->flushes);
        for (i = 0; i < d->ranks; ++i) {
            const rs_dist_rank_stats *k = &d->rank[i];
            double idle = k->wall_s > 0 ? 1.0 - k->busy_s / k->wall_s : 0.0;
            fprintf(f, "      {\"rank\": %d, \"desc\": ", i);
            json_string(f, k->desc);
            fprintf(f,
                    ", \"passes\": %u, \"samples\": %llu, \"busy_s\": %.6f, "
                    "\"wall_s\": %.6f, \"idle_share\": %.6f, \"samples_per_s\": %.3f, "
                    "\"film_bytes\": %llu, \"comm_cpu_s\": %.6f, \"lost\": %s, "
                    "\"failed\": %s}%s\n",
                    k->passes, (unsigned long long)k->paths, k->busy_s, k->wall_s,
                    idle > 0 ? idle : 0.0, k->busy_s > 0 ? (double)k->paths / k->busy_s : 0.0,
                    (unsigned long long)k->film_bytes, k->comm_cpu_s, k->alive ? "false" : "true",
                    k->failed ? "true" : "false", i + 1 < d->ranks ? "," : "");
        }
        fprintf(f, "    ]}");
    }
    fprintf(f, "\n}\n");
    ok = !ferror(f);
    if (fclose(f) != 0 || !ok) {
        fprintf(stderr, "raystream: %s: cannot write the stats (%s)\n", shown, strerror(errno));
        return 0;
    }
    return 1;
}

/* The --timeline picture, a lane per device, then the render thread's, into `path`.  0 after
 * printing why. */
static int write_timeline(const char *path, const rs_cli_options *o, const render_run *r,
                          const device_rows *t)
{
    char lanes[RS_MAX_DEVICES + 1][96], title[160];
    const char *names[RS_MAX_DEVICES + 1];
    int i;
    for (i = 0; i < t->n; ++i) {
        if (t->threads[i] > 0)
            snprintf(lanes[i], sizeof lanes[i], "%s (%d thread%s)", t->names[i], t->threads[i],
                     t->threads[i] == 1 ? "" : "s");
        else
            snprintf(lanes[i], sizeof lanes[i], "%s", t->names[i]);
        names[i] = lanes[i];
    }
    snprintf(lanes[t->n], sizeof lanes[t->n], "shading (render thread)");
    names[t->n] = lanes[t->n];
    snprintf(title, sizeof title, "raystream render %s, %ux%u, %u spp, %s integrator", o->scene,
             r->st.width, r->st.height, r->st.spp, o->megakernel ? "megakernel" : "stream");
    if (rs_timeline_write_svg(path, r->timeline, names, t->n + 1, title) != RS_OK) {
        fail(RS_EXIT_RUNTIME, NULL);
        return 0;
    }
    return 1;
}

/* The summary line on stderr (or, with --quiet, only a word on an interruption). */
static void print_summary(const rs_cli_options *o, const render_run *r)
{
    char sps[32], rps[32], rays[32], bvh_name[64], spp[200], inst[160] = "";
    double secs = r->stats.seconds > 0 ? r->stats.seconds : 1e-9;
    uint64_t rays_total = r->stats.rays_closest + r->stats.rays_shadow;
    const rs_render_settings *st = &r->st;
    int i;
    if (o->quiet) {
        if (r->interrupted)
            fprintf(stderr,
                    "raystream: interrupted by %s; wrote a partial image (%llu of %llu samples) "
                    "to %s\n",
                    signal_name(r->interrupted), (unsigned long long)r->stats.paths_done,
                    (unsigned long long)r->stats.paths_total, r->out);
        return;
    }
    human((double)r->stats.paths_done / secs, sps, sizeof sps);
    human((double)rays_total / secs, rps, sizeof rps);
    human((double)rays_total, rays, sizeof rays);
    if (o->adaptive > 0) {
        size_t npix = (size_t)st->width * st->height;
        snprintf(spp, sizeof spp,
                 "%.1f spp on average, %u to %u (adaptive to %g in %u rounds: %.1f%% of the "
                 "pixels stopped early%s)",
                 npix ? (double)r->adaptive.samples / (double)npix : 0.0,
                 rs_film_min_count(r->film), st->spp, o->adaptive, r->adaptive.rounds,
                 npix ? 100.0 * r->adaptive.stopped / (double)npix : 0.0,
                 r->stats.time_limited ? "; stopped at the --time-limit" : "");
    } else if (r->stats.time_limited)
        snprintf(spp, sizeof spp, "%u of %u spp (stopped at the --time-limit of %g s)",
                 rs_film_min_count(r->film), st->spp, o->time_limit_s);
    else
        snprintf(spp, sizeof spp, "%u spp", st->spp);
    if (r->scene->n_instances)
        snprintf(inst, sizeof inst,
                 " (%u of them instances placing %u triangles; bottom levels: %u nodes over %u "
                 "shared triangles)",
                 r->scene->n_instances, r->scene->n_inst_prims, r->bvh->n_blas_nodes,
                 r->scene->n_inst_tris);
    fprintf(stderr,
            "%s %s at %ux%u, %s (%s sampling, %s sampler, max depth %u, seed %llu) in %.2f s: "
            "%ssamples/s, %srays/s (%srays: %llu camera/bounce + %llu shadow). "
            "BVH (%s, SAH cost %.1f): %u nodes over %u primitives%s, built in %.2f ms. ",
            r->interrupted ? "Partial render (interrupted):" : "Rendered", o->scene, st->width,
            st->height, spp, rs_sampling_name(st->sampling), rs_sampler_name(st->sampler),
            st->max_depth, (unsigned long long)st->seed, r->stats.seconds, sps, rps, rays,
            (unsigned long long)r->stats.rays_closest, (unsigned long long)r->stats.rays_shadow,
            rs_bvh_builder_name(&r->bvh->builder, bvh_name, sizeof bvh_name),
            rs_bvh_sah_cost(r->bvh), r->bvh->n_nodes, r->bvh->n_prims, inst, r->bvh_ms);
    for (i = 0; i < r->n_devs; ++i) {
        rs_device_stats ds;
        int alive;
        rs_sched_device_stats(r->sched, i, &ds, &alive);
        human((double)ds.rays, rays, sizeof rays);
        fprintf(stderr, "%s %s (%d thread%s) traced %srays in %llu chunks (%.0f%%)%s%s",
                i == 0 ? "Devices:" : ";", r->devs[i]->name, r->devs[i]->threads,
                r->devs[i]->threads == 1 ? "" : "s", rays, (unsigned long long)ds.chunks,
                rays_total ? 100.0 * (double)ds.rays / (double)rays_total : 0.0,
                alive ? "" : " and then failed", i + 1 == r->n_devs ? ". " : "");
    }
    if (r->mk && rs_device_is_gpu(r->mk))
        fprintf(stderr, "Integrator: megakernel on %s. ", r->mk->name);
    else if (r->mk)
        fprintf(stderr, "Integrator: megakernel on %s (%s, %d thread%s). ", r->mk->name,
                rs_par_strategy_name(o->strategy), r->mk->threads, r->mk->threads == 1 ? "" : "s");
    else
        fprintf(stderr, "Shading took %.2f s, tracing %.2f s. ", r->stats.shade_s,
                r->stats.trace_s);
    if (r->dist)
        fprintf(stderr,
                "MPI: %d ranks took %u passes of %u spp (rank 0: %u)%s%s; %.1f MB of films "
                "came to rank 0. ",
                r->dres.ranks, r->dres.passes_total, r->dres.pass_spp, r->dres.rank[0].passes,
                r->dres.dead ? ", ranks were lost" : "",
                r->dres.reissued ? ", passes were handed out again" : "",
                (double)r->dres.bytes_received / 1e6);
    if (r->film->nonfinite)
        fprintf(stderr, "%llu non-finite samples were dropped. ",
                (unsigned long long)r->film->nonfinite);
    if (o->resume)
        fprintf(stderr, "Continued from %s (%llu samples). ", o->resume,
                (unsigned long long)r->resumed);
    if (r->ckpt_out)
        fprintf(stderr, "Checkpoint %s holds %llu samples. ", r->ckpt_out->path,
                (unsigned long long)(rs_path_ranges_total(&r->held) +
                                     (r->done ? rs_path_ranges_total(r->done) : 0)));
    if (r->interrupted)
        fprintf(stderr, "Wrote %s with %llu of %llu samples (at least %u per pixel).\n", r->out,
                (unsigned long long)(r->stats.paths_done + r->resumed),
                (unsigned long long)(r->stats.paths_total + r->resumed),
                rs_film_min_count(r->film));
    else
        fprintf(stderr, "Wrote %s.\n", r->out);
}

/* What the image's header records of the render (.exr only, core/image_io.h): the scene, the
 * spp every pixel has and the spp asked for, seed, sampling, sampler, max depth, devices,
 * integrator, version.  Strings into `text` (which must outlive meta). */
enum { META_N = 11 };
typedef struct image_meta {
    rs_image_meta meta[META_N];
    char spp[16], spp_requested[16], seed[24], depth[16], devices[RS_MAX_DEVICES * 48];
    char adaptive[32];
} image_meta;

static void make_image_meta(const rs_cli_options *o, const render_run *r, image_meta *m)
{
    static const char *const keys[META_N] = {
        "raystream:scene",      "raystream:spp",     "raystream:spp_requested", "raystream:seed",
        "raystream:sampling",   "raystream:sampler", "raystream:max_depth",     "raystream:devices",
        "raystream:integrator", "raystream:version", "raystream:adaptive"};
    const char *values[META_N];
    size_t used = 0;
    int i;
    snprintf(m->spp, sizeof m->spp, "%u", rs_film_min_count(r->film));
    snprintf(m->spp_requested, sizeof m->spp_requested, "%u", r->st.spp);
    snprintf(m->seed, sizeof m->seed, "%llu", (unsigned long long)r->st.seed);
    snprintf(m->depth, sizeof m->depth, "%u", r->st.max_depth);
    m->devices[0] = '\0';
    for (i = 0; i < (r->mk ? 1 : r->n_devs); ++i) {
        const rs_device *d = r->mk ? r->mk : r->devs[i];
        int k =
            snprintf(m->devices + used, sizeof m->devices - used, "%s%s", i ? "," : "", d->name);
        if (k < 0 || (size_t)k >= sizeof m->devices - used)
            break;
        used += (size_t)k;
    }
    values[0] = o->scene;
    values[1] = m->spp;
    values[2] = m->spp_requested;
    values[3] = m->seed;
    values[4] = rs_sampling_name(r->st.sampling);
    values[5] = rs_sampler_name(r->st.sampler);
    values[6] = m->depth;
    values[7] = m->devices;
    values[8] = o->megakernel ? "megakernel" : "stream";
    values[9] = RS_VERSION;
    if (o->adaptive > 0)
        snprintf(m->adaptive, sizeof m->adaptive, "%g", o->adaptive);
    else
        snprintf(m->adaptive, sizeof m->adaptive, "off");
    values[10] = m->adaptive;
    for (i = 0; i < META_N; ++i) {
        m->meta[i].key = keys[i];
        m->meta[i].value = values[i];
    }
}

/* The outputs, all or none: the stats JSON and the timeline to their staged names, then the
 * image (rs_image_write: its own temporary file, renamed into place), then the staged files
 * renamed.  A failure before the image is in place replaces nothing; a --stats-json that is a
 * special file (/dev/stdout) is written last, in place.  Every name is tracked first, so a second
 * signal removes whichever exist.  Returns the exit code: `code`, or RS_EXIT_RUNTIME. */
/* The --aov layers of the finished render (shading/aov.h) into layers[], their buffers in
 * bufs[] (rs_free them); returns how many, or -1 after a message. */
static int make_aovs(const rs_cli_options *o, const render_run *r, rs_image_layer *layers,
                     float **bufs)
{
    size_t npix = (size_t)r->st.width * r->st.height;
    rs_integrator it;
    int n = 0;
    uint32_t i;
    bufs[0] = bufs[1] = bufs[2] = bufs[3] = NULL;
    if (!o->aovs)
        return 0;
    if (o->aovs & RS_AOV_ALBEDO)
        bufs[0] = (float *)rs_alloc(npix * 3, sizeof(float));
    if (o->aovs & RS_AOV_NORMAL)
        bufs[1] = (float *)rs_alloc(npix * 3, sizeof(float));
    if (o->aovs & RS_AOV_DEPTH)
        bufs[2] = (float *)rs_alloc(npix, sizeof(float));
    if (o->aovs & RS_AOV_SAMPLES)
        bufs[3] = (float *)rs_alloc(npix, sizeof(float));
    if (((o->aovs & RS_AOV_ALBEDO) && !bufs[0]) || ((o->aovs & RS_AOV_NORMAL) && !bufs[1]) ||
        ((o->aovs & RS_AOV_DEPTH) && !bufs[2]) || ((o->aovs & RS_AOV_SAMPLES) && !bufs[3])) {
        rs_error_set(RS_ERR_NOMEM, "out of memory for the --aov layers");
        return -1;
    }
    if (o->aovs & (RS_AOV_ALBEDO | RS_AOV_NORMAL | RS_AOV_DEPTH)) {
        rs_bvh_view v = rs_bvh_view_of(r->bvh);
        if (rs_render_constants(r->scene, &r->st, &it) != RS_OK)
            return -1;
        rs_aov_render(&it, &v, &r->geom, r->st.spp, r->threads, bufs[0], bufs[1], bufs[2]);
    }
    if (bufs[3])
        for (i = 0; i < npix; ++i)
            bufs[3][i] = (float)r->film->count[i];
    if (bufs[0]) {
        layers[n].name = "albedo", layers[n].channels = "RGB", layers[n++].data = bufs[0];
    }
    if (bufs[1]) {
        layers[n].name = "normal", layers[n].channels = "XYZ", layers[n++].data = bufs[1];
    }
    if (bufs[2]) {
        layers[n].name = "depth", layers[n].channels = "Z", layers[n++].data = bufs[2];
    }
    if (bufs[3]) {
        layers[n].name = "samples", layers[n].channels = "Y", layers[n++].data = bufs[3];
    }
    return n;
}

static int write_outputs(const rs_cli_options *o, render_run *r, int code)
{
    rs_image_layer layers[4];
    float *aov_bufs[4];
    int n_layers;
    device_rows rows;
    image_meta meta;
    char timeline_inner[RS_OUTPUT_PATH_MAX + 8];
    int i, ok = 1, replaced = 0;
    rs_film_resolve(r->film, r->rgb);
    collect_rows(r, &rows);
    if (o->stats)
        print_stats_table(r, &rows);
    for (i = 0; i < r->n_outs; ++i)
        if (!r->outs[i].in_place)
            rs_outputs_track(r->outs[i].staged); /* outs[0]'s is the core's image temporary */
    if (r->timeline_out) {                       /* rs_timeline_write_svg's own temporary name */
        snprintf(timeline_inner, sizeof timeline_inner, "%s.tmp", r->timeline_out->staged);
        rs_outputs_track(timeline_inner);
    }
    if (r->stats_out && !r->stats_out->in_place)
        ok = write_stats_json(r->stats_out->staged, r->stats_out->path, r, &rows);
    if (ok && r->timeline_out)
        ok = write_timeline(r->timeline_out->staged, o, r, &rows);
    if (ok && r->ckpt_out) /* renamed below with the others */
        ok = write_checkpoint(r, 0);
    make_image_meta(o, r, &meta);
    n_layers = ok ? make_aovs(o, r, layers, aov_bufs) : 0;
    if (n_layers < 0) {
        fail(0, NULL);
        ok = 0;
        n_layers = 0;
    }
    if (ok && rs_image_write_layers(r->out, r->st.width, r->st.height, r->rgb, layers,
                                    (size_t)n_layers, meta.meta, META_N) != RS_OK) {
        fail(0, NULL);
        ok = 0;
    }
    for (i = 0; i < 4; ++i)
        if (o->aovs)
            rs_free(aov_bufs[i]);
    replaced = ok;
    for (i = 1; ok && i < r->n_outs; ++i)
        if (!r->outs[i].in_place)
            ok = rs_output_commit(&r->outs[i]);
    if (ok && r->stats_out && r->stats_out->in_place)
        ok = write_stats_json(r->stats_out->path, r->stats_out->path, r, &rows);
    rs_outputs_remove_tracked(); /* what was not renamed */
    rs_outputs_untrack();
    if (!ok) {
        fprintf(stderr, "raystream: the run failed; %s\n",
                replaced ? "some outputs were already replaced" : "no output was replaced");
        return RS_EXIT_RUNTIME;
    }
    print_summary(o, r);
    return code;
}

/* ---- under mpirun (app/distributed.h) ------------------------------------------------------ */

/* One pass of an MPI job: samples [s0, s0 + n) of every pixel onto `film`, on this rank's
 * devices, from its render thread. */
static rs_status dist_render_pass(void *user, uint32_t s0, uint32_t n, rs_film *film,
                                  const atomic_int *cancel, rs_render_stats *stats)
{
    render_run *r = (render_run *)user;
    rs_render_hooks h;
    rs_work_plan plan;
    rs_status st;
    memset(&h, 0, sizeof h);
    h.cancel = cancel;
    if (!rs_work_plan_samples(&plan, (uint64_t)r->st.width * r->st.height, s0, s0 + n))
        st = rs_error_set(RS_ERR_NOMEM, "out of memory");
    else
        st = rs_engine_run(r->engine, &plan, &h, film, stats);
    rs_work_plan_free(&plan);
    return st;
}

/* "host: cpu (2 threads), gpu0" */
static void dist_describe(const render_run *r, char *out, size_t n)
{
    char host[64] = "?";
    size_t len;
    int i;
    gethostname(host, sizeof host - 1);
    host[sizeof host - 1] = 0;
    len = (size_t)snprintf(out, n, "%s:", host);
    for (i = 0; i < (r->mk ? 1 : r->n_devs) && len < n; ++i) {
        const rs_device *d = r->mk ? r->mk : r->devs[i];
        len += (size_t)snprintf(out + len, n - len, "%s %s", i ? "," : "", d->name);
    }
}

/* The options an MPI job cannot honour yet, refused by rank 0 (the others stay quiet). */
static int dist_check_options(const rs_cli_options *o, int rank, rs_dist_fault *fault)
{
    const char *what = NULL;
    if (rs_dist_fault_parse(getenv("RS_MPI_FAULT"), fault) != RS_OK) {
        if (rank == 0)
            fail(0, NULL);
        rs_error_clear();
        return RS_EXIT_USAGE;
    }
    if (o->adaptive > 0)
        what = "--adaptive (its rounds depend on the whole film)";
    else if (o->aovs)
        what = "--aov";
    if (!what)
        return RS_EXIT_OK;
    if (rank == 0)
        fprintf(stderr, "raystream: %s is not supported under mpirun yet; run one process\n",
                what);
    return RS_EXIT_USAGE;
}

/* Every rank: scene, settings, BVH, devices; rank 0 also the outputs and the film (with
 * --resume).  The others' messages are held back until the ranks agree: when rank 0 failed too
 * it has said why, and only a rank that failed alone shows its own.  Returns the job's exit
 * code, the same on every rank. */
static int dist_setup(const rs_cli_options *o, render_run *r)
{
    int code, worst, who = 0, saved = -1;
    FILE *held = NULL;
    char desc[RS_DIST_DESC];
    if ((code = dist_check_options(o, r->rank, &r->dist_fault)) != RS_EXIT_OK)
        return code;
    if (r->rank > 0) {
        fflush(stderr);
        if ((held = tmpfile()) != NULL && (saved = dup(2)) >= 0)
            dup2(fileno(held), 2);
    }
    code = load_scene_bounded(o, r);
    if (code == RS_EXIT_OK) {
        make_settings(o, r);
        if (r->rank == 0) {
            if ((code = check_outputs(o, r)) == RS_EXIT_OK)
                code = make_film(o, r);
        } else if (rs_film_create(r->st.width, r->st.height, &r->film) != RS_OK) {
            code = fail(RS_EXIT_RUNTIME, "starting the render");
        }
    }
    if (code == RS_EXIT_OK && r->rank == 0)
        code = resume_whole_samples(o, r, "under mpirun a render continues whole samples only "
                                          "(resume it on one process)");
    if (code == RS_EXIT_OK && (code = build_bvh(o, r)) == RS_EXIT_OK)
        code = start_devices(o, r);
    desc[0] = 0;
    if (code == RS_EXIT_OK)
        dist_describe(r, desc, sizeof desc);
    if (held) {
        fflush(stderr);
        if (saved >= 0) {
            dup2(saved, 2);
            close(saved);
        }
    }
    worst = rs_dist_agree(r->dist, code, &who, desc);
    if (held) {
        if (code != RS_EXIT_OK && who == r->rank) { /* rank 0 started: say why this one did not */
            char line[512];
            rewind(held);
            while (fgets(line, sizeof line, held))
                fprintf(stderr, "raystream: rank %d: %s", r->rank,
                        strncmp(line, "raystream: ", 11) == 0 ? line + 11 : line);
        }
        fclose(held);
    }
    if (worst != RS_EXIT_OK && r->rank == 0 && code == RS_EXIT_OK)
        fprintf(stderr, "raystream: rank %d could not start (its message is above); no rank "
                        "renders\n",
                who);
    return worst;
}

static void on_dist_progress(void *user, uint64_t done, uint64_t total)
{
    rs_progress_update(&((render_run *)user)->progress, done, total);
}

/* The film held r->held, plus the job's finished passes `done` (whole samples). */
static int dist_held(render_run *r, const uint32_t (*done)[2], uint32_t n_done,
                     rs_path_ranges *out)
{
    uint64_t npix = (uint64_t)r->st.width * r->st.height;
    uint32_t i;
    memset(out, 0, sizeof *out);
    if (!rs_path_ranges_union(out, &r->held))
        return 0;
    for (i = 0; i < n_done; ++i)
        if (!rs_path_ranges_add(out, npix * done[i][0], npix * (done[i][0] + done[i][1])))
            return 0;
    return 1;
}

/* rank 0, after each periodic flush of an MPI job: the --checkpoint */
static void on_dist_saved(void *user, const rs_film *film, const uint32_t (*done)[2],
                          uint32_t n_done)
{
    render_run *r = (render_run *)user;
    rs_path_ranges held;
    if (dist_held(r, done, n_done, &held))
        (void)rs_checkpoint_write(r->ckpt_out->path, r->ckpt_out->staged, 1, &r->key, film,
                                  &held);
    rs_path_ranges_free(&held);
}

/* The job: rank 0 hands out the passes and gathers the films, every rank renders.  Rank 0 then
 * has the frame and the statistics in r.  Returns an exit code. */
static int dist_run(const rs_cli_options *o, render_run *r)
{
    rs_dist_job job;
    rs_status st;
    uint64_t npix = (uint64_t)r->st.width * r->st.height;
    uint32_t(*todo)[2] = NULL, n_todo = 0, i;
    install_stop_signals();
    memset(&job, 0, sizeof job);
    job.fault = r->dist_fault;
    job.width = r->st.width;
    job.height = r->st.height;
    job.spp = r->st.spp;
    /* the samples the film lacks (all of them, or the gaps of a --resume) */
    if (r->rank == 0) {
        rs_path_ranges lack;
        memset(&lack, 0, sizeof lack);
        todo = rs_calloc((size_t)r->held.n + 1, sizeof *todo);
        if (!todo || !rs_path_ranges_complement(&r->held, npix * r->st.spp, &lack)) {
            rs_free(todo);
            rs_path_ranges_free(&lack);
            return fail(RS_EXIT_RUNTIME, "out of memory");
        }
        /* every range starts and ends on whole samples (checked at --resume) */
        for (i = 0; i < lack.n; ++i) {
            todo[n_todo][0] = (uint32_t)(lack.r[i][0] / npix);
            todo[n_todo++][1] = (uint32_t)((lack.r[i][1] - lack.r[i][0]) / npix);
        }
        rs_path_ranges_free(&lack);
    }
    job.todo = (const uint32_t(*)[2])todo;
    job.n_todo = n_todo;
    if (r->ckpt_out) {
        job.flush_every_s = o->ckpt_every_s;
        job.saved = on_dist_saved;
    }
    job.pass_spp = o->mpi_pass_spp;
    job.time_limit_s = o->time_limit_s;
    job.timeout_s = o->mpi_timeout_s;
    job.cancel = &g_cancel;
    job.render = dist_render_pass;
    job.user = r;
    if (r->rank == 0)
        job.progress = on_dist_progress;
    if (r->rank == 0)
        rs_progress_begin(&r->progress, !o->quiet);
    st = rs_dist_render(r->dist, &job, r->film, &r->dres);
    rs_free(todo);
    if (r->rank == 0)
        rs_progress_end(&r->progress);
    if (r->rank > 0)
        return st == RS_OK ? RS_EXIT_OK : fail(RS_EXIT_RUNTIME, NULL);
    /* rank 0: the job as one render's statistics */
    r->stats = r->dres.local;
    r->stats.seconds = r->dres.seconds;
    r->stats.paths_total = npix * r->st.spp - r->resumed;
    r->stats.paths_done = npix * r->dres.samples_done;
    r->stats.rays_closest = r->dres.rays_closest;
    r->stats.rays_shadow = r->dres.rays_shadow;
    r->stats.max_bounce = r->dres.max_bounce;
    r->stats.time_limited = r->dres.time_limited;
    if (st != RS_OK)
        return fail(RS_EXIT_RUNTIME, "render failed");
    {
        /* what the film holds now, for the final checkpoint (app/checkpoint.h: any ranges) */
        rs_path_ranges now;
        if (!dist_held(r, (const uint32_t(*)[2])r->dres.done, r->dres.n_done, &now)) {
            rs_path_ranges_free(&now);
            return fail(RS_EXIT_RUNTIME, "out of memory");
        }
        rs_path_ranges_free(&r->held);
        r->held = now;
        r->done = NULL;
    }
    if (r->dres.stopped) {
        r->interrupted = atomic_load(&g_signal) ? atomic_load(&g_signal) : SIGTERM;
        return RS_EXIT_SIGNALLED(r->interrupted);
    }
    return RS_EXIT_OK;
}

static int cmd_render_dist(const rs_cli_options *o, render_run *r)
{
    int code = dist_setup(o, r);
    if (code != RS_EXIT_OK)
        return code;
    code = dist_run(o, r);
    if (r->rank == 0 && (code == RS_EXIT_OK || r->interrupted))
        code = write_outputs(o, r, code);
    rs_dist_result_free(&r->dres);
    return code;
}

/* Whether an MPI launcher started this process: then r->dist (and 1), or an exit code. */
static int start_dist(int *argc, char ***argv, render_run *r, int *code)
{
    int ranks = 1, rank = 0, local = 1;
    *code = RS_EXIT_OK;
    if (!rs_dist_launched(&ranks, &rank, &local))
        return 0;
    if (!rs_dist_built()) {
        if (ranks <= 1)
            return 0;
        if (rank == 0)
            fprintf(stderr, "raystream: started by mpirun as %d ranks, but this raystream was "
                            "built without MPI (install libopenmpi-dev and rebuild; "
                            "RS_MPI=AUTO finds it): every rank would render the whole frame\n",
                    ranks);
        *code = RS_EXIT_USAGE;
        return 1;
    }
    if (rs_dist_init(argc, argv, &r->dist) != RS_OK) {
        *code = fail(RS_EXIT_RUNTIME, "starting MPI");
        return 1;
    }
    r->rank = rs_dist_rank(r->dist);
    r->local_ranks = local;
    return 1;
}

/* `raystream render`: scene, settings, outputs checked, BVH, devices, render, outputs. */
static int cmd_render(const rs_cli_options *o, int *argc, char ***argv)
{
    render_run r;
    int code;
    memset(&r, 0, sizeof r);
    if (start_dist(argc, argv, &r, &code)) {
        if (r.dist) {
            rs_cli_options wo = *o;
            if (r.rank > 0)
                wo.quiet = 1; /* rank 0 shows the progress and the summary */
            if (rs_fault_parse(getenv("RS_FAULT"), &r.fault) != RS_OK)
                code = fail(RS_EXIT_USAGE, NULL);
            else
                code = cmd_render_dist(&wo, &r);
            run_release(&r);
            rs_dist_finish(r.dist);
        }
        return code;
    }
    /* RS_FAULT is input like the options: a bad value is a usage error, before any work */
    if (rs_fault_parse(getenv("RS_FAULT"), &r.fault) != RS_OK)
        return fail(RS_EXIT_USAGE, NULL);
    if ((code = load_scene_bounded(o, &r)) == RS_EXIT_OK) {
        make_settings(o, &r);
        if ((code = check_outputs(o, &r)) == RS_EXIT_OK &&
            (code = make_film(o, &r)) == RS_EXIT_OK && (code = build_bvh(o, &r)) == RS_EXIT_OK &&
            (code = start_devices(o, &r)) == RS_EXIT_OK) {
            code = run_render(o, &r);
            if (code == RS_EXIT_OK || r.interrupted)
                code = write_outputs(o, &r, code);
        }
    }
    run_release(&r);
    return code;
}

/* raystream export SCENE -o FILE.json */
static int cmd_export(const rs_cli_options *o)
{
    render_run r;
    int code;
    size_t n = o->output ? strlen(o->output) : 0;
    if (!o->output || n < 5 || strcmp(o->output + n - 5, ".json") != 0) {
        fprintf(stderr, "raystream: export needs -o FILE.json\n");
        return RS_EXIT_USAGE;
    }
    memset(&r, 0, sizeof r);
    if ((code = load_scene_bounded(o, &r)) == RS_EXIT_OK) {
        /* the format's instances are written as the copies they render as */
        if (r.scene->n_instances && (rs_scene_flatten_instances(r.scene) != RS_OK ||
                                     rs_scene_finalize(r.scene) != RS_OK))
            code = fail(RS_EXIT_RUNTIME, NULL);
        else if (rs_scene_export_json(r.scene, o->output) != RS_OK)
            code = fail(RS_EXIT_RUNTIME, NULL);
        else if (!o->quiet)
            fprintf(stderr, "raystream: wrote %s (%u spheres, %u quads, %u triangles)\n",
                    o->output, r.scene->n_spheres, r.scene->n_quads, r.scene->n_tris);
    }
    run_release(&r);
    return code;
}

int main(int argc, char **argv)
{
    rs_cli_options o;
    int rc;
    /* A reader that goes away (`raystream render ... 2>&1 | head -1`) must not kill the render:
     * writes to stdout or stderr then fail with EPIPE, which nothing here treats as fatal. */
    signal(SIGPIPE, SIG_IGN);
    {
        /* under mpirun every rank parses the same line: only rank 0 tells what is wrong */
        int ranks, rank = 0, local, saved = -1, quiet;
        quiet = rs_dist_launched(&ranks, &rank, &local) && rank > 0;
        if (quiet) {
            int null = open("/dev/null", O_WRONLY);
            fflush(stderr);
            if (null >= 0 && (saved = dup(2)) >= 0)
                dup2(null, 2);
            if (null >= 0)
                close(null);
        }
        rc = rs_cli_parse(argc, argv, &o);
        if (saved >= 0) {
            fflush(stderr);
            dup2(saved, 2);
            close(saved);
        }
    }
    if (rc != RS_EXIT_OK)
        return rc;
    switch (o.command) {
    case RS_CMD_HELP: rs_cli_print_help(o.scene); return RS_EXIT_OK;
    case RS_CMD_VERSION: return cmd_version();
    case RS_CMD_SCENES: return cmd_scenes();
    case RS_CMD_RENDER: return cmd_render(&o, &argc, &argv);
    case RS_CMD_EXPORT: return cmd_export(&o);
    }
    return RS_EXIT_OK;
}
