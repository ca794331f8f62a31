/* gpu/megakernel_path.h — one path of the CUDA megakernel from the camera to its end, traced with
 * the binary BVH: the loop that the CUDA kernel (gpu/cuda_megakernel.cu) and its host stand-in
 * (gpu/gpu_fallback.c) both run, written once so that the fallback's image is the CUDA device's
 * wherever the two compilers agree (tests/gpu_trace_test.c, render_gpucheck_test).  RS_HD: it
 * compiles as C11 and as CUDA C++.
 *
 * The shading is shading/path.h's (rs_path_start, rs_path_step, rs_path_unoccluded, as the CPU
 * megakernel and the wavefront stages run it); the traversal is accel/bvh_traverse.h's, the
 * trace kernel's.  Counts: one closest-hit ray per segment, one shadow ray per rs_path_step that
 * made one, the deepest segment number. */
#ifndef RS_GPU_MEGAKERNEL_PATH_H
#define RS_GPU_MEGAKERNEL_PATH_H

#include "accel/bvh_traverse.h"
#include "scheduler/device_copy.h"
#include "shading/aov.h"
#include "shading/path.h"

/* Path (pixel, sample) traced on `tr` (device pointers on the GPU); its rays added to *n. */
RS_HD rs_vec3 rs_gpu_path_radiance(const rs_render_consts *it, const rs_path_tracer *tr,
                                   uint32_t pixel, uint32_t sample, rs_path_counts *n)
{
    rs_path p;
    rs_path_start(it, pixel, sample, &p);
    for (;;) {
        rs_hit h;
        uint32_t made;
        rs_bvh_closest(&tr->bvh, &tr->geom, p.ray, &h);
        ++n->closest;
        if (p.bounce > n->max_bounce)
            n->max_bounce = p.bounce;
        made = rs_path_step(it, &p, &h);
        if (made & RS_SHADE_SHADOW) {
            ++n->shadow;
            if (!rs_bvh_occluded(&tr->bvh, &tr->geom, p.shadow))
                rs_path_unoccluded(&p);
        }
        if (!(made & RS_SHADE_NEXT))
            return rs_path_result(p.ps.radiance, p.ps.flags);
    }
}

/* What path (pixel, sample)'s camera ray shows at its first hit, for the film's passes: the
 * camera ray and its closest hit as rs_gpu_path_radiance traces them (the same bits), then
 * rs_path_aux_at.  Its own kernel on the GPU, so that the megakernel does not carry the
 * passes' code. */
RS_HD rs_path_aux rs_gpu_path_aux(const rs_render_consts *it, const rs_path_tracer *tr,
                                  uint32_t pixel, uint32_t sample)
{
    rs_path p;
    rs_hit h;
    rs_path_start(it, pixel, sample, &p);
    rs_bvh_closest(&tr->bvh, &tr->geom, p.ray, &h);
    return rs_path_aux_at(it, &p.ray, &h, &p.ps);
}

#endif
