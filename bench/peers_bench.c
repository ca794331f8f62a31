/* bench/peers_bench.c — time to a clean image, raystream against other renderers.
 *
 * Two scenes: builtin:cornell (256x256, max depth 50) and an interior (the living room's
 * geometry from ../shared/models, 143k triangles, every surface Lambertian 0.5, its glass left
 * out, lit through its windows by a uniform sky of radiance 1; max depth 16; skipped with a
 * message where the models are missing).  Each is rendered with raystream's stream engine (each
 * sampler) and megakernel, with Mitsuba 3 (llvm_ad_rgb with its independent sampler and its
 * low-discrepancy `ldsampler`; scalar_rgb on the box), with Blender's Cycles (bpy, its default
 * sampler) and, on the box, LuxCoreRender (PATHCPU, Sobol): a 1-pixel box filter everywhere, at
 * one and at two threads pinned to the first cores, renderers interleaved in rounds.  The peers
 * get raystream's own scene: every quad and triangle exported to OBJ files, one per material,
 * with the same camera, lights, background and diffuse materials, as a Mitsuba scene file and as
 * a JSON description for LuxCore and Cycles (bench/peers/NAME_peer.py render them in the peers'
 * Python virtual environments).
 *
 * First it checks that the peers render the same picture: each renderer's converged reference is
 * the mean of two independent halves (whose difference also measures the reference's own noise),
 * and a block-mean z-test over 16x16-pixel blocks compares the peer's reference with ours.  Then,
 * per renderer, for each sample count: the median time of the render alone over the rounds (no
 * scene loading, BVH building or JIT compiling for anyone), and the RMSE over all pixels and
 * channels against that renderer's own reference, with the reference's noise removed
 * (E|img - ref|^2 = err^2 + var_ref, var_ref = |A - B|^2 / 4).  A line log RMSE = a + b log spp
 * fitted through the levels gives the samples needed for RMSE 0.02 and 0.01 and, at the
 * measured seconds per sample pass, the time, with the ratio to raystream's.
 *
 *   peers_bench [--quick] [--scenes cornell,interior] [--threads 1,2] [--size N]
 *               [--levels A,B,...] [--ref-spp N] [--runs N] [--depth N] [--venv DIR]
 *               [--cycles-venv DIR]
 *               [--no-peers] [--keep DIR]
 *
 * --quick (the test suite's smoke test) renders raystream's part only, small, at one thread,
 * and exports the scenes without running any peer.  Mitsuba and LuxCore run when DIR/bin/python
 * (--venv, else $RS_PEERS_VENV, else peers-venv in the build folder) imports them, Cycles when
 * DIR-cycles/bin/python (--cycles-venv, else $RS_CYCLES_VENV) imports bpy: make them with
 * `sh scripts/install-peers.sh DIR`.  A peer that is missing is skipped with a message.  The
 * interior's levels are 4, 16, 64 unless --levels is given (a sample costs 5x the box's);
 * --depth N sets both scenes' max depth (2: direct light only). */
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <sched.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include "core/parallel.h"
#include "scenes/builtin.h"
#include "scenes/scene_json.h"
#include "scenes/scene_export.h"
#include "machine.h"
#include "render_util.h"

#define USAGE                                                                                  \
    "usage: peers_bench [options]   time to RMSE 0.02 and 0.01, raystream against its peers\n"   \
    "  --quick             raystream only, small, one thread (the test suite's smoke run)\n"    \
    "  --scenes LIST       cornell,interior (default both; interior needs ../shared/models)\n"  \
    "  --threads LIST      thread counts, each pinned to the first cores (default 1,2)\n"      \
    "  --size N            image width and height (default 256; WxH with --export)\n"         \
    "  --levels A,B,...    sample counts measured (default 4,16,64,256; interior 4,16,64)\n"   \
    "  --ref-spp N         samples of each converged reference (default 1024)\n"               \
    "  --runs N            interleaved rounds, the median is kept (default 3)\n"              \
    "  --depth N           max depth of both scenes (default 50 box, 16 interior)\n"          \
    "  --venv DIR          Mitsuba and LuxCore venv (default $RS_PEERS_VENV or build/peers-venv)\n" \
    "  --cycles-venv DIR   Cycles (bpy) venv (default $RS_CYCLES_VENV or the venv + -cycles)\n" \
    "  --no-peers          raystream's rows only\n"                                             \
    "  --keep DIR          keep the exported scenes and images in DIR\n"                        \
    "  --export DIR        only write each scene for the peers and for raystream into DIR/NAME\n" \
    "                      (scene.xml + OBJs, scene.json; --size, --depth apply), then stop\n"   \
    "Install the peers with: sh scripts/install-peers.sh\n"
#define MAX_LEVELS 12
#define MAX_RUNS   9
#define MAX_ROWS   12
#define BLOCK      16

typedef enum row_kind { ROW_RAYSTREAM, ROW_PEER } row_kind;

typedef struct row {
    const char *label;
    row_kind kind;
    /* raystream */
    rs_sampler sampler;
    int megakernel;
    int shade_host; /* the stream engine shading on the render thread (--shade-on host) instead
                       of the CPU device's own waves (the default) */
    /* a peer: bench/peers/SCRIPT SCENE VARIANT SAMPLER ... */
    const char *script, *scene_file, *variant, *mi_sampler, *name, *python;
    /* results */
    int ref_row; /* whose reference it is measured against (the same renderer's) */
    double secs[MAX_LEVELS][MAX_RUNS], err2[MAX_LEVELS];
    double done[MAX_LEVELS]; /* the samples per pixel taken, mean over rounds (LuxCore overshoots) */
    int ok;
    int close; /* its picture differs from ours in a few blocks (same_picture: CLOSE) */
} row;

typedef struct reference {
    float *img;     /* the mean of the two halves */
    float *a, *b;   /* the halves */
    double var_ref; /* mean over pixels and channels of the reference's own noise variance */
} reference;

static const char *prog = "peers_bench";
static uint32_t W = 256, H = 256;
static uint32_t DEPTH = 50; /* the scene's max depth (ray segments, camera ray included) */
static char tmp_dir[512];
static char py_peers[1100];  /* the venv's Python: Mitsuba and LuxCore */
static char py_cycles[1100]; /* the Cycles venv's (bpy needs its own Python, 3.13) */

/* ---- small helpers ---------------------------------------------------------------------- */

static double sq_dist(const float *a, const float *b, size_t n)
{
    double s = 0.0;
    for (size_t i = 0; i < n; ++i)
        s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return s / (double)n;
}

