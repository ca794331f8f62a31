/* scheduler/device_copy.c — see device_copy.h.  Each copy starts from a struct copy of the
 * original (counts, shutter, algorithms) and replaces every array the lists name; the lists are
 * the only place that knows which fields are arrays. */
#include "scheduler/device_copy.h"

#include <stddef.h>
#include <string.h>

#include "core/alloc.h"

static rs_status host_copy(void *user, void **dst, const void *src, size_t bytes)
{
    (void)user;
    *dst = rs_alloc_aligned(bytes, 1);
    if (!*dst)
        return rs_error_set(RS_ERR_NOMEM, "out of memory copying %zu bytes for a device", bytes);
    memcpy(*dst, src, bytes);
    return RS_OK;
}

static void host_release(void *user, void *p)
{
    (void)user;
    rs_free(p);
}

const rs_mirror_ops rs_device_copy_host_ops = {host_copy, host_release, NULL};

rs_status rs_device_copy_geom(const rs_geom *g, const rs_bvh *bvh, const rs_mirror_ops *ops,
                              rs_device_geom *out)
{
    rs_status st = RS_OK;
    void *p;
    memset(out, 0, sizeof *out);
    out->geom = *g;
    out->bvh = rs_bvh_view_of(bvh);
/* One array of `src` copied into `dst` (the field of the same name), listed in out->made. */
#define RS_COPY_FROM(src, dst, field, count)                                                       \
  if (st == RS_OK) {                                                                               \
    st = rs_mirror_copy(&out->made, ops, &p, (src)->field, (count), sizeof *(src)->field);         \
    (dst).field = p;                                                                               \
  }
#define RS_COPY_GEOM(field, count) RS_COPY_FROM(g, out->geom, field, count)
#define RS_COPY_BVH(field, count)  RS_COPY_FROM(bvh, out->bvh, field, count)
    RS_GEOM_ARRAYS(RS_COPY_GEOM, g)
    RS_BVH_ARRAYS(RS_COPY_BVH, bvh)
#undef RS_COPY_BVH
#undef RS_COPY_GEOM
#undef RS_COPY_FROM
    if (st != RS_OK)
        rs_device_geom_release(out, ops);
    return st;
}

void rs_device_geom_release(rs_device_geom *c, const rs_mirror_ops *ops)
{
    rs_mirror_blocks_release(&c->made, ops);
    memset(c, 0, sizeof *c);
}

/* The structs a device receives by value (the CUDA kernel's arguments, the fallback's copies)
 * are exactly their device fields, listed here in order: each starts where the one before it
 * ends, up to padding too small to hold a pointer, and the struct ends with the last.  A field
 * added to one of them (a host pointer, say) fails to compile until it is listed here, and so
 * looked at.  The pointers they hold are the copy's (rs_path_tracer: tests/scenes_mirror_test.c
 * scans every word) or, for rs_render_consts.scene, set by each device to its mirror. */
#define RS_FIRST_FIELD(T, a) _Static_assert(offsetof(T, a) == 0, #T " starts with " #a)
#define RS_NEXT_FIELD(T, a, b)                                                                     \
  _Static_assert(offsetof(T, b) - (offsetof(T, a) + sizeof(((T *)0)->a)) < sizeof(void *),         \
                 #T ": " #b " right after " #a)
#define RS_LAST_FIELD(T, a)                                                                        \
  _Static_assert(sizeof(T) - (offsetof(T, a) + sizeof(((T *)0)->a)) < sizeof(void *),              \
                 #T " ends with " #a)
RS_FIRST_FIELD(rs_render_consts, scene);
RS_NEXT_FIELD(rs_render_consts, scene, camera);
RS_NEXT_FIELD(rs_render_consts, camera, seed);
RS_NEXT_FIELD(rs_render_consts, seed, width);
RS_NEXT_FIELD(rs_render_consts, width, height);
RS_NEXT_FIELD(rs_render_consts, height, npix);
RS_NEXT_FIELD(rs_render_consts, npix, spp);
RS_NEXT_FIELD(rs_render_consts, spp, max_depth);
RS_NEXT_FIELD(rs_render_consts, max_depth, rr_depth);
RS_NEXT_FIELD(rs_render_consts, rr_depth, sampling);
RS_NEXT_FIELD(rs_render_consts, sampling, sampler);
RS_NEXT_FIELD(rs_render_consts, sampler, filter);
RS_NEXT_FIELD(rs_render_consts, filter, tex_spread);
RS_NEXT_FIELD(rs_render_consts, tex_spread, light_sampler);
RS_LAST_FIELD(rs_render_consts, light_sampler);
RS_FIRST_FIELD(rs_path_tracer, bvh);
RS_NEXT_FIELD(rs_path_tracer, bvh, geom);
RS_LAST_FIELD(rs_path_tracer, geom);

rs_status rs_device_copy_scene(const rs_scene *s, const rs_device_geom *geom,
                               const rs_mirror_ops *ops, rs_device_scene *out)
{
    rs_geom sg;
    rs_status st;
    void *p;
    memset(out, 0, sizeof *out);
    if (geom->geom.n_spheres != s->n_spheres || geom->geom.n_quads != s->n_quads ||
        geom->geom.n_tris != s->n_tris || geom->geom.n_instances != s->n_instances ||
        geom->geom.n_inst_tris != s->n_inst_tris)
        return rs_error_set(RS_ERR_ARG,
                            "the device's geometry (%u spheres, %u quads, %u triangles) is not the "
                            "scene's (%u, %u, %u)",
                            geom->geom.n_spheres, geom->geom.n_quads, geom->geom.n_tris,
                            s->n_spheres, s->n_quads, s->n_tris);
    if ((st = rs_scene_mirror_create(s, ops, &out->mirror)) != RS_OK)
        return st;
    if ((st = rs_mirror_copy(&out->mirror.made, ops, &p, &out->mirror.scene, 1,
                             sizeof out->mirror.scene)) != RS_OK) {
        rs_device_scene_release(out, ops);
        return st;
    }
    out->scene = (const rs_scene *)p;
    /* the uploaded geometry's values (algorithms, shutter), the mirror's arrays */
    sg = rs_scene_geom(&out->mirror.scene);
    out->tracer.geom = geom->geom;
#define RS_TAKE_ARRAY(field, count) out->tracer.geom.field = sg.field;
    RS_GEOM_ARRAYS(RS_TAKE_ARRAY, &sg)
#undef RS_TAKE_ARRAY
    /* but the instance table with its roots and the bottom levels are the BVH's (rs_bvh_attach),
     * which the uploaded copy holds */
    out->tracer.geom.instances = geom->geom.instances;
    out->tracer.geom.blas_nodes = geom->geom.blas_nodes;
    out->tracer.geom.blas_prim_ids = geom->geom.blas_prim_ids;
    out->tracer.bvh = geom->bvh;
    return RS_OK;
}

void rs_device_scene_release(rs_device_scene *c, const rs_mirror_ops *ops)
{
    rs_scene_mirror_release(&c->mirror, ops);
    memset(c, 0, sizeof *c);
}
