/* bench/instance_bench.c — what the two-level BVH buys and costs: a forest of K x K placed copies
 * of one generated mesh (a bumpy sphere of T triangles, written as an OBJ with normals next to a
 * scene file, so no model file is needed), loaded and rendered
 *   instanced  top-level instances of a group of triangles: one prototype, one shared bottom level
 *   flattened  the same scene after rs_scene_flatten_instances (--flatten-instances): every
 *              triangle copied, one BVH over them all
 * Both must give the same image bit for bit (checked on the first run).  For each it reports the
 * medians over interleaved runs of the load (parse, mesh import, placement or copies, finalize),
 * the BVH build, the render (stream engine, one CPU device, the widest traversal), and the
 * memory the triangles and BVH take; then flattened / instanced ratios.
 *
 *   instance_bench [--quick] [--runs N] [--grid K] [--tris T] [--width N] [--spp N]
 *                  [--threads N] */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench_render.h"
#include "machine.h"
#include "scenes/scene_json.h"

#define MAX_RUNS 15

/* A bumpy sphere of about `tris` triangles with vertex normals, as an OBJ. */
static int write_mesh(const char *path, uint32_t tris)
{
    uint32_t n = (uint32_t)sqrt(tris / 2.0), i, j;
    FILE *f = fopen(path, "w");
    if (!f)
        return 0;
    n = n < 4 ? 4 : n;
    for (i = 0; i <= n; ++i)
        for (j = 0; j <= n; ++j) {
            double th = 3.14159265358979 * i / n, ph = 2 * 3.14159265358979 * j / n;
            double r = 0.45 * (1 + 0.08 * sin(7 * th) * cos(5 * ph));
            double x = sin(th) * cos(ph), y = cos(th), z = sin(th) * sin(ph);
            fprintf(f, "v %.6f %.6f %.6f\nvn %.6f %.6f %.6f\n", r * x, 0.5 + r * y, r * z, x, y,
                    z);
        }
    for (i = 0; i < n; ++i)
        for (j = 0; j < n; ++j) {
            uint32_t a = i * (n + 1) + j + 1, b = a + 1, c = a + n + 1, d = c + 1;
            fprintf(f, "f %u//%u %u//%u %u//%u\nf %u//%u %u//%u %u//%u\n", a, a, c, c, b, b, b,
                    b, c, c, d, d);
        }
    return fclose(f) == 0;
}

static int write_scene(const char *path, uint32_t grid)
{
    uint32_t i, j;
    FILE *f = fopen(path, "w");
    if (!f)
        return 0;
    fprintf(f, "{\"camera\":{\"from\":[0,%g,%g],\"at\":[0,0,0],\"vfov\":40},\n"
               "\"background\":{\"horizon\":[0.8,0.85,0.9],\"zenith\":[0.3,0.5,0.9]},\n"
               "\"materials\":{\"ground\":{\"type\":\"lambertian\",\"albedo\":[0.5,0.5,0.5]},\n"
               "\"bark\":{\"type\":\"disney_diffuse\",\"albedo\":[0.5,0.35,0.2],\"roughness\":0.6},\n"
               "\"sun\":{\"type\":\"light\",\"emission\":[12,11,10]}},\n"
               "\"groups\":{\"tree\":[{\"type\":\"mesh\",\"file\":\"mesh.obj\",\"material\":\"bark\"}]},\n"
               "\"objects\":[\n"
               "{\"type\":\"quad\",\"q\":[-%u,0,%u],\"u\":[%u,0,0],\"v\":[0,0,-%u],\"material\":\"ground\"},\n"
               "{\"type\":\"quad\",\"q\":[-2,%u,-2],\"u\":[4,0,0],\"v\":[0,0,4],\"material\":\"sun\"}",
            0.9 * grid, 1.1 * grid, grid, grid, 2 * grid, 2 * grid, 2 * grid);
    for (i = 0; i < grid; ++i)
        for (j = 0; j < grid; ++j)
            fprintf(f, ",\n{\"type\":\"instance\",\"group\":\"tree\",\"transform\":[{\"scale\":%g},"
                       "{\"rotate\":[0,%u,0]},{\"translate\":[%g,0,%g]}]}",
                    0.7 + 0.05 * ((i * 7 + j * 3) % 7), (i * 37 + j * 53) % 360,
                    (double)i - 0.5 * (grid - 1), (double)j - 0.5 * (grid - 1));
    fprintf(f, "]}\n");
    return fclose(f) == 0;
}