static int pin_to_cores(int n)
{
    cpu_set_t set;
    static cpu_set_t all;
    static int saved = 0;
    if (!saved) {
        if (sched_getaffinity(0, sizeof all, &all) != 0)
            return -1;
        saved = 1;
    }
    if (n <= 0)
        return sched_setaffinity(0, sizeof all, &all);
    /* the first n allowed cores (core 0 first where allowed), as every other one-thread figure
     * of the project is taken (`taskset -c 0`), so that the tables compare like with like */
    CPU_ZERO(&set);
    for (int c = 0, k = 0; c < CPU_SETSIZE && k < n; ++c)
        if (CPU_ISSET(c, &all)) {
            CPU_SET(c, &set);
            k++;
        }
    if (CPU_COUNT(&set) < n) {
        errno = EINVAL;
        return -1;
    }
    return sched_setaffinity(0, sizeof set, &set);
}

/* Runs argv with stdout to a pipe; calls line(ctx, text) for each line.  Returns the exit code
 * (-1 when it could not be started or was killed). */
static int run_child(char *const argv[], void (*line)(void *, const char *), void *ctx)
{
    int fds[2], status;
    pid_t pid;
    FILE *f;
    char buf[512];
    if (pipe(fds) != 0)
        return -1;
    pid = fork();
    if (pid < 0)
        return -1;
    if (pid == 0) {
        dup2(fds[1], 1);
        close(fds[0]);
        close(fds[1]);
        execv(argv[0], argv);
        _exit(127);
    }
    close(fds[1]);
    f = fdopen(fds[0], "r");
    while (f && fgets(buf, sizeof buf, f))
        if (line)
            line(ctx, buf);
    if (f)
        fclose(f);
    if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status))
        return -1;
    return WEXITSTATUS(status);
}

/* ---- the scene, as Mitsuba reads it ----------------------------------------------------- */

static void obj_vertex(FILE *f, rs_vec3 p) { fprintf(f, "v %.9g %.9g %.9g\n", p.x, p.y, p.z); }

/* Writes tmp_dir/mat<K>.obj for every material K with geometry and tmp_dir/scene.xml.  Only
 * what the Cornell box needs is exported: quads and triangles, Lambertian surfaces (two-sided in
 * raystream, so wrapped in `twosided`) and one-sided diffuse lights, a pinhole camera. */
static int export_mitsuba(const rs_scene *s, const char *path_xml, const char *path_json)
{
    FILE *x, *js;
    int first_mesh = 1;
    uint32_t m, i;
    const rs_camera_desc *c = &s->camera;
    rs_vec3 bg = s->background;
    /* what lights the scene from outside: a constant (a uniform map or a plain colour) */
    if (s->env_image != RS_NO_TEXTURE && s->env_uniform) {
        bg = s->env_uniform_le;
    } else if (s->env_image != RS_NO_TEXTURE || s->background_sky) {
        fprintf(stderr, "%s: %s: only a constant background is exported\n", prog, s->name);
        return 0;
    }
    x = fopen(path_xml, "w");
    js = fopen(path_json, "w");
    if (!x || !js) {
        fprintf(stderr, "%s: cannot write %s: %s\n", prog, x ? path_json : path_xml,
                strerror(errno));
        if (x)
            fclose(x);
        if (js)
            fclose(js);
        return 0;
    }
    /* the same for LuxCore's script, which builds its scene in Python */
    fprintf(js,
            "{\"width\": %u, \"height\": %u, \"vfov\": %.9g, \"max_depth\": %u,\n"
            " \"background\": [%.9g, %.9g, %.9g],\n"
            " \"from\": [%.9g, %.9g, %.9g], \"at\": [%.9g, %.9g, %.9g], \"up\": [%.9g, %.9g, "
            "%.9g],\n \"meshes\": [",
            W, H, c->vfov_deg, DEPTH, bg.x, bg.y, bg.z, c->from.x, c->from.y, c->from.z, c->at.x, c->at.y, c->at.z,
            c->up.x, c->up.y, c->up.z);
    if (s->n_spheres > 0) {
        fprintf(stderr, "%s: %s: spheres are not exported\n", prog, s->name);
        fclose(x);
        fclose(js);
        return 0;
    }
    fprintf(x, "<scene version=\"3.0.0\">\n"
               "  <default name=\"sampler\" value=\"independent\"/>\n"
               "  <integrator type=\"path\"><integer name=\"max_depth\" value=\"%u\"/>"
               "</integrator>\n"
               "  <sensor type=\"perspective\">\n"
               "    <float name=\"fov\" value=\"%.9g\"/><string name=\"fov_axis\" value=\"y\"/>\n"
               "    <transform name=\"to_world\"><lookat origin=\"%.9g,%.9g,%.9g\" "
               "target=\"%.9g,%.9g,%.9g\" up=\"%.9g,%.9g,%.9g\"/></transform>\n"
               "    <sampler type=\"$sampler\"><integer name=\"sample_count\" value=\"4\"/>"
               "</sampler>\n"
               "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"%u\"/>"
               "<integer name=\"height\" value=\"%u\"/>"
               "<string name=\"component_format\" value=\"float32\"/>"
               "<rfilter type=\"box\"/></film>\n"
               "  </sensor>\n",
            DEPTH, c->vfov_deg, c->from.x, c->from.y, c->from.z, c->at.x, c->at.y, c->at.z, c->up.x,
            c->up.y, c->up.z, W, H);
    if (bg.x > 0 || bg.y > 0 || bg.z > 0)
        fprintf(x,
                "  <emitter type=\"constant\"><rgb name=\"radiance\" value=\"%.9g,%.9g,%.9g\"/>"
                "</emitter>\n",
                bg.x, bg.y, bg.z);
    for (m = 0; m < s->n_materials; ++m) {
        const rs_material *mat = &s->materials[m];
        char path[600];
        FILE *o;
        uint32_t nv = 0;
        int any = 0, lambert;
        for (i = 0; i < s->n_quads && !any; ++i)
            any = s->quad_mat[i] == m;
        for (i = 0; i < s->n_tris && !any; ++i)
            any = s->tri_mat[i] == m;
        if (!any)
            continue;
        lambert = mat->type == RS_MAT_LAMBERTIAN && mat->albedo_tex == RS_NO_TEXTURE;
        if (lambert || (mat->type == RS_MAT_DIFFUSE_LIGHT && !(mat->flags & RS_MAT_TWO_SIDED))) {
            rs_vec3 rgb = lambert ? mat->albedo : mat->emission;
            fprintf(x,
                    "  <shape type=\"obj\"><string name=\"filename\" value=\"mat%u.obj\"/>"
                    "<boolean name=\"face_normals\" value=\"true\"/>\n",
                    m);
            if (lambert)
                fprintf(x,
                        "    <bsdf type=\"twosided\"><bsdf type=\"diffuse\"><rgb "
                        "name=\"reflectance\" value=\"%.9g,%.9g,%.9g\"/></bsdf></bsdf>\n",
                        rgb.x, rgb.y, rgb.z);
            else /* emits on the side its winding faces (u x v, as raystream's quads) and
                    reflects nothing, as raystream's lights */
                fprintf(x,
                        "    <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0,0,0\"/>"
                        "</bsdf>\n    <emitter type=\"area\"><rgb name=\"radiance\" "
                        "value=\"%.9g,%.9g,%.9g\"/></emitter>\n",
                        rgb.x, rgb.y, rgb.z);
            fprintf(x, "  </shape>\n");
            fprintf(js, "%s\n  {\"obj\": \"mat%u.obj\", \"kind\": \"%s\", \"rgb\": [%.9g, %.9g, %.9g]}",
                    first_mesh ? "" : ",", m, lambert ? "diffuse" : "light", rgb.x, rgb.y, rgb.z);
            first_mesh = 0;
        } else {
            fprintf(stderr, "%s: %s: material %u is not exported (only Lambertian surfaces and "
                            "one-sided diffuse lights)\n",
                    prog, s->name, m);
            fclose(x);
            fclose(js);
            return 0;
        }
        snprintf(path, sizeof path, "%s/mat%u.obj", tmp_dir, m);
        o = fopen(path, "w");
        if (!o) {
            fprintf(stderr, "%s: cannot write %s: %s\n", prog, path, strerror(errno));
            fclose(x);
            fclose(js);
            return 0;
        }
        for (i = 0; i < s->n_quads; ++i) {
            const rs_quad *q = &s->quads[i];
            if (s->quad_mat[i] != m)
                continue;
            obj_vertex(o, q->q);
            obj_vertex(o, rs_v3_add(q->q, q->u));
            obj_vertex(o, rs_v3_add(rs_v3_add(q->q, q->u), q->v));
            obj_vertex(o, rs_v3_add(q->q, q->v));
            fprintf(o, "f %u %u %u\nf %u %u %u\n", nv + 1, nv + 2, nv + 3, nv + 1, nv + 3, nv + 4);
            nv += 4;
        }
        for (i = 0; i < s->n_tris; ++i) {
            const rs_tri *t = &s->tris[i];
            if (s->tri_mat[i] != m)
                continue;
            obj_vertex(o, t->v0);
            obj_vertex(o, t->v1);
            obj_vertex(o, t->v2);
            fprintf(o, "f %u %u %u\n", nv + 1, nv + 2, nv + 3);
            nv += 3;
        }
        if (fclose(o) != 0) {
            fprintf(stderr, "%s: cannot write %s\n", prog, path);
            fclose(x);
            fclose(js);
            return 0;
        }
    }
    fprintf(x, "</scene>\n");
    fprintf(js, "\n]}\n");
    if (fclose(js) != 0 || fclose(x) != 0) {
        fprintf(stderr, "%s: cannot write %s\n", prog, path_xml);
        return 0;
    }
    return 1;
}

