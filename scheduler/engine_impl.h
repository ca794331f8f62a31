/* scheduler/engine_impl.h — the engine's state, shared by its parts (not a public header):
 * engine.c (set-up, plans), run.c (a run's bookkeeping and the time limit's cut), stream_engine.c
 * (the stream engine's waves), passes.c (the megakernel's calls) and wavefront.c (the path
 * devices' threads).  They call down into run.c, never back into engine.c. */
#ifndef RS_SCHEDULER_ENGINE_IMPL_H
#define RS_SCHEDULER_ENGINE_IMPL_H

#include <pthread.h>

#include "scheduler/render.h"
#include "streams/wave.h"

/* SLOT_IDLE: the slot holds no wave.  Otherwise its `stage` is an rs_stage. */
#define SLOT_IDLE 0xffu

/* One wave in flight and its buffers (allocated once per engine). */
typedef struct rs_slot {
    rs_wave_buffers b;
    uint8_t stage;  /* next stage to run, or SLOT_IDLE */
    uint64_t wave;  /* index of the wave it holds, in the run */
    uint64_t start; /* its first path, in the plan's numbering */
    uint32_t count, alive, bounce, cur;
    uint32_t n_shadow;
    rs_trace_batch batch; /* what `job` traces: must live as long as the job */
    rs_sched_job job;
} rs_slot;

struct rs_engine {
    const rs_scene *scene;
    rs_render_settings st; /* the automatic choices made */
    rs_render_consts it;   /* the render's constants, what a device receives */
    rs_sched *sched;       /* the stream engine's devices, or NULL */
    rs_device *mk;         /* the megakernel's device, or NULL */
    /* Devices that run paths whole (render_paths: a GPU's wavefront), beside the stream
     * engine's own devices (sched, which may then be NULL), each with a film of its own when
     * others render beside it (merged into the run's film after each call). */
    rs_device *pdev[RS_ENGINE_MAX_PATH_DEVICES];
    rs_film *pfilm[RS_ENGINE_MAX_PATH_DEVICES];
    int n_pdev;
    uint64_t plan_id;      /* counts the runs: rs_paths_job.plan_id */
    rs_slot slots[RS_RENDER_MAX_WAVES];
    uint32_t n_slots;
    double t_start;        /* rs_now_s at creation: the time limit's clock */
    int any_done;          /* a run has finished paths: the first pass is behind */
    rs_render_stats total; /* every run's, summed */
    rs_path_ranges done;   /* the last run's paths on the film */
};

/* One run of a plan. */
typedef struct rs_run {
    rs_engine *e;
    rs_path_map map;  /* the plan's pixels (host memory: its stages and film only) */
    rs_stage_exec ex; /* threads granted to the stage running now */
    const rs_work_plan *plan;
    const rs_render_hooks *hooks;
    rs_render_stats *stats;
    rs_film *film;
    uint32_t n_ranges;  /* the plan's ranges still in the run (the time limit drops the rest) */
    uint32_t range;     /* the range waves start from */
    uint64_t next_path; /* the first path of that range no wave has started */
    uint64_t end_path;  /* its end, or the end of the pass under way once the time is up */
    uint64_t ended;     /* paths ended in waves not yet on the film */
    uint64_t cut;       /* once the time limit has cut the run: no path at or past this one */
    /* With path devices beside the stream engine (wavefront.c), their threads and the render
     * thread share the run: the ranges dealt, the film, the stats and the hooks, under `lock`
     * (NULL: one thread, no lock).  Each participant's rate (paths/s, 0 until measured: the
     * stream engine's is rate[n_pdev]) sizes what it takes next. */
    pthread_mutex_t *lock;
    double rate[RS_ENGINE_MAX_PATH_DEVICES + 1];
    uint64_t redo[RS_ENGINE_MAX_PATH_DEVICES][2]; /* ranges a failed device gave back */
    uint32_t n_redo;
    double t0;           /* rs_now_s at the run's start (the stream engine's rate) */
    uint64_t host_paths; /* paths the stream engine put on the film in this run */
} rs_run;

/* rs_run's lock, where it has one. */
static inline void rs_run_lock(rs_run *c)
{
    if (c->lock)
        pthread_mutex_lock(c->lock);
}
static inline void rs_run_unlock(rs_run *c)
{
    if (c->lock)
        pthread_mutex_unlock(c->lock);
}

/* Whether hooks->cancel is set. */
int rs_run_cancelled(const rs_run *c);
/* Once the time limit has passed: where the run must end, given that paths up to `next` are
 * started (the end of the pass under way, or of the run's first pass while no pass of the
 * render is done); UINT64_MAX while there is time.  Sets stats->time_limited when it cuts. */
uint64_t rs_run_time_cut(rs_run *c, uint64_t next);
/* Whether paths remain to start (moving on to the next range when the current one is all
 * started). */
int rs_run_more(rs_run *c);
/* The run's paths [lo, hi) are on the film: recorded, and the film_ready hook told.  RS_ERR_NOMEM
 * when the record cannot grow. */
rs_status rs_run_on_film(rs_run *c, uint64_t lo, uint64_t hi);

/* The stream engine: buffers for the engine's slots (creation), the run, their release. */
rs_status rs_stream_setup(rs_engine *e);
rs_status rs_stream_run(rs_run *c);
void rs_stream_release(rs_engine *e);
/* Paths [*lo, *lo + *n) for participant `who` (a path device's index, or n_pdev for the stream
 * engine) to run next, at most `most`: a range a failed device gave back first, else the next of
 * the plan, sized by the participants' rates so that near the end each takes a share it finishes
 * about when the others finish theirs (guided self-scheduling).  0 when nothing is left (or the
 * run is cancelled).  Takes the run's lock. */
int rs_run_take(rs_run *c, int who, uint64_t most, uint64_t *lo, uint64_t *n);
/* The path devices (wavefront.c): their upload_scene (creation) and the run, with the stream
 * engine's waves on the render thread beside them when the engine has a scheduler. */
rs_status rs_paths_setup(rs_engine *e);
rs_status rs_paths_run(rs_run *c);
/* The megakernel: upload_scene (creation) and the run. */
rs_status rs_passes_setup(rs_engine *e);
rs_status rs_passes_run(rs_run *c);

#endif
