/* api/raystream.c — the C API (include/raystream.h) over the raystream command's own steps
 * (app/render_run.h): the options are parsed by the command's parser from the same text, the
 * scene loaded, the film, BVH, devices and engine made, and the image resolved by the very
 * functions `raystream render` runs, so a render here is the command's bit for bit.  What the
 * steps print goes to a sink (app/fail.h): warnings to the caller's log, the failure's line to
 * raystream_last_error(). */
#include "raystream.h"

#include <math.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "app/render_run.h"
#include "app/tev.h"
#include "core/alloc.h"
#include "core/clock.h"
#include "core/image_io.h"
#include "core/parallel.h"
#include "core/view.h"
#include "gpu/gpu_device.h"
#include "scenes/scene_json.h"
#include "shading/aov.h"

#define API_ERROR_MAX 1024
#define API_LAYERS    5

static _Thread_local char g_error[API_ERROR_MAX];

/* ---- errors and the sink ------------------------------------------------------------------ */

/* Sets this thread's error (printf-style) and returns `st`. */
static raystream_status fail(raystream_status st, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(g_error, sizeof g_error, fmt, ap);
    va_end(ap);
    return st;
}

/* The core's message (core/status.h) as this thread's error. */
static raystream_status fail_core(rs_status st)
{
    raystream_status s = st == RS_ERR_NOMEM ? RAYSTREAM_ERROR_MEMORY
                         : st == RS_ERR_IO  ? RAYSTREAM_ERROR_IO
                         : st == RS_ERR_ARG ? RAYSTREAM_ERROR_ARGUMENT
                                            : RAYSTREAM_ERROR_RUNTIME;
    fail(s, "%s", *rs_error_message() ? rs_error_message() : "failed");
    rs_error_clear();
    return s;
}

/* What one call into the steps printed: the first line that is not a warning is the failure's;
 * warnings go to the log. */
typedef struct api_sink {
    raystream_log_fn log;
    void *user;
    int have_error;
} api_sink;

static void sink_line(void *user, const char *line)
{
    api_sink *s = (api_sink *)user;
    char text[API_ERROR_MAX];
    size_t n;
    if (strncmp(line, "raystream: ", 11) == 0)
        line += 11;
    snprintf(text, sizeof text, "%s", line);
    n = strlen(text);
    while (n && (text[n - 1] == '\n' || text[n - 1] == '\r'))
        text[--n] = '\0';
    if (strncmp(text, "warning: ", 9) == 0) {
        if (s->log)
            s->log(s->user, text);
        else
            fprintf(stderr, "raystream: %s\n", text);
        return;
    }
    if (!s->have_error) {
        s->have_error = 1;
        snprintf(g_error, sizeof g_error, "%s", text);
    }
}

static void sink_begin(api_sink *s, raystream_log_fn log, void *user)
{
    memset(s, 0, sizeof *s);
    s->log = log;
    s->user = user;
    g_error[0] = '\0';
    rs_app_set_sink(sink_line, s);
}

static void sink_end(void) { rs_app_set_sink(NULL, NULL); }

/* An exit code of the steps (RS_EXIT_*) as a status, its line already in g_error. */
static raystream_status from_exit(const api_sink *s, int code)
{
    if (code == RS_EXIT_OK)
        return RAYSTREAM_OK;
    if (!s->have_error && *rs_error_message())
        snprintf(g_error, sizeof g_error, "%s", rs_error_message());
    else if (!s->have_error)
        snprintf(g_error, sizeof g_error, "failed (exit status %d)", code);
    rs_error_clear();
    if (code == RS_EXIT_USAGE)
        return strstr(g_error, "no such scene file") ? RAYSTREAM_ERROR_IO
                                                     : RAYSTREAM_ERROR_ARGUMENT;
    return strstr(g_error, "out of memory") ? RAYSTREAM_ERROR_MEMORY : RAYSTREAM_ERROR_RUNTIME;
}

int raystream_version(void) { return RAYSTREAM_VERSION; }

static char g_version[160];

static void make_version(void)
{
    const char *why = "";
    snprintf(g_version, sizeof g_version, "%d.%d.%d (%s%s, %s)", RAYSTREAM_VERSION_MAJOR,
             RAYSTREAM_VERSION_MINOR, RAYSTREAM_VERSION_PATCH,
             !rs_gpu_compiled()       ? "CPU only"
             : rs_gpu_count(&why) > 0 ? "CUDA"
                                      : "CUDA built in, no GPU",
             RS_HAVE_OPENMP ? ", OpenMP" : "", rs_image_library_version());
}

const char *raystream_version_string(void)
{
    static pthread_once_t once = PTHREAD_ONCE_INIT;
    pthread_once(&once, make_version);
    return g_version;
}

const char *raystream_last_error(void) { return g_error; }

/* ---- options ------------------------------------------------------------------------------ */

#define API_MAX_OPTIONS 64

struct raystream_options {
    char *name[API_MAX_OPTIONS];  /* "--spp" */
    char *value[API_MAX_OPTIONS]; /* "64", or NULL for a flag that is on */
    int n;
    raystream_progress_fn progress;
    void *progress_user;
    raystream_log_fn log;
    void *log_user;
};

