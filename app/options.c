/* app/options.c — parsing and help text for the command line. */
#include "app/options.h"
#include "app/fail.h"
#include "app/tev.h"

#include "shading/aov.h"
#include "scenes/gltf.h"
#include "scenes/sky.h"
#include "core/view.h"

#include <errno.h>
#include <inttypes.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

static int usage_error(const char *fmt, const char *a, const char *b)
{
    char what[1024];
    snprintf(what, sizeof what, fmt, a, b);
    rs_app_print("raystream: %s (see 'raystream --help')\n", what);
    return RS_EXIT_USAGE;
}

/* A whole number in [lo, hi], written in decimal with nothing else around it. */
static int parse_u64(const char *opt, const char *text, uint64_t lo, uint64_t hi, uint64_t *out)
{
    char *end;
    unsigned long long v;
    char range[96];
    if (!text || !*text)
        return usage_error("%s needs a value%s", opt, "");
    if (text[0] == '-' || text[0] == '+' || text[0] == ' ')
        goto bad;
    errno = 0;
    v = strtoull(text, &end, 10);
    if (errno || *end != '\0' || end == text)
        goto bad;
    if (v < lo || v > hi) {
        snprintf(range, sizeof range, " must be between %" PRIu64 " and %" PRIu64, lo, hi);
        rs_app_print("raystream: %s %s:%s (see 'raystream --help')\n", opt, text, range);
        return RS_EXIT_USAGE;
    }
    *out = v;
    return RS_EXIT_OK;
bad:
    if (text[0] == '-' && strspn(text + 1, "0123456789") == strlen(text + 1) && text[1]) {
        rs_app_print("raystream: %s %s: must be a positive whole number (see 'raystream --help')\n",
                     opt, text);
        return RS_EXIT_USAGE;
    }
    return usage_error("%s: '%s' is not a whole number", opt, text);
}

/* A number of seconds: a positive, finite decimal number (1, 0.5, 2.5e3) up to 10^9, nothing
 * around it. */
static int parse_seconds(const char *opt, const char *text, double *out)
{
    char *end;
    double v;
    if (!text || !*text)
        return usage_error("%s needs a value%s", opt, "");
    /* strtod also takes "inf", "nan" and hex: only digits, a point, an exponent */
    if (strspn(text, "0123456789.eE+-") != strlen(text) || text[0] == '+' || text[0] == 'e' ||
        text[0] == 'E')
        return usage_error("%s: '%s' is not a number of seconds", opt, text);
    errno = 0;
    v = strtod(text, &end);
    if (*end != '\0' || end == text)
        return usage_error("%s: '%s' is not a number of seconds", opt, text);
    if (errno || !(v > 0.0) || v > 1e9) {
        rs_app_print("raystream: %s %s: must be a number of seconds above 0 and at most 1e9 (see "
                     "'raystream --help')\n",
                     opt, text);
        return RS_EXIT_USAGE;
    }
    *out = v;
    return RS_EXIT_OK;
}

static int parse_u32(const char *opt, const char *text, uint32_t lo, uint32_t hi, uint32_t *out)
{
    uint64_t v;
    int rc = parse_u64(opt, text, lo, hi, &v);
    if (rc == RS_EXIT_OK)
        *out = (uint32_t)v;
    return rc;
}

static int parse_devices(const char *text, rs_cli_options *o)
{
    char buf[256];
    char *tok, *save = NULL;
    if (strlen(text) >= sizeof buf)
        return usage_error("--devices: list too long: '%s'%s", text, "");
    strcpy(buf, text);
    o->n_devices = 0;
    o->devices_auto = 0;
    if (strcmp(text, "auto") == 0) {
        o->devices_auto = 1;
        return RS_EXIT_OK;
    }
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        rs_device_spec d = {0, 0, 0};
        char *colon = strchr(tok, ':');
        uint32_t v;
        int i;
        if (colon)
            *colon = '\0';
        if (strcmp(tok, "cpu") == 0) {
            if (colon && parse_u32("--devices cpu:THREADS", colon + 1, 1, 1024, &v))
                return RS_EXIT_USAGE;
            d.threads = colon ? (int)v : 0;
        } else if (strcmp(tok, "gpu") == 0) {
            d.is_gpu = 1;
            if (colon && parse_u32("--devices gpu:INDEX", colon + 1, 0, 63, &v))
                return RS_EXIT_USAGE;
            d.index = colon ? (int)v : 0;
        } else {
            return usage_error("--devices: unknown device '%s' in '%s' (use auto, or cpu, "
                               "cpu:THREADS, gpu, gpu:INDEX)",
                               tok, text);
        }
        for (i = 0; i < o->n_devices; ++i)
            if (o->devices[i].is_gpu == d.is_gpu && (!d.is_gpu || o->devices[i].index == d.index))
                return usage_error("--devices: '%s' is listed twice in '%s'", tok, text);
        if (o->n_devices == RS_MAX_DEVICES)
            return usage_error("--devices: more than 16 devices in '%s'%s", text, "");
        o->devices[o->n_devices++] = d;
    }
    if (o->n_devices == 0)
        return usage_error("--devices: empty device list '%s'%s", text, "");
    return RS_EXIT_OK;
}

/* `raystream export --help`. */
static void help_export(void)
{
    fputs("usage: raystream export SCENE -o FILE.json [--models DIR] [--camera NAME]\n"
          "\n"
          "Writes SCENE (builtin:NAME, FILE.json or FILE.gltf) as a scene file\n"
          "(docs/scene-format.md): the camera, image size, background, textures,\n"
          "materials (m0, m1, ...) and every primitive as an object.  Image textures\n"
          "and an environment map go beside it as FILE-image-N.exr.  Numbers keep 9\n"
          "digits, so the file renders the scene bit for bit.  A scene with what the\n"
          "format cannot say (glTF's metallic-roughness, emissive and normal textures)\n"
          "is refused.\n",
          stdout);
}

