/* scenes/scene.h — the flat scene: arrays of each primitive type, a material per primitive, the
 * emitters prepared for light sampling, the camera and the background.
 *
 * Build it with the rs_scene_add_* calls, then rs_scene_finalize() once: that validates the
 * geometry (finite coordinates, non-degenerate quads and spheres), numbers the primitives
 * globally (spheres, then quads, then triangles; see core/geom.h) and builds the light table.
 * After finalize the scene is read-only and may be shared by any number of threads. */
#ifndef RS_SCENES_SCENE_H
#define RS_SCENES_SCENE_H

#include <stddef.h>

#include "core/geom.h"
#include "core/status.h"

typedef enum rs_material_type {
    RS_MAT_LAMBERTIAN = 0,      /* ideal diffuse: f = albedo / pi, cosine-weighted sampling */
    RS_MAT_DIFFUSE_UNIFORM = 1, /* the thesis's uniform-hemisphere diffuse: f cos = albedo / 2pi */
    RS_MAT_DISNEY_DIFFUSE = 2,  /* Burley 2012 diffuse with `roughness` */
    RS_MAT_PHONG = 3,           /* modified Phong (Lafortune & Willems 1994): albedo = kd,
                                   `specular` = ks, `exponent` = n */
    RS_MAT_METAL = 4,           /* mirror reflection perturbed by `fuzz` (RTIOW) */
    RS_MAT_DIELECTRIC = 5,      /* glass of index `ior`: Schlick Fresnel, total internal
                                   reflection; albedo tints it */
    RS_MAT_DIFFUSE_LIGHT = 6,   /* emitter of `emission`; reflects nothing */
    RS_MAT_CONDUCTOR = 7,       /* GGX rough metal of roughness `alpha`: Fresnel from the complex
                                   index `eta` + i `k`, or with RS_MAT_F0_COLOR Schlick's from
                                   the colour `albedo`; alpha < RS_GGX_DELTA_ALPHA: a mirror */
    RS_MAT_ROUGH_DIELECTRIC = 8, /* GGX rough glass of index `ior` (Walter et al. 2007), exact
                                    Fresnel; albedo tints it; alpha < RS_GGX_DELTA_ALPHA: smooth */
    RS_MAT_PBR = 9              /* glTF 2.0 metallic-roughness: `albedo` the base colour,
                                   `metallic`, GGX `alpha`; a diffuse base under a specular layer
                                   of index 1.5 mixed with a metal of F0 = albedo */
} rs_material_type;

#define RS_MAT_TYPE_LAST RS_MAT_PBR

/* Below this GGX alpha a conductor or rough dielectric is perfectly smooth (a delta BSDF); the
 * pbr material's alpha is held at least this. */
#define RS_GGX_DELTA_ALPHA 1e-3f

/* Material flags. */
#define RS_MAT_TWO_SIDED                                                                           \
  1u /* a light emits on both sides (else only where its normal                                    \
        points) */
#define RS_MAT_UNIFORM_SAMPLING                                                                    \
  2u /* not importance-sampled: directions uniform over the                                        \
        hemisphere (the thesis's "without importance sampling") */
#define RS_MAT_EXACT_FRESNEL 4u /* dielectric: the exact Fresnel equations, not Schlick's */
#define RS_MAT_F0_COLOR      8u /* conductor: Schlick's Fresnel from the colour albedo */

#define RS_NO_TEXTURE 0xffffffffu

/* One material; the fields a type does not use are ignored.  Plain data. */
typedef struct rs_material {
    uint32_t type;       /* rs_material_type, stored fixed-width */
    uint32_t flags;      /* RS_MAT_* */
    rs_vec3 albedo;      /* reflectance in [0, 1] per channel (used when albedo_tex is none) */
    uint32_t albedo_tex; /* texture index for the albedo, or RS_NO_TEXTURE */
    rs_vec3 specular;    /* Phong ks; pbr: its dielectric layer's Fresnel F0 colour, glTF's
                            ((ior - 1) / (ior + 1))^2 times KHR_materials_specular's colour,
                            held to 1 (0.04 by default) */
    rs_vec3 emission;    /* emitted radiance, for lights */
    float roughness;     /* Disney diffuse, in [0, 1] */
    float exponent;      /* Phong n >= 0 */
    float fuzz;          /* metal, in [0, 1] */
    float ior;           /* dielectric index of refraction (> 0) */
    rs_vec3 eta, k;      /* conductor: complex index of refraction eta + i k per channel */
    float alpha;         /* GGX roughness (conductor, rough dielectric, pbr), in [0, 1] */
    float metallic;      /* pbr, in [0, 1] */
    uint32_t mr_tex;     /* pbr: glTF's metallic-roughness texture (roughness *= G, metallic
                            *= B, linear), or RS_NO_TEXTURE */
    uint32_t emission_tex; /* pbr: `emission` (glTF's emissive factor; the surface emits on both
                              sides: light-sampled when constant, found by paths when textured)
                              times this texture */
    uint32_t normal_tex; /* pbr: a tangent-space normal map (linear, [0, 1] -> [-1, 1]; triangles with
                            UVs), or RS_NO_TEXTURE */
    float normal_scale;  /* glTF's normalTexture.scale: x and y of the map are multiplied by it */
    uint32_t alpha_mask; /* 1 + index of an alpha cut-out (rs_scene_add_mask) that rays pass
                            through where it is 0; 0: opaque.  Triangles only */
    float spec_weight;   /* pbr: KHR_materials_specular's specularFactor, the dielectric
                            layer's strength (1 by default) */
    rs_vec3 sigma_a;     /* transmitting materials: the absorption coefficient inside, per unit
                            length (KHR_materials_volume: -ln(colour) / distance); 0: clear */
    float coat;          /* pbr: KHR_materials_clearcoat's clearcoatFactor, in [0, 1]; 0: none */
    float coat_alpha;    /* pbr: the coat's GGX alpha (clearcoatRoughnessFactor^2, at least
                            RS_GGX_DELTA_ALPHA) */
    rs_vec3 sheen;       /* pbr: KHR_materials_sheen's sheenColorFactor; 0: none */
    float sheen_rough;   /* pbr: its sheenRoughnessFactor, in [0, 1] */
} rs_material;

