/* raystream.h — the raystream library's C API: load or build a scene, render it on the CPU and
 * GPUs into an image of floats, with its AOV passes, a progress callback that can cancel, and
 * live preview in tev.  docs/api.md documents it with a complete example program.
 *
 * Conventions
 *   - Every name starts with raystream_ / RAYSTREAM_.  Objects are opaque handles made by a
 *     *_create / *_load / raystream_render call and given back with *_release (NULL is
 *     accepted); a scene is reference counted (raystream_scene_retain).
 *   - Functions that can fail return a raystream_status; on failure the calling thread's
 *     raystream_last_error() holds one line saying why (the raystream command's own message,
 *     without its "raystream: " prefix), and every output handle is left NULL.  The library never
 *     exits the program, never installs signal handlers and prints nothing but the warnings of a
 *     render (to the options' log callback, or to stderr without one).
 *   - Render settings are the raystream command's options by name ("spp", "max-depth" or
 *     "max_depth", "sampler", "filter", "devices", "aov", "tev", ...: `raystream render --help`
 *     lists them), given as text exactly as on its command line: a render through the library
 *     and `raystream render` with the same options make the same image, bit for bit.
 *   - Images are row-major, top row first, RGB float32, scene-linear.
 *   - One render at a time per scene handle (another is refused, as is a change to the scene while
 *     it renders); different scenes may render on different threads at once.
 */
#ifndef RAYSTREAM_H
#define RAYSTREAM_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#if defined(_WIN32)
#  define RAYSTREAM_API
#elif defined(__GNUC__)
#  define RAYSTREAM_API __attribute__((visibility("default")))
#else
#  define RAYSTREAM_API
#endif

#define RAYSTREAM_VERSION_MAJOR 0
#define RAYSTREAM_VERSION_MINOR 2
#define RAYSTREAM_VERSION_PATCH 0
/* MAJOR * 10000 + MINOR * 100 + PATCH: what raystream_version() returns for this header. */
#define RAYSTREAM_VERSION                                                                          \
  (RAYSTREAM_VERSION_MAJOR * 10000 + RAYSTREAM_VERSION_MINOR * 100 + RAYSTREAM_VERSION_PATCH)

typedef enum raystream_status {
    RAYSTREAM_OK = 0,
    RAYSTREAM_ERROR_ARGUMENT = 1, /* a bad argument or option (the command's usage errors) */
    RAYSTREAM_ERROR_IO = 2,       /* a file that cannot be read or written */
    RAYSTREAM_ERROR_RUNTIME = 3,  /* the render failed (a device, a malformed scene file, ...) */
    RAYSTREAM_ERROR_MEMORY = 4,   /* out of memory */
    RAYSTREAM_CANCELLED = 5       /* the progress callback stopped the render: the image holds
                                     the samples finished so far */
} raystream_status;

/* The library's version, RAYSTREAM_VERSION of the build (compare with the header's). */
RAYSTREAM_API int raystream_version(void);
/* "0.2.0", then what the build has: "0.2.0 (CUDA, OpenMP, OpenImageIO 2.4)". */
RAYSTREAM_API const char *raystream_version_string(void);
/* The calling thread's last failure, one line; "" when none. */
RAYSTREAM_API const char *raystream_last_error(void);

/* ---- scenes ------------------------------------------------------------------------------ */

typedef struct raystream_scene raystream_scene;

/* What the raystream command takes as SCENE: "builtin:NAME" (`raystream scenes` lists them), a
 * JSON scene file, or a glTF file (.gltf, .glb; lit by the default sky unless a render's
 * "background" option says otherwise). */
RAYSTREAM_API raystream_status raystream_scene_load(const char *scene, raystream_scene **out);
/* A scene from the text of a JSON scene file (docs/scene-format.md); relative file names in it
 * are found from `base_dir` (NULL: the current folder). */
RAYSTREAM_API raystream_status raystream_scene_from_json(const char *json, const char *base_dir,
                                                         raystream_scene **out);
/* An empty scene: a camera at (0, 0, 1) looking at the origin, 40 degrees, 512 x 512, a black
 * background; add materials, shapes and lights below. */
