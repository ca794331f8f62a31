/* scenes/scene.c — see scene.h. */
#include "scenes/scene.h"

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/image_io.h"

/* Grows *arr (of element size `size`) to hold at least `need` elements. */
static int grow(void **arr, uint32_t *cap, uint32_t need, size_t size)
{
    uint32_t n;
    void *p;
    if (need <= *cap)
        return 1;
    n = *cap ? *cap : 16;
    while (n < need) {
        if (n > UINT32_MAX / 2)
            return 0;
        n *= 2;
    }
    p = rs_alloc(n, size);
    if (!p)
        return 0;
    if (*arr)
        memcpy(p, *arr, (size_t)*cap * size);
    rs_free(*arr);
    *arr = p;
    *cap = n;
    return 1;
}

/* Grows a primitive array and its parallel material array together. */
static rs_status grow_prims(void **prims, uint32_t **mats, uint32_t *cap, uint32_t need,
                            size_t size)
{
    uint32_t cap_p = *cap, cap_m = *cap;
    if (!grow(prims, &cap_p, need, size) || !grow((void **)mats, &cap_m, need, sizeof **mats))
        return rs_error_set(RS_ERR_NOMEM, "out of memory adding primitives");
    /* both grow by the same doubling rule from the same start, so the capacities agree */
    *cap = cap_p < cap_m ? cap_p : cap_m;
    return RS_OK;
}

rs_status rs_scene_create(const char *name, rs_scene **out)
{
    rs_scene *s = (rs_scene *)rs_calloc(1, sizeof *s);
    *out = NULL;
    if (!s)
        return rs_error_set(RS_ERR_NOMEM, "out of memory creating a scene");
    snprintf(s->name, sizeof s->name, "%s", name ? name : "scene");
    s->camera.from = rs_v3(0, 0, 1);
    s->camera.at = rs_v3(0, 0, 0);
    s->camera.up = rs_v3(0, 1, 0);
    s->camera.vfov_deg = 40.0f;
    s->width = s->height = 512;
    s->env_image = RS_NO_TEXTURE;
    *out = s;
    return RS_OK;
}

void rs_scene_destroy(rs_scene *s)
{
    if (!s)
        return;
    rs_free(s->spheres);
    rs_free(s->sphere_mat);
    rs_free(s->quads);
    rs_free(s->quad_mat);
    rs_free(s->tris);
    rs_free(s->tri_mat);
    rs_free(s->sphere_motion);
    rs_free(s->tri_uv);
    rs_free(s->tri_normal);
    rs_free(s->materials);
    rs_free(s->textures);
    if (s->images) {
        uint32_t i;
        for (i = 0; i < s->n_images; ++i)
            rs_free(s->images[i].rgb);
    }
    rs_free(s->images);
    rs_free(s->lights);
    rs_free(s->light_cdf);
    rs_free(s->prim_light);
    rs_free(s->light_nodes);
    rs_free(s->light_trail);
    rs_free(s->env_marg_cdf);
    rs_free(s->env_cond_cdf);
    rs_free(s->punctuals);
    rs_free(s->inst_tris);
    rs_free(s->inst_tri_mat);
    rs_free(s->inst_tri_uv);
    rs_free(s->inst_tri_normal);
    rs_free(s->instances);
    rs_free(s->masks);
    rs_free(s->mask_bits);
    rs_free(s->tri_mask);
    rs_free(s);
}

rs_status rs_scene_add_punctual(rs_scene *s, const rs_punctual *p)
{
    rs_punctual q = *p;
    if (q.type > RS_PUNCTUAL_DIRECTIONAL || !(q.intensity.x >= 0 && q.intensity.y >= 0 &&
                                              q.intensity.z >= 0) ||
        !isfinite(q.intensity.x + q.intensity.y + q.intensity.z) ||
        !isfinite(q.pos.x + q.pos.y + q.pos.z) || !isfinite(q.dir.x + q.dir.y + q.dir.z))
        return rs_error_set(RS_ERR_ARG, "a light needs a finite position, direction and an "
                                        "intensity >= 0");
    if (q.type != RS_PUNCTUAL_POINT) {
        if (rs_v3_is_zero(q.dir))
            return rs_error_set(RS_ERR_ARG, "a spot or directional light needs a direction");
        q.dir = rs_v3_normalize(q.dir);
    }
    if (q.type == RS_PUNCTUAL_SPOT &&
        !(q.cos_outer >= 0.0f && q.cos_outer <= q.cos_inner && q.cos_inner <= 1.0f))
        return rs_error_set(RS_ERR_ARG, "a spot light's cones need 0 <= inner <= outer <= 90 "
                                        "degrees");
    if (!grow((void **)&s->punctuals, &s->cap_punctuals, s->n_punctuals + 1, sizeof q))
        return rs_error_set(RS_ERR_NOMEM, "out of memory adding a light");
    s->punctuals[s->n_punctuals++] = q;
    s->finalized = 0;
    return RS_OK;
}

