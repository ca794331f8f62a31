/* cpu/cpu_paths.c — the CPU device's render_paths (scheduler/device.h): each of its threads runs
 * waves of its own through every stage of the stream engine, traversal included, so that no
 * thread waits for another between the stages.
 *
 * The stream engine on the render thread (scheduler/stream_engine.c) runs one wave at a time
 * through its stage table: the host stages split each stage among the threads and the device's team
 * traces between them, so every stage ends at a barrier and at two threads the render thread
 * waited for traversal for a third of the render (docs/performance.md, "Two threads").  Here a
 * call's paths are cut into waves of at most RS_RENDER_HOST_WAVE consecutive paths (a wave's
 * buffers stay in a core's caches; near the call's end, smaller, so that the threads finish about
 * together), handed out in order from one counter; a thread runs its wave from
 * camera rays to the last bounce alone (the same stages, shading/integrator.h, with one thread,
 * and the device's own 8-wide, 4-wide or binary traversal inline), then adds the wave's samples to
 * the job's film under a lock.  The film's sums are exact integers, so the order in which waves
 * land does not matter: the image is the stream engine's bit for bit.
 *
 * When job->cancelled says stop, each thread finishes the wave it holds and takes no other:
 * the waves taken are always a prefix of the call's paths, and all of them are on the film. */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "cpu/internal.h"
#include "scheduler/render.h"
#include "shading/integrator.h"

/* Paths per wave and thread: the buffers (194 B a path) of one wave fit a core's L2 cache
 * beside the scene's hot nodes. */
#define CPU_WAVE RS_RENDER_HOST_WAVE
/* The smallest wave the end of a call is cut into. */
#define CPU_WAVE_MIN 1024u

/* ---- Which walk traces a wave's rays (rs_cpu_walk) ----
 * The 8-wide tree answers the same, bit for bit, whether its rays walk alone or eight as a
 * packet; which is faster depends on how alike neighbouring rays are: on the Cornell box every
 * ray visits the same few leaves and packets win everywhere, in the living room only camera rays
 * stay together and a diffuse bounce's packets fall apart (docs/performance.md).  So with `auto`
 * each thread times both on its first traces of each kind, closest hit and any hit apart for
 * camera rays, the first bounce and the later ones, and keeps the faster: a trace of at least
 * WALK_MIN_RAYS rays, the two in turn until each has WALK_TRIES, then the packets where they took
 * less time per ray by WALK_MARGIN.  Only the speed depends on it. */
#define WALK_KEYS     6
#define WALK_MIN_RAYS 512u
#define WALK_TRIES    3u
#define WALK_MARGIN   0.97

typedef struct walk_pick {
    double secs[2];    /* time in the walk: alone (0), packets (1) */
    uint64_t rays[2];  /* rays it traced */
    uint32_t tries[2]; /* traces timed */
    uint32_t pick;     /* 0: not decided yet; 1 + the walk kept */
} walk_pick;

struct cpu_walk_picks {
    walk_pick key[WALK_KEYS];
};

size_t rs_cpu_walk_picks_size(void) { return sizeof(struct cpu_walk_picks); }

/* ---- Recording the rays a render traces (a benchmark's input) ----
 * With RS_RECORD_RAYS=FILE in the environment, the first RS_RECORD_RAYS_MAX rays (default
 * 4,000,000) the waves trace are appended to FILE as they are traced, in the waves' order:
 * bench/traversal_bench --rays FILE races the walks and Embree on a real render's camera, bounce
 * and shadow rays (docs/traversal.md).  The file: the 8 bytes "RSRAYS01", then per ray
 * o.x o.y o.z d.x d.y d.z tmin tmax (floats), the query (0 closest hit, 1 any hit) and the bounce
 * (bytes, the bounce capped at 255) and two zero bytes, all little-endian, 36 bytes a ray.  A
 * file that cannot be opened is reported once on stderr and nothing is recorded. */
#define RECORD_MAX_DEFAULT 4000000u

static pthread_mutex_t record_lock = PTHREAD_MUTEX_INITIALIZER;
static FILE *record_file;
static uint64_t record_left;
static atomic_int record_state; /* 0 not looked at yet, 1 recording, 2 off (read unlocked) */

