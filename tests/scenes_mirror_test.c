/* tests/scenes_mirror_test.c — rs_scene_mirror_create, the deep copy the CUDA megakernel makes of
 * a scene in device memory, checked here with host memory (the same code; only the copy
 * callbacks differ):
 *   - every array is copied (no pointer shared with the original), the byte count adds up;
 *   - the original's arrays are then scribbled over and freed, and the mirror still renders the
 *     original's image bit for bit (a shallow or missing copy changes the image, and under
 *     AddressSanitizer is a use after free);
 *   - a copy failing at any step releases every block made before it and reports the error;
 *   - the device copies (scheduler/device_copy.h: geometry + BVH for trace, the scene for the
 *     megakernel) of scenes with every kind of array (moving spheres, quads, triangles with UVs
 *     and normals, textures, images, lights) hold no pointer into the original's memory.  The
 *     original's blocks are recorded from the library allocator (rs_alloc_set_observer) while the
 *     scene and its BVH are built, the copy's from the copy callbacks; then EVERY pointer-sized,
 *     pointer-aligned word of the copied rs_geom, rs_bvh_view, rs_scene (and its rs_image array,
 *     the megakernel's rs_path_tracer, and the render constants a device holds) is checked, not
 *     only the fields the array lists name, so an array missing from a list (RS_SCENE_ARRAYS,
 *     RS_GEOM_ARRAYS, RS_BVH_ARRAYS) fails here; and a copy failing at any step releases every
 *     block it made. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <stdlib.h>
#include <string.h>

#include <pthread.h>

#include "render_util.h"
#include "scheduler/device_copy.h"

typedef struct host_ops {
    int live;    /* blocks allocated and not yet released */
    int calls;   /* copy calls so far */
    int fail_at; /* the copy call that fails (1-based); 0: none */
} host_ops;

static rs_status host_copy(void *user, void **dst, const void *src, size_t bytes)
{
    host_ops *h = (host_ops *)user;
    *dst = NULL;
    if (++h->calls == h->fail_at)
        return rs_error_set(RS_ERR_NOMEM, "copy %d refused by the test", h->calls);
    *dst = malloc(bytes);
    if (!*dst)
        return rs_error_set(RS_ERR_NOMEM, "out of memory");
    memcpy(*dst, src, bytes);
    ++h->live;
    return RS_OK;
}

static void host_release(void *user, void *p)
{
    host_ops *h = (host_ops *)user;
    --h->live;
    free(p);
}

/* The materials scene (every material, checker/stripes/image textures, a sphere light, a quad
 * light) plus what it lacks: a moving sphere under an open shutter, a triangle with UVs and
 * vertex normals under the image texture, and an environment map. */
