/* bench/bench_scene.h — the scenes and ray sets the BVH and traversal benchmarks share
 * (benchmark-only helper).
 *
 * A scene spec is one of
 *   soup:N          N random triangles (edges up to ~2 units) in a cube that grows with the cube
 *                   root of N, so every N sees about the same density;
 *   builtin:NAME    a built-in scene (its meshes from the shared models folder);
 *   FILE.json       a raystream scene file (scenes/scene_json.c; its own camera), e.g. the shared
 *                   models' living room;
 *   FILE            any mesh file, read by the real importer (scenes/mesh.c) into an empty scene.
 * Scenes without a camera of their own (soup, files) get a pinhole camera on the diagonal
 * (1, 0.6, 1.4) of their bounding box that just holds the bounding sphere.
 *
 * Three ray sets per scene, all made with a fixed seed and the same for every BVH:
 *   primary  one camera ray per pixel of a W x W image, in scanline order (coherent);
 *   diffuse  bounce rays from the primary hits: cosine-distributed about the surface normal on
 *            the side the camera ray came from, spread evenly over the hits in pixel order
 *            (incoherent directions, as a path tracer's second segment);
 *   shadow   from the same points as the diffuse rays to a uniform point on one of the scene's
 *            lights (picked by area); for a scene lit only by its environment (the living room
 *            through its windows), toward the sky as the renderer samples a constant one: a
 *            second cosine-distributed direction about the normal, tmax infinite; for a scene
 *            with neither, to a point on a square the size of the bounding box floating half a
 *            box above it; tmax stops just short of a light or the square.
 * Secondary rays start 1e-4 of the scene's diagonal off the surface (tmin).  The primary hits
 * they start from are found with a median BVH the helper builds and throws away. */
#ifndef RS_BENCH_BENCH_SCENE_H
#define RS_BENCH_BENCH_SCENE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "accel/bvh.h"
#include "scenes/builtin.h"
#include "scenes/mesh.h"
#include "scenes/scene_json.h"
#include "shading/envmap.h"
#include "shading/camera.h"
#include "test_rand.h"

typedef struct bs_scene {
    char label[96];
    rs_scene *scene;
    rs_geom g;
    rs_aabb box;
} bs_scene;

typedef struct bs_rays {
    const char *name;
    rs_ray *rays;
    uint32_t n;
} bs_rays;

enum { BS_PRIMARY = 0, BS_DIFFUSE = 1, BS_SHADOW = 2, BS_N_SETS = 3 };

static inline rs_aabb bs_geom_box(const rs_geom *g)
{
    rs_aabb b;
    uint32_t i, n = rs_geom_prim_count(g);
    b.lo = rs_v3_splat(INFINITY);
    b.hi = rs_v3_splat(-INFINITY);
    for (i = 0; i < n; ++i) {
        rs_aabb p = rs_geom_prim_bounds(g, i);
        b.lo = rs_v3_min(b.lo, p.lo);
        b.hi = rs_v3_max(b.hi, p.hi);
    }
    return b;
}

/* The shared models folder rs_builtin_create would use with `dir` (may be NULL), or NULL if it
 * does not exist. */
static inline const char *bs_models_dir(const char *dir)
{
    const char *d = rs_builtin_models_dir(dir);
    struct stat sb;
    return d && stat(d, &sb) == 0 && S_ISDIR(sb.st_mode) ? d : NULL;
}

static inline void bs_scene_free(bs_scene *s)
{
    rs_scene_destroy(s->scene);
    memset(s, 0, sizeof *s);
}

static inline int bs_soup(rs_scene *sc, uint32_t n, uint64_t seed)
{
    float h = 30.0f * cbrtf((float)n / 100000.0f);
    uint32_t i, mat;
    rs_material m = rs_mat_lambertian(rs_v3_splat(0.5f));
    if (rs_scene_add_material(sc, &m, &mat) != RS_OK)
        return 0;
    for (i = 0; i < n; ++i) {
        rs_vec3 c = rnd_box(&seed, h), v[3];
        int k;
        for (k = 0; k < 3; ++k)
            v[k] = rs_v3_madd(c, rnd_unit(&seed), rnd_range(&seed, 0.1, 1.0));
        if (rs_scene_add_triangle(sc, v[0], v[1], v[2], mat) != RS_OK)
            return 0;
    }
    return 1;
}

