/* app/options.h — the command line of `raystream`. */
#ifndef RS_APP_OPTIONS_H
#define RS_APP_OPTIONS_H

#include <stdint.h>

#include "accel/bvh.h"
#include "cpu/cpu_device.h"
#include "shading/integrator.h"

#define RS_EXIT_OK          0
#define RS_EXIT_RUNTIME     1
#define RS_EXIT_USAGE       2
#define RS_EXIT_INTERRUPTED 130 /* SIGINT (Ctrl-C): RS_EXIT_SIGNALLED(SIGINT) */
/* A render stopped by a signal (SIGINT, SIGTERM, SIGHUP) exits with 128 + its number, as a shell
 * reports a command the signal killed: 130, 143, 129. */
#define RS_EXIT_SIGNALLED(sig) (128 + (sig))

#define RS_MAX_DEVICES 16

typedef enum rs_cli_command {
    RS_CMD_RENDER,
    RS_CMD_SCENES,
    RS_CMD_HELP,
    RS_CMD_VERSION,
    RS_CMD_EXPORT
} rs_cli_command;

/* What --background (or --envmap) put in place of the scene's background. */
enum { RS_BG_NONE = 0, RS_BG_COLOR, RS_BG_SKY, RS_BG_FILE };

typedef struct rs_device_spec {
    int is_gpu;  /* 0: cpu, 1: gpu */
    int index;   /* gpu: CUDA device index */
    int threads; /* cpu: thread count, 0 = the --threads value */
} rs_device_spec;

typedef struct rs_cli_options {
    rs_cli_command command;
    const char *scene;      /* "builtin:NAME" */
    const char *output;     /* NULL: "<scene name>.png" */
    uint32_t width, height; /* 0: the scene's own */
    uint32_t spp;
    uint32_t max_depth;
    uint64_t seed;
    int threads; /* 0: every core */
    rs_sampling sampling;
    rs_sampler sampler;  /* --sampler */
    uint32_t chunk_size; /* 0: adaptive */
    uint32_t wave_paths;
    uint32_t waves; /* waves in flight; 0: auto */
    int quiet;
    const char *mesh;      /* --mesh FILE: into the Cornell box */
    const char *camera;    /* --camera NAME: a glTF scene's camera */
    const char *envmap;    /* --envmap FILE: light the scene with this environment map */
    float envmap_scale;    /* --envmap-scale S (default 1) */
    int envmap_scale_given;
    int background_kind;   /* --background: RS_BG_NONE (the scene's own), RS_BG_COLOR
                              (background_rgb), RS_BG_SKY (background: "sky[:...]", the part
                              after "sky" parsed by scenes/sky.h) or RS_BG_FILE (envmap) */
    const char *background;
    float background_rgb[3];
    rs_filter filter;      /* --filter NAME[:WIDTH] (default blackman-harris:1.5) */
    uint32_t texture_filter; /* --texture-filter: rs_texture_filter (shading/texture.h),
                                0 trilinear (the default) */
    uint32_t light_sampler; /* --light-sampler: rs_light_sampler (shading/light_sampler.h), 0 power */
    const char *view;      /* --view NAME: the display outputs' view transform (core/view.h);
                              NULL: standard */
    float exposure;        /* --exposure EV: display outputs scaled by 2^EV first */
    int denoise;           /* --denoise: OIDN on the beauty, with the albedo and normal */
    const char *models;    /* --models DIR */
    rs_bvh_builder bvh;    /* --bvh NAME */
    int bvh_on_gpu;        /* --bvh-device gpu: Morton codes and sort on CUDA device 0 */
    uint32_t isect_sphere; /* --isect-sphere: rs_isect_sphere_algo */
    uint32_t isect_tri;    /* --isect-tri: rs_isect_tri_algo */
    uint32_t isect_aabb;   /* --isect-aabb: rs_isect_aabb_algo */
    uint32_t bvh_width;    /* --bvh-width 2|4|8: the CPU device's traversal (0: the widest
                              this CPU runs, 8 with AVX2) */
    int devices_auto;      /* --devices auto (the default): the GPUs, else the CPU (under
                              mpirun this rank's share of them, app/devices.h) */
    int n_devices;
    rs_device_spec devices[RS_MAX_DEVICES];
    int require_gpu;       /* --require-gpu: a gpu that cannot be used is an error, not the
                              CPU fallback (app/devices.h) */
    int megakernel;           /* --integrator megakernel: the per-pixel loop on one device */
    int shade_host;           /* --shade-on host: devices only trace, the host shades every ray
                                 (the thesis's design); default: a device that can runs its
                                 paths whole (a GPU's wavefront) */
    rs_par_strategy strategy; /* --cpu-strategy */
    rs_cpu_walk cpu_walk;     /* --cpu-walk */
    int no_bvh;               /* --no-bvh: every ray tests every primitive */
    int flatten_instances;    /* --flatten-instances: instances copied, one-level BVH */
    int stats;                /* --stats: a per-device table after the render */
    const char *stats_json;   /* --stats-json FILE */
    const char *timeline;     /* --timeline FILE.svg */
    int spp_given;            /* --spp was on the command line (--resume takes the file's) */
    double time_limit_s;      /* --time-limit SECONDS; 0: none */
    unsigned aovs;            /* --aov LIST: RS_AOV_* layers in the EXR (shading/aov.h) */
    double adaptive;          /* --adaptive THRESHOLD; 0: every pixel gets spp */
    uint32_t adaptive_min_spp; /* --adaptive-min-spp N (default 16) */
    const char *tev;           /* --tev [HOST:]PORT: live preview in tev (app/tev.h) */
    const char *checkpoint;   /* --checkpoint FILE */
    double ckpt_every_s;      /* --checkpoint-interval SECONDS (default 60) */
    const char *resume;       /* --resume FILE */
    uint32_t mpi_pass_spp;    /* --mpi-pass N: samples per pass of an MPI job; 0: auto */
    double mpi_timeout_s;     /* --mpi-timeout SECONDS: a rank silent this long is dead (60) */
} rs_cli_options;

/* Parses argv.  Returns RS_EXIT_OK, or RS_EXIT_USAGE after printing one line naming the
 * problem on stderr. */
int rs_cli_parse(int argc, char **argv, rs_cli_options *o);
void rs_cli_print_help(const char *command);
/* Whether the render option `name` ("--spp") takes a value: 1, 0 for a flag (--denoise), -1 for
 * no such option (-h and -q included). */
int rs_cli_option_value(const char *name);

#endif
