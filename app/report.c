/* app/report.c — the four ways a finished render is reported; see report.h.  Each writer reads
 * only the report, so they cannot disagree about what happened. */
#include "app/report.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <strings.h>

#include "app/signals.h"
#include "shading/light_sampler.h"

#ifndef RS_VERSION
#  define RS_VERSION "0.0.0"
#endif

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

void rs_report_device_label(const rs_report *rep, int i, char *buf, size_t n)
{
    if (rep->megakernel) /* one device traced everything, one path at a time */
        snprintf(buf, n, "%s (megakernel)", rep->dev[i].name);
    else if (rep->dev[i].paths) /* its own wavefront: paths whole, shading included */
        snprintf(buf, n, "%s (wavefront)", rep->dev[i].name);
    else
        snprintf(buf, n, "%s", rep->dev[i].name);
}

static double mrays_per_s(const rs_device_stats *d)
{
    return d->busy_s > 0 ? (double)d->rays / d->busy_s / 1e6 : 0.0;
}

/* ---- --stats ----------------------------------------------------------------------------- */

static void print_rank_table(const rs_dist_result *d)
{
    int i;
    fprintf(stderr, "%-5s %-34s %7s %12s %9s %9s %10s %12s %s\n", "rank", "host: devices", "passes",
            "samples", "busy s", "idle", "samples/s", "film bytes", "state");
    for (i = 0; i < d->ranks; ++i) {
        const rs_dist_rank_stats *k = &d->rank[i];
        double idle = k->wall_s > 0 ? 1.0 - k->busy_s / k->wall_s : 0.0;
        fprintf(stderr, "%-5d %-34.34s %7u %12llu %9.3f %8.1f%% %10.0f %12llu %s\n", i, k->desc,
                k->passes, (unsigned long long)k->paths, k->busy_s, 100.0 * (idle > 0 ? idle : 0.0),
                k->busy_s > 0 ? (double)k->paths / k->busy_s : 0.0,
                (unsigned long long)k->film_bytes,
                !k->alive   ? "lost"
                : k->failed ? "failed"
                            : "ok");
    }
    fprintf(stderr, "(the device and stage rows are rank 0's)\n");
}

void rs_report_print_table(const rs_report *rep)
{
    int i;
    fprintf(stderr, "%-24s %14s %8s %9s %9s %9s %7s %12s %12s %s\n", "device", "rays", "chunks",
            "busy s", "idle s", "Mrays/s", "share", "bytes in", "bytes out", "state");
    for (i = 0; i < rep->n_dev; ++i) {
        const rs_device_stats *d = &rep->dev[i].ds;
        char name[80];
        rs_report_device_label(rep, i, name, sizeof name);
        fprintf(stderr, "%-24s %14llu %8llu %9.3f %9.3f %9.2f %6.1f%% %12llu %12llu %s\n", name,
                (unsigned long long)d->rays, (unsigned long long)d->chunks, d->busy_s, d->idle_s,
                mrays_per_s(d),
                rep->dev_rays ? 100.0 * (double)d->rays / (double)rep->dev_rays : 0.0,
                (unsigned long long)d->bytes_to_device, (unsigned long long)d->bytes_from_device,
                rep->dev[i].alive ? "ok" : "failed");
    }
    if (rep->dist)
        print_rank_table(rep->dist);
    fprintf(stderr, "%-24s %9s %7s\n", "stage (render thread)", "s", "share");
    for (i = 0; i < RS_STAGE_COUNT; ++i)
        if (rep->stats.stage_s[i] > 0)
            fprintf(
                stderr, "%-24s %9.3f %6.1f%%\n", rs_stage_name((rs_stage)i), rep->stats.stage_s[i],
                rep->stats.seconds > 0 ? 100.0 * rep->stats.stage_s[i] / rep->stats.seconds : 0.0);
}

/* ---- --stats-json ------------------------------------------------------------------------ */

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

/* "settings": every image setting's row (app/image_settings.h), its value as text. */
static void json_settings(FILE *f, const rs_image_settings *img)
{
    size_t i;
    fprintf(f, "},\n  \"settings\": {");
    for (i = 0; i < rs_image_settings_count(); ++i) {
        const rs_setting_desc *d = rs_image_setting(i);
        char v[RS_SETTING_TEXT];
        d->text(img, v, sizeof v);
        fprintf(f, "%s\"%s\": ", i ? ", " : "", d->name);
        json_string(f, v);
    }
}

