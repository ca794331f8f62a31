/* tests/gpu_trace_test.c — the CUDA device answers like the CPU device (same RS_HD traversal),
 * also from page-locked batches (host_alloc: DMA without staging) and with moving spheres (the
 * device's copy of sphere_motion), and the CUDA megakernel renders like the CPU megakernel (same
 * RS_HD path code), on the Cornell box, the materials scene, RTNW's bouncing spheres (motion
 * blur), a mesh (builtin:cornell-teapot; skipped with a message where the shared models or
 * the mesh importer are missing) and builtin:gpucheck (every device function of the megakernel).
 * Runs only where a CUDA device exists; elsewhere it prints why and exits 77 (CTest: skipped).
 * Hits, and so the stream integrator's images, agree with the CPU's bit for bit (--fmad=false),
 * and so do the megakernel's images (test_gpucheck_megakernel_vs_cpu says why: core/hdmath.h,
 * whose functions test_hdmath_device_bits compares one by one).
 * scripts/gpu-check.sh runs it on a lent GPU machine. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/rng.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"
#include "scenes/builtin.h"
#include "scheduler/sched.h"
#include "gpucheck_util.h"
#include "hdmath_eval.h"
#include "render_util.h"
#include "test_rand.h"

static void trace_with(rs_device *d, const rs_geom *g, const rs_bvh *bvh, rs_trace_batch *b,
                       uint32_t chunk)
{
    rs_sched *s;
    rs_sched_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.chunk_size = chunk;
    assert_int_equal(rs_device_upload(d, g, bvh), RS_OK);
    assert_int_equal(rs_sched_create(&d, 1, &cfg, &s), RS_OK);
    assert_int_equal(rs_sched_trace(s, b), RS_OK);
    rs_sched_destroy(s);
}

/* A copy of `rays` (n of them) in arrays from d's host_alloc, with room for the answers: a batch
 * with pinned = 1.  0 if the device has no host_alloc or it ran short. */
static int pinned_batch(rs_device *d, rs_trace_batch *b, const rs_ray_soa *rays, uint32_t n)
{
    int ok = d->ops->host_alloc != NULL;
    memset(b, 0, sizeof *b);
    if (!ok)
        return 0;
#define RS_PIN(type, name)                                                                         \
  b->rays.name = (type *)d->ops->host_alloc(d, n * sizeof(type));                                  \
  ok = ok && b->rays.name;                                                                         \
  if (b->rays.name)                                                                                \
    memcpy(b->rays.name, rays->name, n * sizeof(type));
    RS_RAY_FIELDS(RS_PIN)
#undef RS_PIN
#define RS_PIN(type, name)                                                                         \
  b->hits.name = (type *)d->ops->host_alloc(d, n * sizeof(type));                                  \
  ok = ok && b->hits.name;
    RS_HIT_FIELDS(RS_PIN)
#undef RS_PIN
    b->occluded = (uint8_t *)d->ops->host_alloc(d, n);
    b->rays.count = b->rays.capacity = b->hits.capacity = n;
    b->count = n;
    b->pinned = 1;
    return ok && b->occluded;
}

static void pinned_batch_free(rs_device *d, rs_trace_batch *b)
{
#define RS_UNPIN(type, name) d->ops->host_free(d, b->rays.name);
    RS_RAY_FIELDS(RS_UNPIN)
#undef RS_UNPIN
#define RS_UNPIN(type, name) d->ops->host_free(d, b->hits.name);
    RS_HIT_FIELDS(RS_UNPIN)
#undef RS_UNPIN
    d->ops->host_free(d, b->occluded);
    memset(b, 0, sizeof *b);
}

/* Two devices over one scene and one ray stream: the CPU device with the binary kernel (the code
 * the CUDA kernel runs) and the CUDA device. */
typedef struct pair {
    rs_scene *scene;
    rs_bvh *bvh;
    rs_geom g;
    rs_ray_soa rays;
    rs_hit_soa h_cpu, h_gpu;
    uint8_t *o_cpu, *o_gpu;
    rs_device *cpu, *gpu;
    rs_trace_batch b;
    uint32_t n;
} pair;