/* Loads `spec` (see the top of this file); prints one line naming what failed and returns 0. */
static inline int bs_load(const char *spec, const char *models_dir, bs_scene *out)
{
    rs_status st = RS_OK;
    int has_camera = 0;
    memset(out, 0, sizeof *out);
    if (strncmp(spec, "builtin:", 8) == 0) {
        rs_builtin_opts o;
        memset(&o, 0, sizeof o);
        o.models_dir = models_dir;
        st = rs_builtin_create_ex(spec + 8, &o, &out->scene);
        has_camera = 1;
        snprintf(out->label, sizeof out->label, "%s", spec);
    } else if (strncmp(spec, "soup:", 5) == 0) {
        long n = atol(spec + 5);
        if (n < 1 || n > 100000000L) {
            fprintf(stderr, "bench: %s: the soup needs 1 to 10^8 triangles\n", spec);
            return 0;
        }
        st = rs_scene_create("soup", &out->scene);
        if (st == RS_OK && !bs_soup(out->scene, (uint32_t)n, 0x50u))
            st = RS_ERR_NOMEM;
        if (st == RS_OK)
            st = rs_scene_finalize(out->scene);
        snprintf(out->label, sizeof out->label, "soup of %ld random triangles", n);
    } else if (strlen(spec) > 5 && strcmp(spec + strlen(spec) - 5, ".json") == 0) {
        const char *base = strrchr(spec, '/');
        st = rs_scene_load_json_ex(spec, NULL, &out->scene);
        has_camera = 1;
        snprintf(out->label, sizeof out->label, "%s", base ? base + 1 : spec);
    } else {
        rs_mesh_opts mo;
        rs_mesh_info info;
        rs_material m = rs_mat_lambertian(rs_v3_splat(0.5f));
        uint32_t mat;
        const char *base = strrchr(spec, '/');
        st = rs_scene_create("mesh", &out->scene);
        if (st == RS_OK)
            st = rs_scene_add_material(out->scene, &m, &mat);
        mo = rs_mesh_opts_default(mat);
        if (st == RS_OK)
            st = rs_scene_add_mesh(out->scene, spec, &mo, &info);
        if (st == RS_OK)
            st = rs_scene_finalize(out->scene);
        snprintf(out->label, sizeof out->label, "%s", base ? base + 1 : spec);
    }
    if (st != RS_OK) {
        fprintf(stderr, "bench: %s: %s\n", spec, rs_error_message());
        bs_scene_free(out);
        return 0;
    }
    out->g = rs_scene_geom(out->scene);
    out->box = bs_geom_box(&out->g);
    if (!has_camera) {
        rs_camera_desc *c = &out->scene->camera;
        rs_vec3 ctr = rs_v3_scale(rs_v3_add(out->box.lo, out->box.hi), 0.5f);
        float r = 0.5f * rs_v3_length(rs_v3_sub(out->box.hi, out->box.lo));
        memset(c, 0, sizeof *c);
        c->from = rs_v3_madd(ctr, rs_v3_normalize(rs_v3(1.0f, 0.6f, 1.4f)), 2.5f * r);
        c->at = ctr;
        c->up = rs_v3(0, 1, 0);
        /* the sphere fills the view: sin(half angle) = r / (2.5 r) */
        c->vfov_deg = 2.0f * asinf(1.0f / 2.5f) * (180.0f / RS_PI);
    }
    return 1;
}

/* Loads each of scenes[n] in turn and hands it to `fn`; stops at the first failure.  Returns 1
 * when every scene loaded and `fn` returned nonzero for each. */