/* ---- renders ------------------------------------------------------------------------------ */

static float *render_raystream(const rs_scene *scene, const row *r, uint32_t spp, uint64_t seed,
                               int threads, double *secs)
{
    rt_args a = rt_defaults("cornell", W, spp);
    rs_render_stats st;
    float *img;
    a.height = H;
    a.seed = seed;
    a.threads = threads;
    a.sampler = r->sampler;
    a.megakernel = r->megakernel;
    a.wavefront = !r->megakernel && !r->shade_host; /* the CLI's default: the CPU's own waves */
    a.bvh = RS_BVH_SAH;
    a.cli_bvh = 1; /* the renderer's own tree: 8-wide where AVX2 runs */
    a.max_depth = DEPTH;
    img = rt_render_scene(scene, &a, &st);
    if (img && secs)
        *secs = st.seconds;
    return img;
}

typedef struct mi_lines {
    double secs[MAX_LEVELS], done[MAX_LEVELS];
    uint32_t spp[MAX_LEVELS];
    int n;
} mi_lines;

static void mi_line(void *ctx, const char *text)
{
    mi_lines *l = (mi_lines *)ctx;
    unsigned spp;
    double s, done;
    int got = l->n < MAX_LEVELS ? sscanf(text, "%u %lf %lf", &spp, &s, &done) : 0;
    if (got >= 2) {
        l->spp[l->n] = spp;
        l->done[l->n] = got == 3 ? done : spp;
        l->secs[l->n++] = s;
    }
}

/* Renders every level in one Mitsuba process; fills secs[] and, when imgs is not NULL, reads
 * the images.  Returns 0 after printing why. */
static int render_peer(const row *r, const uint32_t *levels, int n_levels, uint64_t seed,
                       int threads, int warmup, double *secs, double *done, float **imgs)
{
    char script[1024], xml[600], out[600], thr[16], sd[32], spps[256] = "", *argv[12];
    mi_lines got;
    int i, n = 0, rc;
    snprintf(script, sizeof script, "%s/bench/peers/%s", RS_SOURCE_DIR, r->script);
    snprintf(xml, sizeof xml, "%s/%s", tmp_dir, r->scene_file);
    snprintf(out, sizeof out, "%s/mi", tmp_dir);
    snprintf(thr, sizeof thr, "%d", threads);
    snprintf(sd, sizeof sd, "%llu", (unsigned long long)seed);
    for (i = 0; i < n_levels; ++i)
        snprintf(spps + strlen(spps), sizeof spps - strlen(spps), "%s%u", i ? "," : "",
                 levels[i]);
    argv[n++] = (char *)r->python;
    argv[n++] = script;
    argv[n++] = xml;
    argv[n++] = (char *)r->variant;
    argv[n++] = (char *)r->mi_sampler;
    argv[n++] = thr;
    argv[n++] = sd;
    argv[n++] = out;
    argv[n++] = spps;
    if (!warmup && strstr(r->script, "mitsuba"))
        argv[n++] = (char *)"--no-warmup";
    argv[n] = NULL;
    memset(&got, 0, sizeof got);
    rc = run_child(argv, mi_line, &got);
    if (rc != 0 || got.n != n_levels) {
        fprintf(stderr, "%s: %s: %s failed (exit %d, %d of %d renders)\n", prog, r->label,
                r->script, rc, got.n, n_levels);
        return 0;
    }
    for (i = 0; i < n_levels; ++i) {
        secs[i] = got.secs[i];
        if (done)
            done[i] = got.done[i];
        if (imgs) {
            char path[700];
            FILE *f;
            size_t nf = (size_t)W * H * 3, got_n = 0;
            snprintf(path, sizeof path, "%s_%u.f32", out, levels[i]);
            imgs[i] = (float *)malloc(nf * sizeof(float));
            f = fopen(path, "rb");
            if (f) {
                got_n = imgs[i] ? fread(imgs[i], sizeof(float), nf, f) : 0;
                if (fgetc(f) != EOF)
                    got_n = 0;
                fclose(f);
            }
            if (got_n != nf) {
                fprintf(stderr, "%s: %s: %s is not a %ux%u RGB float image\n", prog, r->label,
                        path, W, H);
                free(imgs[i]);
                imgs[i] = NULL;
                return 0;
            }
        }
    }
    return 1;
}