raystream_status raystream_options_create(raystream_options **out)
{
    if (!out)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_options_create: out is NULL");
    *out = (raystream_options *)calloc(1, sizeof **out);
    return *out ? RAYSTREAM_OK : fail(RAYSTREAM_ERROR_MEMORY, "out of memory");
}

static void option_drop(raystream_options *o, int i)
{
    free(o->name[i]);
    free(o->value[i]);
    memmove(o->name + i, o->name + i + 1, (size_t)(o->n - i - 1) * sizeof o->name[0]);
    memmove(o->value + i, o->value + i + 1, (size_t)(o->n - i - 1) * sizeof o->value[0]);
    --o->n;
}

void raystream_options_release(raystream_options *o)
{
    if (!o)
        return;
    while (o->n)
        option_drop(o, o->n - 1);
    free(o);
}

/* The command's options that are about its files or its process, not the image. */
static int command_only(const char *opt)
{
    static const char *const names[] = {
        "--output",     "-o",         "--checkpoint", "--resume",      "--stats",
        "--stats-json", "--timeline", "--mpi-pass",   "--mpi-timeout", "--checkpoint-interval",
        "--scene",      NULL};
    int i;
    for (i = 0; names[i]; ++i)
        if (strcmp(opt, names[i]) == 0)
            return 1;
    return 0;
}

/* A flag's value: 1 on, 0 off, -1 neither. */
static int flag_value(const char *v)
{
    static const char *const on[] = {"1", "true", "on", "yes"}, *const off[] = {"0", "false", "off",
                                                                                "no"};
    int i;
    for (i = 0; i < 4; ++i) {
        if (strcasecmp(v, on[i]) == 0)
            return 1;
        if (strcasecmp(v, off[i]) == 0)
            return 0;
    }
    return -1;
}

raystream_status raystream_options_set(raystream_options *o, const char *name, const char *value)
{
    char opt[64];
    size_t i, len;
    int kind, k, on = 1;
    if (!o || !name)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_options_set: %s is NULL",
                    o ? "name" : "options");
    while (*name == '-')
        ++name;
    len = strlen(name);
    if (len == 0 || len + 3 > sizeof opt)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "'%s' is not an option", name);
    opt[0] = opt[1] = '-';
    for (i = 0; i <= len; ++i)
        opt[2 + i] = name[i] == '_' ? '-' : name[i];
    if (command_only(opt) || strcmp(opt, "--quiet") == 0)
        return fail(RAYSTREAM_ERROR_ARGUMENT,
                    "%s is an option of the raystream command, not of a render through the "
                    "library (raystream_image_write writes the image)",
                    opt);
    kind = rs_cli_option_value(opt);
    if (kind < 0)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "unknown option '%s' (see 'raystream render --help')",
                    name);
    if (value && kind == 0 && (on = flag_value(value)) < 0)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "%s is a flag: its value is true or false, not '%s'",
                    opt, value);
    for (k = 0; k < o->n; ++k)
        if (strcmp(o->name[k], opt) == 0) {
            option_drop(o, k);
            break;
        }
    if (!value || !on)
        return RAYSTREAM_OK;
    if (o->n == API_MAX_OPTIONS)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "more than %d options", API_MAX_OPTIONS);
    o->name[o->n] = strdup(opt);
    o->value[o->n] = kind ? strdup(value) : NULL;
    if (!o->name[o->n] || (kind && !o->value[o->n])) {
        free(o->name[o->n]);
        free(o->value[o->n]);
        return fail(RAYSTREAM_ERROR_MEMORY, "out of memory");
    }
    ++o->n;
    return RAYSTREAM_OK;
}

raystream_status raystream_options_set_int(raystream_options *o, const char *name, long long value)
{
    char text[32];
    snprintf(text, sizeof text, "%lld", value);
    return raystream_options_set(o, name, text);
}

raystream_status raystream_options_set_double(raystream_options *o, const char *name, double value)
{
    char text[40];
    snprintf(text, sizeof text, "%.17g", value);
    return raystream_options_set(o, name, text);
}

void raystream_options_set_progress(raystream_options *o, raystream_progress_fn progress,
                                    void *user)
{
    if (!o)
        return;
    o->progress = progress;
    o->progress_user = user;
}

void raystream_options_set_log(raystream_options *o, raystream_log_fn log, void *user)
{
    if (!o)
        return;
    o->log = log;
    o->log_user = user;
}

/* `raystream render SCENE OPTIONS` parsed by the command's parser into *co; argv's strings stay
 * the options' (co points into them).  Returns an exit code after a line. */
static int parse_options(const raystream_options *o, const char *scene, char **argv,
                         rs_cli_options *co)
{
    int argc = 0, i;
    argv[argc++] = (char *)"raystream";
    argv[argc++] = (char *)"render";
    if (scene)
        argv[argc++] = (char *)scene;
    for (i = 0; o && i < o->n; ++i) {
        argv[argc++] = o->name[i];
        if (o->value[i])
            argv[argc++] = o->value[i];
    }
    argv[argc] = NULL;
    return rs_cli_parse(argc, argv, co);
}