/* The scene, its BVH, both devices and room for n rays (the caller fills pair.rays). */
static void pair_init(pair *p, const char *scene, uint32_t n)
{
    rs_cpu_device_opts co;
    memset(p, 0, sizeof *p);
    p->n = n;
    assert_int_equal(rs_builtin_create(scene, &p->scene), RS_OK);
    p->g = rs_scene_geom(p->scene);
    assert_int_equal(rs_bvh_build(&p->g, NULL, &p->bvh), RS_OK);
    assert_int_equal(rs_ray_soa_init(&p->rays, n), RS_OK);
    assert_int_equal(rs_hit_soa_init(&p->h_cpu, n), RS_OK);
    assert_int_equal(rs_hit_soa_init(&p->h_gpu, n), RS_OK);
    p->o_cpu = (uint8_t *)malloc(n);
    p->o_gpu = (uint8_t *)malloc(n);
    assert_non_null(p->o_cpu);
    assert_non_null(p->o_gpu);
    memset(&co, 0, sizeof co);
    co.threads = 2;
    co.bvh_width = 2;
    assert_int_equal(rs_cpu_device_create_opts(&co, &p->cpu), RS_OK);
    assert_int_equal(rs_gpu_device_create(0, &p->gpu), RS_OK);
    print_message("GPU device: %s\n", p->gpu->name);
    p->rays.count = n;
    p->b.count = n;
}

/* Closest hits on both devices, bit for bit: the traversal is compiled with --fmad=false (and the
 * host with -ffp-contract=off), so both round every operation the same way. */
static void pair_closest(pair *p)
{
    uint32_t i, mismatched = 0;
    p->b.rays = p->rays;
    p->b.kind = RS_TRACE_CLOSEST;
    p->b.hits = p->h_cpu;
    trace_with(p->cpu, &p->g, p->bvh, &p->b, 65536);
    p->b.hits = p->h_gpu;
    trace_with(p->gpu, &p->g, p->bvh, &p->b, 65536);
    for (i = 0; i < p->n; ++i)
        mismatched += p->h_cpu.prim[i] != p->h_gpu.prim[i] ||
                      memcmp(&p->h_cpu.t[i], &p->h_gpu.t[i], sizeof(float)) != 0 ||
                      memcmp(&p->h_cpu.u[i], &p->h_gpu.u[i], sizeof(float)) != 0 ||
                      memcmp(&p->h_cpu.v[i], &p->h_gpu.v[i], sizeof(float)) != 0;
    print_message("%s: closest hits that differ in any bit: %u of %u\n", p->scene->name, mismatched,
                  p->n);
    assert_int_equal(mismatched, 0);
}

/* The same rays as shadow rays of length tmax: the same answers on both devices. */
static void pair_occlusion(pair *p, float tmax)
{
    uint32_t i;
    p->b.kind = RS_TRACE_OCCLUDED;
    for (i = 0; i < p->n; ++i)
        p->rays.tmax[i] = tmax;
    p->b.rays = p->rays;
    p->b.occluded = p->o_cpu;
    trace_with(p->cpu, &p->g, p->bvh, &p->b, 10000);
    p->b.occluded = p->o_gpu;
    trace_with(p->gpu, &p->g, p->bvh, &p->b, 10000);
    assert_memory_equal(p->o_cpu, p->o_gpu, p->n);
}

static void pair_free(pair *p)
{
    rs_device_destroy(p->cpu);
    rs_device_destroy(p->gpu);
    rs_ray_soa_free(&p->rays);
    rs_hit_soa_free(&p->h_cpu);
    rs_hit_soa_free(&p->h_gpu);
    free(p->o_cpu);
    free(p->o_gpu);
    rs_bvh_destroy(p->bvh);
    rs_scene_destroy(p->scene);
}