/* `raystream render --help`, 1/5: the scene and the image. */
static void help_render_scene(void)
{
    fputs("usage: raystream render [SCENE] [options]\n"
          "\n"
          "Renders SCENE (default builtin:cornell) to an image.\n"
          "\n"
          "  SCENE, --scene S    builtin:NAME ('raystream scenes' lists them), FILE.json\n"
          "                      (docs/scene-format.md) or a glTF 2.0 FILE.gltf / FILE.glb\n"
          "  --camera NAME       a glTF scene's camera by name (default: its first; a\n"
          "                      camera framing the model when it has none)\n"
          "  --background B      what rays leaving the scene see, in place of its own\n"
          "                      background: a grey 0.5 or R,G,B (linear radiance), an\n"
          "                      equirectangular image FILE (EXR, HDR, PNG, ...) or sky\n"
          "                      (a sun and sky, docs/sky.md: sky:elevation=E,azimuth=A,\n"
          "                      turbidity=T,intensity=I,sun=0|1).  A glTF file has none\n"
          "                      of its own: it gets the default sky\n"
          "  --envmap FILE       the same as --background FILE\n"
          "  --envmap-scale S    multiply the map's radiance by S (default 1)\n"
          "  --filter F[:W]      pixel filter, drawn by filter importance sampling: box,\n"
          "                      gaussian, blackman-harris or mitchell, W its full width in\n"
          "                      pixels (default blackman-harris:1.5, as Cycles; box:1 is\n"
          "                      the 1-pixel box of raystream before 0.9; docs/filters.md)\n"
          "  --texture-filter F  image textures: trilinear (mip-mapped, the default) or\n"
          "                      bilinear (level 0 only, as before 0.9; docs/textures.md)\n"          "  --light-sampler S   how next-event estimation picks a light (MIS): power (in\n"
          "                      proportion to power, the default) or bvh (a light BVH by\n"
          "                      each light's estimated contribution at the point: many\n"
          "                      lights; docs/sampling.md)\n"
          "  --view NAME         view transform of 8-bit outputs (PNG, JPEG, TIFF): standard\n"
          "                      (clip and sRGB, the default), filmic (AgX-like: highlights\n"
          "                      desaturate instead of clipping) or pbr-neutral (Khronos PBR\n"
          "                      Neutral); with $OCIO, also that config's views.  EXR and\n"
          "                      HDR stay scene-linear (docs/view.md)\n"
          "  --exposure EV       scale 8-bit outputs by 2^EV before the view (default 0)\n"
          "  --denoise           denoise with Intel Open Image Denoise (the albedo and\n"
          "                      normal layers guide it; lights and background seen\n"
          "                      directly are kept out of it; an EXR keeps the raw image\n"
          "                      as the layer 'noisy'; docs/denoise.md)\n"
          "  --mesh FILE         drop a mesh (OBJ, PLY, glTF, FBX, ...) into the Cornell box,\n"
          "                      scaled to fit, with its own materials\n"
          "  --models DIR        the test models folder for builtin scenes with meshes\n"
          "                      (default ../shared/models beside the source tree)\n"
          "  -o, --output FILE   image to write; the format follows the extension: .png\n"
          "                      (sRGB, 8-bit), .exr or .hdr (linear float), .jpg, .tif\n"
          "                      (default: NAME.png)\n"
          "  --width N, --height N   image size in pixels (default: the scene's, 600x600\n"
          "                      for the Cornell box; give one to keep the aspect ratio)\n"
          "  --spp N             samples per pixel (default 64)\n"
          "  --max-depth N       most ray segments per path, camera ray included (default 50)\n"
          "  --seed N            random seed; same seed, same image (default 1)\n",
          stdout);
}

/* 2/5: devices, stats, sampling, the BVH, the integrator. */
static void help_render_devices(void)
{
    fputs("  --threads N         CPU threads (default: every core)\n"
          "  --devices LIST      auto (default: every usable CUDA device, else the CPU; with\n"
          "                      --shade-on host the CPU and every CUDA device), or comma-\n"
          "                      separated cpu, cpu:THREADS, gpu, gpu:INDEX.  A gpu that\n"
          "                      cannot be used runs on the CPU fallback (one warning).\n"
          "                      Under mpirun, auto deals a machine's GPUs out to its ranks\n"
          "                      round robin (2 ranks, 4 GPUs: rank 0 takes gpu 0 and 2,\n"
          "                      rank 1 gpu 1 and 3); with more ranks than GPUs each rank\n"
          "                      takes one, shared (3 ranks, 2 GPUs: ranks 0 and 2 share\n"
          "                      gpu 0).  Every rank also takes its share of the cores.\n"
          "  --require-gpu       GPU or fail: a gpu that cannot be used, or auto finding no\n"
          "                      CUDA device, is an error (exit 1, before the render), not\n"
          "                      the CPU fallback\n"
          "  --stats             after the render, a table per device: rays, chunks, busy\n"
          "                      and idle seconds, Mrays/s, share, bytes moved; and the\n"
          "                      seconds of each named stage\n"
          "  --stats-json FILE   the same as JSON\n"
          "  --sampling MODE     mis (default): light + BSDF sampling, power heuristic;\n"
          "                      mixture: the thesis's light/BSDF mixture pdf;\n"
          "                      bsdf: BSDF sampling only; uniform: no importance sampling\n"
          "  --sampler NAME      sobol (default): Owen-scrambled Sobol points, 2D-stratified\n"
          "                      per decision; zsobol: the same, pixels in Morton order on\n"
          "                      one sequence (blue-noise error, pbrt-v4's ZSobolSampler);\n"
          "                      independent: independent random numbers\n"
          "  --bvh NAME          BVH builder: sah (default) or sah:BINS, median, lbvh, or the\n"
          "                      thesis grid AXIS-PARTITION-KEY: AXIS random|rotational|\n"
          "                      largest, PARTITION sort|partial|nth, KEY min|max|centroid\n"
          "  --integrator NAME   stream (default: the wavefront engine on every device) or\n"
          "                      megakernel (the thesis's per-pixel loop, on one device: the\n"
          "                      cpu, or a gpu (CUDA, one thread per pixel); auto picks the\n"
          "                      gpu where there is one; same image)\n"
          "  --shade-on WHERE    stream integrator: device (default): each device runs its\n"
          "                      paths whole, shading included (a GPU its own wavefront,\n"
          "                      --devices auto then takes the GPU alone; each CPU thread a\n"
          "                      wave of its own); host: the devices only trace and the\n"
          "                      render thread shades every ray (the thesis's design); same\n"
          "                      image\n"
          "  --cpu-strategy S    how CPU threads split work: for-dynamic (default), columns,\n"
          "                      tasks (the thesis's three OpenMP strategies)\n"
          "  --cpu-walk W        how each CPU thread's waves walk the 8-wide BVH: auto\n"
          "                      (default: each thread times both on its first waves and\n"
          "                      keeps the faster, per kind of ray), single (each ray alone)\n"
          "                      or packets (eight neighbouring rays together); same image\n",
          stdout);
}