typedef struct sample {
    double load_s, build_s, render_s;
    double bytes;
} sample;

/* One load, build and render of the scene, instanced or flattened. */
static int run_once(const char *path, int flatten, const br_config *c, float *rgb, sample *out)
{
    rs_scene *s = NULL;
    rs_geom g;
    rs_bvh *bvh = NULL;
    rs_bvh_build_opts bo;
    rs_render_stats stats;
    double t0 = rs_now_s();
    int ok;
    if (rs_scene_load_json(path, &s) != RS_OK ||
        (flatten && (rs_scene_flatten_instances(s) != RS_OK || rs_scene_finalize(s) != RS_OK))) {
        fprintf(stderr, "instance_bench: %s\n", rs_error_message());
        rs_scene_destroy(s);
        return 0;
    }
    out->load_s = rs_now_s() - t0;
    g = rs_scene_geom(s);
    memset(&bo, 0, sizeof bo);
    bo.builder.method = RS_BVH_SAH;
    bo.leaf_block = bo.max_leaf = rs_bvh_wide_leaf_size(0, &g);
    t0 = rs_now_s();
    if (rs_bvh_build(&g, &bo, &bvh) != RS_OK) {
        fprintf(stderr, "instance_bench: %s\n", rs_error_message());
        rs_scene_destroy(s);
        return 0;
    }
    out->build_s = rs_now_s() - t0;
    /* the triangles (with materials, UVs, normals) and the trees */
    out->bytes = (double)(s->n_tris + s->n_inst_tris) *
                     (sizeof(rs_tri) + sizeof(uint32_t) + (s->tri_uv || s->inst_tri_uv ? 24 : 0) +
                      (s->tri_normal || s->inst_tri_normal ? 36 : 0)) +
                 (double)s->n_instances * sizeof(rs_instance) * 2 +
                 (double)bvh->n_nodes * sizeof(rs_bvh_node) + bvh->n_prims * 4.0 +
                 (double)bvh->n_blas_nodes * sizeof(rs_bvh_node) + s->n_inst_tris * 4.0;
    t0 = rs_now_s();
    ok = br_render("instance_bench", s, &g, bvh, c, rgb, &stats);
    out->render_s = rs_now_s() - t0;
    rs_bvh_destroy(bvh);
    rs_scene_destroy(s);
    return ok;
}