static rs_scene *make_scene(void)
{
    rs_scene *s;
    rs_material m;
    uint32_t id;
    rs_vec3 v[3];
    static const float uv[6] = {0.1f, 0.2f, 0.9f, 0.1f, 0.5f, 0.95f};
    static const float nrm[9] = {0, 0.6f, 0.8f, 0.6f, 0, 0.8f, 0, 0, 1};
    uint32_t k;
    if (rs_builtin_create("materials", &s) != RS_OK)
        return NULL;
    m = rs_mat_lambertian(rs_v3(.7f, .3f, .2f));
    for (k = 0; k < s->n_textures; ++k)
        if (s->textures[k].type == RS_TEX_IMAGE)
            m.albedo_tex = k;
    assert_int_not_equal(m.albedo_tex, RS_NO_TEXTURE);
    assert_int_equal(rs_scene_add_material(s, &m, &id), RS_OK);
    assert_int_equal(
        rs_scene_add_moving_sphere(s, rs_v3(-1, 2.5f, 1), 0.0f, rs_v3(1, 2.5f, 1), 1.0f, 0.5f, id),
        RS_OK);
    v[0] = rs_v3(-2, 0.1f, 2);
    v[1] = rs_v3(2, 0.1f, 2);
    v[2] = rs_v3(0, 2.5f, 2.5f);
    assert_int_equal(rs_scene_add_triangle_full(s, v, uv, nrm, id), RS_OK);
    {
        /* an alpha cut-out on a second triangle (the masks, the per-triangle table, the UVs the
         * traversal reads) */
        static const float alpha[4] = {0, 1, 1, 0};
        rs_material cut = rs_mat_lambertian(rs_v3(.2f, .6f, .3f));
        uint32_t cid;
        rs_vec3 w[3];
        assert_int_equal(rs_scene_add_mask(s, 2, 2, alpha, 1.0f, 0.5f, &cut.alpha_mask), RS_OK);
        assert_int_equal(rs_scene_add_material(s, &cut, &cid), RS_OK);
        w[0] = rs_v3(-2, 0.2f, 1.5f);
        w[1] = rs_v3(2, 0.2f, 1.5f);
        w[2] = rs_v3(0, 3, 1.5f);
        assert_int_equal(rs_scene_add_triangle_full(s, w, uv, NULL, cid), RS_OK);
    }
    {
        /* instances: a prototype of that triangle (with UVs and normals), placed twice, once
         * mirrored (the instance table, the prototypes' arrays, the bottom levels) */
        static const double m1[12] = {0.5, 0, 0, 1, 0, 0.5, 0, 0.2, 0, 0, 0.5, 0.5};
        static const double m2[12] = {-0.4, 0, 0, -1, 0, 0.4, 0, 0.3, 0, 0, 0.4, 0.2};
        uint32_t first, count;
        assert_int_equal(rs_scene_add_triangle_full(s, v, uv, nrm, id), RS_OK);
        assert_int_equal(rs_scene_make_prototype(s, s->n_tris - 1, &first, &count), RS_OK);
        assert_int_equal(count, 1u);
        assert_int_equal(rs_scene_add_instance(s, first, count, m1), RS_OK);
        assert_int_equal(rs_scene_add_instance(s, first, count, m2), RS_OK);
    }
    {
        /* an environment map (its CDF arrays), instead of the sky */
        float env[8 * 4 * 3];
        uint32_t img;
        for (k = 0; k < 8 * 4 * 3; ++k)
            env[k] = 0.1f + 0.05f * (float)(k % 7) + (k / 3 == 9 ? 40.0f : 0.0f);
        assert_int_equal(rs_scene_add_image(s, 8, 4, env, &img), RS_OK);
        assert_int_equal(rs_scene_set_environment(s, img, rs_v3(.5f, .6f, .7f), NULL), RS_OK);
    }
    s->camera.shutter_open = 0.0f;
    s->camera.shutter_close = 1.0f;
    assert_int_equal(rs_scene_finalize(s), RS_OK);
    return s;
}

#define SHARED(field) (m.scene.field && m.scene.field == s->field)