/* ---- scenes ------------------------------------------------------------------------------- */

struct raystream_scene {
    rs_scene *s;
    atomic_int refs;
    atomic_int busy;       /* a render of it is under way: no other, and no change */
    uint32_t (*protos)[2]; /* raystream_scene_add_prototype's: first, count (inst_tris) */
    uint32_t n_protos, cap_protos;
    char name[64]; /* the default output name's stem */
    char lighting[160];
    char source[512]; /* what it was loaded from (the EXR header's raystream:scene), or "scene" */
};

static raystream_status wrap_scene(rs_scene *s, const char *name, raystream_scene **out)
{
    raystream_scene *h = (raystream_scene *)calloc(1, sizeof *h);
    if (!h) {
        rs_scene_destroy(s);
        return fail(RAYSTREAM_ERROR_MEMORY, "out of memory");
    }
    h->s = s;
    snprintf(h->source, sizeof h->source, "scene");
    atomic_init(&h->refs, 1);
    atomic_init(&h->busy, 0);
    snprintf(h->name, sizeof h->name, "%s", name);
    *out = h;
    return RAYSTREAM_OK;
}

/* A scene file that is not there: RAYSTREAM_ERROR_IO with the command's line. */
static raystream_status check_scene_name(const char *scene)
{
    struct stat sb;
    if (!scene || !*scene)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "no scene given (builtin:NAME or a file)");
    if (strncmp(scene, "builtin:", 8) != 0 && stat(scene, &sb) != 0)
        return fail(RAYSTREAM_ERROR_IO,
                    "%s: no such scene file (built-in scenes are named builtin:NAME; see "
                    "'raystream scenes')",
                    scene);
    return RAYSTREAM_OK;
}

raystream_status raystream_scene_load(const char *scene, raystream_scene **out)
{
    rs_cli_options co;
    char *argv[4];
    render_run r;
    api_sink sink;
    raystream_status st;
    int code;
    if (!out)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_scene_load: out is NULL");
    *out = NULL;
    if ((st = check_scene_name(scene)) != RAYSTREAM_OK)
        return st;
    memset(&r, 0, sizeof r);
    r.library = 1;
    sink_begin(&sink, NULL, NULL);
    code = parse_options(NULL, scene, argv, &co);
    if (code == RS_EXIT_OK)
        code = rs_run_load_scene(&co, &r);
    st = from_exit(&sink, code);
    sink_end();
    if (st != RAYSTREAM_OK) {
        rs_run_release(&r);
        return st;
    }
    st = wrap_scene(r.scene, r.name, out);
    if (st == RAYSTREAM_OK) {
        snprintf((*out)->lighting, sizeof(*out)->lighting, "%s", r.lighting);
        snprintf((*out)->source, sizeof(*out)->source, "%s", scene);
    }
    return st;
}

raystream_status raystream_scene_from_json(const char *json, const char *base_dir,
                                           raystream_scene **out)
{
    rs_scene *s;
    rs_status st;
    if (!out || !json)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_scene_from_json: %s is NULL",
                    out ? "json" : "out");
    *out = NULL;
    st = rs_scene_parse_json(json, strlen(json), "scene", base_dir ? base_dir : ".", &s);
    if (st != RS_OK)
        return fail_core(st);
    return wrap_scene(s, "scene", out);
}

raystream_status raystream_scene_create(raystream_scene **out)
{
    rs_scene *s;
    rs_status st;
    if (!out)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_scene_create: out is NULL");
    *out = NULL;
    if ((st = rs_scene_create("scene", &s)) != RS_OK)
        return fail_core(st);
    return wrap_scene(s, "scene", out);
}

raystream_scene *raystream_scene_retain(raystream_scene *h)
{
    if (h)
        atomic_fetch_add(&h->refs, 1);
    return h;
}

void raystream_scene_release(raystream_scene *h)
{
    if (!h || atomic_fetch_sub(&h->refs, 1) != 1)
        return;
    rs_scene_destroy(h->s);
    free(h->protos);
    free(h);
}

/* A scene to change: there, and not being rendered. */
#define NEED_SCENE(h, fn)                                                                          \
  do {                                                                                             \
    if (!(h))                                                                                      \
      return fail(RAYSTREAM_ERROR_ARGUMENT, "%s: scene is NULL", fn);                              \
    if (atomic_load(&(h)->busy))                                                                   \
      return fail(RAYSTREAM_ERROR_ARGUMENT, "%s: the scene is being rendered", fn);                \
  } while (0)

static int finite3(const float *v) { return isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]); }

raystream_status raystream_scene_add_material(raystream_scene *h, const char *json, uint32_t *id)
{
    rs_status st;
    uint32_t mid;
    NEED_SCENE(h, "raystream_scene_add_material");
    if (!json)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_scene_add_material: json is NULL");
    if ((st = rs_scene_add_material_json(h->s, json, "material", &mid)) != RS_OK)
        return fail_core(st);
    if (id)
        *id = mid;
    return RAYSTREAM_OK;
}

