/* scheduler/device_copy.h — a device's own copy of what it traces and shades.
 *
 * One family of functions builds both copies a device with memory of its own needs, through an
 * rs_mirror_ops (scenes/scene.h): cudaMalloc + cudaMemcpy for the CUDA device, rs_alloc + memcpy
 * for its host stand-in (rs_device_copy_host_ops), which so really traces in memory of its own,
 * as a GPU would.
 *
 *   rs_device_copy_geom   at upload: the geometry's arrays (RS_GEOM_ARRAYS, core/geom.h) and the
 *                         BVH view's (RS_BVH_ARRAYS, accel/bvh_traverse.h): what `trace` reads;
 *   rs_device_copy_scene  at upload_scene: the scene's arrays (RS_SCENE_ARRAYS and the images,
 *                         rs_scene_mirror_create), the mirror's rs_scene struct itself, and the
 *                         tracer the megakernel traces with: the geometry over the mirror's own
 *                         arrays (no array is copied twice) with the uploaded geometry's
 *                         intersection algorithms and shutter, and the uploaded BVH copy.
 *
 * Invariants: every pointer in a copy's structs points into a block the copy made (or is NULL);
 * every block made is listed in the copy's `made`, so it is released without reading device
 * memory; a failure at any step releases everything made before it and leaves the copy zeroed.
 * The structs themselves (rs_device_geom, rs_device_scene) are host memory; only the blocks are
 * the device's.  Nothing here is thread-safe: one thread builds and releases a copy. */
#ifndef RS_SCHEDULER_DEVICE_COPY_H
#define RS_SCHEDULER_DEVICE_COPY_H

#include "accel/bvh.h"
#include "scenes/scene.h"
#include "shading/path.h"

/* What trace reads: the geometry and its binary BVH. */
typedef struct rs_device_geom {
    rs_geom geom;    /* counts, shutter and algorithms as uploaded; the arrays the copies */
    rs_bvh_view bvh; /* the copies of the BVH's nodes and primitive ids */
    rs_mirror_blocks made;
} rs_device_geom;

/* What a megakernel with a copy traces with (gpu/megakernel_path.h): the binary BVH over `geom`.
 * Passed by value to the CUDA kernel: device-safe data only, every pointer into the copy's
 * blocks (scheduler/device_copy.c asserts at compile time that it is exactly these two fields;
 * tests/scenes_mirror_test.c scans its words). */
typedef struct rs_path_tracer {
    rs_bvh_view bvh;
    rs_geom geom;
} rs_path_tracer;

/* What the megakernel (render_pass) reads. */
typedef struct rs_device_scene {
    rs_scene_mirror mirror; /* mirror.scene: a host struct of the copies' pointers */
    const rs_scene *scene;  /* the mirror's struct copied through the ops (the render constants'
                               `scene` on the device) */
    rs_path_tracer tracer;  /* geometry over mirror.scene's arrays, the uploaded BVH copy */
} rs_device_scene;

#ifdef __cplusplus
extern "C" {
#endif
/* rs_alloc_aligned + memcpy, rs_free: a host device's own copy. */
extern const rs_mirror_ops rs_device_copy_host_ops;

/* Copies every array of `g` and of `bvh`'s view through `ops` into *out.  RS_OK, or the error
 * (everything made released, *out zeroed). */
rs_status rs_device_copy_geom(const rs_geom *g, const rs_bvh *bvh, const rs_mirror_ops *ops,
                              rs_device_geom *out);
/* Releases every block of `c` through `ops` (the ones it was made with) and zeroes it.  A zeroed
 * copy is a no-op. */
void rs_device_geom_release(rs_device_geom *c, const rs_mirror_ops *ops);

/* Copies the finalized scene `s` through `ops` for a device whose geometry copy is `geom` (made
 * by rs_device_copy_geom from the scene's geometry: the counts must agree, else RS_ERR_ARG).
 * The result borrows geom->bvh: release it before `geom`. */
rs_status rs_device_copy_scene(const rs_scene *s, const rs_device_geom *geom,
                               const rs_mirror_ops *ops, rs_device_scene *out);
void rs_device_scene_release(rs_device_scene *c, const rs_mirror_ops *ops);
#ifdef __cplusplus
}
#endif

#endif