static void json_devices(FILE *f, const rs_report *rep)
{
    int i;
    fprintf(f, "},\n  \"devices\": [\n");
    for (i = 0; i < rep->n_dev; ++i) {
        const rs_device_stats *d = &rep->dev[i].ds;
        char name[80];
        rs_report_device_label(rep, i, name, sizeof name);
        fprintf(f, "    {\"name\": ");
        json_string(f, name);
        fprintf(f,
                ", \"threads\": %d, \"rays\": %llu, \"chunks\": %llu, \"busy_s\": %.6f, "
                "\"idle_s\": %.6f, \"mrays_per_s\": %.4f, \"share\": %.6f, "
                "\"bytes_to_device\": %llu, \"bytes_from_device\": %llu, \"failures\": %llu, "
                "\"failed\": %s}%s\n",
                rep->dev[i].threads, (unsigned long long)d->rays, (unsigned long long)d->chunks,
                d->busy_s, d->idle_s, mrays_per_s(d),
                rep->dev_rays ? (double)d->rays / (double)rep->dev_rays : 0.0,
                (unsigned long long)d->bytes_to_device, (unsigned long long)d->bytes_from_device,
                (unsigned long long)d->failures, rep->dev[i].alive ? "false" : "true",
                i + 1 < rep->n_dev ? "," : "");
    }
    fprintf(f, "  ]");
}

static void json_mpi(FILE *f, const rs_dist_result *d)
{
    int i;
    fprintf(f,
            ",\n  \"mpi\": {\"ranks\": %d, \"pass_spp\": %u, \"passes\": %u, "
            "\"reissued\": %u, \"ranks_lost\": %d, \"bytes_received\": %llu, "
            "\"messages\": %llu, \"message_bytes\": %llu, "
            "\"rays\": %llu, \"complete\": %s, \"flushes\": %u,\n    \"per_rank\": [\n",
            d->ranks, d->pass_spp, d->passes_total, d->reissued, d->dead,
            (unsigned long long)d->bytes_received, (unsigned long long)d->messages,
            (unsigned long long)d->message_bytes,
            (unsigned long long)(d->rays_closest + d->rays_shadow), d->complete ? "true" : "false",
            d->flushes);
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

int rs_report_write_json(const rs_report *rep, const char *path, const char *shown)
{
    const rs_render_stats *s = &rep->stats;
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
            s->seconds > 0 ? s->seconds : 1e-9, (unsigned long long)rep->dev_rays, rep->spp_min,
            rep->spp, (unsigned long long)(rep->resumed + s->paths_done),
            (unsigned long long)rep->resumed, s->time_limited ? "true" : "false",
            rep->interrupted ? "true" : "false", rep->img->adaptive, rep->adaptive_stats.rounds,
            rep->adaptive_stats.stopped);
    for (i = 0; i < RS_STAGE_COUNT; ++i)
        fprintf(f, "%s\"%s\": %.9f", i ? ", " : "", rs_stage_name((rs_stage)i), s->stage_s[i]);
    json_settings(f, rep->img);
    json_devices(f, rep);
    if (rep->dist)
        json_mpi(f, rep->dist);
    fprintf(f, "\n}\n");
    ok = !ferror(f);
    if (fclose(f) != 0 || !ok) {
        fprintf(stderr, "raystream: %s: cannot write the stats (%s)\n", shown, strerror(errno));
        return 0;
    }
    return 1;
}

/* ---- the summary line -------------------------------------------------------------------- */

/* "64 spp", or how many an adaptive or time-limited render took. */
static void summary_spp(const rs_report *rep, char *spp, size_t n)
{
    if (rep->img->adaptive > 0) {
        size_t npix = (size_t)rep->width * rep->height;
        snprintf(spp, n,
                 "%.1f spp on average, %u to %u (adaptive to %g in %u rounds: %.1f%% of the "
                 "pixels stopped early%s)",
                 npix ? (double)rep->adaptive_stats.samples / (double)npix : 0.0, rep->spp_min,
                 rep->spp, rep->img->adaptive, rep->adaptive_stats.rounds,
                 npix ? 100.0 * rep->adaptive_stats.stopped / (double)npix : 0.0,
                 rep->stats.time_limited ? "; stopped at the --time-limit" : "");
    } else if (rep->stats.time_limited)
        snprintf(spp, n, "%u of %u spp (stopped at the --time-limit of %g s)", rep->spp_min,
                 rep->spp, rep->time_limit_s);
    else
        snprintf(spp, n, "%u spp", rep->spp);
}

