/* app/render_outputs.c — the outputs of a finished render, all or none: the report
 * (app/report.h) filled once, the --stats table, the --stats-json file, the --timeline
 * picture, the last --checkpoint, the image with its --aov layers and header, then the summary
 * line. */
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "app/render_run.h"
#include "app/report.h"
#include "app/timeline_svg.h"
#include "core/alloc.h"
#include "core/denoise.h"
#include "core/parallel.h"
#include "core/view.h"
#include "shading/aov.h"

/* The devices' rows: the stream engine's (the scheduler's counters) or the megakernel's one,
 * which traced everything, one path at a time. */
static void report_devices(const render_run *r, rs_report *rep)
{
    int i;
    if (r->mk) {
        rs_report_device *d = &rep->dev[0];
        d->ds.rays = rep->dev_rays = r->stats.rays_closest + r->stats.rays_shadow;
        d->ds.busy_s = r->stats.seconds;
        d->ds.chunks = r->stats.waves;
        d->ds.bytes_to_device = r->mk->stats.bytes_to_device;
        snprintf(d->name, sizeof d->name, "%s", r->mk->name);
        d->threads = r->mk->threads;
        d->alive = 1;
        rep->n_dev = 1;
        rep->megakernel = 1;
        rep->mk_gpu = rs_device_owns_memory(r->mk);
        return;
    }
    for (i = 0; r->sched && i < rs_sched_device_count(r->sched); ++i) {
        rs_report_device *d = &rep->dev[rep->n_dev++];
        rs_device *dev = rs_sched_device(r->sched, i);
        rs_sched_device_stats(r->sched, i, &d->ds, &d->alive);
        snprintf(d->name, sizeof d->name, "%s", dev->name);
        d->threads = dev->threads;
        rep->dev_rays += d->ds.rays;
    }
    for (i = 0; i < r->n_pdev; ++i) { /* the stream integrator's paths run whole there */
        rs_report_device *d = &rep->dev[rep->n_dev++];
        d->ds = r->pdev[i]->stats;
        d->alive = d->ds.failures == 0;
        snprintf(d->name, sizeof d->name, "%s", r->pdev[i]->name);
        d->threads = r->pdev[i]->threads;
        d->paths = 1;
        rep->dev_rays += d->ds.rays;
        rep->wavefront = 1;
    }
}

void rs_run_report(const rs_cli_options *o, const render_run *r, rs_report *rep)
{
    memset(rep, 0, sizeof *rep);
    rep->scene = o->scene;
    rep->image = r->out;
    rep->resume = o->resume;
    rep->checkpoint = r->ckpt_out ? r->ckpt_out->path : NULL;
    rep->quiet = o->quiet;
    rep->strategy = rs_par_strategy_name(o->strategy);
    rep->width = r->st.width;
    rep->height = r->st.height;
    rep->spp = r->st.spp;
    rep->spp_min = rs_film_min_count(r->film);
    rep->img = &r->img;
    rep->lighting = r->lighting[0] ? r->lighting : NULL;
    rep->extensions = r->gltf_extensions[0] ? r->gltf_extensions : NULL;
    rep->denoised = r->denoised ? r->denoise_device : NULL;
    rep->time_limit_s = o->time_limit_s;
    rep->interrupted = r->interrupted;
    rep->stats = r->stats;
    rep->adaptive_stats = r->adaptive;
    rep->resumed = r->resumed;
    rep->checkpoint_samples = r->img.adaptive > 0 ? rs_film_samples(r->film)
                                              : rs_path_ranges_total(&r->held) +
                                                    (r->done ? rs_path_ranges_total(r->done) : 0);
    rep->nonfinite = r->film->nonfinite;
    rs_bvh_builder_name(&r->bvh->builder, rep->bvh_builder, sizeof rep->bvh_builder);
    rep->bvh_sah = rs_bvh_sah_cost(r->bvh);
    rep->bvh_ms = r->bvh_ms;
    rep->bvh_nodes = r->bvh->n_nodes;
    rep->bvh_prims = r->bvh->n_prims;
    rep->blas_nodes = r->bvh->n_blas_nodes;
    rep->instances = r->scene->n_instances;
    rep->inst_prims = r->scene->n_inst_prims;
    rep->inst_tris = r->scene->n_inst_tris;
    report_devices(r, rep);
    rep->dist = r->dist ? &r->dres : NULL;
}