/* The reference of a row: two halves of ref_spp / 2 with different seeds, every core. */
static int make_reference(const rs_scene *scene, const row *r, uint32_t ref_spp, reference *ref)
{
    size_t nf = (size_t)W * H * 3, i;
    uint32_t half = ref_spp / 2 ? ref_spp / 2 : 1;
    double t;
    if (r->kind == ROW_RAYSTREAM) {
        ref->a = render_raystream(scene, r, half, 90001, rs_cpu_count(), NULL);
        ref->b = render_raystream(scene, r, half, 90002, rs_cpu_count(), NULL);
    } else {
        float *img[1] = {NULL};
        if (!render_peer(r, &half, 1, 90001, rs_cpu_count(), 0, &t, NULL, img))
            return 0;
        ref->a = img[0];
        if (!render_peer(r, &half, 1, 90002, rs_cpu_count(), 0, &t, NULL, img))
            return 0;
        ref->b = img[0];
    }
    if (!ref->a || !ref->b)
        return 0;
    ref->img = (float *)malloc(nf * sizeof *ref->img);
    if (!ref->img)
        return 0;
    for (i = 0; i < nf; ++i) {
        if (!isfinite(ref->a[i]) || !isfinite(ref->b[i])) {
            fprintf(stderr, "%s: %s: non-finite reference pixel\n", prog, r->label);
            return 0;
        }
        ref->img[i] = 0.5f * (ref->a[i] + ref->b[i]);
    }
    ref->var_ref = sq_dist(ref->a, ref->b, nf) / 4.0;
    return 1;
}

/* Block-mean z-test of two references: per 16x16 block and channel, the difference of the block
 * means over its standard error (each reference's from its halves' per-pixel differences).
 * Prints the result and the blocks over |z| 3; returns SAME when no more than 1% of the blocks
 * have |z| > 3 (0.27% expected by chance) and the image means agree within 1%, CLOSE when more
 * blocks differ but the means agree within 0.1% and no differing block's mean by more than 2%
 * (a small local difference, e.g. Cycles on the box: its time to its own reference still means
 * something, and the table marks it), else DIFFERENT. */
enum { DIFFERENT = 0, SAME = 1, CLOSE = 2 };
static int same_picture(const char *label, const reference *x, const reference *y)
{
    uint32_t bx, by, px, py, nb = 0, over = 0;
    int c;
    double zmax = 0.0, mx = 0.0, my = 0.0, rel_max = 0.0;
    for (by = 0; by + BLOCK <= H; by += BLOCK)
        for (bx = 0; bx + BLOCK <= W; bx += BLOCK)
            for (c = 0; c < 3; ++c) {
                double sx = 0, sy = 0, vx = 0, vy = 0, z, n = 0;
                for (py = by; py < by + BLOCK; ++py)
                    for (px = bx; px < bx + BLOCK; ++px) {
                        if (py == 0 || px == 0 || py == H - 1 || px == W - 1)
                            continue; /* the image's edge (LuxCore's bottom row is made up) */
                        size_t i = ((size_t)py * W + px) * 3 + (size_t)c;
                        double dx = (double)x->a[i] - x->b[i], dy = (double)y->a[i] - y->b[i];
                        sx += x->img[i];
                        sy += y->img[i];
                        vx += dx * dx / 4.0;
                        vy += dy * dy / 4.0;
                        n += 1;
                    }
                mx += sx;
                my += sy;
                z = (sx / n - sy / n) / sqrt((vx + vy) / (n * n) + 1e-30);
                if (fabs(z) > zmax)
                    zmax = fabs(z);
                if (fabs(z) > 3.0) {
                    double rel = fabs(sx - sy) / (fabs(sy) > 1e-30 ? fabs(sy) : 1e-30);
                    rel_max = rel > rel_max ? rel : rel_max;
                    if (over < 12) /* where, for the reader */
                        printf("  %s: block at pixel (%u, %u), channel %d: z %+.1f (%.4f against "
                               "%.4f)\n", label, bx, by, c, z, sx / n, sy / n);
                }
                over += fabs(z) > 3.0;
                nb++;
            }
    printf("same picture (%s against raystream, %ux%u-pixel blocks x 3 channels): %u of %u "
           "blocks |z| > 3 (%.2f%%; 0.27%% by chance), max |z| %.1f, mean ratio %.4f\n",
           label, BLOCK, BLOCK, over, nb, 100.0 * over / nb, zmax, mx / my);
    if (over <= nb / 100 && fabs(mx / my - 1.0) < 0.01)
        return SAME;
    return fabs(mx / my - 1.0) < 0.001 && rel_max < 0.02 ? CLOSE : DIFFERENT;
}

/* ---- fit and table -------------------------------------------------------------------------- */

/* Least squares of log err = a + b log spp over the levels whose error is measurable. */
static int fit(const row *r, int n_levels, double *a, double *b)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    int n = 0, l;
    for (l = 0; l < n_levels; ++l)
        if (r->err2[l] > 0.0) {
            double lx = log(r->done[l]), ly = 0.5 * log(r->err2[l]);
            sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
            n++;
        }
    if (n < 2 || sxx * n - sx * sx <= 0.0)
        return 0;
    *b = (n * sxy - sx * sy) / (n * sxx - sx * sx);
    *a = (sy - *b * sx) / n;
    return *b < 0.0;
}