/* Whether a surface of material m is a light that light sampling picks: an emitter, or a glTF
 * material of constant emission (a textured one is left to the paths that hit it). */
static inline int rs_material_is_light(const rs_material *m)
{
    return (m->type == RS_MAT_DIFFUSE_LIGHT ||
            (m->type == RS_MAT_PBR && m->emission_tex == RS_NO_TEXTURE)) &&
           0.2126f * m->emission.x + 0.7152f * m->emission.y + 0.0722f * m->emission.z > 0.0f;
}

typedef enum rs_texture_type {
    RS_TEX_SOLID = 0,   /* a */
    RS_TEX_CHECKER = 1, /* 3D checker of cell size `scale` (RTNW v4): a on even cells, b on odd */
    RS_TEX_STRIPES = 2, /* `scale` stripes across u: a, b, a, ... */
    RS_TEX_IMAGE = 3    /* image `image`, bilinear, wrapping, v = 0 at the bottom row */
} rs_texture_type;

typedef struct rs_texture {
    uint32_t type;  /* rs_texture_type */
    uint32_t image; /* index into the scene's images (RS_TEX_IMAGE) */
    rs_vec3 a, b;
    float scale;
    uint32_t uv_xform; /* RS_TEX_IMAGE: 1 when uv_m applies (glTF's KHR_texture_transform);
                          0 (a zeroed texture): the surface's UVs as they are */
    float uv_m[6];     /* (u, v) -> (m0 u + m1 v + m2, m3 u + m4 v + m5), in the renderer's UVs
                          (v = 0 at the bottom row) */
} rs_texture;

/* A texture image in linear RGB (8-bit files are sRGB-decoded when loaded), with its mip
 * pyramid (docs/textures.md) after level 0 in the same block: level k + 1 is
 * max(1, floor(w_k / 2)) x max(1, floor(h_k / 2)), down to 1x1, built by rs_scene_finalize for
 * the images an image texture uses.  Level 0 is the image as loaded; whoever reads width *
 * height texels (the environment map, the checkpoint's hash, export) reads exactly it. */
typedef struct rs_image {
    uint32_t width, height;
    float *rgb;      /* the levels one after another, each row-major from the top row */
    uint32_t levels; /* levels in rgb; 0 or 1: level 0 only */
} rs_image;

/* The most mip levels an image has (a side of 65536 texels has 17). */
#define RS_IMAGE_MAX_LEVELS 24u

/* Floats of rgb that levels [0, levels) of a width x height image take (3 per texel). */
RS_HD size_t rs_image_levels_floats(uint32_t width, uint32_t height, uint32_t levels)
{
    size_t n = 0;
    uint32_t k;
    for (k = 0; k < levels; ++k) {
        n += 3 * (size_t)width * height;
        width = width > 1 ? width / 2 : 1;
        height = height > 1 ? height / 2 : 1;
    }
    return n;
}

/* A punctual light (glTF's KHR_lights_punctual): a delta light, which only light sampling
 * finds (the bsdf and uniform sampling modes never see it). */
typedef enum rs_punctual_type {
    RS_PUNCTUAL_POINT = 0,
    RS_PUNCTUAL_SPOT = 1,
    RS_PUNCTUAL_DIRECTIONAL = 2
} rs_punctual_type;

typedef struct rs_punctual {
    uint32_t type;     /* rs_punctual_type */
    rs_vec3 pos;       /* point, spot */
    rs_vec3 dir;       /* spot: its axis; directional: the way its light travels (unit) */
    rs_vec3 intensity; /* point, spot: radiant intensity (W/sr); directional: irradiance on a
                          surface facing it (W/m^2) */
    float cos_inner, cos_outer; /* spot: full intensity inside the inner cone, none outside the
                                   outer, glTF's smooth falloff between */
} rs_punctual;

/* Most triangles the instances of one scene may place (global numbers stay below 2^31). */
#define RS_MAX_INST_PRIMS (1u << 30)

/* In rs_light.prim: a punctual light, its index in the low bits. */
#define RS_LIGHT_PUNCTUAL 0x80000000u

/* An emitter that light sampling can pick: a quad or triangle with an emissive material, or a
 * punctual light (after every emitter in the table). */
