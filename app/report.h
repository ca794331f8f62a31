/* app/report.h — what a finished render reports, filled once (app/render_outputs.c) and written
 * four ways: the --stats table, the --stats-json file, the summary line and the .exr header's
 * attributes.  Internal to app/. */
#ifndef RS_APP_REPORT_H
#define RS_APP_REPORT_H

#include <stddef.h>
#include <stdint.h>

#include "app/distributed.h"
#include "app/image_settings.h"
#include "app/options.h"
#include "core/image_io.h"
#include "scheduler/adaptive.h"
#include "scheduler/render.h"

/* One device: the stream engine's (the scheduler's counters) or the megakernel's one. */
typedef struct rs_report_device {
    char name[48]; /* the device's own name */
    int threads, alive;
    int paths; /* it ran the stream integrator's paths whole (a GPU's wavefront) */
    rs_device_stats ds;
} rs_report_device;

typedef struct rs_report {
    /* what was asked: the options' strings (they outlive the report) */
    const char *scene, *image, *resume, *checkpoint; /* resume, checkpoint: NULL where none */
    int quiet, megakernel, mk_gpu;                   /* mk_gpu: the megakernel ran on a GPU */
    int wavefront; /* some devices ran the stream integrator's paths whole (dev[i].paths) */
    const char *strategy;                            /* the megakernel's host thread split */
    uint32_t width, height, spp, spp_min; /* spp asked; spp_min every pixel has */
    const rs_image_settings *img; /* what decided the image (its table: the header, the JSON) */
    const char *extensions;     /* a glTF file's extensions that were read, or NULL */
    const char *denoised;  /* --denoise: the OIDN device that ran it; NULL: not denoised */
    const char *lighting;  /* how the scene was lit when the file said nothing ("the default
                              sky: ..."), or NULL */
    double time_limit_s; /* --time-limit */
    /* what happened */
    int interrupted; /* the stop signal, or 0 */
    rs_render_stats stats;
    rs_adaptive_stats adaptive_stats;
    uint64_t resumed, checkpoint_samples, nonfinite;
    /* the BVH and the scene's instances */
    char bvh_builder[64];
    double bvh_sah, bvh_ms;
    uint32_t bvh_nodes, bvh_prims, blas_nodes, instances, inst_prims, inst_tris;
    /* the devices and their rays, summed */
    rs_report_device dev[RS_MAX_DEVICES];
    int n_dev;
    uint64_t dev_rays;
    const rs_dist_result *dist; /* rank 0 of an MPI job, else NULL */
} rs_report;

/* Device i's name as the table, the JSON and the timeline show it. */
void rs_report_device_label(const rs_report *rep, int i, char *buf, size_t n);
/* --stats: the device, rank and stage tables on stderr. */
void rs_report_print_table(const rs_report *rep);
/* --stats-json into `path` (named `shown` in messages); 0 after printing why it failed. */
int rs_report_write_json(const rs_report *rep, const char *path, const char *shown);
/* The summary line on stderr (with --quiet, only a word on an interruption). */
void rs_report_print_summary(const rs_report *rep);

/* The .exr header's attributes (core/image_io.h): the scene, the spp every pixel has and the
 * spp asked for, devices, integrator, version, the lighting when the scene's file gave none,
 * the denoiser, then every image setting's row ("raystream:NAME", app/image_settings.h: seed,
 * sampling, sampler, max depth, the filters, adaptive, ...); their strings in the struct
 * itself, n of them. */
enum { RS_REPORT_META_FIXED = 8, RS_REPORT_META_MAX = 40 };
typedef struct rs_report_meta {
    rs_image_meta meta[RS_REPORT_META_MAX];
    size_t n;
    char spp[16], spp_requested[16], devices[RS_MAX_DEVICES * 48];
    char keys[RS_REPORT_META_MAX - RS_REPORT_META_FIXED][48];
    char values[RS_REPORT_META_MAX - RS_REPORT_META_FIXED][RS_SETTING_TEXT];
} rs_report_meta;
void rs_report_image_meta(const rs_report *rep, rs_report_meta *m);

#endif