static void test_gpu_matches_cpu(void **state)
{
    pair p;
    uint32_t i, n = 200000;
    (void)state;
    pair_init(&p, "cornell", n);
    for (i = 0; i < n; ++i) {
        rs_rng_f4 r = rs_rng_float4(7, i, 0, 0, 0);
        rs_ray ray;
        ray.o = rs_v3(20.0f + 515.0f * r.v[0], 20.0f + 515.0f * r.v[1], 20.0f + 515.0f * r.v[2]);
        ray.d = rs_v3_normalize(rs_v3(r.v[3] - 0.5f, r.v[2] - 0.5f, r.v[1] - 0.5f));
        ray.tmin = 0.0f;
        ray.time = 0.0f;
        ray.tmax = 3.4e38f;
        rs_ray_soa_set(&p.rays, i, &ray, i);
    }
    pair_closest(&p);
    /* the GPU answers the same at every chunk size: one piece, four pieces over the two streams
     * (a chunk of 2^20 rays is cut into pieces of 50000), adaptive */
    {
        static const uint32_t chunks[] = {1000, 1u << 20, 0};
        rs_hit_soa h2;
        size_t k;
        assert_int_equal(rs_hit_soa_init(&h2, n), RS_OK);
        for (k = 0; k < sizeof chunks / sizeof chunks[0]; ++k) {
            p.b.hits = h2;
            trace_with(p.gpu, &p.g, p.bvh, &p.b, chunks[k]);
            assert_memory_equal(h2.prim, p.h_gpu.prim, n * sizeof *h2.prim);
            assert_memory_equal(h2.t, p.h_gpu.t, n * sizeof *h2.t);
        }
        rs_hit_soa_free(&h2);
    }
    /* a batch in the device's page-locked memory (host_alloc): copied by DMA straight from and
     * to its arrays, the same answers */
    {
        rs_trace_batch pb;
        memset(&pb, 0, sizeof pb);
        assert_true(pinned_batch(p.gpu, &pb, &p.rays, n));
        pb.kind = RS_TRACE_CLOSEST;
        trace_with(p.gpu, &p.g, p.bvh, &pb, 1u << 20);
        assert_memory_equal(pb.hits.prim, p.h_gpu.prim, n * sizeof *p.h_gpu.prim);
        assert_memory_equal(pb.hits.t, p.h_gpu.t, n * sizeof *p.h_gpu.t);
        trace_with(p.gpu, &p.g, p.bvh, &pb, 3000); /* pieces that start at odd offsets */
        assert_memory_equal(pb.hits.prim, p.h_gpu.prim, n * sizeof *p.h_gpu.prim);
        pinned_batch_free(p.gpu, &pb);
    }
    pair_occlusion(&p, 100.0f);
    pair_free(&p);
}

/* Moving spheres on the device: RTNW's bouncing spheres, rays from inside the scene's bounds at
 * random times in the shutter.  The device traces with its own copy of sphere_motion (a host
 * pointer left in the copy would fault here); closest hits and occlusion agree with the CPU's. */
static void test_gpu_motion_matches_cpu(void **state)
{
    pair p;
    uint32_t i, n = 100000, moving_hits = 0;
    rs_vec3 lo, hi;
    (void)state;
    pair_init(&p, "bouncing-spheres", n);
    assert_non_null(p.scene->sphere_motion);
    assert_true(p.g.time1 > p.g.time0);
    /* among the small spheres (a grid over x, z in [-11, 11]), above the ground sphere */
    lo = rs_v3(-12.0f, 0.05f, -12.0f);
    hi = rs_v3(12.0f, 2.0f, 12.0f);
    for (i = 0; i < n; ++i) {
        rs_rng_f4 r = rs_rng_float4(9, i, 0, 0, 0), q = rs_rng_float4(9, i, 1, 0, 0);
        rs_ray ray;
        ray.o = rs_v3(lo.x + (hi.x - lo.x) * r.v[0], lo.y + (hi.y - lo.y) * r.v[1],
                      lo.z + (hi.z - lo.z) * r.v[2]);
        ray.d = rs_v3_normalize(rs_v3(q.v[0] - 0.5f, q.v[1] - 0.5f, q.v[2] - 0.5f));
        ray.tmin = 0.0f;
        ray.tmax = 3.4e38f;
        ray.time = p.g.time0 + (p.g.time1 - p.g.time0) * r.v[3];
        rs_ray_soa_set(&p.rays, i, &ray, i);
    }
    pair_closest(&p);
    for (i = 0; i < n; ++i)
        moving_hits += p.h_cpu.prim[i] < p.scene->n_spheres &&
                       !rs_v3_is_zero(p.scene->sphere_motion[p.h_cpu.prim[i]]);
    print_message("bouncing-spheres: %u hits on moving spheres\n", moving_hits);
    assert_true(moving_hits > n / 100);
    pair_occlusion(&p, 2.0f);
    pair_free(&p);
}

/* The LBVH with its Morton codes and sort on the GPU is the host LBVH, bit for bit: a random
 * soup of 300000 triangles and the Cornell box. */