/* The --timeline picture, a lane per device, then the render thread's, into `path`.  0 after
 * printing why. */
static int write_timeline(const char *path, const render_run *r, const rs_report *rep)
{
    char lanes[RS_MAX_DEVICES + 1][96], title[160];
    const char *names[RS_MAX_DEVICES + 1];
    int i, t;
    for (i = 0; i < rep->n_dev; ++i) {
        size_t len;
        rs_report_device_label(rep, i, lanes[i], sizeof lanes[i]);
        len = strlen(lanes[i]);
        if ((t = rep->dev[i].threads) > 0)
            snprintf(lanes[i] + len, sizeof lanes[i] - len, " (%d thread%s)", t, t == 1 ? "" : "s");
        names[i] = lanes[i];
    }
    snprintf(lanes[rep->n_dev], sizeof lanes[rep->n_dev], "shading (render thread)");
    names[rep->n_dev] = lanes[rep->n_dev];
    snprintf(title, sizeof title, "raystream render %s, %ux%u, %u spp, %s integrator", rep->scene,
             rep->width, rep->height, rep->spp, rep->megakernel ? "megakernel" : "stream");
    if (rs_timeline_write_svg(path, r->timeline, names, rep->n_dev + 1, title) != RS_OK) {
        rs_app_fail(RS_EXIT_RUNTIME, NULL);
        return 0;
    }
    return 1;
}

/* The buffers of the --aov layers asked for (rs_free them); 0 when out of memory. */
static int alloc_aovs(unsigned aovs, size_t npix, float **bufs)
{
    if (aovs & RS_AOV_ALBEDO)
        bufs[0] = (float *)rs_alloc(npix * 3, sizeof(float));
    if (aovs & RS_AOV_NORMAL)
        bufs[1] = (float *)rs_alloc(npix * 3, sizeof(float));
    if (aovs & RS_AOV_DEPTH)
        bufs[2] = (float *)rs_alloc(npix, sizeof(float));
    if (aovs & RS_AOV_SAMPLES)
        bufs[3] = (float *)rs_alloc(npix, sizeof(float));
    return !(((aovs & RS_AOV_ALBEDO) && !bufs[0]) || ((aovs & RS_AOV_NORMAL) && !bufs[1]) ||
             ((aovs & RS_AOV_DEPTH) && !bufs[2]) || ((aovs & RS_AOV_SAMPLES) && !bufs[3]));
}

/* The --aov layers come from the film's passes (shading/aov.h), which the devices wrote as they
 * rendered. */
int rs_run_make_aovs(unsigned aovs, const render_run *r, rs_image_layer *layers, float **bufs)
{
    static const char *const names[4] = {"albedo", "normal", "depth", "samples"};
    static const char *const channels[4] = {"RGB", "XYZ", "Z", "Y"};
    size_t npix = (size_t)r->st.width * r->st.height;
    int n = 0, k;
    uint32_t i;
    bufs[0] = bufs[1] = bufs[2] = bufs[3] = NULL;
    if (!aovs)
        return 0;
    if (!alloc_aovs(aovs, npix, bufs)) {
        rs_error_set(RS_ERR_NOMEM, "out of memory for the --aov layers");
        return -1;
    }
    if (aovs & (RS_AOV_ALBEDO | RS_AOV_NORMAL | RS_AOV_DEPTH))
        rs_film_resolve_passes(r->film, bufs[0], bufs[1], NULL, bufs[2]);
    if (bufs[3])
        for (i = 0; i < npix; ++i)
            bufs[3][i] = (float)r->film->count[i];
    for (k = 0; k < 4; ++k)
        if (bufs[k]) {
            layers[n].name = names[k];
            layers[n].channels = channels[k];
            layers[n++].data = bufs[k];
        }
    return n;
}