static raystream_status check_material(const raystream_scene *h, uint32_t material)
{
    if (material >= h->s->n_materials)
        return fail(RAYSTREAM_ERROR_ARGUMENT,
                    "material %u: the scene has %u material%s (raystream_scene_add_material)",
                    material, h->s->n_materials, h->s->n_materials == 1 ? "" : "s");
    return RAYSTREAM_OK;
}

/* The mesh's arrays checked before anything is added: finite values, indices in range. */
static raystream_status check_mesh(const float *p, size_t nv, const uint32_t *idx, size_t nt,
                                   const float *nrm, const float *uv)
{
    size_t i;
    if (!p || !idx)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_scene_add_mesh: %s is NULL",
                    p ? "indices" : "positions");
    if (nv > (size_t)UINT32_MAX || nt > (size_t)RS_SCENE_MAX_COPIED_PRIMS)
        return fail(RAYSTREAM_ERROR_ARGUMENT,
                    "raystream_scene_add_mesh: %zu vertices, %zu "
                    "triangles: too many",
                    nv, nt);
    for (i = 0; i < nv; ++i) {
        if (!finite3(p + 3 * i))
            return fail(RAYSTREAM_ERROR_ARGUMENT, "mesh: vertex %zu is not finite", i);
        if (nrm && !finite3(nrm + 3 * i))
            return fail(RAYSTREAM_ERROR_ARGUMENT, "mesh: normal %zu is not finite", i);
        if (uv && !(isfinite(uv[2 * i]) && isfinite(uv[2 * i + 1])))
            return fail(RAYSTREAM_ERROR_ARGUMENT, "mesh: uv %zu is not finite", i);
    }
    for (i = 0; i < 3 * nt; ++i)
        if (idx[i] >= nv)
            return fail(RAYSTREAM_ERROR_ARGUMENT,
                        "mesh: triangle %zu uses vertex %u, but there are %zu vertices", i / 3,
                        idx[i], nv);
    return RAYSTREAM_OK;
}

/* One triangle as a scene file's "triangle" object adds it (scenes/json_objects.c). */
static rs_status add_tri(rs_scene *s, const float *p, const uint32_t *t, const float *nrm,
                         const float *uv, uint32_t mat)
{
    rs_vec3 v[3];
    float uvs[6], ns[9];
    int k;
    for (k = 0; k < 3; ++k) {
        v[k] = rs_v3(p[3 * t[k]], p[3 * t[k] + 1], p[3 * t[k] + 2]);
        if (uv)
            uvs[2 * k] = uv[2 * t[k]], uvs[2 * k + 1] = uv[2 * t[k] + 1];
        if (nrm)
            ns[3 * k] = nrm[3 * t[k]], ns[3 * k + 1] = nrm[3 * t[k] + 1],
                   ns[3 * k + 2] = nrm[3 * t[k] + 2];
    }
    if (!uv && !nrm)
        return rs_scene_add_triangle(s, v[0], v[1], v[2], mat);
    if (!nrm)
        return rs_scene_add_triangle_uv(s, v[0], v[1], v[2], uvs, mat);
    return rs_scene_add_triangle_full(s, v, uv ? uvs : NULL, ns, mat);
}

raystream_status raystream_scene_add_mesh(raystream_scene *h, const float *positions,
                                          size_t n_vertices, const uint32_t *indices,
                                          size_t n_triangles, const float *normals,
                                          const float *uvs, uint32_t material)
{
    raystream_status st;
    uint32_t before;
    size_t i;
    NEED_SCENE(h, "raystream_scene_add_mesh");
    if ((st = check_material(h, material)) != RAYSTREAM_OK ||
        (st = check_mesh(positions, n_vertices, indices, n_triangles, normals, uvs)) !=
            RAYSTREAM_OK)
        return st;
    before = h->s->n_tris;
    for (i = 0; i < n_triangles; ++i) {
        rs_status rst = add_tri(h->s, positions, indices + 3 * i, normals, uvs, material);
        if (rst != RS_OK) {
            h->s->n_tris = before; /* all or nothing */
            return fail_core(rst);
        }
    }
    return RAYSTREAM_OK;
}

raystream_status raystream_scene_add_light(raystream_scene *h, const char *json)
{
    rs_status st;
    NEED_SCENE(h, "raystream_scene_add_light");
    if (!json)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_scene_add_light: json is NULL");
    st = rs_scene_add_light_json(h->s, json, "light");
    return st == RS_OK ? RAYSTREAM_OK : fail_core(st);
}