static void test_gpu_lbvh(void **state)
{
    const uint32_t n = 300000;
    rs_tri *tris = (rs_tri *)malloc(n * sizeof *tris);
    rs_geom g;
    rs_bvh_build_opts o;
    rs_bvh *host, *gpu;
    uint32_t i;
    int ordinal = 0;
    (void)state;
    for (i = 0; i < n; ++i) {
        rs_rng_f4 a = rs_rng_float4(11, i, 0, 0, 0), b = rs_rng_float4(11, i, 1, 0, 0);
        rs_vec3 c = rs_v3(100.0f * a.v[0], 100.0f * a.v[1], 100.0f * a.v[2]);
        memset(&tris[i], 0, sizeof tris[i]);
        tris[i].v0 = c;
        tris[i].v1 = rs_v3_add(c, rs_v3(b.v[0], 0.0f, b.v[1]));
        tris[i].v2 = rs_v3_add(c, rs_v3(0.0f, b.v[2], b.v[3]));
    }
    memset(&g, 0, sizeof g);
    g.tris = tris;
    g.n_tris = n;
    memset(&o, 0, sizeof o);
    o.builder.method = RS_BVH_LBVH;
    assert_int_equal(rs_bvh_build(&g, &o, &host), RS_OK);
    o.lbvh_sort = rs_gpu_lbvh_sort;
    o.lbvh_sort_user = &ordinal;
    assert_int_equal(rs_bvh_build(&g, &o, &gpu), RS_OK);
    assert_int_equal(host->n_nodes, gpu->n_nodes);
    assert_memory_equal(host->nodes, gpu->nodes, host->n_nodes * sizeof *host->nodes);
    assert_memory_equal(host->prim_ids, gpu->prim_ids, n * sizeof *host->prim_ids);
    rs_bvh_destroy(host);
    rs_bvh_destroy(gpu);
    free(tris);
}

/* 1 if built-in scene `name` can be made here; else prints why (a mesh scene without the shared
 * models, ../shared/models or $RS_MODELS_DIR, or without the mesh importer) and returns 0. */
static int scene_available(const char *name)
{
    rs_scene *s = NULL;
    if (rs_builtin_create(name, &s) == RS_OK) {
        rs_scene_destroy(s);
        return 1;
    }
    print_message("SKIP builtin:%s: %s\n", name, rs_error_message());
    rs_error_clear();
    return 0;
}

/* How far image b is from image a (nf floats each): the largest and the mean absolute difference
 * and the two means. */
typedef struct img_diff {
    double max, mean, mean_a, mean_b;
} img_diff;

static img_diff image_diff(const float *a, const float *b, size_t nf)
{
    img_diff d = {0.0, 0.0, 0.0, 0.0};
    size_t i;
    for (i = 0; i < nf; ++i) {
        double e = fabs((double)a[i] - b[i]);
        d.max = e > d.max ? e : d.max;
        d.mean += e;
        d.mean_a += a[i];
        d.mean_b += b[i];
    }
    d.mean /= (double)nf;
    d.mean_a /= (double)nf;
    d.mean_b /= (double)nf;
    return d;
}

/* Renders on the CPU, on the GPU and on both: the images agree up to float rounding of hit
 * distances (the GPU's own maths can send a path another way).  Prints the measured max and
 * mean absolute differences (issue 5's determinism statement).  The Cornell box, the bouncing
 * spheres (motion blur: moving spheres traced on the device) and a mesh. */
static void test_render_cpu_vs_gpu(void **state)
{
    static const char *scenes[] = {"cornell", "bouncing-spheres", "cornell-teapot"};
    const size_t nf = 64 * 64 * 3;
    size_t k;
    (void)state;
    for (k = 0; k < sizeof scenes / sizeof scenes[0]; ++k) {
        rt_args a = rt_defaults(scenes[k], 64, 16);
        float *cpu, *gpu, *both;
        img_diff dg, db;
        if (!scene_available(scenes[k]))
            continue;
        a.threads = 2;
        cpu = rt_render(&a, NULL);
        a.fallback_only = a.real_gpu = 1;
        gpu = rt_render(&a, NULL);
        a.fallback_only = 0;
        a.with_fallback = 1;
        both = rt_render(&a, NULL);
        assert_non_null(cpu);
        assert_non_null(gpu);
        assert_non_null(both);
        dg = image_diff(cpu, gpu, nf);
        db = image_diff(cpu, both, nf);
        print_message("%s: cpu vs gpu image: max abs diff %.3g, mean abs diff %.3g (mean value "
                      "%.3g); cpu vs cpu+gpu: max %.3g, mean %.3g\n",
                      scenes[k], dg.max, dg.mean, dg.mean_a, db.max, db.mean);
        assert_true(dg.mean <= 0.01 * dg.mean_a);
        assert_true(db.mean <= 0.01 * db.mean_a);
        free(cpu);
        free(gpu);
        free(both);
    }
}