rs_status rs_scene_add_material(rs_scene *s, const rs_material *m, uint32_t *id)
{
    const uint32_t tex[4] = {m->albedo_tex, m->mr_tex, m->emission_tex, m->normal_tex};
    int k;
    for (k = 0; k < 4; ++k)
        if (tex[k] != RS_NO_TEXTURE && tex[k] >= s->n_textures)
            return rs_error_set(RS_ERR_ARG, "material names texture %u (scene has %u)", tex[k],
                                s->n_textures);
    if (!grow((void **)&s->materials, &s->cap_materials, s->n_materials + 1, sizeof *m))
        return rs_error_set(RS_ERR_NOMEM, "out of memory adding a material");
    s->materials[s->n_materials] = *m;
    *id = s->n_materials++;
    return RS_OK;
}

static rs_status check_mat(const rs_scene *s, uint32_t mat)
{
    if (mat >= s->n_materials)
        return rs_error_set(RS_ERR_ARG, "material id %u out of range (scene has %u)", mat,
                            s->n_materials);
    return RS_OK;
}

rs_status rs_scene_add_sphere(rs_scene *s, rs_vec3 center, float radius, uint32_t mat)
{
    rs_status st = check_mat(s, mat);
    if (st == RS_OK)
        st = grow_prims((void **)&s->spheres, &s->sphere_mat, &s->cap_spheres, s->n_spheres + 1,
                        sizeof *s->spheres);
    if (st != RS_OK)
        return st;
    if (s->sphere_motion) {
        if (!grow((void **)&s->sphere_motion, &s->cap_motion, s->n_spheres + 1,
                  sizeof *s->sphere_motion))
            return rs_error_set(RS_ERR_NOMEM, "out of memory adding a sphere");
        s->sphere_motion[s->n_spheres] = rs_v3_splat(0.0f);
    }
    s->spheres[s->n_spheres].center = center;
    s->spheres[s->n_spheres].radius = radius;
    s->sphere_mat[s->n_spheres++] = mat;
    s->finalized = 0;
    return RS_OK;
}

rs_status rs_scene_add_moving_sphere(rs_scene *s, rs_vec3 c0, float t0, rs_vec3 c1, float t1,
                                     float radius, uint32_t mat)
{
    rs_vec3 v;
    rs_status st;
    if (!(t1 != t0))
        return rs_error_set(RS_ERR_ARG, "moving sphere: the two times must differ");
    v = rs_v3_scale(rs_v3_sub(c1, c0), 1.0f / (t1 - t0));
    if (!s->sphere_motion) {
        uint32_t i;
        if (!grow((void **)&s->sphere_motion, &s->cap_motion, s->n_spheres + 1,
                  sizeof *s->sphere_motion))
            return rs_error_set(RS_ERR_NOMEM, "out of memory adding a moving sphere");
        for (i = 0; i < s->n_spheres; ++i)
            s->sphere_motion[i] = rs_v3_splat(0.0f);
    }
    /* stored as the centre at time 0 plus a velocity */
    st = rs_scene_add_sphere(s, rs_v3_madd(c0, v, -t0), radius, mat);
    if (st == RS_OK)
        s->sphere_motion[s->n_spheres - 1] = v;
    return st;
}