raystream_status raystream_scene_add_prototype(raystream_scene *h, const float *positions,
                                               size_t n_vertices, const uint32_t *indices,
                                               size_t n_triangles, const float *normals,
                                               const float *uvs, uint32_t material,
                                               uint32_t *prototype)
{
    raystream_status st;
    uint32_t from;
    rs_status rst;
    NEED_SCENE(h, "raystream_scene_add_prototype");
    if (h->n_protos == h->cap_protos) {
        uint32_t cap = h->cap_protos ? 2 * h->cap_protos : 8;
        void *p = realloc(h->protos, cap * sizeof *h->protos);
        if (!p)
            return fail(RAYSTREAM_ERROR_MEMORY, "out of memory");
        h->protos = (uint32_t(*)[2])p;
        h->cap_protos = cap;
    }
    if (material < h->s->n_materials && rs_material_is_light(&h->s->materials[material]))
        return fail(RAYSTREAM_ERROR_ARGUMENT,
                    "prototype: material %u emits light, and placed triangles are not lights "
                    "(add the mesh with raystream_scene_add_mesh)",
                    material);
    from = h->s->n_tris;
    if ((st = raystream_scene_add_mesh(h, positions, n_vertices, indices, n_triangles, normals, uvs,
                                       material)) != RAYSTREAM_OK)
        return st;
    rst =
        rs_scene_make_prototype(h->s, from, &h->protos[h->n_protos][0], &h->protos[h->n_protos][1]);
    if (rst != RS_OK) {
        h->s->n_tris = from;
        return fail_core(rst);
    }
    if (prototype)
        *prototype = h->n_protos;
    ++h->n_protos;
    return RAYSTREAM_OK;
}

raystream_status raystream_scene_add_instance(raystream_scene *h, uint32_t prototype,
                                              const double matrix[12])
{
    rs_status st;
    int i;
    NEED_SCENE(h, "raystream_scene_add_instance");
    if (prototype >= h->n_protos)
        return fail(RAYSTREAM_ERROR_ARGUMENT,
                    "instance: prototype %u, but the scene has %u (raystream_scene_add_prototype)",
                    prototype, h->n_protos);
    for (i = 0; matrix && i < 12; ++i)
        if (!isfinite(matrix[i]) || fabs(matrix[i]) > 1e30)
            return fail(RAYSTREAM_ERROR_ARGUMENT, "instance: matrix[%d] is not a finite number", i);
    if (!matrix)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_scene_add_instance: matrix is NULL");
    if (h->protos[prototype][1] == 0)
        return RAYSTREAM_OK; /* an empty prototype places nothing, as an empty group */
    st = rs_scene_add_instance(h->s, h->protos[prototype][0], h->protos[prototype][1], matrix);
    if (st != RS_OK) {
        char msg[600];
        snprintf(msg, sizeof msg, "instance: %s", rs_error_message());
        rs_error_clear();
        return fail(st == RS_ERR_NOMEM ? RAYSTREAM_ERROR_MEMORY : RAYSTREAM_ERROR_ARGUMENT, "%s",
                    msg);
    }
    return RAYSTREAM_OK;
}

raystream_status raystream_scene_add_sphere(raystream_scene *h, const float center[3], float radius,
                                            uint32_t material)
{
    raystream_status st;
    rs_status rst;
    NEED_SCENE(h, "raystream_scene_add_sphere");
    if ((st = check_material(h, material)) != RAYSTREAM_OK)
        return st;
    if (!center || !finite3(center) || !(radius > 0.0f) || !isfinite(radius))
        return fail(RAYSTREAM_ERROR_ARGUMENT, "sphere: needs a finite centre and a radius > 0");
    rst = rs_scene_add_sphere(h->s, rs_v3(center[0], center[1], center[2]), radius, material);
    return rst == RS_OK ? RAYSTREAM_OK : fail_core(rst);
}

raystream_status raystream_scene_add_quad(raystream_scene *h, const float q[3], const float u[3],
                                          const float v[3], uint32_t material)
{
    raystream_status st;
    rs_vec3 uu, vv;
    rs_status rst;
    NEED_SCENE(h, "raystream_scene_add_quad");
    if ((st = check_material(h, material)) != RAYSTREAM_OK)
        return st;
    if (!q || !u || !v || !finite3(q) || !finite3(u) || !finite3(v))
        return fail(RAYSTREAM_ERROR_ARGUMENT, "quad: needs finite q, u and v");
    uu = rs_v3(u[0], u[1], u[2]);
    vv = rs_v3(v[0], v[1], v[2]);
    if (rs_v3_is_zero(rs_v3_cross(uu, vv)))
        return fail(RAYSTREAM_ERROR_ARGUMENT, "quad: u and v must span a parallelogram");
    rst = rs_scene_add_quad(h->s, rs_v3(q[0], q[1], q[2]), uu, vv, material);
    return rst == RS_OK ? RAYSTREAM_OK : fail_core(rst);
}