static int is_exr(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && strcasecmp(path + n - 4, ".exr") == 0;
}

/* Whether the render traced on a GPU of its own (not the CPU fallback). */
static int used_gpu(const render_run *r)
{
    int i;
    if (r->mk)
        return rs_device_owns_memory(r->mk);
    for (i = 0; i < r->n_devs; ++i)
        if (rs_device_owns_memory(r->devs[i]))
            return 1;
    return 0;
}

/* --denoise: r->denoised from r->rgb with OIDN, guided by the first-hit albedo and normal (the
 * film's passes: averaged over the render's own camera samples, so taken as clean: cleanAux;
 * bench/denoise_bench measures both), on OIDN's CUDA device when the render used a GPU.  Up to
 * RS_AOV_EMISSION_SPP spp, what the camera sees emitted (the film's emission pass) is kept out
 * of the denoiser and added back, better estimated on its edges (rs_aov_refine,
 * rs_denoise_split): beyond that the render's own samples resolve a light's outline, and the
 * refinement would cost more.  0 after a message. */
int rs_run_denoise(render_run *r)
{
    size_t npix = (size_t)r->st.width * r->st.height;
    int split = r->st.spp <= RS_AOV_EMISSION_SPP;
    float *albedo = (float *)rs_alloc(npix * 3, sizeof(float));
    float *normal = (float *)rs_alloc(npix * 3, sizeof(float));
    float *direct = split ? (float *)rs_alloc(npix * 6, sizeof(float)) : NULL;
    rs_render_consts it;
    rs_bvh_view v = rs_bvh_view_of(r->bvh);
    int ok = 0;
    r->denoised = (float *)rs_alloc(npix * 3, sizeof(float));
    if (!albedo || !normal || !r->denoised || (split && !direct))
        rs_error_set(RS_ERR_NOMEM, "out of memory for --denoise (%ux%u)", r->st.width,
                     r->st.height);
    else if (rs_render_constants(r->scene, &r->st, &it) == RS_OK) {
        rs_film_resolve_passes(r->film, albedo, normal, split ? direct : NULL, NULL);
        if (split)
            rs_aov_refine(&it, &v, &r->geom, r->film->count, r->threads, direct,
                          direct + npix * 3);
        ok = rs_denoise_split(r->rgb, direct, split ? direct + npix * 3 : NULL, albedo, normal,
                              r->st.width, r->st.height, 1, used_gpu(r), r->denoised,
                              r->denoise_device, sizeof r->denoise_device) == RS_OK;
    }
    rs_free(albedo);
    rs_free(normal);
    rs_free(direct);
    if (!ok) {
        rs_free(r->denoised);
        r->denoised = NULL;
        rs_app_fail(0, "--denoise");
    }
    return ok;
}

/* The image with its --aov layers and header (rs_image_write: its own temporary file, renamed
 * into place).  0 after a message. */
static int write_image(const rs_cli_options *o, const render_run *r, const rs_report *rep)
{
    rs_image_layer layers[5];
    float *bufs[4];
    rs_report_meta meta;
    rs_view view;
    char why[512];
    int i, ok = 1, n_layers;
    rs_report_image_meta(rep, &meta);
    /* --view and --exposure (checked when the options were read): an 8-bit image gets the
     * view's display values; an .exr stays linear and records the view (core/image_io.h) */
    if (!rs_view_from_name(o->view, o->exposure, &view, why, sizeof why)) {
        rs_app_print("raystream: %s\n", why);
        return 0;
    }
    n_layers = rs_run_make_aovs(o->aovs, r, layers, bufs);
    if (n_layers < 0) {
        rs_app_fail(0, NULL);
        ok = 0;
        n_layers = 0;
    }
    if (r->denoised && is_exr(r->out)) { /* the raw image beside the denoised one */
        layers[n_layers].name = "noisy";
        layers[n_layers].channels = "RGB";
        layers[n_layers++].data = r->rgb;
    }
    if (ok && rs_image_write_view(r->out, r->st.width, r->st.height,
                                  r->denoised ? r->denoised : r->rgb, layers,
                                  (size_t)n_layers, meta.meta, meta.n, &view) != RS_OK) {
        rs_app_fail(0, NULL);
        ok = 0;
    }
    for (i = 0; i < 4; ++i)
        if (o->aovs)
            rs_free(bufs[i]);
    return ok;
}

