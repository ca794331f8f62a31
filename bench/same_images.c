/* bench/same_images.c — the images a refactor must not change: every option set rendered by
 * raystream, each compared pixel for pixel (the EXR's floats; metadata such as timings aside)
 * with the same scene, sampler and estimator on the first device set, and, given --old BIN, with
 * what another build (the commit before a change) renders.
 *
 *   same_images [--quick] [--new BIN] [--old BIN] [--args ARGS] [--new-args ARGS]
 *
 * --args: more options for every render (e.g. "--filter mitchell": the matrix with that filter);
 * --new-args: more options for the new build's renders only (e.g. "--filter box" against a build
 * from before pixel filters, whose only filter was that box).
 *
 * The matrix: scenes x samplers x estimators x {stream on the CPU (its own waves, and shaded on
 * the render thread: --shade-on host), stream on the CPU and the GPU fallback (both ways), the
 * megakernel on the CPU, the megakernel on the fallback} (a real GPU where there
 * is one, through --devices gpu), and the plans: the same render stopped by a checkpoint and
 * resumed, and adaptive sampling on one and two devices.  Exit 0 when every image is the same,
 * 1 with a line per difference.  --quick (the test suite's smoke run) takes two scenes, one
 * sampler and two estimators. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/alloc.h"
#include "core/image_io.h"
#include "machine.h"

#ifndef RS_BINARY_DIR
#  define RS_BINARY_DIR "."
#endif

static const char *k_devices[][2] = {
    {"stream cpu", "--devices cpu"},
    {"stream cpu, shaded on the render thread", "--devices cpu --shade-on host"},
    {"stream cpu+gpu", "--devices cpu,gpu"},
    {"stream cpu+gpu, shaded on the render thread", "--devices cpu,gpu --shade-on host"},
    {"megakernel cpu", "--integrator megakernel --devices cpu"},
    {"megakernel gpu", "--integrator megakernel --devices gpu"},
};

typedef struct image {
    uint32_t w, h;
    float *rgb;
} image;

/* Runs `bin` with `args` writing `out`; 0 after a message when it fails. */
static const char *g_args = "", *g_new_args = "", *g_new_bin = "";

static int render(const char *bin, const char *args, const char *out)
{
    char cmd[4096];
    int rc;
    snprintf(cmd, sizeof cmd, "%s render %s %s %s -q -o %s 2>/dev/null", bin, args, g_args,
             strcmp(bin, g_new_bin) == 0 ? g_new_args : "", out);
    rc = system(cmd);
    if (rc != 0) {
        fprintf(stderr, "same_images: failed (%d): %s\n", rc, cmd);
        return 0;
    }
    return 1;
}

static int load(const char *path, image *im)
{
    if (rs_image_read(path, &im->w, &im->h, &im->rgb) != RS_OK) {
        fprintf(stderr, "same_images: cannot read %s\n", path);
        return 0;
    }
    return 1;
}

/* 1 when a and b hold the same floats; else prints the first difference. */
static int same(const image *a, const image *b, const char *what)
{
    size_t i, n = (size_t)a->w * a->h * 3;
    if (a->w != b->w || a->h != b->h) {
        printf("DIFFERENT  %s: %ux%u against %ux%u\n", what, a->w, a->h, b->w, b->h);
        return 0;
    }
    for (i = 0; i < n; ++i)
        if (memcmp(&a->rgb[i], &b->rgb[i], sizeof(float)) != 0) {
            printf("DIFFERENT  %s: pixel %zu channel %zu: %.9g against %.9g\n", what, i / 3, i % 3,
                   (double)a->rgb[i], (double)b->rgb[i]);
            return 0;
        }
    return 1;
}

typedef struct ctx {
    const char *new_bin, *old_bin, *dir;
    int renders, bad;
} ctx;

/* Renders `args` with the new build (and the old one), compares with `ref` (NULL: becomes the
 * reference) and with the old build's image. */
static void check(ctx *c, const char *label, const char *args, image *ref)
{
    char out[1024], old_out[1024];
    image im = {0, 0, NULL}, old = {0, 0, NULL};
    snprintf(out, sizeof out, "%s/new.%s", c->dir, br_float_ext());
    snprintf(old_out, sizeof old_out, "%s/old.%s", c->dir, br_float_ext());
    c->renders++;
    if (!render(c->new_bin, args, out) || !load(out, &im)) {
        c->bad++;
        return;
    }
    if (ref->rgb && !same(&im, ref, label))
        c->bad++;
    if (c->old_bin) {
        char what[1200];
        snprintf(what, sizeof what, "%s (against --old)", label);
        if (!render(c->old_bin, args, old_out) || !load(old_out, &old) || !same(&im, &old, what))
            c->bad++;
        rs_free(old.rgb);
    }
    if (!ref->rgb)
        *ref = im;
    else
        rs_free(im.rgb);
}

/* The same render as two plans: a checkpoint written at the end of a render of 3 samples,
 * resumed to all of them. */