/* The first sentences: what was rendered, how fast, the BVH. */
static void summary_render(const rs_report *rep)
{
    char sps[32], rps[32], rays[32], spp[200], inst[160] = "", filter[RS_SETTING_TEXT];
    const rs_render_stats *s = &rep->stats;
    const rs_image_settings *img = rep->img;
    double secs = s->seconds > 0 ? s->seconds : 1e-9;
    uint64_t rays_total = s->rays_closest + s->rays_shadow;
    human((double)s->paths_done / secs, sps, sizeof sps);
    human((double)rays_total / secs, rps, sizeof rps);
    human((double)rays_total, rays, sizeof rays);
    summary_spp(rep, spp, sizeof spp);
    rs_filter_describe(&img->filter, filter, sizeof filter);
    if (rep->instances)
        snprintf(inst, sizeof inst,
                 " (%u of them instances placing %u triangles; bottom levels: %u nodes over %u "
                 "shared triangles)",
                 rep->instances, rep->inst_prims, rep->blas_nodes, rep->inst_tris);
    fprintf(stderr,
            "%s %s at %ux%u, %s (%s sampling%s, %s sampler, %s filter, max depth %u, seed %llu) "
            "in %.2f s: "
            "%ssamples/s, %srays/s (%srays: %llu camera/bounce + %llu shadow). "
            "BVH (%s, SAH cost %.1f): %u nodes over %u primitives%s, built in %.2f ms. ",
            rep->interrupted ? "Partial render (interrupted):" : "Rendered", rep->scene, rep->width,
            rep->height, spp, rs_sampling_name(img->sampling),
            img->light_sampler == RS_LIGHT_SAMPLER_BVH ? " with a light BVH" : "",
            rs_sampler_name(img->sampler), filter, img->max_depth,
            (unsigned long long)img->seed, s->seconds, sps, rps, rays,
            (unsigned long long)s->rays_closest, (unsigned long long)s->rays_shadow,
            rep->bvh_builder, rep->bvh_sah, rep->bvh_nodes, rep->bvh_prims, inst, rep->bvh_ms);
    if (rep->extensions)
        fprintf(stderr, "glTF extensions read: %s. ", rep->extensions);
    if (rep->lighting)
        fprintf(stderr, "Lit by %s. ", rep->lighting);
    if (rep->denoised)
        fprintf(stderr, "Denoised with Open Image Denoise on %s%s. ", rep->denoised,
                rep->image && strlen(rep->image) > 4 &&
                        strcasecmp(rep->image + strlen(rep->image) - 4, ".exr") == 0
                    ? " (the raw image: the layer 'noisy')"
                    : "");
}

/* The devices' sentence and the integrator's. */
static void summary_devices(const rs_report *rep)
{
    uint64_t rays_total = rep->stats.rays_closest + rep->stats.rays_shadow;
    char rays[32];
    int i;
    for (i = 0; !rep->megakernel && i < rep->n_dev; ++i) {
        const rs_report_device *d = &rep->dev[i];
        human((double)d->ds.rays, rays, sizeof rays);
        fprintf(stderr, "%s %s (%d thread%s) traced %srays in %llu chunks (%.0f%%)%s%s",
                i == 0 ? "Devices:" : ";", d->name, d->threads, d->threads == 1 ? "" : "s", rays,
                (unsigned long long)d->ds.chunks,
                rays_total ? 100.0 * (double)d->ds.rays / (double)rays_total : 0.0,
                d->alive ? "" : " and then failed", i + 1 == rep->n_dev ? ". " : "");
    }
    if (rep->wavefront && rep->n_dev == 1)
        fprintf(stderr, "Integrator: stream, paths run whole on %s (its own wavefront). ",
                rep->dev[0].name);
    else if (rep->wavefront)
        fprintf(stderr, "Integrator: stream, the GPU running its paths whole (its own wavefront) "
                        "beside the host's stages (%.2f s). ",
                rep->stats.host_s);
    else if (rep->megakernel && rep->mk_gpu)
        fprintf(stderr, "Integrator: megakernel on %s. ", rep->dev[0].name);
    else if (rep->megakernel)
        fprintf(stderr, "Integrator: megakernel on %s (%s, %d thread%s). ", rep->dev[0].name,
                rep->strategy, rep->dev[0].threads, rep->dev[0].threads == 1 ? "" : "s");
    else
        fprintf(stderr, "Host stages took %.2f s, waiting for the devices %.2f s. ",
                rep->stats.host_s, rep->stats.wait_s);
}