/* 3/5: adaptive sampling, layers, traversal, chunks and waves. */
static void help_render_engine(void)
{
    fputs("  --adaptive T        adaptive sampling: a pixel stops once the relative error\n"
          "                      of its mean is below T (e.g. 0.01); --spp is then the most\n"
          "  --adaptive-min-spp N  samples every pixel gets first (default 16)\n"
          "  --aov LIST          extra EXR layers: albedo, normal, depth, samples or all\n"
          "                      (comma-separated; -o must be a .exr, the default then)\n"
          "  --no-bvh            no acceleration structure: every ray tests every primitive\n"
          "  --flatten-instances copy every instance's triangles into the scene instead of\n"
          "                      placing shared ones by a two-level BVH (same image)\n"
          "  --bvh-device D      where --bvh lbvh computes and sorts its Morton codes: cpu\n"
          "                      (default) or gpu (CUDA device 0; the tree is the same)\n"
          "  --bvh-width W       the CPU's traversal: 8 (the default where the CPU has AVX2;\n"
          "                      the binary BVH collapsed to 8-wide nodes), 4 (4-wide nodes,\n"
          "                      SSE; the default elsewhere) or 2 (the binary BVH, as on\n"
          "                      the GPU).  Same image either way.\n"
          "  --isect-sphere A    algebraic (default) or geometric\n"
          "  --isect-tri A       moller (default), snyder-barr or watertight\n"
          "  --isect-aabb A      slab (default), branchless, williams, kensler or swap\n"
          "  --chunk-size N|auto rays per scheduler chunk (default auto: each device's from\n"
          "                      its measured speed, a few ms of work per chunk)\n"
          "  --wave-size N|auto  paths in flight: bounds memory (default auto, on the CPU\n"
          "                      alone: 131072 per thread, 16384 when confined to one\n"
          "                      core; 1048576 with a GPU or several devices)\n"
          "  --waves N|auto      waves in flight, 1..4: the CPU shades one while the devices\n"
          "                      trace another (default auto: 2 with a GPU, else 1)\n",
          stdout);
}

/* 4/5: timeline, time limit, checkpoints, MPI, quiet, help. */
static void help_render_long(void)
{
    fputs("  --tev [HOST:]PORT   show the image in a running tev viewer as it converges (tev's\n"
          "                      port, 14158 by default; HOST 127.0.0.1): a few updates a\n"
          "                      second; without tev the render goes on after one warning\n"
          "  --timeline FILE.svg draw the render: a lane per device and one for shading, busy\n"
          "                      spans coloured by stage, idle gaps, waves labelled\n"
          "  --time-limit S      stop after S seconds (a decimal number > 0), at the end of\n"
          "                      the sample pass under way: every pixel gets the same\n"
          "                      number of samples; the summary and --stats-json say how\n"
          "                      many (checked when a wave of paths, or a device's call\n"
          "                      of about 0.25 s of them, starts: the render may run over\n"
          "                      by that much; at least one pass is done)\n"
          "  --checkpoint FILE   save the film to FILE every --checkpoint-interval, when a\n"
          "                      signal stops the render and at the end (FILE.tmp-PID,\n"
          "                      then renamed: the last good one stays until then)\n"
          "  --checkpoint-interval S  seconds between checkpoints (default 60)\n"
          "  --resume FILE       continue the render saved in FILE to --spp samples (default:\n"
          "                      the spp it was started with); the image is the one an\n"
          "                      uninterrupted render gives, bit for bit, on any devices.\n"
          "                      The scene, size, seed, sampling, sampler, max depth and\n"
          "                      intersection tests must be the same (and for zsobol the\n"
          "                      spp): a mismatch is refused with the field named\n"
          "  --mpi-pass N        under mpirun: samples of every pixel per pass handed to a\n"
          "                      rank (default: about 8 passes per rank, at most about\n"
          "                      2 million paths a pass)\n"
          "  --mpi-timeout S     under mpirun: a rank silent for S seconds is dead and its\n"
          "                      passes go to the others (default 60; docs/distributed.md)\n"
          "  -q, --quiet         no progress bar and no summary\n"
          "  -h, --help          this text\n",
          stdout);
}