rs_status rs_scene_add_sphere_velocity(rs_scene *s, rs_vec3 center, rs_vec3 velocity,
                                       float radius, uint32_t mat)
{
    rs_status st = rs_scene_add_moving_sphere(s, center, 0.0f, rs_v3_add(center, velocity), 1.0f,
                                              radius, mat);
    if (st == RS_OK)
        s->sphere_motion[s->n_spheres - 1] = velocity; /* exactly, not as c1 - c0 rounds it */
    return st;
}

void rs_scene_set_camera(rs_scene *s, const rs_camera_desc *camera) { s->camera = *camera; }

void rs_scene_set_image_size(rs_scene *s, uint32_t width, uint32_t height)
{
    s->width = width;
    s->height = height;
}

void rs_scene_set_background(rs_scene *s, rs_vec3 color)
{
    s->background = color;
    s->background_sky = 0;
}

void rs_scene_set_background_gradient(rs_scene *s, rs_vec3 horizon, rs_vec3 zenith)
{
    s->background = horizon;
    s->background_top = zenith;
    s->background_sky = 1;
}

rs_status rs_scene_scale_image(rs_scene *s, uint32_t image, rs_vec3 factor)
{
    rs_image *im;
    size_t i, n;
    if (image >= s->n_images)
        return rs_error_set(RS_ERR_ARG, "no image %u to scale", image);
    im = &s->images[image];
    n = (size_t)im->width * im->height;
    for (i = 0; i < n; ++i) {
        im->rgb[3 * i] *= factor.x;
        im->rgb[3 * i + 1] *= factor.y;
        im->rgb[3 * i + 2] *= factor.z;
    }
    return RS_OK;
}

rs_status rs_scene_add_quad(rs_scene *s, rs_vec3 q, rs_vec3 u, rs_vec3 v, uint32_t mat)
{
    rs_status st = check_mat(s, mat);
    if (st == RS_OK)
        st = grow_prims((void **)&s->quads, &s->quad_mat, &s->cap_quads, s->n_quads + 1,
                        sizeof *s->quads);
    if (st != RS_OK)
        return st;
    s->quads[s->n_quads] = rs_quad_make(q, u, v);
    s->quad_mat[s->n_quads++] = mat;
    s->finalized = 0;
    return RS_OK;
}

rs_status rs_scene_add_triangle(rs_scene *s, rs_vec3 v0, rs_vec3 v1, rs_vec3 v2, uint32_t mat)
{
    rs_status st = check_mat(s, mat);
    if (st == RS_OK)
        st = grow_prims((void **)&s->tris, &s->tri_mat, &s->cap_tris, s->n_tris + 1,
                        sizeof *s->tris);
    if (st != RS_OK)
        return st;
    if (s->tri_uv) {
        static const float def[6] = {0, 0, 1, 0, 0, 1};
        if (!grow((void **)&s->tri_uv, &s->cap_uv, s->n_tris + 1, 6 * sizeof *s->tri_uv))
            return rs_error_set(RS_ERR_NOMEM, "out of memory adding a triangle");
        memcpy(&s->tri_uv[6 * (size_t)s->n_tris], def, sizeof def);
    }
    if (s->tri_normal) {
        if (!grow((void **)&s->tri_normal, &s->cap_normal, s->n_tris + 1,
                  9 * sizeof *s->tri_normal))
            return rs_error_set(RS_ERR_NOMEM, "out of memory adding a triangle");
        memset(&s->tri_normal[9 * (size_t)s->n_tris], 0, 9 * sizeof *s->tri_normal);
    }
    s->tris[s->n_tris].v0 = v0;
    s->tris[s->n_tris].v1 = v1;
    s->tris[s->n_tris].v2 = v2;
    s->tri_mat[s->n_tris++] = mat;
    s->finalized = 0;
    return RS_OK;
}

rs_status rs_scene_add_triangle_uv(rs_scene *s, rs_vec3 v0, rs_vec3 v1, rs_vec3 v2,
                                   const float uv[6], uint32_t mat)
{
    rs_status st;
    if (!s->tri_uv) {
        static const float def[6] = {0, 0, 1, 0, 0, 1};
        uint32_t i;
        if (!grow((void **)&s->tri_uv, &s->cap_uv, s->n_tris + 1, 6 * sizeof *s->tri_uv))
            return rs_error_set(RS_ERR_NOMEM, "out of memory adding a triangle");
        for (i = 0; i < s->n_tris; ++i)
            memcpy(&s->tri_uv[6 * (size_t)i], def, sizeof def);
    }
    st = rs_scene_add_triangle(s, v0, v1, v2, mat);
    if (st == RS_OK)
        memcpy(&s->tri_uv[6 * (size_t)(s->n_tris - 1)], uv, 6 * sizeof *uv);
    return st;
}