/* Tracks every name an output may be written under, so a second signal removes whichever
 * exist. */
static void track_outputs(const render_run *r, char *timeline_inner, size_t n)
{
    int i;
    for (i = 0; i < r->n_outs; ++i)
        if (!r->outs[i].in_place)
            rs_outputs_track(r->outs[i].staged); /* outs[0]'s is the core's image temporary */
    if (r->timeline_out) {                       /* rs_timeline_write_svg's own temporary name */
        snprintf(timeline_inner, n, "%s.tmp", r->timeline_out->staged);
        rs_outputs_track(timeline_inner);
    }
}

/* The outputs, all or none: the stats JSON and the timeline to their staged names, then the
 * image, then the staged files renamed.  A failure before the image is in place replaces
 * nothing; a --stats-json that is a special file (/dev/stdout) is written last, in place.
 * Returns the exit code: `code`, or RS_EXIT_RUNTIME. */
int rs_run_write_outputs(const rs_cli_options *o, render_run *r, int code)
{
    rs_report rep;
    char timeline_inner[RS_OUTPUT_PATH_MAX + 8];
    int i, ok = 1, replaced = 0, undenoised = 0, skipped = 0;
    rs_film_resolve(r->film, r->rgb);
    /* a denoise that still fails after the render (checked before it: rs_denoise_probe) loses
     * nothing: the outputs are written with the image as rendered, then the failure reported.
     * After Ctrl-C the samples so far are written at once, as rendered: an interrupt asks to
     * stop, not for seconds more of the denoiser on an image cut short */
    if (o->denoise && r->interrupted)
        skipped = 1;
    else if (o->denoise && !rs_run_denoise(r))
        undenoised = 1;
    rs_run_report(o, r, &rep);
    if (o->stats)
        rs_report_print_table(&rep);
    track_outputs(r, timeline_inner, sizeof timeline_inner);
    if (r->stats_out && !r->stats_out->in_place)
        ok = rs_report_write_json(&rep, r->stats_out->staged, r->stats_out->path);
    if (ok && r->timeline_out)
        ok = write_timeline(r->timeline_out->staged, r, &rep);
    if (ok && r->ckpt_out) /* renamed below with the others */
        ok = rs_run_write_checkpoint(r, 0);
    if (ok)
        ok = write_image(o, r, &rep);
    replaced = ok;
    for (i = 1; ok && i < r->n_outs; ++i)
        if (!r->outs[i].in_place && !r->outs[i].dropped)
            ok = rs_output_commit(&r->outs[i]);
    if (ok && r->stats_out && r->stats_out->in_place)
        ok = rs_report_write_json(&rep, r->stats_out->path, r->stats_out->path);
    rs_outputs_remove_tracked(); /* what was not renamed */
    rs_outputs_untrack();
    if (!ok) {
        rs_app_print("raystream: the run failed; %s\n",
                     replaced ? "some outputs were already replaced" : "no output was replaced");
        return RS_EXIT_RUNTIME;
    }
    rs_report_print_summary(&rep);
    if (skipped)
        rs_app_print("raystream: interrupted: %s was written as rendered, not denoised\n", r->out);
    if (undenoised) {
        rs_app_print("raystream: --denoise failed after the render: %s was written as "
                     "rendered, not denoised\n",
                     r->out);
        return RS_EXIT_RUNTIME;
    }
    return code;
}
