/* shading/aov.c — see aov.h. */
#include "shading/aov.h"

#include <math.h>
#include <string.h>

#include "core/alloc.h"

/* The largest component of |e|: how bright a pixel's direct emission is, sign aside. */
static float brightness(const float *e)
{
    return rs_fmaxf(rs_fmaxf(fabsf(e[0]), fabsf(e[1])), fabsf(e[2]));
}

/* The mean direct emission of pixel p over samples [0, n) of the sampler in `it`. */
static rs_vec3 mean_emission(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                             uint32_t p, uint32_t n)
{
    double sum[3] = {0, 0, 0};
    uint32_t s;
    for (s = 0; s < n; ++s) {
        rs_path_state ps;
        rs_ray r = rs_path_begin_at(it, p, s, NULL, &ps);
        rs_hit h;
        rs_vec3 e;
        rs_bvh_closest(bvh, g, r, &h);
        e = rs_path_first_emission(it, &r, &h, &ps);
        sum[0] += e.x;
        sum[1] += e.y;
        sum[2] += e.z;
    }
    if (n == 0)
        return rs_v3_splat(0.0f);
    return rs_v3((float)(sum[0] / n), (float)(sum[1] / n), (float)(sum[2] / n));
}

/* Whether pixel p's neighbourhood of radius rad holds means of the direct emission that differ
 * by more than 5% of its brightest. */
static int on_edge(const rs_render_consts *it, const float *e, long p, int rad)
{
    int x = (int)(p % it->width), y = (int)(p / it->width), dx, dy;
    float mn = INFINITY, mx = 0.0f;
    for (dy = -rad; dy <= rad; ++dy)
        for (dx = -rad; dx <= rad; ++dx) {
            int xx = x + dx, yy = y + dy;
            float b;
            if (xx < 0 || yy < 0 || xx >= (int)it->width || yy >= (int)it->height)
                continue;
            b = brightness(&e[3 * ((long)yy * it->width + xx)]);
            mn = b < mn ? b : mn;
            mx = b > mx ? b : mx;
        }
    return mx > 0.0f && mx - mn > 0.05f * mx;
}

size_t rs_aov_refine(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                     const uint32_t *count, int threads, const float *e_render, float *e_fine)
{
    long p, npix = (long)it->npix;
    int nt = threads > 0 ? threads : 1;
    int rad = (int)ceilf(it->filter.width * 0.5f) + 1;
    unsigned char *edge = (unsigned char *)rs_alloc((size_t)npix, 1);
    size_t n_edge = 0, refined = 0;
    uint32_t fine_n = RS_AOV_EMISSION_SPP;
    rs_render_consts fine = *it;
    memcpy(e_fine, e_render, (size_t)npix * 3 * sizeof(float));
    if (!edge) /* no room to find edges: the render's own samples everywhere */
        return 0;
#pragma omp parallel for schedule(static) num_threads(nt) reduction(+ : n_edge)
    for (p = 0; p < npix; ++p) {
        edge[p] = (unsigned char)on_edge(it, e_render, p, rad);
        n_edge += edge[p];
    }
    /* at most 64 camera rays a pixel on average for the better estimates */
    if (n_edge && (double)n_edge * fine_n > 64.0 * (double)npix)
        fine_n = (uint32_t)(64.0 * (double)npix / (double)n_edge);
    fine.sampler = RS_SAMPLER_SOBOL;
    fine.spp = fine_n;
    fine.seed = it->seed ^ 0x5d0c1a3e9b7f4c21ull; /* numbers of their own, not the render's */
#pragma omp parallel for schedule(dynamic, 16) num_threads(nt) reduction(+ : refined)
    for (p = 0; p < npix; ++p)
        if (edge[p] && fine_n > count[p]) {
            rs_vec3 v = mean_emission(&fine, bvh, g, (uint32_t)p, fine_n);
            e_fine[3 * p] = v.x;
            e_fine[3 * p + 1] = v.y;
            e_fine[3 * p + 2] = v.z;
            ++refined;
        }
    rs_free(edge);
    return refined;
}
