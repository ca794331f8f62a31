/* scenes/scene_mirror.c — see rs_scene_mirror_create in scene.h. */
#include <string.h>

#include "core/alloc.h"
#include "scenes/scene.h"

/* Copies n elements of `size` bytes from src (NULL or n = 0: the copy is NULL) and lists the
 * block for release. */
static rs_status mirror_array(rs_scene_mirror *m, const rs_mirror_ops *ops, void **dst,
                              const void *src, size_t n, size_t size)
{
    rs_status st;
    *dst = NULL;
    if (!src || n == 0)
        return RS_OK;
    if (m->n_blocks == m->cap_blocks) {
        uint32_t cap = m->cap_blocks ? 2 * m->cap_blocks : 32;
        void **b = (void **)rs_alloc(cap, sizeof *b);
        if (!b)
            return rs_error_set(RS_ERR_NOMEM, "out of memory mirroring the scene");
        if (m->n_blocks)
            memcpy(b, m->blocks, m->n_blocks * sizeof *b);
        rs_free(m->blocks);
        m->blocks = b;
        m->cap_blocks = cap;
    }
    if ((st = ops->copy(ops->user, dst, src, n * size)) != RS_OK)
        return st;
    m->blocks[m->n_blocks++] = *dst;
    m->bytes += n * size;
    return RS_OK;
}

#define MIRROR(field, count)                                                                       \
  do {                                                                                             \
    void *p_;                                                                                      \
    if ((st = mirror_array(out, ops, &p_, s->field, (count), sizeof *s->field)) != RS_OK)          \
      goto fail;                                                                                   \
    d->field = p_;                                                                                 \
  } while (0)

rs_status rs_scene_mirror_create(const rs_scene *s, const rs_mirror_ops *ops, rs_scene_mirror *out)
{
    rs_scene *d = &out->scene;
    rs_image *images = NULL;
    size_t nprim = (size_t)s->n_spheres + s->n_quads + s->n_tris;
    rs_status st = RS_OK;
    uint32_t i;
    memset(out, 0, sizeof *out);
    if (!s->finalized)
        return rs_error_set(RS_ERR_ARG, "mirroring a scene that is not finalized");
    *d = *s; /* counts, camera, background; every pointer is replaced below */
    MIRROR(spheres, s->n_spheres);
    MIRROR(sphere_mat, s->n_spheres);
    MIRROR(sphere_motion, s->n_spheres);
    MIRROR(quads, s->n_quads);
    MIRROR(quad_mat, s->n_quads);
    MIRROR(tris, s->n_tris);
    MIRROR(tri_mat, s->n_tris);
    MIRROR(tri_uv, 6 * (size_t)s->n_tris);
    MIRROR(tri_normal, 9 * (size_t)s->n_tris);
    MIRROR(materials, s->n_materials);
    MIRROR(textures, s->n_textures);
    MIRROR(lights, s->n_lights);
    MIRROR(light_cdf, s->n_lights ? s->n_lights + 1 : 0);
    MIRROR(prim_light, nprim);
    /* the images' texels first, then the image array that points to those copies */
    d->images = NULL;
    if (s->n_images) {
        images = (rs_image *)rs_alloc(s->n_images, sizeof *images);
        if (!images) {
            st = rs_error_set(RS_ERR_NOMEM, "out of memory mirroring the scene");
            goto fail;
        }
        for (i = 0; i < s->n_images; ++i) {
            void *p;
            images[i] = s->images[i];
            if ((st = mirror_array(out, ops, &p, s->images[i].rgb,
                                   3 * (size_t)s->images[i].width * s->images[i].height,
                                   sizeof(float))) != RS_OK)
                goto fail;
            images[i].rgb = (float *)p;
        }
        {
            void *p;
            if ((st = mirror_array(out, ops, &p, images, s->n_images, sizeof *images)) != RS_OK)
                goto fail;
            d->images = (rs_image *)p;
        }
    }
    d->cap_spheres = d->n_spheres;
    d->cap_quads = d->n_quads;
    d->cap_tris = d->n_tris;
    d->cap_motion = d->sphere_motion ? d->n_spheres : 0;
    d->cap_uv = d->tri_uv ? d->n_tris : 0;
    d->cap_normal = d->tri_normal ? d->n_tris : 0;
    d->cap_materials = d->n_materials;
    d->cap_textures = d->n_textures;
    d->cap_images = d->n_images;
    rs_free(images);
    return RS_OK;
fail:
    rs_free(images);
    rs_scene_mirror_release(out, ops);
    return st;
}

void rs_scene_mirror_release(rs_scene_mirror *m, const rs_mirror_ops *ops)
{
    uint32_t i;
    for (i = 0; i < m->n_blocks; ++i)
        ops->release(ops->user, m->blocks[i]);
    rs_free(m->blocks);
    memset(m, 0, sizeof *m);
}