/* 5/5: outputs, MPI, signals, environment, exit status. */
static void help_render_notes(void)
{
    fputs("\n"
          "Every output (-o, --stats-json, --timeline, --checkpoint) is checked before the\n"
          "render: a folder, a file that cannot be written or a missing or read-only folder\n"
          "is a usage error.  Outputs are written to FILE.tmp-PID and renamed into place\n"
          "only when all of them are written: a run that fails replaces no file.\n"
          "\n"
          "Under mpirun (mpirun -n N raystream render ...) every rank loads the scene and\n"
          "renders on its own --devices; rank 0 hands out passes, adds the films and\n"
          "writes the outputs: the image is the one-process image, bit for bit.\n"
          "\n"
          "Ctrl-C (SIGINT), SIGTERM or SIGHUP writes the samples finished so far and exits\n"
          "with 128 + the signal: 130, 143, 129.  A second signal stops at once, also\n"
          "while the outputs are written: their temporary files are removed.\n"
          "\n"
          "Environment: RS_FAULT=cpu:after=N,gpu:after=N makes those devices fail after N\n"
          "chunks (to test recovery; a bad value is a usage error); RS_MODELS_DIR is the\n"
          "default --models.\n"
          "\n"
          "Exit status: 0 done, 1 runtime error, 2 usage error (nothing written),\n"
          "130/143/129 interrupted by SIGINT/SIGTERM/SIGHUP.\n",
          stdout);
}

/* `raystream --help`: the commands. */
static void help_commands(void)
{
    fputs("usage: raystream COMMAND [options]\n"
          "\n"
          "raystream is a heterogeneous CPU+GPU streaming path tracer.\n"
          "\n"
          "commands:\n"
          "  render [SCENE] [options]   render a scene to an image (default builtin:cornell)\n"
          "  scenes                     list the built-in scenes\n"
          "  export SCENE -o FILE.json  write a scene (a built-in one, say) as a scene file\n"
          "                             (image textures beside it as FILE-image-N.exr)\n"
          "  help [COMMAND]             show help (also -h, --help)\n"
          "  version                    show the version and the build's features (also\n"
          "                             --version)\n"
          "\n"
          "'raystream render --help' lists the render options.\n",
          stdout);
}

void rs_cli_print_help(const char *command)
{
    if (command && strcmp(command, "export") == 0) {
        help_export();
    } else if (command && strcmp(command, "render") == 0) {
        help_render_scene();
        help_render_devices();
        help_render_engine();
        help_render_long();
        help_render_notes();
    } else {
        help_commands();
    }
}

#define NOT_MINE (-1)

/* ---- the options: one table of rows, each a kind with its field or a small handler ----------
 * (pbrt-v4's and Mitsuba's option lists read the same way: a name, what it takes, where it
 * goes).  A row's handler gets the option's name and value and returns RS_EXIT_OK or
 * RS_EXIT_USAGE after printing why; the messages name the option as it was written. */

typedef int (*opt_handler)(const char *name, const char *v, rs_cli_options *o);

typedef enum opt_kind {
    OPT_FLAG,     /* no value: the int field becomes 1 */
    OPT_U32,      /* a whole number in [lo, hi] into a uint32_t field */
    OPT_U32_AUTO, /* the same, or "auto" for 0 */
    OPT_U64,      /* a whole number in [lo, hi] into a uint64_t field */
    OPT_SECONDS,  /* parse_seconds into a double field */
    OPT_TEXT,     /* a non-empty string into a const char * field; `what` names the value */
    OPT_CALL      /* the value to `call` */
} opt_kind;

typedef struct opt_row {
    const char *name, *alias;
    opt_kind kind;
    size_t field; /* offsetof(rs_cli_options, ...) */
    uint64_t lo, hi;
    const char *what;
    opt_handler call;
} opt_row;

/* --scene S: like the positional SCENE, once. */
static int opt_scene(const char *name, const char *v, rs_cli_options *o)
{
    if (!*v)
        return usage_error("%s needs a scene (builtin:NAME or FILE.json), not an empty "
                           "name%s",
                           name, "");
    if (o->scene)
        return usage_error("more than one scene given ('%s' and '%s')", o->scene, v);
    o->scene = v;
    return RS_EXIT_OK;
}

static int opt_spp(const char *name, const char *v, rs_cli_options *o)
{
    o->spp_given = 1;
    return parse_u32(name, v, 1, 1u << 20, &o->spp);
}

static int opt_threads(const char *name, const char *v, rs_cli_options *o)
{
    uint32_t t = 0;
    int rc = parse_u32(name, v, 1, 1024, &t);
    o->threads = (int)t;
    return rc;
}

static int opt_devices(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    return parse_devices(v, o);
}

static int opt_sampling(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!rs_sampling_parse(v, &o->sampling))
        return usage_error("--sampling: unknown mode '%s'%s (use mis, mixture, bsdf or "
                           "uniform)",
                           v, "");
    return RS_EXIT_OK;
}

static int opt_sampler(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!rs_sampler_parse(v, &o->sampler))
        return usage_error("--sampler: unknown sampler '%s'%s (use independent, sobol or "
                           "zsobol)",
                           v, "");
    return RS_EXIT_OK;
}

static int opt_envmap_scale(const char *name, const char *v, rs_cli_options *o)
{
    char *end;
    double val = strtod(v, &end);
    (void)name;
    if (end == v || *end || !(val >= 0) || val > 1e30)
        return usage_error("--envmap-scale needs a number >= 0, not '%s'%s", v, "");
    o->envmap_scale = (float)val;
    o->envmap_scale_given = 1;
    return RS_EXIT_OK;
}

/* --background COLOR|FILE|sky[:k=v,...]: a grey "0.5" or "R,G,B" (linear radiance), the sky
 * (checked when the scene is made, scenes/sky.h), or else an image file (as --envmap). */