/* The CUDA megakernel (the device's render_pass: one thread per pixel running rs_gpu_path_radiance:
 * shading, light sampling, textures and traversal all on the GPU) against the CPU megakernel on
 * the scenes with every material and texture, the Cornell box, the bouncing spheres (the scene
 * copy's sphere_motion) and a mesh: every pixel bit for bit, as test_gpucheck_megakernel_vs_cpu
 * explains.  Prints the pixels that differ, the max and mean differences and the two image
 * means, so that a failure shows how far off it is. */
static void test_megakernel_cpu_vs_gpu(void **state)
{
    static const char *scenes[] = {"materials", "cornell", "bouncing-spheres", "cornell-teapot"};
    size_t k;
    (void)state;
    for (k = 0; k < sizeof scenes / sizeof scenes[0]; ++k) {
        rt_args a = rt_defaults(scenes[k], 64, 32);
        float *cpu, *gpu;
        img_diff d;
        char what[96];
        uint32_t differ;
        if (!scene_available(scenes[k]))
            continue;
        a.threads = 2;
        a.megakernel = 1;
        cpu = rt_render(&a, NULL);
        a.fallback_only = a.real_gpu = 1; /* the megakernel's passes on CUDA device 0 */
        gpu = rt_render(&a, NULL);
        assert_non_null(cpu);
        assert_non_null(gpu);
        d = image_diff(cpu, gpu, 64 * 64 * 3);
        snprintf(what, sizeof what, "%s megakernel cpu vs cuda", scenes[k]);
        differ = gc_diff_pixels(what, cpu, gpu, 64, 64);
        print_message("%s: max abs diff %.3g, mean abs diff %.3g, means %.5g vs %.5g\n", what,
                      d.max, d.mean, d.mean_a, d.mean_b);
        assert_int_equal(differ, 0);
        free(cpu);
        free(gpu);
    }
}

/* The device as CUDA sees it: the kernels' registers, local memory and block bounds
 * (__launch_bounds__) and the stack limit the device was created with (cudaFuncGetAttributes:
 * the limit must cover every kernel's local memory). */
static void test_gpu_kernel_limits(void **state)
{
    char line[512];
    rs_device *d = NULL;
    (void)state;
    assert_int_equal(rs_gpu_device_create(0, &d), RS_OK);
    assert_int_equal(rs_gpu_describe(0, line, sizeof line), 0);
    print_message("%s\n", line);
    assert_non_null(strstr(line, "stack limit"));
    rs_device_destroy(d);
}

/* builtin:gpucheck (every material, texture, light, primitive and instance; scenes/
 * builtin_gpucheck.c), the stream integrator, every sampling mode: the CPU device, the CUDA
 * device alone, and both in small chunks give one image, bit for bit.  Expected by construction:
 * the stream integrator shades on the host, and the CUDA trace kernel runs the CPU's binary
 * traversal compiled with --fmad=false (IEEE division and square root are nvcc's defaults, and
 * the instances' transforms are double), so its hits are the CPU's bit for bit. */
static void test_gpucheck_stream_bit_exact(void **state)
{
    int c;
    (void)state;
    for (c = 0; c < GC_N_CASES; ++c) {
        rt_args a = gc_args(&gc_cases[c]);
        float *cpu, *img;
        char what[96];
        cpu = rt_render(&a, NULL);
        assert_non_null(cpu);
        a.fallback_only = a.real_gpu = 1;
        img = rt_render(&a, NULL);
        assert_non_null(img);
        snprintf(what, sizeof what, "gpucheck %s stream: cpu vs cuda", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, cpu, img, GC_W, GC_H), 0);
        free(img);
        a.fallback_only = 0;
        a.with_fallback = 1; /* with real_gpu: the CPU device and CUDA device 0 */
        a.chunk_size = 500;
        img = rt_render(&a, NULL);
        assert_non_null(img);
        snprintf(what, sizeof what, "gpucheck %s stream: cpu vs cpu + cuda", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, cpu, img, GC_W, GC_H), 0);
        free(img);
        free(cpu);
    }
}