raystream_status raystream_scene_set_camera(raystream_scene *h, const float from[3],
                                            const float at[3], const float up[3], float vfov_deg,
                                            float aperture, float focus_dist)
{
    rs_camera_desc d;
    NEED_SCENE(h, "raystream_scene_set_camera");
    if (!from || !at || !up || !finite3(from) || !finite3(at) || !finite3(up))
        return fail(RAYSTREAM_ERROR_ARGUMENT, "camera: needs finite from, at and up");
    if (!(vfov_deg >= 1e-3f && vfov_deg <= 179.0f) || !(aperture >= 0.0f) || !isfinite(aperture) ||
        !(focus_dist >= 0.0f) || !isfinite(focus_dist))
        return fail(RAYSTREAM_ERROR_ARGUMENT,
                    "camera: vfov in [0.001, 179] degrees, aperture and focus_dist >= 0");
    d = h->s->camera;
    d.from = rs_v3(from[0], from[1], from[2]);
    d.at = rs_v3(at[0], at[1], at[2]);
    d.up = rs_v3(up[0], up[1], up[2]);
    d.vfov_deg = vfov_deg;
    d.aperture = aperture;
    d.focus_dist = focus_dist;
    if (rs_v3_length(rs_v3_sub(d.from, d.at)) == 0.0f)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "camera: 'from' and 'at' must differ");
    if (rs_v3_length(rs_v3_cross(d.up, rs_v3_sub(d.from, d.at))) == 0.0f)
        return fail(RAYSTREAM_ERROR_ARGUMENT,
                    "camera: 'up' must not be parallel to the viewing direction");
    rs_scene_set_camera(h->s, &d);
    return RAYSTREAM_OK;
}

raystream_status raystream_scene_set_background(raystream_scene *h, const float rgb[3])
{
    NEED_SCENE(h, "raystream_scene_set_background");
    if (!rgb || !finite3(rgb) || rgb[0] < 0.0f || rgb[1] < 0.0f || rgb[2] < 0.0f)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "background: needs three finite values >= 0");
    rs_scene_set_background(h->s, rs_v3(rgb[0], rgb[1], rgb[2]));
    return RAYSTREAM_OK;
}

raystream_status raystream_scene_set_image_size(raystream_scene *h, uint32_t width, uint32_t height)
{
    NEED_SCENE(h, "raystream_scene_set_image_size");
    if (width < 1 || height < 1 || width > 32768 || height > 32768)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "image size %ux%u: each side in [1, 32768]", width,
                    height);
    rs_scene_set_image_size(h->s, width, height);
    return RAYSTREAM_OK;
}

void raystream_scene_counts(const raystream_scene *h, uint32_t *spheres, uint32_t *quads,
                            uint32_t *triangles, uint32_t *materials)
{
    const rs_scene *s = h ? h->s : NULL;
    if (spheres)
        *spheres = s ? s->n_spheres : 0;
    if (quads)
        *quads = s ? s->n_quads : 0;
    if (triangles)
        *triangles = s ? s->n_tris + s->n_inst_prims : 0;
    if (materials)
        *materials = s ? s->n_materials : 0;
}

/* ---- images ------------------------------------------------------------------------------- */

struct raystream_image {
    uint32_t width, height;
    float *rgb;
    int n_layers;
    char layer_name[API_LAYERS][16];
    int layer_channels[API_LAYERS];
    float *layer[API_LAYERS];
    double spp;
    char view[64]; /* the render's --view ("" standard) and --exposure, for 8-bit files */
    float exposure;
    rs_image_meta meta[RS_REPORT_META_MAX]; /* the command's EXR header: keys and values */
    size_t n_meta;                          /* (strings of the image's own) */
};

void raystream_image_release(raystream_image *img)
{
    int i;
    if (!img)
        return;
    rs_free(img->rgb);
    for (i = 0; i < img->n_layers; ++i)
        rs_free(img->layer[i]);
    for (i = 0; i < (int)img->n_meta; ++i) {
        free((char *)img->meta[i].key);
        free((char *)img->meta[i].value);
    }
    free(img);
}

uint32_t raystream_image_width(const raystream_image *img) { return img ? img->width : 0; }
uint32_t raystream_image_height(const raystream_image *img) { return img ? img->height : 0; }
const float *raystream_image_pixels(const raystream_image *img) { return img ? img->rgb : NULL; }
double raystream_image_spp(const raystream_image *img) { return img ? img->spp : 0.0; }
int raystream_image_layer_count(const raystream_image *img) { return img ? img->n_layers : 0; }

void raystream_image_copy(const raystream_image *img, float *rgb)
{
    if (img && rgb)
        memcpy(rgb, img->rgb, (size_t)img->width * img->height * 3 * sizeof *rgb);
}

const char *raystream_image_layer_name(const raystream_image *img, int i)
{
    return img && i >= 0 && i < img->n_layers ? img->layer_name[i] : NULL;
}

const float *raystream_image_layer(const raystream_image *img, const char *name, int *channels)
{
    int i;
    for (i = 0; img && name && i < img->n_layers; ++i)
        if (strcmp(img->layer_name[i], name) == 0) {
            if (channels)
                *channels = img->layer_channels[i];
            return img->layer[i];
        }
    if (channels)
        *channels = 0;
    return NULL;
}