static int opt_background(const char *name, const char *v, rs_cli_options *o)
{
    float c[3];
    int n = 0, whole = 0; /* whole: the last number read ended the text ("0.5," does not) */
    char *end;
    const char *at = v;
    (void)name;
    if (!*v)
        return usage_error("--background needs a colour, an image file or sky%s%s", "", "");
    if (o->background_kind != RS_BG_NONE)
        return usage_error("the background is given twice (--background or --envmap '%s')%s", v,
                           "");
    if (strcmp(v, "sky") == 0 || strncmp(v, "sky:", 4) == 0) {
        rs_sky_params p;
        char why[200];
        if (!rs_sky_parse(v + 3, &p, why, sizeof why))
            return usage_error("--background %s: %s", v, why);
        o->background_kind = RS_BG_SKY;
        o->background = v;
        return RS_EXIT_OK;
    }
    while (n < 3) {
        double x = strtod(at, &end);
        if (end == at || !(x >= 0.0 && x <= 1e12) || (*end && *end != ','))
            break;
        c[n++] = (float)x;
        if (!*end) {
            whole = 1;
            break;
        }
        at = end + 1;
    }
    if ((n == 1 || n == 3) && whole) {
        o->background_kind = RS_BG_COLOR;
        o->background = v;
        o->background_rgb[0] = c[0];
        o->background_rgb[1] = n == 3 ? c[1] : c[0];
        o->background_rgb[2] = n == 3 ? c[2] : c[0];
        return RS_EXIT_OK;
    }
    if (strspn(v, "0123456789.,eE+-") == strlen(v)) /* numbers, but not a colour */
        return usage_error("--background '%s' is not a colour (a grey 0.5 or R,G,B, each a "
                           "radiance in [0, 1e12])%s",
                           v, "");
    o->background_kind = RS_BG_FILE;
    o->background = o->envmap = v;
    return RS_EXIT_OK;
}

/* --envmap FILE: --background FILE. */
static int opt_envmap(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!*v)
        return usage_error("--envmap needs an image file%s%s", "", "");
    if (o->background_kind != RS_BG_NONE)
        return usage_error("the background is given twice (--background or --envmap '%s')%s", v,
                           "");
    o->background_kind = RS_BG_FILE;
    o->background = o->envmap = v;
    return RS_EXIT_OK;
}

static int opt_filter(const char *name, const char *v, rs_cli_options *o)
{
    char why[200];
    (void)name;
    if (!rs_filter_parse(v, &o->filter, why, sizeof why))
        return usage_error("--filter: %s%s", why, "");
    return RS_EXIT_OK;
}

static int opt_texture_filter(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (strcmp(v, "trilinear") == 0)
        o->texture_filter = RS_TEXTURE_TRILINEAR;
    else if (strcmp(v, "bilinear") == 0)
        o->texture_filter = RS_TEXTURE_BILINEAR;
    else
        return usage_error("--texture-filter: '%s' is not trilinear or bilinear%s", v, "");
    return RS_EXIT_OK;
}

static int opt_light_sampler(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (strcmp(v, "power") == 0)
        o->light_sampler = RS_LIGHT_SAMPLER_POWER;
    else if (strcmp(v, "bvh") == 0)
        o->light_sampler = RS_LIGHT_SAMPLER_BVH;
    else
        return usage_error("--light-sampler: '%s' is not power or bvh%s", v, "");
    return RS_EXIT_OK;
}

static int opt_exposure(const char *name, const char *v, rs_cli_options *o)
{
    char *end;
    double val = strtod(v, &end);
    (void)name;
    if (end == v || *end || !(val >= -64.0 && val <= 64.0))
        return usage_error("--exposure needs a number of stops in [-64, 64], not '%s'%s", v, "");
    o->exposure = (float)val;
    return RS_EXIT_OK;
}

static int opt_integrator(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (strcmp(v, "stream") != 0 && strcmp(v, "megakernel") != 0)
        return usage_error("--integrator: '%s'%s (use stream or megakernel)", v, "");
    o->megakernel = v[0] == 'm';
    return RS_EXIT_OK;
}

static int opt_shade_on(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (strcmp(v, "device") != 0 && strcmp(v, "host") != 0)
        return usage_error("--shade-on: '%s'%s (use device or host)", v, "");
    o->shade_host = v[0] == 'h';
    return RS_EXIT_OK;
}

static int opt_cpu_strategy(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!rs_par_strategy_parse(v, &o->strategy))
        return usage_error("--cpu-strategy: '%s'%s (use for-dynamic, columns or tasks)", v, "");
    return RS_EXIT_OK;
}

static int opt_cpu_walk(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!rs_cpu_walk_parse(v, &o->cpu_walk))
        return usage_error("--cpu-walk: '%s'%s (use auto, single or packets)", v, "");
    return RS_EXIT_OK;
}

static int opt_timeline(const char *name, const char *v, rs_cli_options *o)
{
    size_t n = strlen(v);
    (void)name;
    if (n < 5 || strcmp(v + n - 4, ".svg") != 0)
        return usage_error("--timeline writes an SVG picture: '%s'%s must end in .svg", v, "");
    o->timeline = v;
    return RS_EXIT_OK;
}

static int opt_adaptive(const char *name, const char *v, rs_cli_options *o)
{
    char *end;
    double val = strtod(v, &end);
    (void)name;
    if (end == v || *end || !(val > 0) || !(val < 1))
        return usage_error("--adaptive needs a relative error threshold in (0, 1), such as "
                           "0.01, not '%s'%s",
                           v, "");
    o->adaptive = val;
    return RS_EXIT_OK;
}