/* builtin:gpucheck with the megakernel, every sampling mode: the CUDA megakernel (shading,
 * light sampling, textures, traversal all on the GPU) against the CPU's, which is the fallback's
 * and the stream integrator's bit for bit (render_gpucheck_test): every pixel bit for bit, by
 * construction.  --fmad=false makes +, -, *, / and sqrtf round alike on both, and the shading
 * calls no libm function that is not correctly rounded: sines and cosines (direction sampling,
 * the thin lens, GGX visible normals, the map's sampling), powers (Phong, sheen), exponentials
 * (sheen, Beer-Lambert), acos and atan2 (sphere UVs, the map's lookup) are core/hdmath.h's,
 * built from those operations alone (CUDA's and glibc's own are 1-4 ulp off and differ, which
 * made a path's directions differ in their last bits and, now and then, a path go another way
 * at a roulette, Fresnel or lobe decision).  A failure prints the first differing pixel and,
 * to show how far off the image is, the pixels that agree, the means, the mean absolute
 * difference and the worst 8x8 block's relative difference (a function wrong on the GPU shows
 * as a region). */
static void test_gpucheck_megakernel_vs_cpu(void **state)
{
    const uint32_t w = GC_W, h = GC_H, spp = 64;
    int c;
    (void)state;
    for (c = 0; c < GC_N_CASES; ++c) {
        rt_args a = gc_args(&gc_cases[c]);
        float *cpu, *gpu;
        img_diff d;
        uint32_t i, same = 0, bx, by;
        double worst = 0.0;
        char what[96];
        a.spp = spp;
        a.megakernel = 1;
        cpu = rt_render(&a, NULL);
        a.fallback_only = a.real_gpu = 1;
        gpu = rt_render(&a, NULL);
        assert_non_null(cpu);
        assert_non_null(gpu);
        assert_true(gc_image_sane(gpu, w, h));
        for (i = 0; i < w * h; ++i)
            same += memcmp(&cpu[3 * i], &gpu[3 * i], 3 * sizeof(float)) == 0;
        for (by = 0; by + 8 <= h; by += 8)
            for (bx = 0; bx + 8 <= w; bx += 8) {
                double sa = 0.0, sb = 0.0;
                uint32_t x, y, k;
                for (y = by; y < by + 8; ++y)
                    for (x = bx; x < bx + 8; ++x)
                        for (k = 0; k < 3; ++k) {
                            sa += cpu[3 * (y * w + x) + k];
                            sb += gpu[3 * (y * w + x) + k];
                        }
                if (sa > 0.0 && fabs(sa - sb) / sa > worst)
                    worst = fabs(sa - sb) / sa;
            }
        d = image_diff(cpu, gpu, (size_t)w * h * 3);
        print_message("gpucheck %s megakernel cpu vs cuda: %u of %u pixels bit for bit; max abs "
                      "diff %.3g, mean abs diff %.3g, means %.5g vs %.5g, worst 8x8 block %.2f%%\n",
                      gc_cases[c].name, same, w * h, d.max, d.mean, d.mean_a, d.mean_b,
                      100.0 * worst);
        snprintf(what, sizeof what, "gpucheck %s megakernel: cpu vs cuda", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, cpu, gpu, w, h), 0);
        free(cpu);
        free(gpu);
    }
}

/* The CUDA wavefront (gpu/cuda_wavefront.cu: the paths run whole on the GPU, shading included)
 * against the CPU stream engine: `a` rendered both ways gives one image, bit for bit.  Expected
 * where the shading's arithmetic rounds alike on both (--fmad=false); the film's sums are exact
 * integers, so the order of the GPU's atomic adds does not matter. */