int main(int argc, char **argv)
{
    int quick = 0, runs = 5, r, i, k;
    uint32_t grid = 8, tris = 20000;
    br_config c;
    char dir[] = "/tmp/rs_instance_bench_XXXXXX", mesh[128], scene[128];
    sample smp[2][MAX_RUNS];
    float *rgb[2];
    BR_SKIP_NO_SCENE_FILES(argv[0]);
    memset(&c, 0, sizeof c);
    c.width = 320;
    c.height = 240;
    c.spp = 8;
    c.sampling = RS_SAMPLING_MIS;
    c.threads = 1;
    for (i = 1; i < argc; ++i) {
        if (strcmp(argv[i], "--quick") == 0)
            quick = 1;
        else if (i + 1 < argc && strcmp(argv[i], "--runs") == 0)
            runs = atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--grid") == 0)
            grid = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--tris") == 0)
            tris = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--width") == 0)
            c.width = (uint32_t)atoi(argv[++i]), c.height = c.width * 3 / 4;
        else if (i + 1 < argc && strcmp(argv[i], "--spp") == 0)
            c.spp = (uint32_t)atoi(argv[++i]);
        else if (i + 1 < argc && strcmp(argv[i], "--threads") == 0)
            c.threads = atoi(argv[++i]);
        else {
            fprintf(stderr, "usage: instance_bench [--quick] [--runs N] [--grid K] [--tris T] "
                            "[--width N] [--spp N] [--threads N]\n");
            return 2;
        }
    }
    if (quick) {
        runs = 1, grid = 3, tris = 2000;
        c.width = 64, c.height = 48, c.spp = 2;
    }
    if (runs < 1 || runs > MAX_RUNS || grid < 1 || grid > 64 || tris < 32 || c.width < 8 ||
        c.spp < 1 || c.threads < 1) {
        fprintf(stderr, "instance_bench: runs 1..%d, grid 1..64, tris >= 32, width >= 8\n",
                MAX_RUNS);
        return 2;
    }
    if (!mkdtemp(dir))
        return 1;
    snprintf(mesh, sizeof mesh, "%s/mesh.obj", dir);
    snprintf(scene, sizeof scene, "%s/scene.json", dir);
    if (!write_mesh(mesh, tris) || !write_scene(scene, grid))
        return 1;
    rgb[0] = (float *)malloc(sizeof(float) * 3 * c.width * c.height);
    rgb[1] = (float *)malloc(sizeof(float) * 3 * c.width * c.height);
    if (!rgb[0] || !rgb[1])
        return 1;

    rs_bench_print_machine(stdout);
    printf("settings: %ux%u instances of a %u-triangle mesh (%u triangles placed), %ux%u, %u spp, "
           "mis, %d thread%s, stream engine, %u-wide traversal; medians of %d interleaved runs\n\n",
           grid, grid, 2 * (uint32_t)sqrt(tris / 2.0) * (uint32_t)sqrt(tris / 2.0),
           grid * grid * 2 * (uint32_t)sqrt(tris / 2.0) * (uint32_t)sqrt(tris / 2.0), c.width,
           c.height, c.spp, c.threads, c.threads == 1 ? "" : "s", rs_bvh8_supported() ? 8u : 4u,
           runs);
    for (r = 0; r < runs; ++r)
        for (k = 0; k < 2; ++k) {
            int m = (r & 1) ? 1 - k : k; /* alternate which goes first */
            if (!run_once(scene, m, &c, r == 0 ? rgb[m] : NULL, &smp[m][r]))
                return 1;
        }
    if (memcmp(rgb[0], rgb[1], sizeof(float) * 3 * c.width * c.height) != 0) {
        fprintf(stderr, "instance_bench: the instanced and flattened images differ\n");
        return 1;
    }
    {
        static const char *const names[2] = {"instanced", "flattened"};
        double med[2][4];
        for (k = 0; k < 2; ++k) {
            double v[MAX_RUNS];
            for (i = 0; i < 4; ++i) {
                for (r = 0; r < runs; ++r)
                    v[r] = i == 0   ? smp[k][r].load_s
                           : i == 1 ? smp[k][r].build_s
                           : i == 2 ? smp[k][r].render_s
                                    : smp[k][r].bytes;
                med[k][i] = rs_bench_median(v, runs);
            }
        }
        printf("%-10s %10s %10s %10s %12s\n", "", "load s", "BVH s", "render s", "memory MB");
        for (k = 0; k < 2; ++k)
            printf("%-10s %10.3f %10.3f %10.3f %12.2f\n", names[k], med[k][0], med[k][1],
                   med[k][2], med[k][3] / 1e6);
        printf("%-10s %10.2f %10.2f %10.2f %12.2f   (flattened / instanced)\n", "ratio",
               med[1][0] / med[0][0], med[1][1] / med[0][1], med[1][2] / med[0][2],
               med[1][3] / med[0][3]);
        printf("\nsame image bit for bit: yes\n");
    }
    free(rgb[0]);
    free(rgb[1]);
    unlink(mesh);
    unlink(scene);
    rmdir(dir);
    return 0;
}