static void test_mirror_renders_alone(void **state)
{
    rs_scene *s = make_scene();
    host_ops h = {0, 0, 0};
    rs_mirror_ops ops = {host_copy, host_release, &h};
    rs_scene_mirror m;
    rt_args a = rt_defaults("", 48, 4);
    float *ref, *img;
    uint64_t want;
    uint32_t i;
    (void)state;
    assert_non_null(s);
    assert_non_null(s->sphere_motion);
    assert_non_null(s->tri_uv);
    assert_non_null(s->tri_normal);
    assert_true(s->n_images > 0 && s->n_lights >= 2);
    a.threads = 2;
    ref = rt_render_scene(s, &a, NULL);
    assert_non_null(ref);

    assert_int_equal(rs_scene_mirror_create(s, &ops, &m), RS_OK);
    assert_false(SHARED(spheres) || SHARED(sphere_mat) || SHARED(sphere_motion) || SHARED(quads) ||
                 SHARED(quad_mat) || SHARED(tris) || SHARED(tri_mat) || SHARED(tri_uv) ||
                 SHARED(tri_normal) || SHARED(materials) || SHARED(textures) || SHARED(images) ||
                 SHARED(lights) || SHARED(light_cdf) || SHARED(light_nodes) ||
                 SHARED(light_trail) || SHARED(prim_light) ||
                 SHARED(env_marg_cdf) || SHARED(env_cond_cdf) || SHARED(inst_tris) ||
                 SHARED(inst_tri_mat) || SHARED(inst_tri_uv) || SHARED(inst_tri_normal) ||
                 SHARED(instances) || SHARED(masks) || SHARED(mask_bits) ||
                 SHARED(tri_mask));
    want = s->n_spheres * (sizeof(rs_sphere) + sizeof(uint32_t) + sizeof(rs_vec3)) +
           s->n_quads * (sizeof(rs_quad) + sizeof(uint32_t)) +
           s->n_tris * (sizeof(rs_tri) + sizeof(uint32_t) + 15 * sizeof(float)) +
           s->n_materials * sizeof(rs_material) + s->n_textures * sizeof(rs_texture) +
           s->n_images * sizeof(rs_image) + s->n_lights * sizeof(rs_light) +
           (s->n_lights + 1) * sizeof(float) +
           s->n_light_nodes * sizeof(rs_light_node) + /* the light BVH */
           (s->light_nodes ? s->n_lights * sizeof(uint64_t) : 0) +
           (s->n_spheres + s->n_quads + s->n_tris) * sizeof(int32_t) +
           (4 + 1 + 4 * (8 + 1)) * sizeof(float) + /* the 8 x 4 map's two CDFs */
           s->n_inst_tris * (sizeof(rs_tri) + sizeof(uint32_t) + 15 * sizeof(float)) +
           s->n_instances * sizeof(rs_instance) + s->n_masks * sizeof(rs_alpha_mask) +
           s->n_mask_bits + s->n_tris * sizeof(uint32_t); /* the masks, tri_mask */
    assert_non_null(s->tri_mask);
    assert_int_equal(s->n_instances, 2u);
    assert_non_null(s->env_marg_cdf);
    for (i = 0; i < s->n_images; ++i) {
        want +=
            rs_image_levels_floats(s->images[i].width, s->images[i].height, s->images[i].levels) *
            sizeof(float); /* mip levels too */
        assert_ptr_not_equal(m.scene.images[i].rgb, s->images[i].rgb);
    }
    assert_int_equal(m.made.bytes, want);
    assert_int_equal(h.live, (int)m.made.n_blocks);

    /* the original's data scribbled over, then freed: only the mirror is left */
    memset(s->spheres, 0x7f, s->n_spheres * sizeof *s->spheres);
    memset(s->materials, 0x7f, s->n_materials * sizeof *s->materials);
    memset(s->tri_uv, 0x7f, 6 * s->n_tris * sizeof(float));
    memset(s->inst_tri_uv, 0x7f, 6 * s->n_inst_tris * sizeof(float));
    memset(s->instances, 0x7f, s->n_instances * sizeof *s->instances);
    memset(s->mask_bits, 1, s->n_mask_bits); /* all opaque: a shared mask would show */
    for (i = 0; i < s->n_images; ++i)
        memset(s->images[i].rgb, 0,
               3ull * s->images[i].width * s->images[i].height * sizeof(float));
    rs_scene_destroy(s);

    img = rt_render_scene(&m.scene, &a, NULL);
    assert_non_null(img);
    assert_memory_equal(img, ref, (size_t)48 * 48 * 3 * sizeof(float));
    rs_scene_mirror_release(&m, &ops);
    assert_int_equal(h.live, 0);
    free(img);
    free(ref);
}