/* The last sentences: MPI, dropped samples, --resume, --checkpoint, what was written. */
static void summary_files(const rs_report *rep)
{
    const rs_dist_result *d = rep->dist;
    if (d)
        fprintf(stderr,
                "MPI: %d ranks took %u passes of %u spp (rank 0: %u)%s%s; %.1f MB of films "
                "came to rank 0. ",
                d->ranks, d->passes_total, d->pass_spp, d->rank[0].passes,
                d->dead ? ", ranks were lost" : "",
                d->reissued ? ", passes were handed out again" : "",
                (double)d->bytes_received / 1e6);
    if (rep->nonfinite)
        fprintf(stderr, "%llu non-finite samples were dropped. ",
                (unsigned long long)rep->nonfinite);
    if (rep->resume)
        fprintf(stderr, "Continued from %s (%llu samples). ", rep->resume,
                (unsigned long long)rep->resumed);
    if (rep->checkpoint)
        fprintf(stderr, "Checkpoint %s holds %llu samples. ", rep->checkpoint,
                (unsigned long long)rep->checkpoint_samples);
    if (rep->interrupted)
        fprintf(stderr, "Wrote %s with %llu of %llu samples (at least %u per pixel).\n", rep->image,
                (unsigned long long)(rep->stats.paths_done + rep->resumed),
                (unsigned long long)(rep->stats.paths_total + rep->resumed), rep->spp_min);
    else
        fprintf(stderr, "Wrote %s.\n", rep->image);
}

void rs_report_print_summary(const rs_report *rep)
{
    if (rep->quiet) {
        if (rep->interrupted)
            fprintf(stderr,
                    "raystream: interrupted by %s; wrote a partial image (%llu of %llu samples) "
                    "to %s\n",
                    rs_signal_name(rep->interrupted), (unsigned long long)rep->stats.paths_done,
                    (unsigned long long)rep->stats.paths_total, rep->image);
        return;
    }
    summary_render(rep);
    summary_devices(rep);
    summary_files(rep);
}

/* ---- the image's header ------------------------------------------------------------------ */

void rs_report_image_meta(const rs_report *rep, rs_report_meta *m)
{
    static const char *const keys[RS_REPORT_META_FIXED] = {
        "raystream:scene",      "raystream:spp",     "raystream:spp_requested",
        "raystream:devices",    "raystream:integrator", "raystream:version",
        "raystream:lighting",   "raystream:denoised"};
    const char *values[RS_REPORT_META_FIXED];
    size_t used = 0, i;
    snprintf(m->spp, sizeof m->spp, "%u", rep->spp_min);
    snprintf(m->spp_requested, sizeof m->spp_requested, "%u", rep->spp);
    m->devices[0] = '\0';
    for (i = 0; i < (size_t)rep->n_dev; ++i) {
        int k = snprintf(m->devices + used, sizeof m->devices - used, "%s%s", i ? "," : "",
                         rep->dev[i].name);
        if (k < 0 || (size_t)k >= sizeof m->devices - used)
            break;
        used += (size_t)k;
    }
    values[0] = rep->scene;
    values[1] = m->spp;
    values[2] = m->spp_requested;
    values[3] = m->devices;
    values[4] = rep->megakernel ? "megakernel" : "stream";
    values[5] = RS_VERSION;
    values[6] = rep->lighting ? rep->lighting : "the scene's own";
    values[7] = rep->denoised ? rep->denoised : "no";
    for (i = 0; i < RS_REPORT_META_FIXED; ++i) {
        m->meta[i].key = keys[i];
        m->meta[i].value = values[i];
    }
    m->n = RS_REPORT_META_FIXED;
    /* then the image settings' rows, as the checkpoint and the JSON have them */
    for (i = 0; i < rs_image_settings_count() && m->n < RS_REPORT_META_MAX; ++i) {
        const rs_setting_desc *d = rs_image_setting(i);
        size_t k = m->n - RS_REPORT_META_FIXED;
        snprintf(m->keys[k], sizeof m->keys[k], "raystream:%s", d->name);
        d->text(rep->img, m->values[k], sizeof m->values[k]);
        m->meta[m->n].key = m->keys[k];
        m->meta[m->n].value = m->values[k];
        m->n++;
    }
}