static double median_secs(const row *r, int l, int runs)
{
    double v[MAX_RUNS];
    memcpy(v, r->secs[l], sizeof(double) * (size_t)runs);
    return rs_bench_median(v, runs);
}

/* Seconds to reach `target`: the spp the fit needs at the seconds per spp of the top level. */
static double time_to(const row *r, int n_levels, int runs, double target, double *spp_out)
{
    double a, b, spp, per_spp;
    if (!fit(r, n_levels, &a, &b))
        return -1.0;
    spp = exp((log(target) - a) / b);
    per_spp = median_secs(r, n_levels - 1, runs) / r->done[n_levels - 1];
    if (spp_out)
        *spp_out = spp;
    return spp * per_spp;
}

static void print_table(row *rows, int n_rows, const uint32_t *levels, int n_levels, int runs,
                        int threads)
{
    int k, l;
    double base01 = -1.0;
    printf("\n| renderer | samples/s (%d thread%s) |", threads, threads == 1 ? "" : "s");
    for (l = 0; l < n_levels; ++l)
        printf(" RMSE %u spp |", levels[l]);
    printf(" slope | time to RMSE 0.02 | time to RMSE 0.01 | vs raystream at 0.01 |\n|---|---:|");
    for (l = 0; l < n_levels; ++l)
        printf("---:|");
    printf("---:|---:|---:|---:|\n");
    for (k = 0; k < n_rows; ++k) {
        row *r = &rows[k];
        double t02, t01, a, b, sps;
        if (!r->ok)
            continue;
        sps = (double)W * H * r->done[n_levels - 1] / median_secs(r, n_levels - 1, runs);
        t02 = time_to(r, n_levels, runs, 0.02, NULL);
        t01 = time_to(r, n_levels, runs, 0.01, NULL);
        if (k == 0)
            base01 = t01;
        printf("| %s%s | %.2f M |", r->label, r->close ? " (*)" : "", sps / 1e6);
        for (l = 0; l < n_levels; ++l)
            printf(" %.4f |", sqrt(r->err2[l] > 0 ? r->err2[l] : 0));
        if (fit(r, n_levels, &a, &b))
            printf(" %.2f |", b);
        else
            printf(" — |");
        if (t02 > 0)
            printf(" %.2f s |", t02);
        else
            printf(" — |");
        if (t01 > 0 && base01 > 0)
            printf(" %.2f s | %.2fx %s |\n", t01, t01 > base01 ? t01 / base01 : base01 / t01,
                   k == 0 ? "(baseline)" : t01 > base01 ? "slower" : "faster");
        else
            printf(" — | — |\n");
    }
    printf("\nslope: d log RMSE / d log spp over the levels (-0.5 for independent samples); times "
           "from that fit at the median seconds per spp of the %u-spp renders\n",
           levels[n_levels - 1]);
    for (k = 0; k < n_rows; ++k)
        if (rows[k].ok && rows[k].close) {
            printf("(*) its converged picture differs from raystream's in a few blocks by less "
                   "than 2%% (listed above); it is timed against its own reference\n");
            break;
        }
}

/* ---- main ------------------------------------------------------------------------------------ */

static int parse_levels(const char *s, uint32_t *levels, int *n)
{
    *n = 0;
    while (*s && *n < MAX_LEVELS) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < 1 || (*n > 0 && (uint32_t)v <= levels[*n - 1]))
            return 0;
        levels[(*n)++] = (uint32_t)v;
        s = *end == ',' ? end + 1 : end;
        if (end == s && *s)
            return 0;
    }
    return *n >= 2 && !*s;
}

/* Whether the venv's Python imports `module` (python[] is set to the venv's interpreter). */
static int peer_available(const char *venv, const char *module, char *python, size_t size)
{
    char *argv[4];
    char code[128];
    struct stat sb;
    snprintf(python, size, "%s/bin/python", venv);
    if (stat(python, &sb) != 0)
        return 0;
    snprintf(code, sizeof code, "import %s", module);
    argv[0] = python;
    argv[1] = (char *)"-c";
    argv[2] = code;
    argv[3] = NULL;
    return run_child(argv, NULL, NULL) == 0;
}

static row *add_peer(row *rows, int *n_rows, const char *label, const char *name,
                     const char *script, const char *scene_file, const char *variant,
                     const char *sampler, const char *python)
{
    row *r = &rows[(*n_rows)++];
    r->python = python;
    r->label = label;
    r->name = name;
    r->kind = ROW_PEER;
    r->script = script;
    r->scene_file = scene_file;
    r->variant = variant;
    r->mi_sampler = sampler;
    r->ref_row = *n_rows - 1;
    return r;
}

/* The interior: the living room's geometry (../shared/models/living-room, 143k triangles) with
 * every surface one two-sided Lambertian of albedo 0.5 and its glass left out (so that the
 * windows are open), lit only by a uniform environment of radiance 1 given as a constant map:
 * the setting of the held-out atrium, on a real interior that every peer renders the
 * same.  NULL (after a message) where the models folder or the JSON reader is missing. */
static rs_scene *make_interior(void)
{
    char path[1200];
    const char *dir = rs_builtin_models_dir(NULL);
    rs_scene *src = NULL, *s = NULL;
    rs_material grey;
    uint32_t mat, img, i, dropped = 0;
    const float one[3] = {1.0f, 1.0f, 1.0f};
    struct stat sb;
    snprintf(path, sizeof path, "%s/living-room/living-room.raystream.json", dir ? dir : ".");
    if (stat(path, &sb) != 0) {
        printf("interior: skipped: no %s (the shared models folder; set RS_MODELS_DIR or "
               "build beside ../shared/models)\n",
               path);
        return NULL;
    }
    if (rs_scene_load_json(path, &src) != RS_OK) {
        printf("interior: skipped: %s\n", rs_error_message());
        return NULL;
    }
    if (src->n_instances > 0 || src->n_spheres > 0 || src->n_quads > 0 ||
        rs_scene_create("interior", &s) != RS_OK) {
        printf("interior: skipped: %s is not the triangle scene expected\n", path);
        rs_scene_destroy(src);
        return NULL;
    }
    grey = rs_mat_lambertian(rs_v3(0.5f, 0.5f, 0.5f));
    if (rs_scene_add_material(s, &grey, &mat) != RS_OK)
        goto fail;
    for (i = 0; i < src->n_tris; ++i) {
        const rs_tri *t = &src->tris[i];
        if (src->materials[src->tri_mat[i]].type == RS_MAT_DIELECTRIC) {
            dropped++;
            continue;
        }
        if (rs_scene_add_triangle(s, t->v0, t->v1, t->v2, mat) != RS_OK)
            goto fail;
    }
    s->camera = src->camera;
    if (rs_scene_add_image(s, 1, 1, one, &img) != RS_OK ||
        rs_scene_set_environment(s, img, rs_v3(1, 1, 1), NULL) != RS_OK ||
        rs_scene_finalize(s) != RS_OK)
        goto fail;
    printf("interior: %s: %u triangles, every one Lambertian 0.5 with face normals, the glass "
           "(%u triangles) left out; a uniform sky of radiance 1 (a constant map)\n",
           path, s->n_tris, dropped);
    rs_scene_destroy(src);
    return s;
fail:
    printf("interior: skipped: %s\n", rs_error_message());
    rs_scene_destroy(src);
    rs_scene_destroy(s);
    return NULL;
}