typedef struct rs_light {
    uint32_t prim;  /* global primitive index, or RS_LIGHT_PUNCTUAL | punctual index */
    float area;     /* surface area */
    float power;    /* pi * area * luminance(emission) * (2 if two-sided): selection weight */
    float pick_pdf; /* power / total power: probability that sampling picks this light */
} rs_light;

/* A node of the light BVH (scenes/light_bvh.c builds it, shading/light_bvh.h samples it; the
 * bounds and importance of Conty and Kulla 2018, as pbrt-v4's BVHLightSampler has them, without
 * the receiver's normal).  Nodes are depth-first: an interior node's first child follows it,
 * its second is at `child`; a leaf holds one light (`child` its index in the scene's lights). */
typedef struct rs_light_node {
    float lo[3], hi[3]; /* the lights' bounds (a moving sphere's over the shutter) */
    float w[3];         /* the axis of the cone holding their normals (emission directions) */
    float cos_o;        /* cos of that cone's half-angle (-1: every direction) */
    float cos_e;        /* cos of the angle beyond cos_o over which they still emit (pi/2: 0) */
    float phi;          /* their power (rs_light.power summed) */
    uint32_t child;     /* interior: the second child's index; leaf: the light's index */
    uint32_t flags;     /* RS_LIGHT_NODE_* */
} rs_light_node;

#define RS_LIGHT_NODE_LEAF      1u
#define RS_LIGHT_NODE_TWO_SIDED 2u /* a leaf's emitter emits on both sides of its normal */

typedef struct rs_camera_desc {
    rs_vec3 from, at, up;
    float vfov_deg;      /* vertical field of view, degrees */
    float aperture;      /* lens diameter; 0 for a pinhole */
    float focus_dist;    /* distance to the plane in focus; 0 means |at - from| */
    float shutter_open;  /* each camera ray gets a time uniform in [open, close) */
    float shutter_close; /* (moving spheres are blurred over it) */
} rs_camera_desc;

typedef struct rs_scene {
    char name[64];
    rs_sphere *spheres;
    uint32_t *sphere_mat;
    uint32_t n_spheres, cap_spheres;
    rs_quad *quads;
    uint32_t *quad_mat;
    uint32_t n_quads, cap_quads;
    rs_tri *tris;
    uint32_t *tri_mat;
    uint32_t n_tris, cap_tris;
    rs_vec3 *sphere_motion; /* NULL until a moving sphere is added; then one per sphere */
    uint32_t cap_motion;
    float *tri_uv; /* NULL until a triangle with UVs is added; then 6 per triangle */
    uint32_t cap_uv;
    float *tri_normal; /* NULL until a triangle with vertex normals is added; then 9 per
                          triangle (unit shading normals at v0, v1, v2; zeros: use the face's) */
    uint32_t cap_normal;
    rs_material *materials;
    uint32_t n_materials, cap_materials;
    rs_texture *textures;
    uint32_t n_textures, cap_textures;
    rs_image *images;
    uint32_t n_images, cap_images;

    rs_punctual *punctuals;
    uint32_t n_punctuals, cap_punctuals;

    /* Alpha cut-outs (core/geom.h): the masks materials name, and per own triangle 1 + its
     * material's mask or 0, built by finalize (NULL when no triangle has one). */
    rs_alpha_mask *masks;
    uint8_t *mask_bits;
    uint32_t n_masks, cap_masks, n_mask_bits, cap_mask_bits;
    uint32_t *tri_mask;

    /* Instances (core/geom.h): the prototypes' triangles in object space, with materials, UVs
     * and vertex normals as the scene's own triangles have them, and their placements.  An
     * instance's triangles are numbered after every primitive of the scene's own, in instance
     * order (rs_instance.prim_base, set by finalize); no array here is per placed triangle. */
    rs_tri *inst_tris;
    uint32_t *inst_tri_mat;
    float *inst_tri_uv;     /* NULL until a prototype triangle has UVs; then 6 per triangle */
    float *inst_tri_normal; /* NULL until one has vertex normals; then 9 per triangle */
    uint32_t n_inst_tris, cap_inst_tris, cap_inst_uv, cap_inst_normal;
    rs_instance *instances;
    uint32_t n_instances, cap_instances;
    uint32_t n_inst_prims; /* triangles the instances place, all together */

    /* built by rs_scene_finalize */
    rs_light *lights;
    float *light_cdf; /* n_lights + 1 entries, cdf[0] = 0, cdf[n] = 1 */
    uint32_t n_lights;
    uint32_t n_area_lights; /* lights[0, n_area_lights) are emitters, the rest punctual */
    rs_light_node *light_nodes; /* the light BVH over the emitters, point and spot lights (not
                                   directional ones, not the map); NULL when there are none */
    uint32_t n_light_nodes;
    uint64_t *light_trail;      /* per light: its path from the BVH's root (bit k: the second
                                   child at depth k) under a leading 1 bit; 0: not in the BVH */
    float light_bvh_mass;       /* the BVH's lights' share of the lights' power (the rest:
                                   directional lights, picked by power) */
    int light_bvh_built;        /* rs_scene_build_light_bvh ran (rs_scene_set_extras) */
    float area_mass;        /* the probability that light sampling picks the map or an emitter
                               (1 without punctual lights) */
    int32_t *prim_light; /* per global primitive: index into lights, or -1 */
    int finalized;
    /* What rs_scene_finalize refused, for a reader to name it as its file does (the JSON
     * reader: objects[3], materials.lamp): an rs_scene_part and its index; RS_PART_NONE. */
    uint32_t bad_part, bad_index;

    /* The environment map (rs_scene_set_environment): an equirectangular image of the radiance
     * arriving from each direction, importance-sampled by luminance times sin(theta) like a
     * light (shading/envmap.h).  The distribution is built by rs_scene_finalize. */
    uint32_t env_image;   /* index into images, or RS_NO_TEXTURE: none (the background below) */
    rs_vec3 env_scale;    /* multiplies the map's texels */
    float env_rot[9];     /* world -> map rotation, row-major */
    float env_pick;       /* probability that light sampling picks the map (0 without one) */
    float *env_marg_cdf;  /* image height + 1 entries: the rows' CDF */
    float *env_cond_cdf;  /* height x (width + 1): each row's CDF over its texels */
    uint32_t env_uniform; /* every texel the same (a uniform sky), or no map and a constant
                             background colour that is not black: shading/envmap.h samples
                             the sphere uniformly and looks nothing up (built by finalize) */
    rs_vec3 env_uniform_le; /* then: the radiance from every direction (texel times scale, or
                               the background colour) */

    rs_camera_desc camera;
    rs_vec3 background;     /* radiance of rays that leave the scene (the horizon's, when
                               background_sky is set) */
    rs_vec3 background_top; /* with background_sky: the radiance straight up */
    int background_sky;     /* RTIOW sky: lerp(background, background_top, (d.y + 1) / 2) */
    uint32_t width, height; /* the scene's preferred image size */
} rs_scene;