static void record_rays(const rs_trace_batch *tb, uint32_t bounce)
{
    uint32_t i;
    pthread_mutex_lock(&record_lock);
    if (atomic_load(&record_state) == 0) {
        const char *path = getenv("RS_RECORD_RAYS"), *max = getenv("RS_RECORD_RAYS_MAX");
        atomic_store(&record_state, 2);
        if (path && *path) {
            record_file = fopen(path, "wb");
            if (!record_file || fwrite("RSRAYS01", 1, 8, record_file) != 8)
                fprintf(stderr, "raystream: RS_RECORD_RAYS: cannot write %s: no rays recorded\n",
                        path);
            else
                atomic_store(&record_state, 1);
            record_left = max && *max ? strtoull(max, NULL, 10) : RECORD_MAX_DEFAULT;
        }
    }
    for (i = 0; atomic_load(&record_state) == 1 && i < tb->count && record_left > 0;
         ++i, --record_left) {
        rs_ray r = rs_ray_soa_get(&tb->rays, i);
        float f[8];
        unsigned char tail[4] = {(unsigned char)(tb->kind == RS_TRACE_CLOSEST ? 0 : 1),
                                 (unsigned char)(bounce < 255u ? bounce : 255u), 0, 0};
        f[0] = r.o.x, f[1] = r.o.y, f[2] = r.o.z, f[3] = r.d.x, f[4] = r.d.y, f[5] = r.d.z;
        f[6] = r.tmin, f[7] = r.tmax;
        if (fwrite(f, sizeof f, 1, record_file) != 1 || fwrite(tail, 4, 1, record_file) != 1) {
            fprintf(stderr, "raystream: RS_RECORD_RAYS: a write failed: recording stopped\n");
            record_left = 0;
            break;
        }
    }
    /* each batch on disk as it is traced: a render that ends short of the limit (or a library
     * caller that goes on) leaves no rays in stdio's buffer */
    if (atomic_load(&record_state) == 1 && record_left > 0)
        fflush(record_file);
    if (atomic_load(&record_state) == 1 && record_left == 0) {
        fclose(record_file);
        record_file = NULL;
        atomic_store(&record_state, 2);
    }
    pthread_mutex_unlock(&record_lock);
}

/* Traces tb's rays of bounce `bounce` on this thread with the walk c->walk and `picks` say. */
static void trace_wave(const cpu_impl *c, struct cpu_walk_picks *picks, const rs_trace_batch *tb,
                       uint32_t bounce)
{
    walk_pick *w;
    uint32_t m;
    double t0;
    if (atomic_load_explicit(&record_state, memory_order_relaxed) != 2)
        record_rays(tb, bounce);
    if (!c->bvh8 || c->walk == RS_CPU_WALK_SINGLE) {
        rs_cpu_trace_range(c, tb, 0, tb->count);
        return;
    }
    if (c->walk == RS_CPU_WALK_PACKETS) {
        rs_bvh8_trace_packets(c->bvh8, &c->geom, tb, 0, tb->count);
        return;
    }
    w = &picks->key[(tb->kind == RS_TRACE_CLOSEST ? 0 : 3) + (bounce < 2 ? bounce : 2)];
    if (w->pick || tb->count < WALK_MIN_RAYS) {
        if (w->pick == 2)
            rs_bvh8_trace_packets(c->bvh8, &c->geom, tb, 0, tb->count);
        else
            rs_bvh8_trace(c->bvh8, &c->geom, tb, 0, tb->count);
        return;
    }
    m = w->tries[0] <= w->tries[1] ? 0u : 1u;
    t0 = rs_now_s();
    if (m)
        rs_bvh8_trace_packets(c->bvh8, &c->geom, tb, 0, tb->count);
    else
        rs_bvh8_trace(c->bvh8, &c->geom, tb, 0, tb->count);
    w->secs[m] += rs_now_s() - t0;
    w->rays[m] += tb->count;
    if (++w->tries[m] >= WALK_TRIES && w->tries[m ^ 1u] >= WALK_TRIES)
        w->pick = w->secs[1] / (double)w->rays[1] < WALK_MARGIN * w->secs[0] / (double)w->rays[0]
                      ? 2u
                      : 1u;
}