raystream_status raystream_image_write(const raystream_image *img, const char *path)
{
    rs_image_layer layers[API_LAYERS];
    static const char *const chans[4] = {"", "Y", "", "RGB"};
    rs_view view;
    char why[300];
    rs_status st;
    int i;
    if (!img || !path || !*path)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_image_write: %s",
                    img ? "no file name" : "image is NULL");
    if (!rs_view_from_name(img->view[0] ? img->view : NULL, img->exposure, &view, why, sizeof why))
        return fail(RAYSTREAM_ERROR_ARGUMENT, "%s", why);
    for (i = 0; i < img->n_layers; ++i) {
        const char *n = img->layer_name[i];
        layers[i].name = n;
        layers[i].channels = strcmp(n, "normal") == 0  ? "XYZ"
                             : strcmp(n, "depth") == 0 ? "Z"
                                                       : chans[img->layer_channels[i]];
        layers[i].data = img->layer[i];
    }
    if ((st = rs_image_check_output(path)) != RS_OK)
        return fail_core(st == RS_ERR_ARG ? RS_ERR_ARG : RS_ERR_IO);
    /* layers into an .exr only (the command refuses --aov with another format) */
    if (img->n_layers && !(strlen(path) >= 4 && strcasecmp(path + strlen(path) - 4, ".exr") == 0))
        i = 0;
    else
        i = img->n_layers;
    st = rs_image_write_view(path, img->width, img->height, img->rgb, layers, (size_t)i, img->meta,
                             img->n_meta, &view);
    return st == RS_OK ? RAYSTREAM_OK : fail_core(st == RS_ERR_NOMEM ? st : RS_ERR_IO);
}

raystream_status raystream_image_read(const char *path, raystream_image **out)
{
    raystream_image *img;
    rs_status st;
    if (!out || !path)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_image_read: %s is NULL",
                    out ? "path" : "out");
    *out = NULL;
    if (!(img = (raystream_image *)calloc(1, sizeof *img)))
        return fail(RAYSTREAM_ERROR_MEMORY, "out of memory");
    st = rs_image_read_linear(path, &img->width, &img->height, &img->rgb);
    if (st != RS_OK) {
        free(img);
        return fail_core(st == RS_ERR_NOMEM ? st : RS_ERR_IO);
    }
    *out = img;
    return RAYSTREAM_OK;
}

/* ---- rendering ---------------------------------------------------------------------------- */

/* The render's progress, passed on to the caller at most every 50 ms (and at the end). */
typedef struct api_progress {
    const raystream_options *o;
    atomic_int cancel;
    double last;
    rs_tev *tev;
    const render_run *r;
} api_progress;

static void on_progress(void *user, uint64_t done, uint64_t total)
{
    api_progress *p = (api_progress *)user;
    double now;
    if (!p->o || !p->o->progress)
        return;
    now = rs_now_s();
    if (now - p->last < 0.05 && done < total)
        return;
    p->last = now;
    if (p->o->progress(p->o->progress_user, total ? (double)done / (double)total : 1.0))
        atomic_store(&p->cancel, 1);
}

static void on_film_ready(void *user, const rs_film *film, const rs_path_ranges *done)
{
    api_progress *p = (api_progress *)user;
    (void)done;
    rs_tev_film(p->tev, film, 0);
}

/* The image of the finished (or cancelled) render: r->rgb and the layers taken over. */
/* The command's EXR header for this render (app/report.c), copied into the image; 0 when out
 * of memory. */
static int image_meta(raystream_image *img, const rs_cli_options *co, const render_run *r,
                      const char *scene)
{
    rs_report rep;
    rs_report_meta m;
    size_t i;
    rs_run_report(co, r, &rep);
    rep.scene = scene;
    rs_report_image_meta(&rep, &m);
    for (i = 0; i < m.n; ++i) {
        img->meta[i].key = strdup(m.meta[i].key);
        img->meta[i].value = strdup(m.meta[i].value);
        img->n_meta = i + 1;
        if (!img->meta[i].key || !img->meta[i].value)
            return 0;
    }
    return 1;
}

static raystream_status make_image(const rs_cli_options *co, render_run *r, const char *scene,
                                   raystream_image **out)
{
    raystream_image *img = (raystream_image *)calloc(1, sizeof *img);
    rs_image_layer layers[4];
    float *bufs[4];
    int n, i;
    if (!img)
        return fail(RAYSTREAM_ERROR_MEMORY, "out of memory");
    if (!image_meta(img, co, r, scene)) {
        raystream_image_release(img);
        return fail(RAYSTREAM_ERROR_MEMORY, "out of memory");
    }
    img->width = r->st.width;
    img->height = r->st.height;
    img->spp = (double)rs_film_samples(r->film) / ((double)img->width * img->height);
    snprintf(img->view, sizeof img->view, "%s", co->view ? co->view : "");
    img->exposure = co->exposure;
    if ((n = rs_run_make_aovs(co->aovs, r, layers, bufs)) < 0) {
        for (i = 0; i < 4; ++i)
            rs_free(bufs[i]);
        raystream_image_release(img);
        return fail_core(RS_ERR_NOMEM);
    }
    for (i = 0; i < n; ++i) {
        snprintf(img->layer_name[i], sizeof img->layer_name[i], "%s", layers[i].name);
        img->layer_channels[i] = (int)strlen(layers[i].channels);
        img->layer[i] = (float *)layers[i].data;
    }
    img->n_layers = n;
    if (r->denoised) { /* the raw image as the layer "noisy", as in the command's .exr */
        snprintf(img->layer_name[n], sizeof img->layer_name[n], "noisy");
        img->layer_channels[n] = 3;
        img->layer[n] = r->rgb;
        img->n_layers = n + 1;
        img->rgb = r->denoised;
        r->denoised = NULL;
    } else {
        img->rgb = r->rgb;
    }
    r->rgb = NULL;
    *out = img;
    return RAYSTREAM_OK;
}

