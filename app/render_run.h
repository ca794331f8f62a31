/* app/render_run.h — what one `raystream render` makes and the named steps that make it
 * (render_steps.c, scene_load.c, render_outputs.c), shared by the render command (render_cmd.c)
 * and its MPI glue (dist_glue.c).  Internal to app/.
 *
 * The steps run in this order, each returning an exit code (RS_EXIT_*; a failure has printed
 * one line): rs_run_load_scene, rs_run_settings, rs_run_check_outputs, rs_run_make_film,
 * rs_run_build_bvh, rs_run_start_devices, then the render, then rs_run_write_outputs.  Whatever
 * they made is released by rs_run_release, whichever step stopped. */
#ifndef RS_APP_RENDER_RUN_H
#define RS_APP_RENDER_RUN_H

#include "app/checkpoint.h"
#include "app/distributed.h"
#include "app/fail.h"
#include "app/options.h"
#include "app/outputs.h"
#include "app/progress.h"
#include "app/report.h"
#include "app/tev.h"
#include "core/image_io.h"
#include "scheduler/adaptive.h"
#include "scheduler/fault.h"
#include "scheduler/render.h"

#ifndef RS_VERSION
#  define RS_VERSION "0.0.0"
#endif

/* Everything one `raystream render` makes, released by rs_run_release. */
typedef struct render_run {
    rs_scene *scene;
    uint64_t scene_hash;   /* the scene as loaded, before --flatten-instances (the checkpoint
                              key: flattening changes no pixel); 0: hash r->scene when needed */
    rs_bvh *bvh;
    rs_geom geom;
    double bvh_ms;
    rs_device *devs[RS_MAX_DEVICES]; /* the stream engine's devices */
    int n_devs;
    rs_device *mk; /* the megakernel's one device */
    /* those of devs that run the stream integrator's paths whole (a GPU's wavefront:
     * rs_engine_create_paths); the others are the scheduler's */
    rs_device *pdev[RS_ENGINE_MAX_PATH_DEVICES];
    int n_pdev;
    rs_sched *sched;
    rs_engine *engine; /* set up once; every plan of the render runs on it */
    rs_film *film;
    rs_timeline *timeline;
    float *rgb;
    float *denoised;             /* --denoise: the denoised image (rgb stays the raw one) */
    char denoise_device[160];    /* --denoise: the OIDN device that ran it */
    rs_cores cores;
    int threads;
    rs_image_settings img;  /* what decides the image, made once from the options
                               (rs_run_settings; --resume may take the file's spp) */
    rs_render_settings st;  /* the engine's: img's, and how the render runs */
    rs_render_stats stats;
    rs_adaptive_stats adaptive; /* --adaptive: rounds, samples, pixels stopped */
    rs_adaptive_state ad;       /* --adaptive: where it stands (a checkpoint saves it) */
    char name[64];              /* the scene's stem: default output name */
    char gltf_extensions[512];  /* a glTF file's extensions that raystream read (summary) */
    char lighting[160];         /* how the scene is lit when its file says nothing (a glTF
                                   file's default sky), for the summary and the EXR; "" */
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
    rs_dist *dist;            /* under mpirun (app/distributed.h), or NULL */
    int rank;                 /* this process's rank (0 without MPI) */
    int local_ranks;          /* ranks on this machine: they share its cores */
    rs_dist_result dres;      /* rank 0: the job's result */
    rs_dist_fault dist_fault; /* RS_MPI_FAULT */
    rs_tev *tev;              /* --tev: the preview, or NULL */
    int library;              /* run by the C API (api/raystream.c): no load watchdog */
} render_run;

/* The steps (render_steps.c, scene_load.c, render_outputs.c); see the top of this file. */
int rs_run_load_scene(const rs_cli_options *o, render_run *r); /* under the load watchdog */
void rs_run_settings(const rs_cli_options *o, render_run *r);
int rs_run_check_outputs(const rs_cli_options *o, render_run *r);
/* --denoise: OIDN loads and makes a device (rs_run_check_outputs's last check).  Exit code. */
int rs_run_check_denoise(const rs_cli_options *o);
int rs_run_make_film(const rs_cli_options *o, render_run *r);
/* An empty film of the render's size, keeping the passes where the render writes them
 * (r->st.passes). */
rs_status rs_run_new_film(const render_run *r, rs_film **out);
int rs_run_resume_whole_samples(const rs_cli_options *o, const render_run *r, const char *what);
int rs_run_build_bvh(const rs_cli_options *o, render_run *r);
int rs_run_start_devices(const rs_cli_options *o, render_run *r);
/* After the scene: rs_run_settings, rs_run_check_outputs (the library: rs_run_check_denoise),
 * rs_run_make_film, rs_run_build_bvh, rs_run_start_devices; the first failure's exit code. */
int rs_run_prepare(const rs_cli_options *o, render_run *r);
/* The engine's run over what the film lacks: everything, or the gaps of a --resume; or the
 * rounds of --adaptive. */
rs_status rs_run_engine(render_run *r, const rs_render_hooks *hooks);
/* --denoise: r->denoised from r->rgb (the film resolved); 0 after a message. */
int rs_run_denoise(render_run *r);
/* The --aov layers `aovs` (RS_AOV_*) of the finished render into layers[] (room for 4), their
 * buffers in bufs[4] (rs_free them); returns how many, or -1 (out of memory, rs_error set). */
int rs_run_make_aovs(unsigned aovs, const render_run *r, rs_image_layer *layers, float **bufs);
/* The report of the render (the summary's, --stats-json's, the EXR header's), once the film is
 * final. */
void rs_run_report(const rs_cli_options *o, const render_run *r, rs_report *rep);
/* The outputs, all or none, then the summary; returns `code` or RS_EXIT_RUNTIME. */
int rs_run_write_outputs(const rs_cli_options *o, render_run *r, int code);
/* The --checkpoint of the film as it is now; 0 after a message. */
int rs_run_write_checkpoint(const render_run *r, int rename_now);
/* rs_render_hooks.film_ready (user: the render_run), whenever the film holds what it held plus
 * `done`: a periodic checkpoint.  A failed one is reported and the render goes on (the last
 * good file stays). */
void rs_run_on_film_ready(void *user, const rs_film *film, const rs_path_ranges *done);
void rs_run_release(render_run *r);

/* The commands (render_cmd.c, scene_load.c). */
int rs_cmd_render(const rs_cli_options *o, int *argc, char ***argv);
int rs_cmd_export(const rs_cli_options *o);

#endif