RAYSTREAM_API raystream_status raystream_scene_create(raystream_scene **out);
RAYSTREAM_API raystream_scene *raystream_scene_retain(raystream_scene *scene);
RAYSTREAM_API void raystream_scene_release(raystream_scene *scene);

/* A material, written as a scene file's material object (docs/scene-format.md), e.g.
 * {"type": "lambertian", "albedo": [0.7, 0.3, 0.2]} or {"type": "light", "emission": [4,4,4]};
 * its id (for the shapes below) in *id. */
RAYSTREAM_API raystream_status raystream_scene_add_material(raystream_scene *scene,
                                                            const char *json, uint32_t *id);
/* A triangle mesh: n_vertices positions (x, y, z), n_triangles triangles of three vertex
 * indices; optional unit vertex normals (x, y, z a vertex) and texture coordinates (u, v a
 * vertex), NULL when absent.  Every value must be finite and every index < n_vertices. */
RAYSTREAM_API raystream_status raystream_scene_add_mesh(raystream_scene *scene,
                                                        const float *positions, size_t n_vertices,
                                                        const uint32_t *indices, size_t n_triangles,
                                                        const float *normals, const float *uvs,
                                                        uint32_t material);
RAYSTREAM_API raystream_status raystream_scene_add_sphere(raystream_scene *scene,
                                                          const float center[3], float radius,
                                                          uint32_t material);
/* The parallelogram q + a u + b v, a, b in [0, 1] (a quad light with a "light" material). */
RAYSTREAM_API raystream_status raystream_scene_add_quad(raystream_scene *scene, const float q[3],
                                                        const float u[3], const float v[3],
                                                        uint32_t material);
/* A point, spot or directional light, written as a scene file's object of that type, e.g.
 * {"type": "point_light", "position": [0, 3, 0], "intensity": [10, 10, 10]}. */
RAYSTREAM_API raystream_status raystream_scene_add_light(raystream_scene *scene, const char *json);
/* A mesh, as raystream_scene_add_mesh, that is not placed itself but by instances (one copy in
 * memory however often it is placed): its id in *prototype.  Its material may not emit light
 * (placed triangles are not lights). */
RAYSTREAM_API raystream_status
raystream_scene_add_prototype(raystream_scene *scene, const float *positions, size_t n_vertices,
                              const uint32_t *indices, size_t n_triangles, const float *normals,
                              const float *uvs, uint32_t material, uint32_t *prototype);
/* Places a prototype by an affine transform: the top three rows of a 4x4 matrix, row by row
 * (x' = m[0] x + m[1] y + m[2] z + m[3], ...); invertible and finite. */
RAYSTREAM_API raystream_status raystream_scene_add_instance(raystream_scene *scene,
                                                            uint32_t prototype,
                                                            const double matrix[12]);
/* A pinhole (aperture 0) or thin-lens camera; focus_dist 0: |at - from|. */
RAYSTREAM_API raystream_status raystream_scene_set_camera(raystream_scene *scene,
                                                          const float from[3], const float at[3],
                                                          const float up[3], float vfov_deg,
                                                          float aperture, float focus_dist);
/* The radiance of rays that leave the scene (a light when not black). */
RAYSTREAM_API raystream_status raystream_scene_set_background(raystream_scene *scene,
                                                              const float rgb[3]);
/* The image size a render gets without "width"/"height" options. */
RAYSTREAM_API raystream_status raystream_scene_set_image_size(raystream_scene *scene,
                                                              uint32_t width, uint32_t height);
/* What the scene holds: spheres, quads, triangles (placed ones included), materials (any may be
 * NULL). */
RAYSTREAM_API void raystream_scene_counts(const raystream_scene *scene, uint32_t *spheres,
                                          uint32_t *quads, uint32_t *triangles,
                                          uint32_t *materials);

/* ---- render options ---------------------------------------------------------------------- */

typedef struct raystream_options raystream_options;