/* The options a built or loaded scene cannot take: they change a scene as it is loaded. */
static int loads_only(const rs_cli_options *co)
{
    return co->background_kind != RS_BG_NONE || co->envmap || co->mesh || co->camera ||
           co->flatten_instances;
}

/* The steps of `raystream render` (render_cmd.c) without its files, signals and progress bar:
 * settings, film, BVH, devices, the engine's run, the film resolved, --denoise, the layers. */
static int run_steps(const rs_cli_options *co, render_run *r, api_progress *p, int *cancelled)
{
    rs_render_hooks hooks;
    rs_status rst;
    int code;
    if ((code = rs_run_prepare(co, r)) != RS_EXIT_OK)
        return code;
    memset(&hooks, 0, sizeof hooks);
    hooks.progress = on_progress;
    hooks.user = p;
    hooks.cancel = &p->cancel;
    if (co->tev) {
        p->tev = rs_tev_open(co->tev, r->name, r->st.width, r->st.height);
        hooks.film_ready = on_film_ready;
    }
    p->last = rs_now_s();
    rst = rs_run_engine(r, &hooks);
    if (rst == RS_ERR_CANCELLED) {
        rs_error_clear();
        *cancelled = 1;
    } else if (rst != RS_OK) {
        return rs_app_fail(RS_EXIT_RUNTIME, "render failed");
    }
    rs_film_resolve(r->film, r->rgb);
    if (co->denoise && !*cancelled && !rs_run_denoise(r))
        return RS_EXIT_RUNTIME;
    rs_tev_film(p->tev, r->film, 1);
    return RS_EXIT_OK;
}

static raystream_status render(raystream_scene *h, const char *scene, const raystream_options *o,
                               raystream_image **out)
{
    rs_cli_options co;
    char *argv[2 * API_MAX_OPTIONS + 4];
    render_run r;
    api_sink sink;
    api_progress p;
    raystream_status st;
    int code, cancelled = 0;
    if (!out)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_render: out is NULL");
    *out = NULL;
    memset(&r, 0, sizeof r);
    memset(&p, 0, sizeof p);
    atomic_init(&p.cancel, 0);
    p.o = o;
    r.library = 1;
    (void)rs_fault_parse(NULL, &r.fault); /* no faults injected (RS_FAULT is the command's) */
    sink_begin(&sink, o ? o->log : NULL, o ? o->log_user : NULL);
    code = parse_options(o, scene, argv, &co);
    if (code == RS_EXIT_OK && h && loads_only(&co)) {
        rs_app_print("raystream: the options background, envmap, mesh, camera and "
                     "flatten-instances apply to a scene as it is loaded: use "
                     "raystream_render_scene, or set them on the scene\n");
        code = RS_EXIT_USAGE;
    }
    if (code == RS_EXIT_OK && h) { /* the extras this render reads, then the scene as it is */
        rs_scene_set_extras(co.light_sampler == RS_LIGHT_SAMPLER_BVH,
                            co.texture_filter == RS_TEXTURE_TRILINEAR);
        if (rs_scene_finalize(h->s) != RS_OK)
            code = rs_app_fail(RS_EXIT_RUNTIME, NULL);
        r.scene = h->s;
        snprintf(r.name, sizeof r.name, "%s", h->name);
        snprintf(r.lighting, sizeof r.lighting, "%s", h->lighting);
    } else if (code == RS_EXIT_OK) {
        code = rs_run_load_scene(&co, &r);
    }
    if (code == RS_EXIT_OK)
        code = run_steps(&co, &r, &p, &cancelled);
    st = from_exit(&sink, code);
    if (st == RAYSTREAM_OK)
        st = make_image(&co, &r, h ? h->source : co.scene, out);
    if (st == RAYSTREAM_OK && cancelled) {
        st = RAYSTREAM_CANCELLED;
        snprintf(g_error, sizeof g_error, "the render was cancelled");
    }
    rs_tev_close(p.tev);
    sink_end();
    if (h)
        r.scene = NULL; /* the caller's */
    rs_run_release(&r);
    return st;
}

raystream_status raystream_render(raystream_scene *scene, const raystream_options *options,
                                  raystream_image **out)
{
    raystream_status st;
    if (out)
        *out = NULL;
    if (!scene)
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_render: scene is NULL");
    if (atomic_exchange(&scene->busy, 1))
        return fail(RAYSTREAM_ERROR_ARGUMENT, "raystream_render: the scene is being rendered by "
                                              "another call (one render at a time per scene)");
    st = render(scene, NULL, options, out);
    atomic_store(&scene->busy, 0);
    return st;
}

raystream_status raystream_render_scene(const char *scene, const raystream_options *options,
                                        raystream_image **out)
{
    raystream_status st = check_scene_name(scene);
    if (st != RAYSTREAM_OK) {
        if (out)
            *out = NULL;
        return st;
    }
    return render(NULL, scene, options, out);
}