rs_status rs_scene_add_triangle_full(rs_scene *s, const rs_vec3 v[3], const float *uv,
                                     const float *normals, uint32_t mat)
{
    rs_status st;
    if (normals && !s->tri_normal) {
        if (!grow((void **)&s->tri_normal, &s->cap_normal, s->n_tris + 1,
                  9 * sizeof *s->tri_normal))
            return rs_error_set(RS_ERR_NOMEM, "out of memory adding a triangle");
        /* earlier triangles: zero normals mean "use the face normal" */
        memset(s->tri_normal, 0, 9 * sizeof *s->tri_normal * (size_t)s->n_tris);
    }
    st = uv ? rs_scene_add_triangle_uv(s, v[0], v[1], v[2], uv, mat)
            : rs_scene_add_triangle(s, v[0], v[1], v[2], mat);
    if (st == RS_OK && normals)
        memcpy(&s->tri_normal[9 * (size_t)(s->n_tris - 1)], normals, 9 * sizeof *normals);
    return st;
}

rs_status rs_scene_add_mask(rs_scene *s, uint32_t width, uint32_t height, const float *alpha,
                            float scale, float cutoff, uint32_t *id)
{
    uint64_t n = alpha ? (uint64_t)width * height : 1, i;
    rs_alpha_mask m;
    if (!alpha)
        width = height = 1;
    if (width == 0 || height == 0 || n > RS_IMAGE_MAX_PIXELS ||
        (uint64_t)s->n_mask_bits + n > 0xffffffffu)
        return rs_error_set(RS_ERR_ARG, "an alpha mask of %ux%u texels", width, height);
    if (!grow((void **)&s->mask_bits, &s->cap_mask_bits, s->n_mask_bits + (uint32_t)n, 1) ||
        !grow((void **)&s->masks, &s->cap_masks, s->n_masks + 1, sizeof m))
        return rs_error_set(RS_ERR_NOMEM, "out of memory adding an alpha mask");
    for (i = 0; i < n; ++i)
        s->mask_bits[s->n_mask_bits + i] = (alpha ? alpha[i] * scale : scale) >= cutoff;
    m.width = width;
    m.height = height;
    m.offset = s->n_mask_bits;
    s->masks[s->n_masks++] = m;
    s->n_mask_bits += (uint32_t)n;
    *id = s->n_masks;
    s->finalized = 0;
    return RS_OK;
}

rs_status rs_scene_add_texture(rs_scene *s, const rs_texture *t, uint32_t *id)
{
    if (t->type == RS_TEX_IMAGE && t->image >= s->n_images)
        return rs_error_set(RS_ERR_ARG, "texture names image %u (scene has %u)", t->image,
                            s->n_images);
    if (!grow((void **)&s->textures, &s->cap_textures, s->n_textures + 1, sizeof *t))
        return rs_error_set(RS_ERR_NOMEM, "out of memory adding a texture");
    s->textures[s->n_textures] = *t;
    *id = s->n_textures++;
    return RS_OK;
}

/* Every texel finite and >= 0 (radiance or reflectance): a NaN texel spread through the mip
 * pyramid into every coarser level, a negative one made negative pixels (issue 39).  `what`
 * names the image in the message (the file, or "an image"). */
static rs_status check_texels(const char *what, uint32_t w, const float *rgb, size_t n)
{
    size_t i;
    for (i = 0; i < n; ++i)
        if (!(rgb[i] >= 0.0f && rgb[i] <= FLT_MAX))
            return rs_error_set(RS_ERR_ARG,
                                "%s: texel (%u, %u) is %s (an image's texels must be finite and "
                                ">= 0)",
                                what, (unsigned)((i / 3) % w), (unsigned)((i / 3) / w),
                                isnan(rgb[i])   ? "not finite (NaN)"
                                : isinf(rgb[i]) ? "not finite (infinite)"
                                                : "negative");
    return RS_OK;
}