static void test_mirror_failure_releases(void **state)
{
    rs_scene *s = make_scene();
    host_ops h = {0, 0, 0};
    rs_mirror_ops ops = {host_copy, host_release, &h};
    rs_scene_mirror m;
    int total, k;
    (void)state;
    assert_non_null(s);
    assert_int_equal(rs_scene_mirror_create(s, &ops, &m), RS_OK);
    total = h.calls;
    rs_scene_mirror_release(&m, &ops);
    assert_true(total >= 16);
    for (k = 1; k <= total; ++k) {
        h.calls = h.live = 0;
        h.fail_at = k;
        assert_int_equal(rs_scene_mirror_create(s, &ops, &m), RS_ERR_NOMEM);
        assert_int_equal(h.live, 0);
        assert_null(m.made.blocks);
        rs_error_clear();
    }
    rs_scene_destroy(s);
}

/* ---- the device copies hold no pointer into the original ------------------------------------ */

/* A set of blocks [lo, hi), as a plain array (a few hundred blocks: linear search). */
typedef struct span {
    uintptr_t lo, hi;
} span;

typedef struct span_set {
    span *v;
    size_t n, cap;
    pthread_mutex_t lock; /* the observer may be called from any allocating thread */
} span_set;

static void set_init(span_set *s)
{
    memset(s, 0, sizeof *s);
    pthread_mutex_init(&s->lock, NULL);
}

static void set_free(span_set *s)
{
    free(s->v);
    pthread_mutex_destroy(&s->lock);
}

static void set_add(span_set *s, const void *p, size_t bytes)
{
    pthread_mutex_lock(&s->lock);
    if (s->n == s->cap) {
        s->cap = s->cap ? 2 * s->cap : 256;
        s->v = (span *)realloc(s->v, s->cap * sizeof *s->v); /* not rs_alloc: not observed */
        assert_non_null(s->v);
    }
    s->v[s->n].lo = (uintptr_t)p;
    s->v[s->n].hi = (uintptr_t)p + bytes;
    s->n++;
    pthread_mutex_unlock(&s->lock);
}

static void set_remove(span_set *s, const void *p)
{
    size_t i;
    pthread_mutex_lock(&s->lock);
    for (i = 0; i < s->n; ++i)
        if (s->v[i].lo == (uintptr_t)p) {
            s->v[i] = s->v[--s->n];
            break;
        }
    pthread_mutex_unlock(&s->lock);
}

static int set_holds(const span_set *s, uintptr_t w)
{
    size_t i;
    for (i = 0; i < s->n; ++i)
        if (w >= s->v[i].lo && w < s->v[i].hi)
            return 1;
    return 0;
}

/* rs_alloc_set_observer's callback: blocks the library allocates, minus the ones it frees (so a
 * freed block that malloc hands to the copy is not taken for the original's). */
static void observe(void *user, void *p, size_t bytes)
{
    span_set *s = (span_set *)user;
    if (bytes)
        set_add(s, p, bytes);
    else
        set_remove(s, p);
}

/* The recording copy callbacks: every block made is in `made` until released. */
typedef struct rec_ops {
    span_set made;
    int calls;   /* copy calls so far */
    int fail_at; /* the copy call that fails (1-based); 0: none */
} rec_ops;

static rs_status rec_copy(void *user, void **dst, const void *src, size_t bytes)
{
    rec_ops *r = (rec_ops *)user;
    *dst = NULL;
    if (++r->calls == r->fail_at)
        return rs_error_set(RS_ERR_CUDA, "copy %d refused by the test", r->calls);
    assert_true(bytes > 0);
    *dst = malloc(bytes);
    assert_non_null(*dst);
    memcpy(*dst, src, bytes);
    set_add(&r->made, *dst, bytes);
    return RS_OK;
}

static void rec_release(void *user, void *p)
{
    rec_ops *r = (rec_ops *)user;
    assert_true(set_holds(&r->made, (uintptr_t)p));
    set_remove(&r->made, p);
    free(p);
}

/* Every pointer-sized, pointer-aligned word of [p, p + bytes): none may lie in a block of the
 * original; the words that lie in a block of the copy are counted into *in_copy. */
