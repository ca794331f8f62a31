/* app/render_cmd.c — `raystream render`: the steps of app/render_run.h in order (render_steps.c,
 * scene_load.c, render_outputs.c), the render itself with the progress bar, the stop signals and
 * periodic checkpoints, then the outputs.  Under mpirun the same steps run through
 * app/dist_glue.c. */
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/dist_glue.h"
#include "app/render_run.h"
#include "app/signals.h"
#include "core/clock.h"

static void on_progress(void *user, uint64_t done, uint64_t total)
{
    rs_progress_update(&((render_run *)user)->progress, done, total);
}

void rs_run_on_film_ready(void *user, const rs_film *film, const rs_path_ranges *done)
{
    render_run *r = (render_run *)user;
    double now;
    r->done = done;
    rs_tev_film(r->tev, film, 0);
    if (!r->ckpt_out || (now = rs_now_s()) - r->last_ckpt < r->ckpt_every_s ||
        rs_path_ranges_total(&r->held) + rs_path_ranges_total(done) ==
            (uint64_t)r->st.width * r->st.height * r->st.spp)
        return; /* the last is written at the end */
    r->last_ckpt = now;
    (void)rs_run_write_checkpoint(r, 1);
}

/* The render itself, with the progress bar and the stop signals (which stay caught until the
 * program ends: a second one while the outputs are written removes their temporary files).
 * Returns an exit code: 128 + the signal for an interrupted render. */
static int run_render(const rs_cli_options *o, render_run *r)
{
    rs_render_hooks hooks;
    rs_status rst;
    rs_signals_install();
    rs_progress_begin(&r->progress, !o->quiet);
    memset(&hooks, 0, sizeof hooks);
    hooks.progress = on_progress;
    hooks.user = r;
    hooks.cancel = rs_signals_cancel();
    r->ckpt_every_s = o->ckpt_every_s;
    r->last_ckpt = rs_now_s();
    if (r->ckpt_out) {
        hooks.film_ready = rs_run_on_film_ready;
        rs_outputs_track(r->ckpt_out->staged); /* a second signal during a periodic write */
    }
    if (o->tev && (r->tev = rs_tev_open(o->tev, r->name, r->st.width, r->st.height)))
        hooks.film_ready = rs_run_on_film_ready;
    rst = rs_run_engine(r, &hooks);
    rs_tev_film(r->tev, r->film, 1);
    r->done = rs_engine_done(r->engine);
    rs_progress_end(&r->progress);
    if (rst == RS_ERR_CANCELLED) {
        rs_error_clear();
        r->interrupted = rs_signals_caught() ? rs_signals_caught() : SIGINT;
        return RS_EXIT_SIGNALLED(r->interrupted);
    }
    if (rst != RS_OK)
        return rs_app_fail(RS_EXIT_RUNTIME, "render failed");
    return RS_EXIT_OK;
}

/* `raystream render`: scene, settings, outputs checked, BVH, devices, render, outputs. */
int rs_cmd_render(const rs_cli_options *o, int *argc, char ***argv)
{
    render_run r;
    int code;
    memset(&r, 0, sizeof r);
    if (rs_mpi_render(o, argc, argv, &r, &code))
        return code;
    /* RS_FAULT is input like the options: a bad value is a usage error, before any work */
    if (rs_fault_parse(getenv("RS_FAULT"), &r.fault) != RS_OK)
        return rs_app_fail(RS_EXIT_USAGE, NULL);
    if ((code = rs_run_load_scene(o, &r)) == RS_EXIT_OK &&
        (code = rs_run_prepare(o, &r)) == RS_EXIT_OK) {
        code = run_render(o, &r);
        if (code == RS_EXIT_OK || r.interrupted)
            code = rs_run_write_outputs(o, &r, code);
    }
    rs_run_release(&r);
    return code;
}