static inline int bs_for_each(const char *const *scenes, int n, const char *models_dir,
                              int (*fn)(const bs_scene *s, const void *ctx), const void *ctx)
{
    int i, ok = 1;
    for (i = 0; ok && i < n; ++i) {
        bs_scene sc;
        if (!bs_load(scenes[i], models_dir, &sc))
            return 0;
        ok = fn(&sc, ctx);
        bs_scene_free(&sc);
    }
    return ok;
}

static inline void bs_rays_free(bs_rays *sets, int n)
{
    int k;
    for (k = 0; k < n; ++k) {
        free(sets[k].rays);
        sets[k].rays = NULL;
        sets[k].n = 0;
    }
}

/* The geometric normal of global primitive `prim` at point p. */
static inline rs_vec3 bs_normal(const rs_geom *g, uint32_t prim, rs_vec3 p)
{
    rs_vec3 n;
    if (prim < g->n_spheres) {
        n = rs_v3_sub(p, g->spheres[prim].center);
    } else if (prim < g->n_spheres + g->n_quads) {
        n = g->quads[prim - g->n_spheres].w;
    } else {
        const rs_tri *t = &g->tris[prim - g->n_spheres - g->n_quads];
        n = rs_v3_cross(rs_v3_sub(t->v1, t->v0), rs_v3_sub(t->v2, t->v0));
    }
    return rs_v3_length2(n) > 0.0f ? rs_v3_normalize(n) : rs_v3(0, 1, 0);
}

/* A uniform point on global primitive `prim` (a quad or a triangle). */
static inline rs_vec3 bs_point_on(const rs_geom *g, uint32_t prim, uint64_t *seed)
{
    double a = rnd01(seed), b = rnd01(seed);
    if (prim < g->n_spheres + g->n_quads) {
        const rs_quad *q = &g->quads[prim - g->n_spheres];
        return rs_v3_madd(rs_v3_madd(q->q, q->u, (float)a), q->v, (float)b);
    } else {
        const rs_tri *t = &g->tris[prim - g->n_spheres - g->n_quads];
        if (a + b > 1.0)
            a = 1.0 - a, b = 1.0 - b;
        return rs_v3_madd(rs_v3_madd(t->v0, rs_v3_sub(t->v1, t->v0), (float)a),
                          rs_v3_sub(t->v2, t->v0), (float)b);
    }
}

/* A point on the scene's lights (by area), or on the square above the box for a scene without. */
static inline rs_vec3 bs_light_point(const bs_scene *s, uint64_t *seed)
{
    const rs_scene *sc = s->scene;
    if (sc->n_lights > 0) {
        double total = 0.0, x;
        uint32_t i;
        for (i = 0; i < sc->n_lights; ++i)
            total += sc->lights[i].area;
        x = rnd01(seed) * total;
        for (i = 0; i + 1 < sc->n_lights && x >= sc->lights[i].area; ++i)
            x -= sc->lights[i].area;
        return bs_point_on(&s->g, sc->lights[i].prim, seed);
    } else {
        rs_vec3 e = rs_v3_sub(s->box.hi, s->box.lo);
        float top = s->box.hi.y + 0.5f * fmaxf(e.x, fmaxf(e.y, e.z));
        return rs_v3(s->box.lo.x + e.x * (float)rnd01(seed), top,
                     s->box.lo.z + e.z * (float)rnd01(seed));
    }
}

/* Fills sets[BS_N_SETS]: w x w primary rays and n_secondary diffuse and shadow rays (fewer when
 * no primary ray hits: then none).  Returns 0 (with a message) if memory runs out. */