RAYSTREAM_API raystream_status raystream_options_create(raystream_options **out);
RAYSTREAM_API void raystream_options_release(raystream_options *options);
/* Sets option `name` (the command's, without "--"; '_' may stand for '-') to `value`, text as on
 * the command line ("64", "sobol", "box:0.5", "cpu:2,gpu", "albedo,normal").  A flag
 * ("denoise") takes "1"/"true"/"on" or "0"/"false"/"off".  A later call replaces an earlier one;
 * value NULL removes the option.  RAYSTREAM_ERROR_ARGUMENT for an unknown option, and for those
 * that name the command's files or its process ("output", "checkpoint", "resume",
 * "stats-json", "timeline", "quiet", the MPI ones).  The value itself is checked by the render,
 * with the command's message. */
RAYSTREAM_API raystream_status raystream_options_set(raystream_options *options, const char *name,
                                                     const char *value);
RAYSTREAM_API raystream_status raystream_options_set_int(raystream_options *options,
                                                         const char *name, long long value);
RAYSTREAM_API raystream_status raystream_options_set_double(raystream_options *options,
                                                            const char *name, double value);

/* Called from the rendering thread after each stage of the render with the fraction done in
 * [0, 1]; returning non-zero stops the render at the next stage boundary (RAYSTREAM_CANCELLED).
 * At most about 20 calls a second. */
typedef int (*raystream_progress_fn)(void *user, double fraction);
RAYSTREAM_API void raystream_options_set_progress(raystream_options *options,
                                                  raystream_progress_fn progress, void *user);
/* Where a render's warnings go (one line each, without a newline); NULL: stderr. */
typedef void (*raystream_log_fn)(void *user, const char *line);
RAYSTREAM_API void raystream_options_set_log(raystream_options *options, raystream_log_fn log,
                                             void *user);

/* ---- rendering and images ---------------------------------------------------------------- */

typedef struct raystream_image raystream_image;

/* Renders `scene` (loaded or built above) with `options` (NULL: the defaults: 64 spp, every
 * core and GPU) into a new image in *out.  On RAYSTREAM_CANCELLED *out is still set (the
 * samples finished so far); on an error it is NULL.  The options "background", "envmap",
 * "mesh" and "camera" change a scene as it is loaded: they are for raystream_render_scene. */
RAYSTREAM_API raystream_status raystream_render(raystream_scene *scene,
                                                const raystream_options *options,
                                                raystream_image **out);
/* Loads `scene` (as raystream_scene_load) and renders it: `raystream render SCENE` with these
 * options. */
RAYSTREAM_API raystream_status raystream_render_scene(const char *scene,
                                                      const raystream_options *options,
                                                      raystream_image **out);

RAYSTREAM_API void raystream_image_release(raystream_image *image);
RAYSTREAM_API uint32_t raystream_image_width(const raystream_image *image);
RAYSTREAM_API uint32_t raystream_image_height(const raystream_image *image);
/* The image: width * height * 3 floats (the denoised one with "denoise"). */
RAYSTREAM_API const float *raystream_image_pixels(const raystream_image *image);
/* Copies the image into a caller's buffer of width * height * 3 floats. */
RAYSTREAM_API void raystream_image_copy(const raystream_image *image, float *rgb);
/* The AOV layers the "aov" option asked for ("albedo", "normal": 3 floats a pixel; "depth",
 * "samples": 1), and "noisy" (the image before "denoise"): count, name, channels, data. */
RAYSTREAM_API int raystream_image_layer_count(const raystream_image *image);
RAYSTREAM_API const char *raystream_image_layer_name(const raystream_image *image, int index);
/* A layer by name: its floats, and the number a pixel in *channels; NULL when absent. */
RAYSTREAM_API const float *raystream_image_layer(const raystream_image *image, const char *name,
                                                 int *channels);
/* Samples each pixel got on average (spp unless cancelled or adaptive). */
RAYSTREAM_API double raystream_image_spp(const raystream_image *image);
/* Writes the image (with its layers into an .exr) as the command writes -o FILE: .exr, .pfm,
 * .hdr stay linear; .png and the other 8-bit formats get the "view" and "exposure" options of the
 * render (the standard sRGB view by default). */
RAYSTREAM_API raystream_status raystream_image_write(const raystream_image *image,
                                                     const char *path);
/* Reads an image file (.exr, .pfm, .hdr, .png, ...) into a new image, as linear RGB. */
RAYSTREAM_API raystream_status raystream_image_read(const char *path, raystream_image **out);

#ifdef __cplusplus
}
#endif

#endif