static int parse_threads(const char *s, int *threads, int *n)
{
    *n = 0;
    while (*s && *n < 4) {
        char *end;
        long v = strtol(s, &end, 10);
        if (end == s || v < 1 || v > 256)
            return 0;
        threads[(*n)++] = (int)v;
        s = *end == ',' ? end + 1 : end;
        if (end == s && *s)
            return 0;
    }
    return *n >= 1 && !*s;
}

typedef struct options {
    uint32_t levels[MAX_LEVELS], ref_spp;
    int n_levels, levels_given, runs, peers, quick;
    int threads[4], n_threads;
    uint32_t depth; /* 0: each scene's own */
    const char *venv, *cycles_venv;
} options;

/* One scene: export, references, the same-picture check, then the timed rounds at each thread
 * count.  Returns 0 when raystream itself failed. */
static int race(rs_scene *scene, const char *title, const options *o)
{
    const uint32_t *levels = o->levels;
    int n_levels = o->n_levels, runs = o->runs, i, k, l, round, n_rows = 0, n_ray, t;
    int interior = strcmp(scene->name, "interior") == 0;
    char xml[600], json[600];
    size_t nf = (size_t)W * H * 3;
    row rows[MAX_ROWS];
    reference refs[MAX_ROWS];

    memset(rows, 0, sizeof rows);
    memset(refs, 0, sizeof refs);
    rows[n_rows].label = "raystream stream, sobol (default)";
    rows[n_rows++].sampler = RS_SAMPLER_SOBOL;
    rows[n_rows].label = "raystream stream --shade-on host, sobol";
    rows[n_rows].sampler = RS_SAMPLER_SOBOL;
    rows[n_rows++].shade_host = 1;
    rows[n_rows].label = "raystream megakernel, sobol";
    rows[n_rows].sampler = RS_SAMPLER_SOBOL;
    rows[n_rows++].megakernel = 1;
    rows[n_rows].label = "raystream stream, zsobol";
    rows[n_rows++].sampler = RS_SAMPLER_ZSOBOL;
    rows[n_rows].label = "raystream stream, independent";
    rows[n_rows++].sampler = RS_SAMPLER_INDEPENDENT;
    n_ray = n_rows;

    snprintf(xml, sizeof xml, "%s/scene.xml", tmp_dir);
    snprintf(json, sizeof json, "%s/peers.json", tmp_dir);
    if (!export_mitsuba(scene, xml, json))
        return 0;
    printf("\n## %s\n\nsettings: %ux%u, max depth %u, 1-pixel box filter, MIS (power heuristic) "
           "everywhere; threads pinned to the first cores, %d interleaved rounds; references "
           "%u spp (two halves, every core)\n",
           title, W, H, DEPTH, runs, o->ref_spp);
    if (!o->peers)
        printf("peers: skipped (%s)\n", o->quick ? "--quick" : "--no-peers");
    if (o->peers && !peer_available(o->venv, "mitsuba, numpy", py_peers, sizeof py_peers)) {
        /* bench/peers/mitsuba_peer.py hands the image over through numpy: without it every
         * Mitsuba render would fail */
        printf("Mitsuba 3: skipped: %s/bin/python cannot import mitsuba and numpy (make the venv "
               "with `sh scripts/install-peers.sh %s`)\n",
               o->venv, o->venv);
    } else if (o->peers) {
        const char *llvm = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so";
        struct stat sb;
        int have_llvm = getenv("DRJIT_LIBLLVM_PATH") != NULL || stat(llvm, &sb) == 0, first;
        if (!getenv("DRJIT_LIBLLVM_PATH") && have_llvm)
            setenv("DRJIT_LIBLLVM_PATH", llvm, 1);
        first = n_rows;
        if (!interior || !have_llvm) /* scalar_rgb: 3x slower than llvm; the box keeps it */
            add_peer(rows, &n_rows, "Mitsuba 3 scalar_rgb, independent", "Mitsuba 3",
                     "mitsuba_peer.py", "scene.xml", "scalar_rgb", "independent", py_peers);
        if (have_llvm) {
            add_peer(rows, &n_rows, "Mitsuba 3 llvm_ad_rgb, independent", "Mitsuba 3",
                     "mitsuba_peer.py", "scene.xml", "llvm_ad_rgb", "independent", py_peers);
            add_peer(rows, &n_rows, "Mitsuba 3 llvm_ad_rgb, ldsampler", "Mitsuba 3",
                     "mitsuba_peer.py", "scene.xml", "llvm_ad_rgb", "ldsampler", py_peers);
            /* the JIT renders the reference 3x faster than scalar_rgb */
            for (k = first; k < n_rows; ++k)
                rows[k].ref_row = interior ? first : first + 1;
        } else {
            printf("Mitsuba 3 llvm_ad_rgb: skipped: no %s (Debian's libllvm19) and no "
                   "DRJIT_LIBLLVM_PATH\n",
                   llvm);
        }
    }
    if (o->peers && !peer_available(o->cycles_venv, "bpy, numpy", py_cycles, sizeof py_cycles))
        printf("Cycles: skipped: %s/bin/python cannot import bpy and numpy (bpy 5.2 needs Python "
               "3.13; `sh scripts/install-peers.sh` makes that venv where it finds one)\n",
               o->cycles_venv);
    else if (o->peers)
        add_peer(rows, &n_rows, "Cycles 5.2 CPU (its default sampler)", "Cycles",
                 "cycles_peer.py", "peers.json", "CPU", "default", py_cycles);
    if (o->peers && interior)
        printf("LuxCoreRender: skipped on the interior (8x slower than raystream on the box; it "
               "would double the bench's time)\n");
    else if (o->peers && !peer_available(o->venv, "pyluxcore", py_peers, sizeof py_peers))
        printf("LuxCoreRender: skipped: %s/bin/python cannot import pyluxcore (`sh "
               "scripts/install-peers.sh %s` installs it)\n",
               o->venv, o->venv);
    else if (o->peers)
        add_peer(rows, &n_rows, "LuxCoreRender 2.11 PATHCPU, sobol", "LuxCoreRender",
                 "luxcore_peer.py", "peers.json", "PATHCPU", "SOBOL", py_peers);
    fflush(stdout);

    /* references, every core, one per renderer (its other rows converge to the same image);
     * the same-picture check */
    for (k = 0; k < n_rows; ++k) {
        row *r = &rows[k];
        if (r->ref_row != k)
            continue;
        r->ok = make_reference(scene, r, o->ref_spp, &refs[k]);
        if (!r->ok) {
            if (k < n_ray)
                return 0;
            printf("%s: skipped: its reference could not be made\n", r->label);
            continue;
        }
        if (k >= n_ray) {
            int v = same_picture(r->name, &refs[k], &refs[0]);
            if (v == DIFFERENT) {
                printf("%s: skipped: it does not render the same picture\n", r->name);
                r->ok = 0;
            } else if (v == CLOSE) {
                printf("%s: the same picture but for the blocks above (each within 2%%): timed, "
                       "marked (*)\n", r->name);
                r->close = 1;
            }
        }
    }
    for (k = 0; k < n_rows; ++k) {
        rows[k].ok = rows[rows[k].ref_row].ok;
        rows[k].close = rows[rows[k].ref_row].close;
    }
    fflush(stdout);

    /* the timed rounds: `threads` cores, renderers interleaved */
    for (t = 0; t < o->n_threads; ++t) {
        int threads = o->threads[t];
        for (k = 0; k < n_rows; ++k) {
            memset(rows[k].secs, 0, sizeof rows[k].secs);
            memset(rows[k].err2, 0, sizeof rows[k].err2);
            memset(rows[k].done, 0, sizeof rows[k].done);
        }
        if (pin_to_cores(threads) != 0) {
            printf("(%d threads: could not pin to %d cores: %s; skipped)\n", threads, threads,
                   strerror(errno));
            continue;
        }
        for (round = 0; round < runs; ++round)
            for (k = 0; k < n_rows; ++k) {
                row *r = &rows[k];
                uint64_t seed = 1 + (uint64_t)round * 1000;
                if (!r->ok)
                    continue;
                if (r->kind == ROW_RAYSTREAM) {
                    for (l = 0; l < n_levels; ++l) {
                        float *img = render_raystream(scene, r, levels[l], seed + (uint64_t)l,
                                                      threads, &r->secs[l][round]);
                        if (!img) {
                            pin_to_cores(0);
                            return 0;
                        }
                        r->done[l] += (double)levels[l] / runs;
                        r->err2[l] += (sq_dist(img, refs[r->ref_row].img, nf) -
                                       refs[r->ref_row].var_ref) / runs;
                        free(img);
                    }
                } else {
                    float *imgs[MAX_LEVELS];
                    double secs[MAX_LEVELS], done[MAX_LEVELS];
                    if (!render_peer(r, levels, n_levels, seed, threads, 1, secs, done, imgs)) {
                        r->ok = 0;
                        continue;
                    }
                    for (l = 0; l < n_levels; ++l) {
                        r->secs[l][round] = secs[l];
                        r->done[l] += done[l] / runs;
                        r->err2[l] += (sq_dist(imgs[l], refs[r->ref_row].img, nf) -
                                       refs[r->ref_row].var_ref) / runs;
                        free(imgs[l]);
                    }
                }
            }
        pin_to_cores(0);
        printf("\n### %s, %d thread%s\n", title, threads, threads == 1 ? "" : "s");
        print_table(rows, n_rows, levels, n_levels, runs, threads);
        fflush(stdout);
    }

    for (k = 0; k < n_rows; ++k) {
        if (rows[k].ref_row != k)
            continue;
        free(refs[k].img);
        free(refs[k].a);
        free(refs[k].b);
    }
    (void)i;
    return 1;
}