/* --aov LIST: comma-separated layer names, added to o->aovs. */
static int opt_aov(const char *name, const char *v, rs_cli_options *o)
{
    static const struct {
        const char *name;
        unsigned bits;
    } layers[] = {{"albedo", RS_AOV_ALBEDO},
                  {"normal", RS_AOV_NORMAL},
                  {"depth", RS_AOV_DEPTH},
                  {"samples", RS_AOV_SAMPLES},
                  {"all", RS_AOV_ALL}};
    const char *tok = v;
    size_t k;
    (void)name;
    while (*tok) { /* the list read in place: any length (a copy of 128 bytes cut it) */
        size_t len = strcspn(tok, ",");
        for (k = 0; k < sizeof layers / sizeof layers[0] &&
                    !(strlen(layers[k].name) == len && strncmp(tok, layers[k].name, len) == 0);
             ++k)
            ;
        if (len && k == sizeof layers / sizeof layers[0]) {
            char bad[64];
            snprintf(bad, sizeof bad, "%.*s", (int)(len < 60 ? len : 60), tok);
            return usage_error("--aov: '%s'%s is not a layer (use albedo, normal, depth, "
                               "samples or all, separated by commas)",
                               bad, len > 60 ? "..." : "");
        }
        if (len)
            o->aovs |= layers[k].bits;
        tok += len + (tok[len] == ',');
    }
    if (!o->aovs)
        return usage_error("--aov needs a list of layers%s%s", "", "");
    return RS_EXIT_OK;
}

static int opt_bvh(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (rs_bvh_builder_parse(v, &o->bvh) != RS_OK) {
        rs_app_print("raystream: --bvh: %s (see 'raystream render --help')\n", rs_error_message());
        rs_error_clear();
        return RS_EXIT_USAGE;
    }
    return RS_EXIT_OK;
}

/* --tev [HOST:]PORT */
static int opt_tev(const char *name, const char *v, rs_cli_options *o)
{
    char host[128], why[200];
    int port;
    if (!rs_tev_parse(v, host, sizeof host, &port, why, sizeof why))
        return usage_error("%s: %s", name, why);
    o->tev = v;
    return RS_EXIT_OK;
}

static int opt_bvh_device(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (strcmp(v, "cpu") != 0 && strcmp(v, "gpu") != 0)
        return usage_error("--bvh-device: '%s'%s (use cpu or gpu)", v, "");
    o->bvh_on_gpu = v[0] == 'g';
    return RS_EXIT_OK;
}

static int opt_bvh_width(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (strcmp(v, "2") != 0 && strcmp(v, "4") != 0 && strcmp(v, "8") != 0)
        return usage_error("--bvh-width must be 2, 4 or 8, not '%s'%s", v, "");
    o->bvh_width = (uint32_t)(v[0] - '0');
    return RS_EXIT_OK;
}

static int opt_isect_sphere(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!rs_isect_sphere_algo_parse(v, &o->isect_sphere))
        return usage_error("--isect-sphere: unknown algorithm '%s'%s (use algebraic or "
                           "geometric)",
                           v, "");
    return RS_EXIT_OK;
}

static int opt_isect_tri(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!rs_isect_tri_algo_parse(v, &o->isect_tri))
        return usage_error("--isect-tri: unknown algorithm '%s'%s (use moller, snyder-barr "
                           "or watertight)",
                           v, "");
    return RS_EXIT_OK;
}

static int opt_isect_aabb(const char *name, const char *v, rs_cli_options *o)
{
    (void)name;
    if (!rs_isect_aabb_algo_parse(v, &o->isect_aabb))
        return usage_error("--isect-aabb: unknown algorithm '%s'%s (use slab, branchless, "
                           "williams, kensler or swap)",
                           v, "");
    return RS_EXIT_OK;
}

#define FIELD(f) offsetof(rs_cli_options, f)
#define ROW_CALL(name, fn)                                                                         \
    { name, NULL, OPT_CALL, 0, 0, 0, NULL, fn }
#define ROW_TEXT(name, alias, f, what)                                                             \
    { name, alias, OPT_TEXT, FIELD(f), 0, 0, what, NULL }
#define ROW_NUM(name, kind, f, lo, hi)                                                             \
    { name, NULL, kind, FIELD(f), lo, hi, NULL, NULL }

/* Every option but -h/--help and -q/--quiet (rs_cli_parse), grouped as `render --help` lists
 * them: the scene and image; how it runs; outputs and long renders; the BVH and the tests. */
