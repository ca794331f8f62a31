/* scenes/scene_mirror.c — the deep copy of a scene through copy callbacks (see
 * rs_scene_mirror_create in scene.h).
 *
 * Invariants: every block ops->copy makes is listed in `made` before the next copy starts, so a
 * failure at any step releases exactly what was made; the mirror's struct starts as a copy of
 * the original's and every pointer in it is then replaced (RS_SCENE_ARRAYS, then the images). */
#include <string.h>

#include "core/alloc.h"
#include "scenes/scene.h"

rs_status rs_mirror_copy(rs_mirror_blocks *made, const rs_mirror_ops *ops, void **dst,
                         const void *src, size_t n, size_t size)
{
    size_t bytes;
    rs_status st;
    *dst = NULL;
    if (!src || n == 0)
        return RS_OK;
    if (!rs_mul_size(n, size, &bytes))
        return rs_error_set(RS_ERR_NOMEM, "a copy of %zu x %zu bytes overflows", n, size);
    /* room in the list first: a block made is always listed */
    if (made->n_blocks == made->cap_blocks) {
        uint32_t cap = made->cap_blocks ? 2 * made->cap_blocks : 32;
        void **b = (void **)rs_alloc(cap, sizeof *b);
        if (!b)
            return rs_error_set(RS_ERR_NOMEM, "out of memory listing the blocks of a copy");
        if (made->n_blocks)
            memcpy(b, made->blocks, made->n_blocks * sizeof *b);
        rs_free(made->blocks);
        made->blocks = b;
        made->cap_blocks = cap;
    }
    if ((st = ops->copy(ops->user, dst, src, bytes)) != RS_OK) {
        *dst = NULL;
        return st;
    }
    made->blocks[made->n_blocks++] = *dst;
    made->bytes += bytes;
    return RS_OK;
}

void rs_mirror_blocks_release(rs_mirror_blocks *made, const rs_mirror_ops *ops)
{
    uint32_t i;
    for (i = 0; i < made->n_blocks; ++i)
        ops->release(ops->user, made->blocks[i]);
    rs_free(made->blocks);
    memset(made, 0, sizeof *made);
}

/* The texels of every image, then the image array pointing to those copies. */
static rs_status mirror_images(const rs_scene *s, const rs_mirror_ops *ops, rs_scene_mirror *out)
{
    rs_image *images;
    rs_status st = RS_OK;
    uint32_t i;
    void *p;
    out->scene.images = NULL;
    if (s->n_images == 0 || !s->images)
        return RS_OK;
    images = (rs_image *)rs_alloc(s->n_images, sizeof *images);
    if (!images)
        return rs_error_set(RS_ERR_NOMEM, "out of memory mirroring the scene's images");
    for (i = 0; i < s->n_images && st == RS_OK; ++i) {
        images[i] = s->images[i];
        /* every mip level: they follow level 0 in the one block */
        st = rs_mirror_copy(&out->made, ops, &p, s->images[i].rgb,
                            rs_image_levels_floats(s->images[i].width, s->images[i].height,
                                                   s->images[i].levels ? s->images[i].levels : 1),
                            sizeof(float));
        images[i].rgb = (float *)p;
    }
    if (st == RS_OK &&
        (st = rs_mirror_copy(&out->made, ops, &p, images, s->n_images, sizeof *images)) == RS_OK)
        out->scene.images = (rs_image *)p;
    rs_free(images);
    return st;
}

rs_status rs_scene_mirror_create(const rs_scene *s, const rs_mirror_ops *ops, rs_scene_mirror *out)
{
    rs_scene *d = &out->scene;
    rs_status st = RS_OK;
    void *p;
    memset(out, 0, sizeof *out);
    if (!s->finalized)
        return rs_error_set(RS_ERR_ARG, "mirroring a scene that is not finalized");
    *d = *s; /* counts, camera, background; every pointer is replaced below */
#define RS_MIRROR_ARRAY(field, count)                                                              \
  if (st == RS_OK) {                                                                               \
    st = rs_mirror_copy(&out->made, ops, &p, s->field, (count), sizeof *s->field);                 \
    d->field = p;                                                                                  \
  }
    RS_SCENE_ARRAYS(RS_MIRROR_ARRAY, s)
#undef RS_MIRROR_ARRAY
    if (st == RS_OK)
        st = mirror_images(s, ops, out);
    if (st != RS_OK) {
        rs_scene_mirror_release(out, ops);
        return st;
    }
    /* the copies hold exactly their elements */
    d->cap_spheres = d->n_spheres;
    d->cap_quads = d->n_quads;
    d->cap_tris = d->n_tris;
    d->cap_motion = d->sphere_motion ? d->n_spheres : 0;
    d->cap_uv = d->tri_uv ? d->n_tris : 0;
    d->cap_normal = d->tri_normal ? d->n_tris : 0;
    d->cap_inst_tris = d->n_inst_tris;
    d->cap_inst_uv = d->inst_tri_uv ? d->n_inst_tris : 0;
    d->cap_inst_normal = d->inst_tri_normal ? d->n_inst_tris : 0;
    d->cap_instances = d->n_instances;
    d->cap_masks = d->n_masks;
    d->cap_mask_bits = d->n_mask_bits;
    d->cap_materials = d->n_materials;
    d->cap_textures = d->n_textures;
    d->cap_images = d->n_images;
    return RS_OK;
}

void rs_scene_mirror_release(rs_scene_mirror *m, const rs_mirror_ops *ops)
{
    rs_mirror_blocks_release(&m->made, ops);
    memset(m, 0, sizeof *m);
}
