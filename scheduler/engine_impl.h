/* scheduler/engine_impl.h — the engine's state, shared by its parts (not a public header):
 * engine.c (set-up, plans, the time limit), render.c (the stream engine's waves) and passes.c
 * (the megakernel's calls). */
#ifndef RS_SCHEDULER_ENGINE_IMPL_H
#define RS_SCHEDULER_ENGINE_IMPL_H

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
    rs_device *mk;         /* the megakernel's device, or the wavefront's (paths), or NULL */
    int paths;             /* mk runs whole paths (render_paths): the device's wavefront */
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
} rs_run;

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
/* A device's wavefront (wavefront.c): whole paths in calls of render_paths. */
rs_status rs_paths_run(rs_run *c);
/* The megakernel: upload_scene (creation) and the run. */
rs_status rs_passes_setup(rs_engine *e);
rs_status rs_passes_run(rs_run *c);

#endif
