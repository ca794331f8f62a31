/* shading/aov.c — see aov.h. */
#include "shading/aov.h"

#include <math.h>
#include <string.h>

#include "core/alloc.h"

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

/* The largest component of |e|: how bright a sample's direct emission is, sign aside. */
static float brightness(rs_vec3 e)
{
    return rs_fmaxf(rs_fmaxf(fabsf(e.x), fabsf(e.y)), fabsf(e.z));
}

/* The mean direct emission of pixel p over samples [0, n) of the sampler in `it`; lo and hi (may
 * be NULL) the least and greatest brightness among them. */
static rs_vec3 mean_emission(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                             uint32_t p, uint32_t n, float *lo, float *hi)
{
    double sum[3] = {0, 0, 0};
    float l0 = 0.0f, l1 = 0.0f;
    uint32_t s;
    for (s = 0; s < n; ++s) {
        rs_path_state ps;
        rs_ray r = rs_path_begin_at(it, p, s, NULL, &ps);
        rs_hit h;
        rs_vec3 e;
        float b;
        rs_bvh_closest(bvh, g, r, &h);
        e = rs_path_first_emission(it, &r, &h, &ps);
        sum[0] += e.x;
        sum[1] += e.y;
        sum[2] += e.z;
        b = brightness(e);
        l0 = s == 0 || b < l0 ? b : l0;
        l1 = s == 0 || b > l1 ? b : l1;
    }
    if (lo)
        *lo = l0;
    if (hi)
        *hi = l1;
    if (n == 0)
        return rs_v3_splat(0.0f);
    return rs_v3((float)(sum[0] / n), (float)(sum[1] / n), (float)(sum[2] / n));
}

static void put3(float *dst, long p, rs_vec3 v)
{
    dst[3 * p] = v.x;
    dst[3 * p + 1] = v.y;
    dst[3 * p + 2] = v.z;
}

size_t rs_aov_emission(const rs_render_consts *it, const rs_bvh_view *bvh, const rs_geom *g,
                       const uint32_t *count, uint32_t spp, int threads, float *e_render,
                       float *e_fine)
{
    long p, npix = (long)it->npix;
    int nt = threads > 0 ? threads : 1;
    int rad = (int)ceilf(it->filter.width * 0.5f) + 1;
    float *lo = (float *)rs_alloc((size_t)npix * 2, sizeof(float));
    float *hi = lo + npix;
    unsigned char *edge = (unsigned char *)rs_alloc((size_t)npix, 1);
    size_t n_edge = 0, refined = 0;
    uint32_t fine_n = RS_AOV_EMISSION_SPP;
    rs_render_consts fine = *it;
    if (!lo || !edge) { /* no room to find edges: the render's own samples everywhere */
        rs_free(lo);
        rs_free(edge);
        lo = NULL;
        edge = NULL;
    }
#pragma omp parallel for schedule(dynamic, 64) num_threads(nt)
    for (p = 0; p < npix; ++p) {
        float l0, l1;
        put3(e_render, p, mean_emission(it, bvh, g, (uint32_t)p, count ? count[p] : spp, &l0, &l1));
        if (lo) {
            lo[p] = l0;
            hi[p] = l1;
        }
    }
    memcpy(e_fine, e_render, (size_t)npix * 3 * sizeof(float));
    if (!lo)
        return 0;
    /* the edges: a neighbourhood within the filter's reach (and a pixel more, for a neighbour
     * whose samples missed a sliver) whose samples differ by more than 5% of its brightest */
#pragma omp parallel for schedule(static) num_threads(nt) reduction(+ : n_edge)
    for (p = 0; p < npix; ++p) {
        int x = (int)(p % it->width), y = (int)(p / it->width), dx, dy;
        float mn = INFINITY, mx = 0.0f;
        for (dy = -rad; dy <= rad; ++dy)
            for (dx = -rad; dx <= rad; ++dx) {
                int xx = x + dx, yy = y + dy;
                long q;
                if (xx < 0 || yy < 0 || xx >= (int)it->width || yy >= (int)it->height)
                    continue;
                q = (long)yy * it->width + xx;
                mn = lo[q] < mn ? lo[q] : mn;
                mx = hi[q] > mx ? hi[q] : mx;
            }
        edge[p] = mx > 0.0f && mx - mn > 0.05f * mx;
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
        if (edge[p] && fine_n > (count ? count[p] : spp)) {
            put3(e_fine, p, mean_emission(&fine, bvh, g, (uint32_t)p, fine_n, NULL, NULL));
            ++refined;
        }
    rs_free(lo);
    rs_free(edge);
    return refined;
}