static rs_status add_image_owned(rs_scene *s, uint32_t w, uint32_t h, float *rgb, uint32_t *id)
{
    if (check_texels("an image", w, rgb, (size_t)w * h * 3) != RS_OK) {
        rs_free(rgb);
        return RS_ERR_ARG;
    }
    if (!grow((void **)&s->images, &s->cap_images, s->n_images + 1, sizeof *s->images)) {
        rs_free(rgb);
        return rs_error_set(RS_ERR_NOMEM, "out of memory adding an image");
    }
    s->images[s->n_images].width = w;
    s->images[s->n_images].height = h;
    s->images[s->n_images].rgb = rgb;
    s->images[s->n_images].levels = 1;
    *id = s->n_images++;
    return RS_OK;
}

rs_status rs_scene_add_image(rs_scene *s, uint32_t width, uint32_t height, const float *rgb,
                             uint32_t *id)
{
    size_t n;
    float *copy;
    if (width == 0 || height == 0 || !rs_mul_size((size_t)width * height, 3, &n))
        return rs_error_set(RS_ERR_ARG, "bad image size %ux%u", width, height);
    copy = (float *)rs_alloc(n, sizeof *copy);
    if (!copy)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for a %ux%u image", width, height);
    memcpy(copy, rgb, n * sizeof *copy);
    return add_image_owned(s, width, height, copy, id);
}

rs_status rs_scene_load_image(rs_scene *s, const char *path, uint32_t *id)
{
    uint32_t w, h;
    float *rgb;
    rs_status st = rs_image_read_linear(path, &w, &h, &rgb);
    if (st != RS_OK)
        return st;
    if ((st = check_texels(path, w, rgb, (size_t)w * h * 3)) != RS_OK) {
        rs_free(rgb);
        return st;
    }
    return add_image_owned(s, w, h, rgb, id);
}

rs_status rs_scene_load_image_data(rs_scene *s, const char *path, uint32_t *id)
{
    uint32_t w, h;
    float *rgb;
    rs_status st = rs_image_read(path, &w, &h, &rgb);
    if (st != RS_OK)
        return st;
    if ((st = check_texels(path, w, rgb, (size_t)w * h * 3)) != RS_OK) {
        rs_free(rgb);
        return st;
    }
    return add_image_owned(s, w, h, rgb, id);
}

rs_status rs_scene_add_box(rs_scene *s, rs_vec3 lo, rs_vec3 hi, float rot_y_deg, rs_vec3 offset,
                           uint32_t mat)
{
    rs_vec3 dx = rs_v3(hi.x - lo.x, 0, 0), dy = rs_v3(0, hi.y - lo.y, 0);
    rs_vec3 dz = rs_v3(0, 0, hi.z - lo.z);
    /* the six faces of RTNW v4's box(), each with its normal pointing out */
    rs_vec3 q[6], u[6], v[6];
    int i;
    q[0] = rs_v3(lo.x, lo.y, hi.z), u[0] = dx, v[0] = dy;            /* front  +z */
    q[1] = rs_v3(hi.x, lo.y, hi.z), u[1] = rs_v3_neg(dz), v[1] = dy; /* right  +x */
    q[2] = rs_v3(hi.x, lo.y, lo.z), u[2] = rs_v3_neg(dx), v[2] = dy; /* back   -z */
    q[3] = rs_v3(lo.x, lo.y, lo.z), u[3] = dz, v[3] = dy;            /* left   -x */
    q[4] = rs_v3(lo.x, hi.y, hi.z), u[4] = dx, v[4] = rs_v3_neg(dz); /* top    +y */
    q[5] = rs_v3(lo.x, lo.y, lo.z), u[5] = dx, v[5] = dz;            /* bottom -y */
    for (i = 0; i < 6; ++i) {
        rs_vec3 qq = rs_v3_add(rs_v3_rotate_y(q[i], rot_y_deg), offset);
        rs_status st = rs_scene_add_quad(s, qq, rs_v3_rotate_y(u[i], rot_y_deg),
                                         rs_v3_rotate_y(v[i], rot_y_deg), mat);
        if (st != RS_OK)
            return st;
    }
    return RS_OK;
}