typedef struct paths_ctx {
    cpu_impl *c;
    const rs_paths_job *job;
    uint64_t p0, n;
    uint32_t wave;
    int threads;
    _Atomic uint64_t next; /* the call's paths handed out so far */
    atomic_int stop;       /* the job was cancelled: take no more waves */
    pthread_mutex_t lock;  /* the film and the counts */
    rs_path_counts counts;
} paths_ctx;

/* Paths [start, start + count) of the plan from camera rays to their end, on this thread. */
static void run_wave(const cpu_impl *c, const rs_paths_job *job, rs_wave_buffers *b,
                     struct cpu_walk_picks *picks, uint64_t start, uint32_t count,
                     rs_path_counts *counts)
{
    const rs_render_consts *it = job->it;
    rs_path_map map;
    rs_stage_exec ex;
    rs_trace_batch tb;
    uint32_t alive = count, bounce, cur = 0;
    map.pixel_of = job->pixel_of;
    map.n_active = job->n_active;
    ex.threads = 1;
    ex.strategy = c->strategy;
    memset(&tb, 0, sizeof tb);
    rs_stage_raygen(it, &map, &ex, start, count, &b->paths, &b->ext[0]);
    for (bounce = 0; alive > 0; ++bounce) {
        uint32_t n_shadow;
        tb.kind = RS_TRACE_CLOSEST;
        tb.count = alive;
        tb.rays = b->ext[cur];
        tb.hits = b->hits;
        trace_wave(c, picks, &tb, bounce);
        counts->closest += alive;
        if (bounce > counts->max_bounce)
            counts->max_bounce = bounce;
        rs_stage_shade(it, &map, &ex, start, bounce, &b->ext[cur], &b->hits, alive, &b->paths,
                       &b->ext[cur ^ 1], &b->shadow, &b->runs);
        n_shadow = rs_stream_pack_runs(&b->shadow, &b->runs, 1, alive);
        if (n_shadow) {
            tb.kind = RS_TRACE_OCCLUDED;
            tb.count = n_shadow;
            tb.rays = b->shadow;
            tb.occluded = b->occluded;
            trace_wave(c, picks, &tb, bounce);
            rs_stage_resolve_shadows(&ex, &b->shadow, b->occluded, n_shadow, &b->paths);
            counts->shadow += n_shadow;
        }
        alive = rs_stream_pack_runs(&b->ext[cur ^ 1], &b->runs, 0, alive);
        cur ^= 1;
    }
}

/* The wave's samples onto the film: path start + i is pixel (start + i) mod n_active. */
static void film_wave(const rs_paths_job *job, const rs_wave_buffers *b, uint64_t start,
                      uint32_t count)
{
    uint32_t npix = job->n_active, k = (uint32_t)(start % npix), i;
    for (i = 0; i < count; ++i) {
        uint32_t pixel = job->pixel_of ? job->pixel_of[k] : k;
        rs_film_add(job->film, pixel, rs_path_result(b->paths.radiance[i], b->paths.flags[i]));
        if (job->film->pass)
            rs_film_add_pass(job->film, pixel, &b->paths.aux[i]);
        if (++k == npix)
            k = 0;
    }
}

/* The next wave of the call: [*start, *start + *count), at most a whole wave and, near the call's
 * end, a share of what is left (guided: the threads finish about together).  0: none left. */
static int take_wave(paths_ctx *x, uint64_t *start, uint32_t *count)
{
    uint64_t at = atomic_load(&x->next);
    for (;;) {
        uint64_t left = x->n - at, want;
        if (at >= x->n)
            return 0;
        want = left / (2u * (uint64_t)x->threads);
        want = want < CPU_WAVE_MIN ? CPU_WAVE_MIN : want > x->wave ? x->wave : want;
        if (want > left)
            want = left;
        if (atomic_compare_exchange_weak(&x->next, &at, at + want)) {
            *start = x->p0 + at;
            *count = (uint32_t)want;
            return 1;
        }
    }
}