/* --export DIR: each scene of `which` as the peers get it (DIR/NAME/scene.xml and its OBJs,
 * peers.json) and as raystream's own scene file (DIR/NAME/scene.json: the same scene, for
 * `raystream render` on another device: bench/gpu_bench.py races Mitsuba's cuda_ad_rgb with
 * it), at --size and each scene's depth; prints "NAME DIR/NAME DEPTH" a scene.  0 or 1. */
static int export_scenes(const char *dir, const char *which, const options *o)
{
    static const char *const names[2] = {"cornell", "interior"};
    int k;
    if (mkdir(dir, 0777) != 0 && errno != EEXIST) {
        fprintf(stderr, "%s: cannot make %s: %s\n", prog, dir, strerror(errno));
        return 1;
    }
    for (k = 0; k < 2; ++k) {
        rs_scene *scene = NULL;
        char xml[700], json[700], own[700];
        if (!strstr(which, names[k]))
            continue;
        if (k == 0 && rs_builtin_create("cornell", &scene) != RS_OK) {
            fprintf(stderr, "%s: %s\n", prog, rs_error_message());
            return 1;
        }
        if (k == 1 && !(scene = make_interior()))
            continue; /* said why */
        DEPTH = o->depth ? o->depth : k == 0 ? 50 : 16;
        snprintf(tmp_dir, sizeof tmp_dir, "%s/%s", dir, names[k]);
        snprintf(xml, sizeof xml, "%s/scene.xml", tmp_dir);
        snprintf(json, sizeof json, "%s/peers.json", tmp_dir);
        snprintf(own, sizeof own, "%s/scene.json", tmp_dir);
        if ((mkdir(tmp_dir, 0777) != 0 && errno != EEXIST) || !export_mitsuba(scene, xml, json) ||
            rs_scene_export_json(scene, own) != RS_OK) {
            fprintf(stderr, "%s: exporting %s into %s failed: %s\n", prog, names[k], tmp_dir,
                    errno ? strerror(errno) : rs_error_message());
            rs_scene_destroy(scene);
            return 1;
        }
        printf("%s %s %u\n", names[k], tmp_dir, DEPTH);
        rs_scene_destroy(scene);
    }
    return 0;
}