rs_status rs_scene_make_prototype(rs_scene *s, uint32_t from, uint32_t *first, uint32_t *count)
{
    uint32_t n = from < s->n_tris ? s->n_tris - from : 0, base = s->n_inst_tris, i;
    *first = base;
    *count = n;
    if (n == 0)
        return RS_OK;
    if (grow_prims((void **)&s->inst_tris, &s->inst_tri_mat, &s->cap_inst_tris, base + n,
                   sizeof *s->inst_tris) != RS_OK)
        return RS_ERR_NOMEM;
    memcpy(&s->inst_tris[base], &s->tris[from], (size_t)n * sizeof *s->tris);
    memcpy(&s->inst_tri_mat[base], &s->tri_mat[from], (size_t)n * sizeof *s->tri_mat);
    /* UVs and normals as the scene's own arrays hold them: once any triangle has them, every
     * prototype triangle gets a row (the defaults (0,0), (1,0), (0,1) and zero normals where it
     * had none) */
    if (s->tri_uv || s->inst_tri_uv) {
        static const float def[6] = {0, 0, 1, 0, 0, 1};
        int had = s->inst_tri_uv != NULL;
        if (!grow((void **)&s->inst_tri_uv, &s->cap_inst_uv, base + n, 6 * sizeof(float)))
            return rs_error_set(RS_ERR_NOMEM, "out of memory making a prototype");
        for (i = had ? base : 0; i < base + n; ++i)
            if (i < base || !s->tri_uv)
                memcpy(&s->inst_tri_uv[6 * (size_t)i], def, sizeof def);
            else
                memcpy(&s->inst_tri_uv[6 * (size_t)i], &s->tri_uv[6 * (size_t)(from + i - base)],
                       sizeof def);
    }
    if (s->tri_normal || s->inst_tri_normal) {
        int had = s->inst_tri_normal != NULL;
        if (!grow((void **)&s->inst_tri_normal, &s->cap_inst_normal, base + n, 9 * sizeof(float)))
            return rs_error_set(RS_ERR_NOMEM, "out of memory making a prototype");
        for (i = had ? base : 0; i < base + n; ++i)
            if (i < base || !s->tri_normal)
                memset(&s->inst_tri_normal[9 * (size_t)i], 0, 9 * sizeof(float));
            else
                memcpy(&s->inst_tri_normal[9 * (size_t)i],
                       &s->tri_normal[9 * (size_t)(from + i - base)], 9 * sizeof(float));
    }
    s->n_inst_tris += n;
    s->n_tris = from; /* the triangles now belong to the prototype */
    s->finalized = 0;
    return RS_OK;
}

rs_status rs_scene_push_instance(rs_scene *s, const rs_instance *in)
{
    if (!grow((void **)&s->instances, &s->cap_instances, s->n_instances + 1, sizeof *in))
        return rs_error_set(RS_ERR_NOMEM, "out of memory adding an instance");
    s->instances[s->n_instances++] = *in;
    s->n_inst_prims += in->n_tris;
    s->finalized = 0;
    return RS_OK;
}

rs_status rs_scene_flatten_instances(rs_scene *s)
{
    uint64_t total = rs_scene_prim_count(s);
    uint32_t i, k;
    for (i = 0; i < s->n_instances; ++i)
        total += s->instances[i].n_tris;
    if (total > RS_SCENE_MAX_COPIED_PRIMS) /* checked before a single copy is made */
        return rs_error_set(RS_ERR_ARG,
                            "flattening %u instances would make %llu primitives, more than "
                            "2^24 (leave them instanced)",
                            s->n_instances, (unsigned long long)total);
    for (i = 0; i < s->n_instances; ++i) {
        const rs_instance *in = &s->instances[i];
        for (k = in->first_tri; k < in->first_tri + in->n_tris; ++k) {
            float uvt[6], vnt[9];
            rs_tri w = rs_instance_tri(in, &s->inst_tris[k]);
            rs_vec3 v[3];
            const float *uv = s->inst_tri_uv ? rs_instance_tri_uv(s, in, k, uvt) : NULL;
            const float *vn = rs_instance_tri_normals(s, in, k, vnt);
            rs_status st;
            v[0] = w.v0;
            v[1] = w.v1;
            v[2] = w.v2;
            if ((st = rs_scene_add_triangle_full(s, v, uv, vn, s->inst_tri_mat[k])) != RS_OK)
                return st;
        }
    }
    s->n_instances = 0;
    s->n_inst_prims = 0;
    s->n_inst_tris = 0;
    s->finalized = 0;
    return RS_OK;
}