/* One thread's share: waves until none is left or the job is cancelled. */
static void worker(paths_ctx *x, int t)
{
    const rs_paths_job *job = x->job;
    rs_wave_buffers *b = &x->c->wave[t];
    rs_path_counts mine;
    uint64_t start;
    uint32_t count;
    memset(&mine, 0, sizeof mine);
    for (;;) {
        if (atomic_load(&x->stop))
            break;
        if (job->cancelled && job->cancelled(job->user)) {
            atomic_store(&x->stop, 1);
            break;
        }
        if (!take_wave(x, &start, &count))
            break;
        run_wave(x->c, job, b, &x->c->picks[t], start, count, &mine);
        pthread_mutex_lock(&x->lock);
        film_wave(job, b, start, count);
        pthread_mutex_unlock(&x->lock);
    }
    pthread_mutex_lock(&x->lock);
    x->counts.closest += mine.closest;
    x->counts.shadow += mine.shadow;
    if (mine.max_bounce > x->counts.max_bounce)
        x->counts.max_bounce = mine.max_bounce;
    pthread_mutex_unlock(&x->lock);
}

/* Wave buffers for `threads` threads, kept for the device's later calls. */
static rs_status wave_buffers_ready(rs_device *d, cpu_impl *c, int threads)
{
    if (c->n_wave >= threads)
        return RS_OK;
    if (!c->wave) {
        c->wave = (rs_wave_buffers *)rs_calloc((size_t)d->threads, sizeof *c->wave);
        c->picks = (struct cpu_walk_picks *)rs_calloc((size_t)d->threads, sizeof *c->picks);
        if (!c->wave || !c->picks) {
            rs_free(c->wave);
            rs_free(c->picks);
            c->wave = NULL;
            c->picks = NULL;
            return rs_error_set(RS_ERR_NOMEM, "device %s: out of memory for its waves", d->name);
        }
    }
    while (c->n_wave < threads) {
        rs_status st = rs_wave_buffers_create(CPU_WAVE, NULL, &c->wave[c->n_wave]);
        if (st != RS_OK)
            return st;
        c->n_wave++;
    }
    return RS_OK;
}

rs_status rs_cpu_render_paths(rs_device *d, const rs_paths_job *job, uint64_t p0, uint64_t p1,
                              uint64_t *done, rs_path_counts *counts)
{
    cpu_impl *c = (cpu_impl *)d->impl;
    paths_ctx x;
    rs_status st;
    uint64_t taken;
    int got, threads;
    *done = 0;
    if (!c->uploaded)
        return rs_error_set(RS_ERR_ARG, "device %s: render_paths before upload", d->name);
    if (p1 <= p0)
        return RS_OK;
    memset(&x, 0, sizeof x);
    x.c = c;
    x.job = job;
    x.p0 = p0;
    x.n = p1 - p0;
    x.wave = CPU_WAVE;
    atomic_init(&x.next, 0u);
    atomic_init(&x.stop, 0);
    got = rs_cores_acquire(c->cores, d->threads);
    threads = (uint64_t)got < (x.n + CPU_WAVE_MIN - 1) / CPU_WAVE_MIN
                  ? got
                  : (int)((x.n + CPU_WAVE_MIN - 1) / CPU_WAVE_MIN);
    x.threads = threads;
    if ((st = wave_buffers_ready(d, c, threads)) != RS_OK) {
        rs_cores_release(c->cores, got);
        return st;
    }
    pthread_mutex_init(&x.lock, NULL);
#pragma omp parallel num_threads(threads) if (threads > 1)
    {
#if RS_HAVE_OPENMP
        worker(&x, omp_get_thread_num());
#else
        worker(&x, 0);
#endif
    }
    pthread_mutex_destroy(&x.lock);
    rs_cores_release(c->cores, got);
    /* every wave handed out was finished: they are the call's first `taken` paths */
    taken = atomic_load(&x.next);
    *done = taken;
    counts->closest += x.counts.closest;
    counts->shadow += x.counts.shadow;
    if (x.counts.max_bounce > counts->max_bounce)
        counts->max_bounce = x.counts.max_bounce;
    return RS_OK;
}