int main(int argc, char **argv)
{
    options o;
    const char *keep = NULL, *which = "cornell,interior", *export_dir = NULL;
    char default_venv[1024], default_cycles[1100];
    uint32_t size = 256, height = 0;
    int i, ok = 1;
    memset(&o, 0, sizeof o);
    o.levels[0] = 4, o.levels[1] = 16, o.levels[2] = 64, o.levels[3] = 256;
    o.n_levels = 4;
    o.ref_spp = 1024;
    o.runs = 3;
    o.peers = 1;
    o.threads[0] = 1, o.threads[1] = 2, o.n_threads = 2;
    o.venv = getenv("RS_PEERS_VENV");
    snprintf(default_venv, sizeof default_venv, "%s/peers-venv", RS_BINARY_DIR);
    if (!o.venv || !*o.venv)
        o.venv = default_venv;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0) {
            o.quick = 1;
        } else if (strcmp(argv[i], "--size") == 0 && i + 1 < argc) {
            /* N, or WxH (with --export only: the races' block test wants a square) */
            unsigned a = 0, b = 0;
            int got = sscanf(argv[++i], "%ux%u", &a, &b);
            size = a;
            height = got == 2 ? b : a;
        } else if (strcmp(argv[i], "--levels") == 0 && i + 1 < argc) {
            if (!parse_levels(argv[++i], o.levels, &o.n_levels)) {
                fprintf(stderr, "%s: --levels takes two or more increasing counts: 4,16,64\n",
                        prog);
                return 2;
            }
            o.levels_given = 1;
        } else if (strcmp(argv[i], "--ref-spp") == 0 && i + 1 < argc) {
            o.ref_spp = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--runs") == 0 && i + 1 < argc) {
            o.runs = atoi(argv[++i]);
        } else if (strcmp(argv[i], "--threads") == 0 && i + 1 < argc) {
            if (!parse_threads(argv[++i], o.threads, &o.n_threads)) {
                fprintf(stderr, "%s: --threads takes one to four counts: 1,2\n", prog);
                return 2;
            }
        } else if (strcmp(argv[i], "--depth") == 0 && i + 1 < argc) {
            o.depth = (uint32_t)atoi(argv[++i]);
        } else if (strcmp(argv[i], "--scenes") == 0 && i + 1 < argc) {
            which = argv[++i];
        } else if (strcmp(argv[i], "--venv") == 0 && i + 1 < argc) {
            o.venv = argv[++i];
        } else if (strcmp(argv[i], "--cycles-venv") == 0 && i + 1 < argc) {
            o.cycles_venv = argv[++i];
        } else if (strcmp(argv[i], "--no-peers") == 0) {
            o.peers = 0;
        } else if (strcmp(argv[i], "--keep") == 0 && i + 1 < argc) {
            keep = argv[++i];
        } else if (strcmp(argv[i], "--export") == 0 && i + 1 < argc) {
            export_dir = argv[++i];
        } else if (strcmp(argv[i], "-h") == 0 || strcmp(argv[i], "--help") == 0) {
            fputs(USAGE, stdout);
            return 0;
        } else {
            fprintf(stderr, "%s: unknown option or missing value '%s'\n%s", prog, argv[i], USAGE);
            return 2;
        }
    }
    /* Cycles' venv: --cycles-venv, else $RS_CYCLES_VENV, else the peers' venv's name + -cycles
     * (where scripts/install-peers.sh makes it) */
    snprintf(default_cycles, sizeof default_cycles, "%s-cycles", o.venv);
    if (!o.cycles_venv)
        o.cycles_venv = getenv("RS_CYCLES_VENV") && *getenv("RS_CYCLES_VENV")
                            ? getenv("RS_CYCLES_VENV")
                            : default_cycles;
    if (o.quick) {
        size = 32;
        o.levels[0] = 1, o.levels[1] = 4, o.n_levels = 2, o.levels_given = 1;
        o.ref_spp = 64;
        o.runs = 1;
        o.peers = 0;
        o.threads[0] = 1, o.n_threads = 1;
    }
    W = H = size;
    if (height && height != size) {
        if (!export_dir) {
            fprintf(stderr, "%s: --size WxH goes with --export only (the races are square)\n",
                    prog);
            return 2;
        }
        H = height;
    }
    if (W < BLOCK || W > 4096 || H < BLOCK || H > 4096 || o.ref_spp < 2 || o.runs < 1 ||
        o.runs > MAX_RUNS) {
        fprintf(stderr, "%s: --size %u..4096, --ref-spp >= 2, --runs 1..%d\n", prog, BLOCK,
                MAX_RUNS);
        return 2;
    }

    if (export_dir)
        return export_scenes(export_dir, which, &o);
    if (keep) {
        if (mkdir(keep, 0777) != 0 && errno != EEXIST) {
            fprintf(stderr, "%s: cannot make %s: %s\n", prog, keep, strerror(errno));
            return 1;
        }
        snprintf(tmp_dir, sizeof tmp_dir, "%s", keep);
    } else {
        snprintf(tmp_dir, sizeof tmp_dir, "%s/peers_bench.XXXXXX",
                 getenv("TMPDIR") ? getenv("TMPDIR") : "/tmp");
        if (!mkdtemp(tmp_dir)) {
            fprintf(stderr, "%s: cannot make a temporary folder: %s\n", prog, strerror(errno));
            return 1;
        }
    }

    rs_bench_print_machine(stdout);
    if (strstr(which, "cornell")) {
        rs_scene *scene = NULL;
        if (rs_builtin_create("cornell", &scene) != RS_OK) {
            fprintf(stderr, "%s: %s\n", prog, rs_error_message());
            return 1;
        }
        DEPTH = o.depth ? o.depth : 50;
        ok = race(scene, "The Cornell box (builtin:cornell)", &o) && ok;
        rs_scene_destroy(scene);
    }
    if (ok && strstr(which, "interior")) {
        rs_scene *scene = make_interior();
        if (scene) {
            options oi = o;
            if (!oi.levels_given) { /* 5x the box's time per sample: one level less */
                oi.n_levels = 3;
            }
            DEPTH = o.depth ? o.depth : 16;
            ok = race(scene, "An interior (the living room's geometry, Lambertian 0.5, "
                             "a uniform sky)",
                      &oi) && ok;
            rs_scene_destroy(scene);
        }
    }
    if (!keep) {
        char cmd[700];
        snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmp_dir);
        if (system(cmd) != 0)
            fprintf(stderr, "%s: could not remove %s\n", prog, tmp_dir);
    }
    return ok ? 0 : 1;
}