static void check_resume(ctx *c, const char *base, const char *label, image *ref)
{
    char args[1400], ckpt[1024], out[1024], what[1200];
    image im = {0, 0, NULL};
    snprintf(ckpt, sizeof ckpt, "%s/part.ckpt", c->dir);
    snprintf(out, sizeof out, "%s/part.%s", c->dir, br_float_ext());
    snprintf(args, sizeof args, "%s --spp 3 --checkpoint %s", base, ckpt);
    unlink(ckpt);
    if (!render(c->new_bin, args, out)) {
        c->bad++;
        return;
    }
    snprintf(args, sizeof args, "%s --resume %s", base, ckpt);
    snprintf(what, sizeof what, "%s, 3 spp then resumed", label);
    c->renders += 2;
    if (!render(c->new_bin, args, out) || !load(out, &im) || !same(&im, ref, what))
        c->bad++;
    rs_free(im.rgb);
}

int main(int argc, char **argv)
{
    static const char *scenes[] = {"builtin:cornell", "builtin:materials",
                                   "builtin:bouncing-spheres", "builtin:cornell-glass"};
    static const char *samplers[] = {"sobol", "zsobol", "independent"};
    static const char *estimators[] = {"mis", "mixture", "bsdf", "uniform"};
    char dir[] = "/tmp/same_images-XXXXXX", def_bin[1024];
    int quick = 0, i, n_sc, n_sa, n_es, a, b, e, d;
    ctx c;
    memset(&c, 0, sizeof c);
    snprintf(def_bin, sizeof def_bin, "%s/raystream", RS_BINARY_DIR);
    c.new_bin = def_bin;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (strcmp(argv[i], "--new") == 0 && i + 1 < argc)
            c.new_bin = argv[++i];
        else if (strcmp(argv[i], "--old") == 0 && i + 1 < argc)
            c.old_bin = argv[++i];
        else if (strcmp(argv[i], "--args") == 0 && i + 1 < argc)
            g_args = argv[++i];
        else if (strcmp(argv[i], "--new-args") == 0 && i + 1 < argc)
            g_new_args = argv[++i];
        else {
            fprintf(stderr, "usage: same_images [--quick] [--new BIN] [--old BIN] [--args ARGS] "
                            "[--new-args ARGS]\n");
            return strcmp(argv[i], "--help") == 0 ? 0 : 2;
        }
    }
    if (!mkdtemp(dir)) {
        fprintf(stderr, "same_images: cannot make a folder in /tmp\n");
        return 1;
    }
    c.dir = dir;
    g_new_bin = c.new_bin;
    n_sc = quick ? 2 : 4;
    n_sa = quick ? 1 : 3;
    n_es = quick ? 2 : 4;
    printf("same_images: %s%s%s, 40x30 pixels, 6 spp, depth 8%s%s%s%s\n", c.new_bin,
           c.old_bin ? " against " : "", c.old_bin ? c.old_bin : "", *g_args ? ", with " : "",
           g_args, *g_new_args ? ", the new build with " : "", g_new_args);
    for (a = 0; a < n_sc; ++a)
        for (b = 0; b < n_sa; ++b)
            for (e = 0; e < n_es; ++e) {
                char base[512], args[700], label[700];
                image ref = {0, 0, NULL};
                snprintf(base, sizeof base,
                         "%s --width 40 --height 30 --spp 6 --max-depth 8 --seed 3 --sampler %s "
                         "--sampling %s",
                         scenes[a], samplers[b], estimators[e]);
                for (d = 0; d < (int)(sizeof k_devices / sizeof k_devices[0]); ++d) {
                    snprintf(args, sizeof args, "%s %s", base, k_devices[d][1]);
                    snprintf(label, sizeof label, "%s %s %s, %s", scenes[a], samplers[b],
                             estimators[e], k_devices[d][0]);
                    check(&c, label, args, &ref);
                }
                /* plans: a resumed render, on the stream engine and the megakernel (zsobol's
                 * point set depends on the spp, so its checkpoints continue to the same spp
                 * only: app_cli_test splits those by a signal) */
                if (b != 1) {
                    snprintf(args, sizeof args, "%s --devices cpu", base);
                    snprintf(label, sizeof label, "%s %s %s, stream", scenes[a], samplers[b],
                             estimators[e]);
                    check_resume(&c, args, label, &ref);
                    snprintf(args, sizeof args, "%s --integrator megakernel --devices cpu", base);
                    snprintf(label, sizeof label, "%s %s %s, megakernel", scenes[a], samplers[b],
                             estimators[e]);
                    check_resume(&c, args, label, &ref);
                }
                /* adaptive sampling: one device, two, against each other and --old */
                if (e == 0) {
                    image aref = {0, 0, NULL};
                    snprintf(args, sizeof args,
                             "%s --adaptive 0.05 --adaptive-min-spp 2 "
                             "--spp 16 --devices cpu",
                             base);
                    snprintf(label, sizeof label, "%s %s adaptive, cpu", scenes[a], samplers[b]);
                    check(&c, label, args, &aref);
                    snprintf(args, sizeof args,
                             "%s --adaptive 0.05 --adaptive-min-spp 2 "
                             "--spp 16 --devices cpu,gpu",
                             base);
                    snprintf(label, sizeof label, "%s %s adaptive, cpu+gpu", scenes[a],
                             samplers[b]);
                    check(&c, label, args, &aref);
                    rs_free(aref.rgb);
                }
                rs_free(ref.rgb);
            }
    printf("same_images: %d renders, %d different%s\n", c.renders, c.bad,
           c.bad ? "" : ": every image the same");
    {
        char cmd[1100];
        snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
        if (system(cmd) != 0)
            fprintf(stderr, "same_images: could not remove %s\n", dir);
    }
    return c.bad ? 1 : 0;
}
