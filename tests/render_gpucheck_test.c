/* tests/render_gpucheck_test.c — builtin:gpucheck (every material, texture, light, primitive and
 * instance the megakernel shades; scenes/builtin_gpucheck.c) on the CPU device and on the GPU's
 * host fallback (gpu/gpu_fallback.c: the CUDA device's data flow and kernel bodies on host
 * threads), with both integrators and every sampling mode: the images are the same bit for bit.
 * Runs everywhere, CI included; tests/gpu_trace_test.c holds the same comparison with a real
 * CUDA device. */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include "gpucheck_util.h"

/* The scene still holds what the GPU check is for. */
static void test_scene_has_everything(void **state)
{
    rs_scene *s = NULL;
    const char *missing;
    (void)state;
    assert_int_equal(rs_builtin_create("gpucheck", &s), RS_OK);
    missing = gc_scene_missing(s);
    if (missing)
        fail_msg("builtin:gpucheck lacks %s", missing);
    rs_scene_destroy(s);
}

static float *render_or_fail(const rt_args *a)
{
    float *img = rt_render(a, NULL);
    assert_non_null(img);
    return img;
}

/* The stream integrator: the CPU device's widest traversal (the CLI's), its binary one (the code
 * the CUDA kernel runs), the fallback alone and beside the CPU device in small chunks (every
 * chunk boundary moves): one image. */
static void test_stream_cpu_vs_fallback(void **state)
{
    int c;
    (void)state;
    for (c = 0; c < GC_N_CASES; ++c) {
        rt_args a = gc_args(&gc_cases[c]);
        float *ref, *img;
        char what[96];
        a.cli_bvh = 1;
        ref = render_or_fail(&a);
        assert_true(gc_image_sane(ref, GC_W, GC_H));
        a.cli_bvh = 0;
        a.bvh_width = 2;
        img = render_or_fail(&a);
        snprintf(what, sizeof what, "%s stream: cpu (widest) vs cpu (binary)", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, ref, img, GC_W, GC_H), 0);
        free(img);
        a.bvh_width = 0;
        a.fallback_only = 1;
        img = render_or_fail(&a);
        snprintf(what, sizeof what, "%s stream: cpu vs gpu-fallback", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, ref, img, GC_W, GC_H), 0);
        free(img);
        a.fallback_only = 0;
        a.with_fallback = 1;
        a.chunk_size = 500;
        img = render_or_fail(&a);
        snprintf(what, sizeof what, "%s stream: cpu vs cpu + gpu-fallback", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, ref, img, GC_W, GC_H), 0);
        free(img);
        free(ref);
    }
}

/* The megakernel: the CPU's per-pixel loop and the fallback's passes (the CUDA render_pass's on
 * host threads), and both against the stream integrator's image. */
static void test_megakernel_cpu_vs_fallback(void **state)
{
    int c;
    (void)state;
    for (c = 0; c < GC_N_CASES; ++c) {
        rt_args a = gc_args(&gc_cases[c]);
        float *stream, *cpu, *fb;
        char what[96];
        stream = render_or_fail(&a);
        a.megakernel = 1;
        cpu = render_or_fail(&a);
        a.fallback_only = 1;
        fb = render_or_fail(&a);
        snprintf(what, sizeof what, "%s megakernel: cpu vs gpu-fallback", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, cpu, fb, GC_W, GC_H), 0);
        snprintf(what, sizeof what, "%s: stream vs megakernel", gc_cases[c].name);
        assert_int_equal(gc_diff_pixels(what, stream, cpu, GC_W, GC_H), 0);
        free(stream);
        free(cpu);
        free(fb);
    }
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_scene_has_everything),
        cmocka_unit_test(test_stream_cpu_vs_fallback),
        cmocka_unit_test(test_megakernel_cpu_vs_fallback),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