static void scan_words(const char *scene, const char *what, const void *p, size_t bytes,
                       const span_set *orig, const span_set *made, int *in_copy)
{
    const unsigned char *b = (const unsigned char *)p;
    size_t off;
    int bad = 0;
    assert_int_equal((uintptr_t)p % sizeof(uintptr_t), 0);
    for (off = 0; off + sizeof(uintptr_t) <= bytes; off += sizeof(uintptr_t)) {
        uintptr_t w;
        memcpy(&w, b + off, sizeof w);
        if (set_holds(orig, w)) {
            print_message("%s: %s, the word at byte %zu (%#llx) points into the original's "
                          "memory\n",
                          scene, what, off, (unsigned long long)w);
            bad = 1;
        }
        *in_copy += set_holds(made, w);
    }
    assert_false(bad);
}

/* A scene built while the library's allocations are recorded, with its BVH. */
typedef struct observed_scene {
    rs_scene *scene;
    rs_geom geom;
    rs_bvh *bvh;
    span_set orig;
} observed_scene;

static void observed_build(observed_scene *o, const char *builtin)
{
    rs_bvh_build_opts bo;
    set_init(&o->orig);
    rs_alloc_set_observer(observe, &o->orig);
    if (builtin)
        assert_int_equal(rs_builtin_create(builtin, &o->scene), RS_OK);
    else
        o->scene = make_scene();
    assert_non_null(o->scene);
    o->geom = rs_scene_geom(o->scene);
    memset(&bo, 0, sizeof bo);
    bo.threads = 1;
    assert_int_equal(rs_bvh_build(&o->geom, &bo, &o->bvh), RS_OK);
    rs_bvh_attach(o->bvh, &o->geom); /* as rs_device_upload does */
    rs_alloc_set_observer(NULL, NULL);
    assert_true(o->orig.n > 0);
}

static void observed_free(observed_scene *o)
{
    rs_bvh_destroy(o->bvh);
    rs_scene_destroy(o->scene);
    set_free(&o->orig);
}