/* The scene's geometry as traversal sees it, with the default intersection tests.  These three
 * are RS_HD: shading calls them on the host and in the CUDA megakernel alike. */
RS_HD rs_geom rs_scene_geom(const rs_scene *s)
{
    rs_geom g;
    g.spheres = s->spheres;
    g.sphere_motion = s->sphere_motion;
    g.time0 = rs_fminf(s->camera.shutter_open, s->camera.shutter_close);
    g.time1 = rs_fmaxf(s->camera.shutter_open, s->camera.shutter_close);
    g.sphere_algo = 0; /* the default intersection tests; the CLI may choose others */
    g.tri_algo = 0;
    g.aabb_algo = 0;
    g.quads = s->quads;
    g.tris = s->tris;
    g.n_spheres = s->n_spheres;
    g.n_quads = s->n_quads;
    g.n_tris = s->n_tris;
    /* the instances' bottom levels come with the BVH (accel/bvh.h: rs_bvh_attach) */
    g.instances = s->instances;
    g.inst_tris = s->inst_tris;
    g.blas_nodes = NULL;
    g.blas_prim_ids = NULL;
    g.n_instances = s->n_instances;
    g.n_inst_tris = s->n_inst_tris;
    g.n_blas_nodes = 0;
    g.tri_mask = s->tri_mask;
    g.masks = s->masks;
    g.mask_bits = s->mask_bits;
    g.tri_uv = s->tri_uv;
    g.n_masks = s->n_masks;
    g.n_mask_bits = s->n_mask_bits;
    return g;
}

/* The instance that places global primitive `prim` (one of the instances' triangles: prim >=
 * rs_scene_prim_count), and in *k the prototype triangle's index into inst_tris. */
RS_HD const rs_instance *rs_scene_prim_instance(const rs_scene *s, uint32_t prim, uint32_t *k)
{
    uint32_t lo = 0, hi = s->n_instances;
    while (hi - lo > 1) {
        uint32_t mid = lo + (hi - lo) / 2;
        if (s->instances[mid].prim_base <= prim)
            lo = mid;
        else
            hi = mid;
    }
    *k = s->instances[lo].first_tri + (prim - s->instances[lo].prim_base);
    return &s->instances[lo];
}

/* Triangle `prim` (a global number in the triangles' range: the scene's own or an instance's) as
 * it lies in the world. */
RS_HD rs_tri rs_scene_tri(const rs_scene *s, uint32_t prim)
{
    uint32_t t = prim - s->n_spheres - s->n_quads, k;
    const rs_instance *in;
    if (t < s->n_tris)
        return s->tris[t];
    in = rs_scene_prim_instance(s, prim, &k);
    return rs_instance_tri(in, &s->inst_tris[k]);
}

/* tmp[6] = (0,0), (1,0), (0,1): the UVs of a triangle added without any. */
RS_HD const float *rs_default_tri_uv(float *tmp)
{
    tmp[0] = tmp[1] = tmp[3] = tmp[4] = 0.0f;
    tmp[2] = tmp[5] = 1.0f;
    return tmp;
}

/* The UVs (u0, v0, u1, v1, u2, v2) of prototype triangle k (an inst_tris index) as instance
 * `in` places it, into tmp[6] (v1 and v2 swapped under a mirror), or (0,0), (1,0), (0,1) when no
 * prototype triangle has UVs. */