uint32_t rs_scene_prim_count(const rs_scene *s) { return s->n_spheres + s->n_quads + s->n_tris; }

static rs_material mat_base(uint32_t type, rs_vec3 albedo)
{
    rs_material m;
    memset(&m, 0, sizeof m);
    m.type = type;
    m.albedo = albedo;
    m.albedo_tex = RS_NO_TEXTURE;
    m.mr_tex = m.emission_tex = m.normal_tex = RS_NO_TEXTURE;
    m.normal_scale = 1.0f;
    m.ior = 1.5f;
    return m;
}

rs_material rs_mat_lambertian(rs_vec3 albedo) { return mat_base(RS_MAT_LAMBERTIAN, albedo); }

rs_material rs_mat_diffuse_uniform(rs_vec3 albedo)
{
    return mat_base(RS_MAT_DIFFUSE_UNIFORM, albedo);
}

rs_material rs_mat_disney_diffuse(rs_vec3 albedo, float roughness)
{
    rs_material m = mat_base(RS_MAT_DISNEY_DIFFUSE, albedo);
    m.roughness = roughness;
    return m;
}

rs_material rs_mat_phong(rs_vec3 kd, rs_vec3 ks, float exponent)
{
    rs_material m = mat_base(RS_MAT_PHONG, kd);
    m.specular = ks;
    m.exponent = exponent;
    return m;
}

rs_material rs_mat_metal(rs_vec3 albedo, float fuzz)
{
    rs_material m = mat_base(RS_MAT_METAL, albedo);
    m.fuzz = fuzz;
    return m;
}

rs_material rs_mat_dielectric(float ior)
{
    rs_material m = mat_base(RS_MAT_DIELECTRIC, rs_v3_splat(1.0f));
    m.ior = ior;
    return m;
}

/* Reflectance at normal incidence of eta + i k: ((eta - 1)^2 + k^2) / ((eta + 1)^2 + k^2). */
static float f0_complex(float eta, float k)
{
    return ((eta - 1) * (eta - 1) + k * k) / ((eta + 1) * (eta + 1) + k * k);
}

rs_material rs_mat_conductor(rs_vec3 eta, rs_vec3 k, float alpha)
{
    rs_material m = mat_base(RS_MAT_CONDUCTOR, rs_v3(f0_complex(eta.x, k.x), f0_complex(eta.y, k.y),
                                                     f0_complex(eta.z, k.z)));
    m.eta = eta;
    m.k = k;
    m.alpha = alpha;
    return m;
}

rs_material rs_mat_conductor_f0(rs_vec3 f0, float alpha)
{
    rs_material m = mat_base(RS_MAT_CONDUCTOR, f0);
    m.flags = RS_MAT_F0_COLOR;
    m.eta = rs_v3_splat(1.5f);
    m.alpha = alpha;
    return m;
}

rs_material rs_mat_rough_dielectric(float ior, float alpha)
{
    rs_material m = mat_base(RS_MAT_ROUGH_DIELECTRIC, rs_v3_splat(1.0f));
    m.ior = ior;
    m.alpha = alpha;
    return m;
}

rs_material rs_mat_pbr(rs_vec3 base, float metallic, float roughness)
{
    rs_material m = mat_base(RS_MAT_PBR, base);
    m.metallic = metallic;
    m.alpha = roughness * roughness < RS_GGX_DELTA_ALPHA ? RS_GGX_DELTA_ALPHA : roughness * roughness;
    m.specular = rs_v3_splat(0.04f); /* glTF's default: ior 1.5 */
    m.spec_weight = 1.0f;
    return m;
}

rs_material rs_mat_light(rs_vec3 emission, int two_sided)
{
    rs_material m = mat_base(RS_MAT_DIFFUSE_LIGHT, rs_v3_splat(0.0f));
    m.emission = emission;
    m.flags = two_sided ? RS_MAT_TWO_SIDED : 0u;
    return m;
}