static void check_device_copy(const char *builtin)
{
    const char *name = builtin ? builtin : "materials+motion+uv+normals";
    observed_scene o;
    rec_ops r;
    rs_mirror_ops ops = {rec_copy, rec_release, &r};
    rs_device_geom dg;
    rs_device_scene ds;
    const rs_scene *ms;
    int in_copy = 0;
    observed_build(&o, builtin);
    memset(&r, 0, sizeof r);
    set_init(&r.made);

    assert_int_equal(rs_device_copy_geom(&o.geom, o.bvh, &ops, &dg), RS_OK);
    assert_int_equal(rs_device_copy_scene(o.scene, &dg, &ops, &ds), RS_OK);
    assert_int_equal((int)r.made.n, (int)(dg.made.n_blocks + ds.mirror.made.n_blocks));
    ms = &ds.mirror.scene;
    print_message("%s: %u + %u blocks copied (%llu + %llu bytes), %zu blocks of the original\n",
                  name, dg.made.n_blocks, ds.mirror.made.n_blocks,
                  (unsigned long long)dg.made.bytes, (unsigned long long)ds.mirror.made.bytes,
                  o.orig.n);

    /* every word of every struct of the copies (the host ops' blocks are readable here) */
    scan_words(name, "trace geometry (rs_geom)", &dg.geom, sizeof dg.geom, &o.orig, &r.made,
               &in_copy);
    scan_words(name, "trace BVH (rs_bvh_view)", &dg.bvh, sizeof dg.bvh, &o.orig, &r.made, &in_copy);
    scan_words(name, "scene mirror (rs_scene)", ms, sizeof *ms, &o.orig, &r.made, &in_copy);
    assert_true(set_holds(&r.made, (uintptr_t)ds.scene));
    scan_words(name, "the mirror's copied rs_scene", ds.scene, sizeof *ds.scene, &o.orig, &r.made,
               &in_copy);
    scan_words(name, "megakernel tracer (rs_path_tracer)", &ds.tracer, sizeof ds.tracer, &o.orig,
               &r.made, &in_copy);
    {
        /* the render constants as a device with a copy holds them (gpu/: upload_scene points
         * `scene` at the copy): no word of them may point into host memory of the original, and
         * `scene` is the copy's (scheduler/device_copy.c asserts they hold nothing else) */
        rt_args a = rt_defaults(name, 8, 2);
        rs_render_settings st = rt_settings(&a);
        rs_render_consts rc;
        int rc_in_copy = 0;
        assert_int_equal(rs_render_constants(o.scene, &st, &rc), RS_OK);
        rc.scene = ds.scene;
        scan_words(name, "render constants (rs_render_consts)", &rc, sizeof rc, &o.orig, &r.made,
                   &rc_in_copy);
        assert_int_equal(rc_in_copy, 1);
    }
    if (ms->n_images)
        scan_words(name, "the mirror's images (rs_image[])", ms->images,
                   ms->n_images * sizeof *ms->images, &o.orig, &r.made, &in_copy);
    assert_true(in_copy > 0); /* the scan sees the copies' pointers */

    /* what the scenes were chosen for really is there and copied */
    if (o.scene->sphere_motion) {
        assert_non_null(dg.geom.sphere_motion);
        assert_true(set_holds(&r.made, (uintptr_t)dg.geom.sphere_motion));
        assert_memory_equal(dg.geom.sphere_motion, o.scene->sphere_motion,
                            o.scene->n_spheres * sizeof *o.scene->sphere_motion);
        assert_ptr_equal(ds.tracer.geom.sphere_motion, ms->sphere_motion);
    }
    if (o.scene->tri_mask) {
        /* the cut-outs: the trace copy's own, the megakernel's from the mirror */
        assert_true(set_holds(&r.made, (uintptr_t)dg.geom.tri_mask));
        assert_true(set_holds(&r.made, (uintptr_t)dg.geom.mask_bits));
        assert_true(set_holds(&r.made, (uintptr_t)dg.geom.tri_uv));
        assert_memory_equal(dg.geom.tri_mask, o.scene->tri_mask,
                            o.scene->n_tris * sizeof *o.scene->tri_mask);
        assert_ptr_equal(ds.tracer.geom.tri_mask, ms->tri_mask);
        assert_ptr_equal(ds.tracer.geom.mask_bits, ms->mask_bits);
        assert_ptr_equal(ds.tracer.geom.tri_uv, ms->tri_uv);
    }
    if (o.scene->n_instances) {
        /* the instances: the BVH's table (with roots) and bottom levels, copied, in the tracer */
        assert_true(set_holds(&r.made, (uintptr_t)dg.geom.instances));
        assert_true(set_holds(&r.made, (uintptr_t)dg.geom.blas_nodes));
        assert_memory_equal(dg.geom.instances, o.bvh->instances,
                            o.scene->n_instances * sizeof *o.bvh->instances);
        assert_memory_equal(dg.geom.blas_nodes, o.bvh->blas_nodes,
                            o.bvh->n_blas_nodes * sizeof *o.bvh->blas_nodes);
        assert_ptr_equal(ds.tracer.geom.instances, dg.geom.instances);
        assert_ptr_equal(ds.tracer.geom.blas_nodes, dg.geom.blas_nodes);
        assert_ptr_equal(ds.tracer.geom.blas_prim_ids, dg.geom.blas_prim_ids);
        assert_ptr_equal(ds.tracer.geom.inst_tris, ms->inst_tris);
        assert_non_null(ms->inst_tri_uv);
        assert_non_null(ms->inst_tri_normal);
    }
    /* the tracer: the mirror's arrays, the uploaded algorithms and BVH copy */
    assert_ptr_equal(ds.tracer.geom.spheres, ms->spheres);
    assert_ptr_equal(ds.tracer.geom.quads, ms->quads);
    assert_ptr_equal(ds.tracer.geom.tris, ms->tris);
    assert_ptr_equal(ds.tracer.bvh.nodes, dg.bvh.nodes);
    assert_ptr_equal(ds.tracer.bvh.prim_ids, dg.bvh.prim_ids);
    assert_int_equal(ds.tracer.bvh.n_nodes, o.bvh->n_nodes);
    assert_memory_equal(dg.bvh.nodes, o.bvh->nodes, o.bvh->n_nodes * sizeof *o.bvh->nodes);
    assert_memory_equal(dg.bvh.prim_ids, o.bvh->prim_ids, o.bvh->n_prims * sizeof(uint32_t));

    rs_device_scene_release(&ds, &ops);
    rs_device_geom_release(&dg, &ops);
    assert_int_equal((int)r.made.n, 0);
    set_free(&r.made);
    observed_free(&o);
}