static void wavefront_same(const char *what, rt_args a)
{
    float *cpu, *img;
    char label[160];
    cpu = rt_render(&a, NULL);
    assert_non_null(cpu);
    a.fallback_only = a.real_gpu = a.wavefront = 1;
    img = rt_render(&a, NULL);
    assert_non_null(img);
    assert_true(gc_image_sane(img, a.width, a.height));
    snprintf(label, sizeof label, "%s: cpu stream vs cuda wavefront", what);
    assert_int_equal(gc_diff_pixels(label, cpu, img, a.width, a.height), 0);
    free(img);
    a.fallback_only = 0;
    a.with_fallback = 1; /* with real_gpu and wavefront: the CPU's stream engine beside it */
    img = rt_render(&a, NULL);
    assert_non_null(img);
    snprintf(label, sizeof label, "%s: cpu stream vs cpu + cuda wavefront", what);
    assert_int_equal(gc_diff_pixels(label, cpu, img, a.width, a.height), 0);
    free(cpu);
    free(img);
}

/* builtin:gpucheck in every sampling mode and sampler, builtin:many-lights with the light BVH,
 * adaptive sampling (plans over some pixels, the device's copy of them). */
static void test_gpucheck_wavefront_bit_exact(void **state)
{
    int c;
    rt_args a;
    rs_adaptive_stats as;
    (void)state;
    for (c = 0; c < GC_N_CASES; ++c) {
        char what[96];
        snprintf(what, sizeof what, "gpucheck %s", gc_cases[c].name);
        wavefront_same(what, gc_args(&gc_cases[c]));
    }
    a = rt_defaults("many-lights", 64, 8);
    a.threads = 4;
    a.sampler = RS_SAMPLER_SOBOL;
    a.light_sampler = RS_LIGHT_SAMPLER_BVH;
    wavefront_same("many-lights, light BVH", a);
    a = rt_defaults("cornell", 64, 64);
    a.threads = 4;
    a.sampler = RS_SAMPLER_SOBOL;
    a.adaptive.threshold = 0.05;
    a.adaptive.min_spp = 4;
    a.adaptive_out = &as;
    wavefront_same("cornell, adaptive", a);
}

/* The film's passes (shading/film.h: what --aov and --denoise read) written on the GPU: the CUDA
 * wavefront's rs_wf_passes_kernel and the megakernel's rs_megakernel_aux_kernel give the CPU
 * stream engine's passes, all ten planes, bit for bit (builtin:gpucheck: textures, normal maps,
 * instances, an environment map, a thin lens; the Cornell box). */
static void passes_same(const char *what, rt_args a)
{
    size_t n = (size_t)a.width * a.height * 10;
    float *cpu = malloc(n * sizeof(float)), *gpu = malloc(n * sizeof(float)), *img;
    int k;
    assert_true(cpu && gpu);
    a.passes_out = cpu;
    img = rt_render(&a, NULL);
    assert_non_null(img);
    free(img);
    for (k = 0; k < 2; ++k) {
        rt_args b = a;
        size_t i, differ = 0;
        b.passes_out = gpu;
        b.fallback_only = b.real_gpu = 1;
        b.wavefront = k == 0;
        b.megakernel = k == 1;
        img = rt_render(&b, NULL);
        assert_non_null(img);
        free(img);
        for (i = 0; i < n; ++i)
            differ += memcmp(&cpu[i], &gpu[i], sizeof(float)) != 0;
        print_message("%s: passes on the cuda %s: %zu of %zu values differ in any bit\n", what,
                      k == 0 ? "wavefront" : "megakernel", differ, n);
        assert_int_equal(differ, 0);
    }
    free(cpu);
    free(gpu);
}

static void test_gpucheck_passes_bit_exact(void **state)
{
    rt_args a;
    (void)state;
    passes_same("gpucheck", gc_args(&gc_cases[0]));
    a = rt_defaults("cornell", 64, 8);
    a.threads = 4;
    a.sampler = RS_SAMPLER_SOBOL;
    passes_same("cornell", a);
}

/* A render of 2.6 million paths: two waves of RS_CUDA_WF_WAVE in flight at once, the second
 * partial (left out of scripts/gpu-check.sh's memcheck run, where it would take minutes). */
static void test_wavefront_two_waves(void **state)
{
    rt_args a = gc_args(&gc_cases[0]);
    (void)state;
    a.width = 256;
    a.height = 256;
    a.spp = 40;
    a.threads = 8;
    wavefront_same("gpucheck 256x256x40 (two waves)", a);
}