static inline int bs_make_rays(const bs_scene *s, uint32_t w, uint32_t n_secondary,
                               bs_rays sets[BS_N_SETS])
{
    const rs_geom *g = &s->g;
    rs_camera cam = rs_camera_make(s->scene->camera.from, s->scene->camera.at, s->scene->camera.up,
                                   s->scene->camera.vfov_deg, 0.0f, 0.0f, w, w);
    float eps = 1e-4f * rs_v3_length(rs_v3_sub(s->box.hi, s->box.lo));
    rs_bvh *bvh = NULL;
    rs_bvh_view view;
    uint32_t *hit_pix = NULL, n_hits = 0, i;
    rs_hit *hits = NULL;
    uint64_t seed = 0xd1ffu;
    int ok = 0;
    memset(sets, 0, BS_N_SETS * sizeof sets[0]);
    sets[BS_PRIMARY].name = "primary";
    sets[BS_DIFFUSE].name = "diffuse";
    sets[BS_SHADOW].name = "shadow";
    sets[BS_PRIMARY].n = w * w;
    sets[BS_PRIMARY].rays = (rs_ray *)malloc((size_t)w * w * sizeof(rs_ray));
    hits = (rs_hit *)malloc((size_t)w * w * sizeof *hits);
    hit_pix = (uint32_t *)malloc((size_t)w * w * sizeof *hit_pix);
    if (!sets[BS_PRIMARY].rays || !hits || !hit_pix || rs_bvh_build(g, NULL, &bvh) != RS_OK)
        goto out;
    view = rs_bvh_view_of(bvh);
    for (i = 0; i < w * w; ++i) {
        rs_ray *r = &sets[BS_PRIMARY].rays[i];
        *r = rs_camera_ray(&cam, i % w, i / w, 0.5f, 0.5f, 0.0f, 0.0f);
        r->tmax = INFINITY;
        r->time = 0.0f;
        if (rs_bvh_closest(&view, g, *r, &hits[i]))
            hit_pix[n_hits++] = i;
    }
    if (n_hits == 0)
        n_secondary = 0;
    for (i = 1; i < BS_N_SETS; ++i) {
        sets[i].n = n_secondary;
        sets[i].rays = (rs_ray *)malloc((size_t)(n_secondary ? n_secondary : 1) * sizeof(rs_ray));
        if (!sets[i].rays)
            goto out;
    }
    for (i = 0; i < n_secondary; ++i) {
        uint32_t px = hit_pix[(uint32_t)((uint64_t)i * n_hits / n_secondary)];
        const rs_ray *pr = &sets[BS_PRIMARY].rays[px];
        rs_vec3 p = rs_v3_madd(pr->o, pr->d, hits[px].t);
        rs_vec3 n = bs_normal(g, hits[px].prim, p), d, l;
        float dist;
        if (rs_v3_dot(n, pr->d) > 0.0f)
            n = rs_v3_neg(n);
        /* cosine-distributed: the normal plus a uniform unit vector (Shirley, RTIOW §9.4) */
        d = rs_v3_add(n, rnd_unit(&seed));
        if (rs_v3_length2(d) < 1e-12f)
            d = n;
        sets[BS_DIFFUSE].rays[i] = mk_ray(p, rs_v3_normalize(d), eps, INFINITY);
        if (s->scene->n_area_lights == 0 && rs_env_present(s->scene)) {
            /* toward the sky: anything in the way occludes */
            l = rs_v3_add(n, rnd_unit(&seed));
            sets[BS_SHADOW].rays[i] =
                mk_ray(p, rs_v3_length2(l) < 1e-12f ? n : rs_v3_normalize(l), eps, INFINITY);
            continue;
        }
        l = rs_v3_sub(bs_light_point(s, &seed), p);
        dist = rs_v3_length(l);
        sets[BS_SHADOW].rays[i] =
            mk_ray(p, dist > 0.0f ? rs_v3_scale(l, 1.0f / dist) : n, eps, dist * (1.0f - 1e-4f));
    }
    ok = 1;
out:
    if (!ok) {
        fprintf(stderr, "bench: %s: out of memory for the rays\n", s->label);
        bs_rays_free(sets, BS_N_SETS);
    }
    rs_bvh_destroy(bvh);
    free(hits);
    free(hit_pix);
    return ok;
}

#endif