RS_HD const float *rs_instance_tri_uv(const rs_scene *s, const rs_instance *in, uint32_t k,
                                      float *tmp)
{
    const float *src;
    if (!s->inst_tri_uv)
        return rs_default_tri_uv(tmp);
    src = &s->inst_tri_uv[6 * (size_t)k];
    tmp[0] = src[0];
    tmp[1] = src[1];
    tmp[2] = src[in->mirror ? 4 : 2];
    tmp[3] = src[in->mirror ? 5 : 3];
    tmp[4] = src[in->mirror ? 2 : 4];
    tmp[5] = src[in->mirror ? 3 : 5];
    return tmp;
}

/* The vertex normals (9 floats) of prototype triangle k as instance `in` places it, into tmp,
 * transformed as flattening transforms a copied triangle's (scenes/transform.c: by the cofactor
 * matrix in double precision, normalised, v1 and v2 swapped under a mirror); NULL when no
 * prototype triangle has normals. */
RS_HD const float *rs_instance_tri_normals(const rs_scene *s, const rs_instance *in, uint32_t k,
                                           float *tmp)
{
    const float *vn;
    uint32_t c, j;
    if (!s->inst_tri_normal)
        return NULL;
    vn = &s->inst_tri_normal[9 * (size_t)k];
    for (c = 0; c < 3; ++c) {
        /* corner c of the placed triangle is corner src of the prototype's */
        uint32_t src = in->mirror && c ? 3 - c : c;
        double n[3], l;
        for (j = 0; j < 3; ++j)
            n[j] = in->cof[3 * j] * vn[3 * src] + in->cof[3 * j + 1] * vn[3 * src + 1] +
                   in->cof[3 * j + 2] * vn[3 * src + 2];
        l = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        /* a zero normal ("use the face's") stays zero; det < 0 flips the cofactor's */
        if (l > 0)
            l = (in->mirror ? -1.0 : 1.0) / l;
        for (j = 0; j < 3; ++j)
            tmp[3 * c + j] = (float)(n[j] * l);
    }
    return tmp;
}

/* The UVs (u0, v0, u1, v1, u2, v2) of triangle `prim`: the scene's own array, or tmp[6] filled;
 * NULL where no triangle of the scene has UVs (shading then takes the barycentrics).  A triangle
 * without UVs in a scene where others have them gets (0,0), (1,0), (0,1), as the scene's own
 * arrays give it, so that a scene and its flattened twin read the same UVs. */
RS_HD const float *rs_scene_tri_uv(const rs_scene *s, uint32_t prim, float *tmp)
{
    uint32_t t = prim - s->n_spheres - s->n_quads, k;
    const rs_instance *in;
    if (t < s->n_tris && s->tri_uv)
        return &s->tri_uv[6 * (size_t)t];
    if (!s->tri_uv && !s->inst_tri_uv)
        return NULL;
    if (t < s->n_tris)
        return rs_default_tri_uv(tmp);
    in = rs_scene_prim_instance(s, prim, &k);
    return rs_instance_tri_uv(s, in, k, tmp);
}

/* The unit vertex normals (9 floats) of triangle `prim`: the scene's own, or an instance's in
 * tmp[9] (rs_instance_tri_normals); NULL where it has none (zeros also mean none). */
RS_HD const float *rs_scene_tri_normals(const rs_scene *s, uint32_t prim, float *tmp)
{
    uint32_t t = prim - s->n_spheres - s->n_quads, k;
    const rs_instance *in;
    if (t < s->n_tris)
        return s->tri_normal ? &s->tri_normal[9 * (size_t)t] : NULL;
    if (!s->inst_tri_normal)
        return NULL;
    in = rs_scene_prim_instance(s, prim, &k);
    return rs_instance_tri_normals(s, in, k, tmp);
}

/* Index into the light table of global primitive `prim`, or -1 (instances' triangles are never
 * lights: a group with emitters is copied, not instanced). */
RS_HD int32_t rs_scene_prim_light(const rs_scene *s, uint32_t prim)
{
    return prim < s->n_spheres + s->n_quads + s->n_tris ? s->prim_light[prim] : -1;
}

/* The material of global primitive `prim`. */
RS_HD const rs_material *rs_scene_prim_material(const rs_scene *s, uint32_t prim)
{
    if (prim < s->n_spheres)
        return &s->materials[s->sphere_mat[prim]];
    prim -= s->n_spheres;
    if (prim < s->n_quads)
        return &s->materials[s->quad_mat[prim]];
    if (prim - s->n_quads < s->n_tris)
        return &s->materials[s->tri_mat[prim - s->n_quads]];
    {
        uint32_t k;
        rs_scene_prim_instance(s, prim + s->n_spheres, &k);
        return &s->materials[s->inst_tri_mat[k]];
    }
}

/* Radiance arriving along direction d (unit) from outside the scene. */
RS_HD rs_vec3 rs_scene_background(const rs_scene *s, rs_vec3 d)
{
    if (s->background_sky) {
        float a = 0.5f * (d.y / rs_v3_length(d) + 1.0f);
        return rs_v3_add(rs_v3_scale(s->background, 1.0f - a), rs_v3_scale(s->background_top, a));
    }
    return s->background;
}