static const opt_row options[] = {
    ROW_CALL("--scene", opt_scene),
    ROW_TEXT("-o", "--output", output, "a file name"),
    ROW_NUM("--width", OPT_U32, width, 1, 32768),
    ROW_NUM("--height", OPT_U32, height, 1, 32768),
    ROW_CALL("--spp", opt_spp),
    ROW_NUM("--max-depth", OPT_U32, max_depth, 1, 10000),
    ROW_NUM("--seed", OPT_U64, seed, 0, UINT64_MAX),
    ROW_CALL("--sampling", opt_sampling),
    ROW_CALL("--sampler", opt_sampler),
    ROW_TEXT("--mesh", NULL, mesh, "a file name"),
    ROW_TEXT("--camera", NULL, camera, "a camera's name"),
    ROW_CALL("--background", opt_background),
    ROW_CALL("--envmap", opt_envmap),
    ROW_CALL("--envmap-scale", opt_envmap_scale),
    ROW_CALL("--filter", opt_filter),
    ROW_CALL("--texture-filter", opt_texture_filter),
    ROW_CALL("--light-sampler", opt_light_sampler),
    ROW_TEXT("--view", NULL, view, "a view's name"),
    ROW_CALL("--exposure", opt_exposure),
    ROW_NUM("--denoise", OPT_FLAG, denoise, 0, 0),
    ROW_TEXT("--models", NULL, models, "a folder"),

    ROW_CALL("--threads", opt_threads),
    ROW_CALL("--devices", opt_devices),
    ROW_NUM("--require-gpu", OPT_FLAG, require_gpu, 0, 0),
    ROW_CALL("--integrator", opt_integrator),
    ROW_CALL("--shade-on", opt_shade_on),
    ROW_CALL("--cpu-strategy", opt_cpu_strategy),
    ROW_CALL("--cpu-walk", opt_cpu_walk),
    ROW_NUM("--stats", OPT_FLAG, stats, 0, 0),
    ROW_TEXT("--stats-json", NULL, stats_json, "a file name"),
    ROW_CALL("--timeline", opt_timeline),
    ROW_CALL("--tev", opt_tev),
    ROW_CALL("--adaptive", opt_adaptive),
    ROW_NUM("--adaptive-min-spp", OPT_U32, adaptive_min_spp, 2, 1u << 20),
    ROW_CALL("--aov", opt_aov),
    ROW_NUM("--time-limit", OPT_SECONDS, time_limit_s, 0, 0),
    ROW_NUM("--mpi-pass", OPT_U32, mpi_pass_spp, 1, 1u << 24),
    ROW_NUM("--mpi-timeout", OPT_SECONDS, mpi_timeout_s, 0, 0),
    ROW_TEXT("--checkpoint", NULL, checkpoint, "a file name"),
    ROW_NUM("--checkpoint-interval", OPT_SECONDS, ckpt_every_s, 0, 0),
    ROW_TEXT("--resume", NULL, resume, "a file name"),
    ROW_NUM("--chunk-size", OPT_U32_AUTO, chunk_size, 1, 1u << 26),
    ROW_NUM("--waves", OPT_U32_AUTO, waves, 1, 4),
    ROW_NUM("--wave-size", OPT_U32_AUTO, wave_paths, 1, 1u << 26),

    ROW_CALL("--bvh", opt_bvh),
    ROW_NUM("--no-bvh", OPT_FLAG, no_bvh, 0, 0),
    ROW_NUM("--flatten-instances", OPT_FLAG, flatten_instances, 0, 0),
    ROW_CALL("--bvh-device", opt_bvh_device),
    ROW_CALL("--bvh-width", opt_bvh_width),
    ROW_CALL("--isect-sphere", opt_isect_sphere),
    ROW_CALL("--isect-tri", opt_isect_tri),
    ROW_CALL("--isect-aabb", opt_isect_aabb),
};

#undef ROW_NUM
#undef ROW_TEXT
#undef ROW_CALL
#undef FIELD

int rs_cli_option_value(const char *name)
{
    size_t k;
    for (k = 0; k < sizeof options / sizeof options[0]; ++k)
        if (strcmp(name, options[k].name) == 0 ||
            (options[k].alias && strcmp(name, options[k].alias) == 0))
            return options[k].kind != OPT_FLAG;
    return -1;
}

/* The option argv[*i], named `name` (its "=value" part `eq`, or NULL): the value is the part
 * after '=', else the next argument.  Returns RS_EXIT_OK, RS_EXIT_USAGE after printing why, or
 * NOT_MINE when no row has that name. */
static int parse_option(int argc, char **argv, int *i, const char *eq, const char *name,
                        rs_cli_options *o)
{
    const opt_row *r = NULL;
    char *field;
    const char *v;
    size_t k;
    for (k = 0; k < sizeof options / sizeof options[0] && !r; ++k)
        if (strcmp(name, options[k].name) == 0 ||
            (options[k].alias && strcmp(name, options[k].alias) == 0))
            r = &options[k];
    if (!r)
        return NOT_MINE;
    field = (char *)o + r->field;
    if (r->kind == OPT_FLAG) {
        *(int *)(void *)field = 1; /* "--stats=x" ignores the x, as it always has */
        return RS_EXIT_OK;
    }
    v = eq ? eq + 1 : *i + 1 < argc ? argv[++*i] : NULL;
    if (!v)
        return usage_error("%s needs a value%s", name, "");
    switch (r->kind) {
    case OPT_U32_AUTO:
        if (strcmp(v, "auto") == 0) {
            *(uint32_t *)(void *)field = 0;
            return RS_EXIT_OK;
        }
        /* fall through */
    case OPT_U32:
        return parse_u32(name, v, (uint32_t)r->lo, (uint32_t)r->hi, (uint32_t *)(void *)field);
    case OPT_U64:
        return parse_u64(name, v, r->lo, r->hi, (uint64_t *)(void *)field);
    case OPT_SECONDS:
        return parse_seconds(name, v, (double *)(void *)field);
    case OPT_TEXT:
        if (!*v)
            return usage_error("%s needs %s", name, r->what);
        *(const char **)(void *)field = v;
        return RS_EXIT_OK;
    default:
        return r->call(name, v, o);
    }
}

/* The command word: sets o->command and returns 1 when argv needs no more parsing. */
static int parse_command(int argc, char **argv, rs_cli_options *o, int *rc)
{
    *rc = RS_EXIT_OK;
    if (argc < 2) {
        o->command = RS_CMD_HELP;
        return 1;
    }
    if (strcmp(argv[1], "--help") == 0 || strcmp(argv[1], "-h") == 0 ||
        strcmp(argv[1], "help") == 0) {
        o->command = RS_CMD_HELP;
        o->scene = argc > 2 ? argv[2] : NULL; /* the command to explain */
        return 1;
    }
    if (strcmp(argv[1], "--version") == 0 || strcmp(argv[1], "version") == 0) {
        o->command = RS_CMD_VERSION;
        return 1;
    }
    if (strcmp(argv[1], "scenes") == 0) {
        o->command = RS_CMD_SCENES;
        return 1;
    }
    if (strcmp(argv[1], "export") == 0) {
        o->command = RS_CMD_EXPORT; /* then the render's options: the scene and -o matter */
        return 0;
    }
    if (strcmp(argv[1], "render") != 0) {
        *rc = usage_error("unknown command '%s'%s", argv[1], "");
        return 1;
    }
    return 0;
}

