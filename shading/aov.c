/* shading/aov.c — see aov.h. */
#include "shading/aov.h"

#include <math.h>

void rs_aov_render(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                   uint32_t spp, int threads, float *albedo, float *normal, float *depth)
{
    uint32_t n = spp < RS_AOV_SPP ? spp : RS_AOV_SPP;
    long p, npix = (long)it->npix;
    if (n == 0)
        n = 1;
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads > 0 ? threads : 1)
    for (p = 0; p < npix; ++p) {
        rs_vec3 a = rs_v3_splat(0.0f), nsum = rs_v3_splat(0.0f);
        double dsum = 0;
        uint32_t s, hits = 0;
        for (s = 0; s < n; ++s) {
            rs_path_state ps;
            rs_ray r = rs_path_begin_at(it, (uint32_t)p, s, NULL, &ps);
            rs_hit h;
            rs_vec3 al, nr;
            float d;
            rs_bvh_closest(bvh, g, r, &h);
            rs_path_aov(it, &r, &h, &al, &nr, &d);
            a = rs_v3_add(a, al);
            nsum = rs_v3_add(nsum, nr);
            if (isfinite(d)) {
                dsum += d;
                ++hits;
            }
        }
        if (albedo) {
            albedo[3 * p] = a.x / (float)n;
            albedo[3 * p + 1] = a.y / (float)n;
            albedo[3 * p + 2] = a.z / (float)n;
        }
        if (normal) {
            /* the mean direction (zero where every ray missed) */
            float l = rs_v3_length(nsum);
            rs_vec3 u = l > 0.0f ? rs_v3_scale(nsum, 1.0f / l) : nsum;
            normal[3 * p] = u.x;
            normal[3 * p + 1] = u.y;
            normal[3 * p + 2] = u.z;
        }
        if (depth)
            depth[p] = hits ? (float)(dsum / hits) : INFINITY;
    }
}