#ifdef __cplusplus
extern "C" {
#endif
rs_status rs_scene_create(const char *name, rs_scene **out);
void rs_scene_destroy(rs_scene *s);

/* Each add returns RS_OK or RS_ERR_NOMEM / RS_ERR_ARG (a material id out of range). */
rs_status rs_scene_add_material(rs_scene *s, const rs_material *m, uint32_t *id);
rs_status rs_scene_add_sphere(rs_scene *s, rs_vec3 center, float radius, uint32_t mat);
/* A sphere at c0 at time t0 and at c1 at time t1, moving linearly (RTNW's moving sphere). */
rs_status rs_scene_add_moving_sphere(rs_scene *s, rs_vec3 c0, float t0, rs_vec3 c1, float t1,
                                     float radius, uint32_t mat);
/* A sphere whose centre at time t is center + t velocity, the velocity stored exactly (what
 * `raystream export` writes and a scene file's "velocity" reads back). */
rs_status rs_scene_add_sphere_velocity(rs_scene *s, rs_vec3 center, rs_vec3 velocity,
                                       float radius, uint32_t mat);
/* Parallelogram Q + a u + b v, a, b in [0, 1]; its normal is u x v. */
rs_status rs_scene_add_quad(rs_scene *s, rs_vec3 q, rs_vec3 u, rs_vec3 v, uint32_t mat);
rs_status rs_scene_add_triangle(rs_scene *s, rs_vec3 v0, rs_vec3 v1, rs_vec3 v2, uint32_t mat);
/* A triangle with texture coordinates uv[0..5] = (u0, v0, u1, v1, u2, v2).  Triangles added
 * without UVs get (0,0), (1,0), (0,1). */
rs_status rs_scene_add_triangle_uv(rs_scene *s, rs_vec3 v0, rs_vec3 v1, rs_vec3 v2,
                                   const float uv[6], uint32_t mat);
/* A triangle with optional UVs (6 floats, or NULL) and optional unit vertex normals (9 floats,
 * or NULL: shading uses the face normal). */
rs_status rs_scene_add_triangle_full(rs_scene *s, const rs_vec3 v[3], const float *uv,
                                     const float *normals, uint32_t mat);
rs_status rs_scene_add_texture(rs_scene *s, const rs_texture *t, uint32_t *id);
/* An alpha cut-out of width x height texels (rows from the top): opaque where
 * alpha[i] * scale >= cutoff; alpha NULL: the constant `scale`.  *id is what a material's
 * alpha_mask takes (1 + the mask's index). */
rs_status rs_scene_add_mask(rs_scene *s, uint32_t width, uint32_t height, const float *alpha,
                            float scale, float cutoff, uint32_t *id);
/* Copies a width x height linear-RGB image into the scene. */
rs_status rs_scene_add_image(rs_scene *s, uint32_t width, uint32_t height, const float *rgb,
                             uint32_t *id);
/* Reads an image file through OpenImageIO into linear RGB (8- and 16-bit files are decoded from
 * sRGB, float files are taken as linear). */
rs_status rs_scene_load_image(rs_scene *s, const char *path, uint32_t *id);
/* The same without decoding: the file's values as stored (8-bit: code / 255), for data textures
 * (normal maps, glTF's metallic-roughness). */
rs_status rs_scene_load_image_data(rs_scene *s, const char *path, uint32_t *id);
/* Axis-aligned box [lo, hi] as six outward-facing quads, rotated by `rot_y_deg` about the y axis
 * (through the origin) and then moved by `offset` (RTNW's box + rotate_y + translate). */
rs_status rs_scene_add_box(rs_scene *s, rs_vec3 lo, rs_vec3 hi, float rot_y_deg, rs_vec3 offset,
                           uint32_t mat);

/* The scene's camera (copied), its preferred image size, and its background: a constant colour
 * (a uniform sky, light-sampled, where it is not black) or RTIOW's gradient from `horizon` to
 * `zenith` by the direction's height.  What a loader knows of the scene besides its parts; the
 * loaders set nothing in the struct themselves (scenes/json_*.c, gltf_scene.c, mesh*.c). */
void rs_scene_set_camera(rs_scene *s, const rs_camera_desc *camera);
void rs_scene_set_image_size(rs_scene *s, uint32_t width, uint32_t height);
void rs_scene_set_background(rs_scene *s, rs_vec3 color);
void rs_scene_set_background_gradient(rs_scene *s, rs_vec3 horizon, rs_vec3 zenith);
/* Multiplies image `image`'s texels by `factor` (glTF's base colour factor baked into its
 * texture).  RS_ERR_ARG for an image that is not there. */
rs_status rs_scene_scale_image(rs_scene *s, uint32_t image, rs_vec3 factor);

/* Lights the scene with image `image` (rs_scene_load_image) as an environment map, its texels
 * times `scale`, turned by `rot_world_to_map` (a rotation, row-major; NULL: none).  The map's
 * texels must be finite and >= 0 (RS_ERR_ARG otherwise, at finalize). */
rs_status rs_scene_set_environment(rs_scene *s, uint32_t image, rs_vec3 scale,
                                   const float *rot_world_to_map);

/* A punctual light; intensity >= 0, finite; spot cones with 0 <= inner <= outer <= 90 degrees
 * (cosines given), dir non-zero (normalised here). */
rs_status rs_scene_add_punctual(rs_scene *s, const rs_punctual *p);

/* Moves the scene's own triangles [from, n_tris) (with their materials, UVs and normals) into
 * the prototype pool, as prototype *first .. *first + *count - 1 (inst_tris indices): what a
 * group's triangles become when it is instanced. */
rs_status rs_scene_make_prototype(rs_scene *s, uint32_t from, uint32_t *first, uint32_t *count);
/* Places prototype [first, first + count) by the affine transform m (row-major 3x4, double:
 * core/geom.h's rs_instance.m).  RS_ERR_ARG (message without a file: the caller prefixes it)
 * for a singular or non-finite transform, a placed coordinate beyond 1e30, or more than 2^30
 * placed triangles in all. */
rs_status rs_scene_add_instance(rs_scene *s, uint32_t first, uint32_t count, const double m[12]);
/* Appends a prepared placement (rs_scene_add_instance's last step). */
rs_status rs_scene_push_instance(rs_scene *s, const rs_instance *in);
/* Replaces every instance by copies of its triangles, transformed as instancing transforms
 * them, appended to the scene's own triangles in instance order: the flattened twin, which
 * numbers, shades and renders every triangle as the instanced scene does.  Before finalize. */
rs_status rs_scene_flatten_instances(rs_scene *s);

/* Where the renderer's arithmetic holds, checked by rs_scene_finalize: every point of the
 * geometry (sphere centres and extents along their motion, the corners of quads, triangles and
 * instances' world boxes, point and spot light positions, the camera) within +-RS_SCENE_MAX_COORD, so that
 * no intersection test's float products overflow (a sphere 1.8e19 away vanished); every
 * emission, light intensity and environment radiance (map times scale) at most
 * RS_SCENE_MAX_RADIANCE, far inside what the film's exact sums hold (shading/film.h: a sample
 * above 2^48 is dropped). */
#define RS_SCENE_MAX_COORD    1e9f
/* The most primitives a reader or --flatten-instances copies into the scene (instancing places
 * more without copying them). */
#define RS_SCENE_MAX_COPIED_PRIMS (1u << 24)
#define RS_SCENE_MAX_RADIANCE 1e12f

typedef enum rs_scene_part {
    RS_PART_NONE = 0,
    RS_PART_SPHERE,
    RS_PART_QUAD,
    RS_PART_TRIANGLE,
    RS_PART_INSTANCE,
    RS_PART_MATERIAL,
    RS_PART_LIGHT, /* a punctual light */
    RS_PART_ENVIRONMENT,
    RS_PART_CAMERA
} rs_scene_part;

/* Checks the scene and builds its light tables.  RS_ERR_ARG naming the part (and bad_part,
 * bad_index saying which) for a scene outside what the renderer holds. */
rs_status rs_scene_finalize(rs_scene *s);

/* What rs_scene_finalize builds that only some renders read: the light BVH (--light-sampler
 * bvh) and the image textures' mip pyramids (trilinear lookups, the default texture filter).
 * Both by default; the CLI leaves out what its render will not read (issue 39: a scene of 10^7
 * emitters spent 2.2 GB on a light BVH a power-sampled render never reads, a 16384^2 texture
 * its pyramid under --texture-filter bilinear).  Per thread: set before scenes are loaded or
 * finalized on it.
 * Without them, a render that asks for them is refused by rs_render_constants. */
void rs_scene_set_extras(int light_bvh, int pyramids);

/* A copy of a finalized scene's arrays in memory that `ops` allocates and fills: the host's, or
 * a CUDA device's for the megakernel (scheduler/device_copy.h builds both), whose shading code
 * then reads `scene` exactly as the host reads the original.  `scene` is a host struct holding
 * the copies' pointers (copy it to the device as it is); every block made is listed, so the
 * mirror can be released without reading device memory. */
typedef struct rs_mirror_ops {
    /* Allocates `bytes` (>= 1) at *dst and copies `src` there; RS_OK, or an error already set
     * (and *dst NULL). */
    rs_status (*copy)(void *user, void **dst, const void *src, size_t bytes);
    void (*release)(void *user, void *p);
    void *user;
} rs_mirror_ops;

/* Every block a copy made, in order (a host array), and the bytes copied in all. */
typedef struct rs_mirror_blocks {
    void **blocks;
    uint32_t n_blocks, cap_blocks;
    uint64_t bytes;
} rs_mirror_blocks;

typedef struct rs_scene_mirror {
    rs_scene scene;
    rs_mirror_blocks made;
} rs_scene_mirror;

/* The lengths of the environment map's CDF arrays (0 without a map or before finalize). */
static inline size_t rs_scene_env_marg_len(const rs_scene *s)
{
    return s->env_marg_cdf ? (size_t)s->images[s->env_image].height + 1 : 0;
}
static inline size_t rs_scene_env_cond_len(const rs_scene *s)
{
    return s->env_cond_cdf ? (size_t)s->images[s->env_image].height *
                                 ((size_t)s->images[s->env_image].width + 1)
                           : 0;
}

/* Every array of rs_scene that a copy of the scene holds, with its element count (`s` a pointer
 * to the scene; the element size is the field's own).  An array that is NULL or has no
 * elements is copied as NULL.  The images are nested (each points to its texels) and are the
 * one special case: rs_scene_mirror_create copies their texels first, then an image array that
 * points to those copies.  A new array of rs_scene goes here, or the device copies miss it
 * (tests/scenes_mirror_test.c checks every pointer-sized word of a copy). */
/* clang-format off */
#define RS_SCENE_ARRAYS(X, s)                                                                      \
    X(spheres, (size_t)(s)->n_spheres)                                                             \
    X(sphere_mat, (size_t)(s)->n_spheres)                                                          \
    X(sphere_motion, (size_t)(s)->n_spheres)                                                       \
    X(quads, (size_t)(s)->n_quads)                                                                 \
    X(quad_mat, (size_t)(s)->n_quads)                                                              \
    X(tris, (size_t)(s)->n_tris)                                                                   \
    X(tri_mat, (size_t)(s)->n_tris)                                                                \
    X(tri_uv, 6 * (size_t)(s)->n_tris)                                                             \
    X(tri_normal, 9 * (size_t)(s)->n_tris)                                                         \
    X(materials, (size_t)(s)->n_materials)                                                         \
    X(textures, (size_t)(s)->n_textures)                                                           \
    X(lights, (size_t)(s)->n_lights)                                                               \
    X(light_cdf, (s)->n_lights ? (size_t)(s)->n_lights + 1 : 0)                                    \
    X(light_nodes, (size_t)(s)->n_light_nodes)                                                     \
    X(light_trail, (s)->light_nodes ? (size_t)(s)->n_lights : 0)                                   \
    X(prim_light, (size_t)(s)->n_spheres + (s)->n_quads + (s)->n_tris)                           \
    X(punctuals, (size_t)(s)->n_punctuals)                                                         \
    X(env_marg_cdf, rs_scene_env_marg_len(s))                                                      \
    X(env_cond_cdf, rs_scene_env_cond_len(s))                                                      \
    X(inst_tris, (size_t)(s)->n_inst_tris)                                                         \
    X(inst_tri_mat, (size_t)(s)->n_inst_tris)                                                      \
    X(inst_tri_uv, 6 * (size_t)(s)->n_inst_tris)                                                   \
    X(inst_tri_normal, 9 * (size_t)(s)->n_inst_tris)                                               \
    X(instances, (size_t)(s)->n_instances)                                                         \
    X(masks, (size_t)(s)->n_masks)                                                                 \
    X(mask_bits, (size_t)(s)->n_mask_bits)                                                         \
    X(tri_mask, (s)->tri_mask ? (size_t)(s)->n_tris : 0)
/* clang-format on */

/* Copies n elements of `size` bytes from `src` through ops into a new block at *dst and lists
 * it in *made; NULL src or n = 0: *dst = NULL and nothing is made.  On failure nothing is
 * added (the blocks made before stay listed for the caller to release). */
rs_status rs_mirror_copy(rs_mirror_blocks *made, const rs_mirror_ops *ops, void **dst,
                         const void *src, size_t n, size_t size);
/* Releases every listed block through ops and frees the list; *made is zeroed. */
void rs_mirror_blocks_release(rs_mirror_blocks *made, const rs_mirror_ops *ops);

/* Copies every array of `s` (RS_SCENE_ARRAYS, then the images) through `ops`.  On failure every
 * block made is released, *out is zeroed and the error returned. */
rs_status rs_scene_mirror_create(const rs_scene *s, const rs_mirror_ops *ops, rs_scene_mirror *out);
void rs_scene_mirror_release(rs_scene_mirror *m, const rs_mirror_ops *ops);

uint32_t rs_scene_prim_count(const rs_scene *s);

/* Material constructors with the RTIOW / thesis defaults for the unused fields. */
rs_material rs_mat_lambertian(rs_vec3 albedo);
rs_material rs_mat_diffuse_uniform(rs_vec3 albedo);
rs_material rs_mat_disney_diffuse(rs_vec3 albedo, float roughness);
rs_material rs_mat_phong(rs_vec3 kd, rs_vec3 ks, float exponent);
rs_material rs_mat_metal(rs_vec3 albedo, float fuzz);
rs_material rs_mat_dielectric(float ior);
rs_material rs_mat_light(rs_vec3 emission, int two_sided);
/* A rough conductor of complex index eta + i k (per channel) and GGX alpha; its albedo (what
 * Russian roulette reads) is the reflectance at normal incidence. */
rs_material rs_mat_conductor(rs_vec3 eta, rs_vec3 k, float alpha);
/* A rough conductor by its colour at normal incidence (Schlick's Fresnel). */
rs_material rs_mat_conductor_f0(rs_vec3 f0, float alpha);
rs_material rs_mat_rough_dielectric(float ior, float alpha);
/* glTF's metallic-roughness: alpha = roughness^2 (held >= RS_GGX_DELTA_ALPHA). */
rs_material rs_mat_pbr(rs_vec3 base, float metallic, float roughness);
#ifdef __cplusplus
}
#endif

#endif