static void test_device_copy_bouncing_spheres(void **state)
{
    (void)state;
    check_device_copy("bouncing-spheres");
}

static void test_device_copy_every_array(void **state)
{
    (void)state;
    check_device_copy(NULL); /* textures, images, lights, moving sphere, UVs, normals */
    check_device_copy("cornell");
}

/* A copy failing at any step (geometry, BVH, scene, images, the scene's struct) releases every
 * block made before it, and the copy is left zeroed. */
static void test_device_copy_failure_releases(void **state)
{
    observed_scene o;
    rec_ops r;
    rs_mirror_ops ops = {rec_copy, rec_release, &r};
    rs_device_geom dg, zg;
    rs_device_scene ds, zs;
    int total, k;
    (void)state;
    observed_build(&o, NULL);
    memset(&r, 0, sizeof r);
    set_init(&r.made);
    memset(&zg, 0, sizeof zg);
    memset(&zs, 0, sizeof zs);
    assert_int_equal(rs_device_copy_geom(&o.geom, o.bvh, &ops, &dg), RS_OK);
    assert_int_equal(rs_device_copy_scene(o.scene, &dg, &ops, &ds), RS_OK);
    total = r.calls;
    rs_device_scene_release(&ds, &ops);
    rs_device_geom_release(&dg, &ops);
    assert_true(total >= 20);
    for (k = 1; k <= total; ++k) {
        rs_status st;
        r.calls = 0;
        r.fail_at = k;
        st = rs_device_copy_geom(&o.geom, o.bvh, &ops, &dg);
        if (st == RS_OK) {
            st = rs_device_copy_scene(o.scene, &dg, &ops, &ds);
            assert_int_equal(st, RS_ERR_CUDA);
            assert_memory_equal(&ds, &zs, sizeof ds);
            rs_device_geom_release(&dg, &ops);
        } else {
            assert_int_equal(st, RS_ERR_CUDA);
            assert_memory_equal(&dg, &zg, sizeof dg);
        }
        assert_int_equal((int)r.made.n, 0);
        rs_error_clear();
    }
    /* a scene that is not the uploaded geometry's is refused */
    r.fail_at = 0;
    assert_int_equal(rs_device_copy_geom(&o.geom, o.bvh, &ops, &dg), RS_OK);
    dg.geom.n_tris++;
    assert_int_equal(rs_device_copy_scene(o.scene, &dg, &ops, &ds), RS_ERR_ARG);
    dg.geom.n_tris--;
    rs_error_clear();
    rs_device_geom_release(&dg, &ops);
    assert_int_equal((int)r.made.n, 0);
    set_free(&r.made);
    observed_free(&o);
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_mirror_renders_alone),
                                       cmocka_unit_test(test_mirror_failure_releases),
                                       cmocka_unit_test(test_device_copy_bouncing_spheres),
                                       cmocka_unit_test(test_device_copy_every_array),
                                       cmocka_unit_test(test_device_copy_failure_releases)};
    return cmocka_run_group_tests(tests, NULL, NULL);
}