/* Whether --devices lists a gpu. */
static int any_gpu_listed(const rs_cli_options *o)
{
    int i;
    for (i = 0; i < o->n_devices; ++i)
        if (o->devices[i].is_gpu)
            return 1;
    return 0;
}

/* What no single option can check: combinations, and the defaults that depend on them. */
static int check_render_options(rs_cli_options *o)
{
    if (o->megakernel && !o->devices_auto && o->n_devices > 1)
        return usage_error("--integrator megakernel runs on one device%s%s (use --devices cpu or "
                           "--devices gpu[:INDEX])",
                           "", "");
    if (o->require_gpu && !o->devices_auto && !any_gpu_listed(o))
        return usage_error("--require-gpu needs a gpu in --devices (gpu, gpu:INDEX or auto)%s%s",
                           "", "");
    if (o->ckpt_every_s > 0 && !o->checkpoint)
        return usage_error("--checkpoint-interval needs --checkpoint FILE%s%s", "", "");
    if (o->ckpt_every_s == 0)
        o->ckpt_every_s = 60.0;
    if (o->bvh_on_gpu && o->bvh.method != RS_BVH_LBVH)
        return usage_error("--bvh-device gpu builds the lbvh only (add --bvh lbvh)%s%s", "", "");
    if (o->mesh) {
        if (o->scene && strcmp(o->scene, "builtin:cornell") != 0)
            return usage_error("--mesh puts a mesh into the Cornell box; it cannot be combined "
                               "with the scene '%s'%s",
                               o->scene, "");
        o->scene = "builtin:cornell-mesh";
    }
    if (!o->scene)
        o->scene = "builtin:cornell";
    if (o->camera && !rs_is_gltf_path(o->scene))
        return usage_error("--camera picks a glTF scene's camera; '%s' is not a .gltf or .glb "
                           "file%s",
                           o->scene, "");
    if (o->adaptive_min_spp && o->adaptive == 0)
        return usage_error("--adaptive-min-spp needs --adaptive THRESHOLD%s%s", "", "");
    if (o->adaptive > 0 && o->megakernel)
        return usage_error("--adaptive runs on the stream integrator, not the megakernel%s%s", "",
                           "");
    if (o->adaptive > 0 && !o->adaptive_min_spp)
        o->adaptive_min_spp = 16;
    if (o->aovs && o->output &&
        (strlen(o->output) < 4 || strcasecmp(o->output + strlen(o->output) - 4, ".exr") != 0))
        return usage_error("--aov writes layers into an EXR file; '%s'%s is not a .exr", o->output,
                           "");
    if (o->view || o->exposure != 0.0f) {
        rs_view v;
        char why[300];
        if (!rs_view_from_name(o->view, o->exposure, &v, why, sizeof why))
            return usage_error("--view: %s%s", why, "");
    }
    if (o->envmap_scale_given && !o->envmap)
        return usage_error("--envmap-scale needs --envmap FILE or --background FILE%s%s", "", "");
    if (!o->envmap_scale_given)
        o->envmap_scale = 1.0f;
    return RS_EXIT_OK;
}

int rs_cli_parse(int argc, char **argv, rs_cli_options *o)
{
    int i, rc;
    memset(o, 0, sizeof *o);
    o->command = RS_CMD_RENDER;
    o->scene = NULL;
    o->spp = 64;
    o->max_depth = 50;
    o->seed = 1;
    o->sampling = RS_SAMPLING_MIS;
    o->sampler = RS_SAMPLER_SOBOL;
    o->bvh.method = RS_BVH_SAH; /* binned, 16 bins: 1.25-1.33x faster traversal than median */
    o->chunk_size = 0; /* adaptive */
    o->wave_paths = 0; /* auto */
    o->waves = 0; /* auto */
    o->devices_auto = 1;
    o->n_devices = 0;
    rs_filter_default(&o->filter);
    if (parse_command(argc, argv, o, &rc))
        return rc;
    if (o->command == RS_CMD_EXPORT) {
        /* export takes the render's options; they are parsed below as the render's */
    }

    for (i = 2; i < argc; ++i) {
        const char *a = argv[i];
        const char *eq = (a[0] == '-' && a[1] == '-') ? strchr(a, '=') : NULL;
        char name[64];
        size_t len = eq ? (size_t)(eq - a) : strlen(a);
        if (len >= sizeof name)
            len = sizeof name - 1;
        memcpy(name, a, len);
        name[len] = '\0';

        if (a[0] != '-' || a[1] == '\0') {
            /* an empty argument ('' from a script's unset variable) would be reported later
             * as the file ": no such scene file", a line that names nothing */
            if (!*a)
                return usage_error("an empty argument where the scene (builtin:NAME or "
                                   "FILE.json) goes%s%s",
                                   "", "");
            if (o->scene)
                return usage_error("more than one scene given ('%s' and '%s')", o->scene, a);
            o->scene = a;
            continue;
        }
        if (strcmp(name, "-h") == 0 || strcmp(name, "--help") == 0) {
            int export = o->command == RS_CMD_EXPORT;
            o->command = RS_CMD_HELP;
            o->scene = export ? "export" : "render";
            return RS_EXIT_OK;
        }
        if (strcmp(name, "-q") == 0 || strcmp(name, "--quiet") == 0) {
            o->quiet = 1;
            continue;
        }
        if ((rc = parse_option(argc, argv, &i, eq, name, o)) == NOT_MINE)
            return usage_error("unknown option '%s'%s", a, "");
        if (rc != RS_EXIT_OK)
            return rc;
    }
    return check_render_options(o);
}