/* core/hdmath.h's functions on the GPU give the host's bits, for 2^22 arguments each: every
 * 1021st float bit pattern (zeros, denormals, huge values, infinities and NaNs among them) and
 * random ones in the shading's ranges (angles within 10 radians, exp's arguments over its whole
 * range, cosines in [-1, 1], pow's bases in [0, 2] with exponents in [-50, 150] or any float).
 * The megakernel tests below check the same through whole images; this one names the function
 * and the argument. */
static void test_hdmath_device_bits(void **state)
{
    static const char *names[HDM_EVAL_N] = {"sin", "cos",  "sincos (sin)", "sincos (cos)", "tan",
                                            "exp", "log",  "pow",          "acos",         "atan2"};
    const size_t n = (size_t)1 << 22;
    float *x = (float *)malloc(n * sizeof(float)), *y = (float *)malloc(n * sizeof(float));
    float *dev = (float *)malloc(n * sizeof(float));
    char msg[256];
    int f, failed = 0;
    (void)state;
    assert_true(x && y && dev);
    for (f = 0; f < HDM_EVAL_N; ++f) {
        uint64_t s = 38 + (uint64_t)f;
        size_t i, differ = 0;
        for (i = 0; i < n; ++i) {
            uint64_t r = splitmix64(&s), r2 = splitmix64(&s);
            double u = (double)(r >> 11) * 0x1.0p-53, v = (double)(r2 >> 11) * 0x1.0p-53;
            uint32_t b = (uint32_t)(i * 1021u + (r & 1023u));
            if (i % 2 == 0)
                memcpy(&x[i], &b, sizeof b);
            else
                x[i] = (float)(f <= 4   ? 20.0 * u - 10.0
                               : f == 5 ? 200.0 * u - 110.0
                               : f == 8 ? 2.0 * u - 1.0
                               : f == 9 ? 2.0 * u - 1.0
                                        : 2.0 * u);
            if (i % 3 == 0)
                memcpy(&y[i], &r2, sizeof y[i]);
            else
                y[i] = (float)(f == 9 ? 2.0 * v - 1.0 : 200.0 * v - 50.0);
        }
        if (hdm_eval_on_gpu(f, x, y, dev, n, msg, sizeof msg) != 0)
            fail_msg("hdm_eval_on_gpu: %s", msg);
        for (i = 0; i < n; ++i) {
            float h = hdm_eval(f, x[i], y[i]);
            if (memcmp(&h, &dev[i], sizeof h) != 0 && !(isnan(h) && isnan(dev[i])) &&
                differ++ < 3)
                print_message("%s(%a, %a): host %a, GPU %a\n", names[f], (double)x[i],
                              (double)y[i], (double)h, (double)dev[i]);
        }
        print_message("hdmath on the GPU: %s: %zu of %zu arguments differ in any bit\n", names[f],
                      differ, n);
        failed |= differ != 0;
    }
    free(x);
    free(y);
    free(dev);
    assert_false(failed);
}

/* gpu_trace_test [PATTERN]: only the tests whose names match PATTERN (cmocka's wildcards), as
 * scripts/gpu-check.sh runs the gpucheck ones under compute-sanitizer. */
int main(int argc, char **argv)
{
    const char *why = "";
    char line[512];
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_gpu_kernel_limits),
        cmocka_unit_test(test_hdmath_device_bits),
        cmocka_unit_test(test_gpu_matches_cpu),
        cmocka_unit_test(test_gpu_motion_matches_cpu),
        cmocka_unit_test(test_gpu_lbvh),
        cmocka_unit_test(test_render_cpu_vs_gpu),
        cmocka_unit_test(test_megakernel_cpu_vs_gpu),
        cmocka_unit_test(test_gpucheck_stream_bit_exact),
        cmocka_unit_test(test_gpucheck_megakernel_vs_cpu),
        cmocka_unit_test(test_gpucheck_wavefront_bit_exact),
        cmocka_unit_test(test_wavefront_two_waves),
        cmocka_unit_test(test_gpucheck_passes_bit_exact),
    };
    if (rs_gpu_count(&why) == 0) {
        printf("SKIP: no CUDA device: %s\n", why);
        return 77;
    }
    if (rs_gpu_describe(0, line, sizeof line) == 0)
        printf("GPU device: %s\n", line);
    if (argc > 1)
        cmocka_set_test_filter(argv[1]);
    return cmocka_run_group_tests(tests, NULL, NULL);
}
