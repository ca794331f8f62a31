/* tests/core_denoise_test.c — core/denoise.h: Open Image Denoise loaded at run time.
 *
 * Without OIDN: a RS_OIDN_LIBRARY that names a missing file, or a library that is not OIDN 2.x,
 * is reported with the path and what to do; bad arguments are refused before any load.
 * With OIDN (sh scripts/install-deps.sh; skipped with the reason otherwise): a synthetic noisy
 * image (smooth shading times a two-colour albedo, plus seeded noise) denoised with a noise-free
 * albedo and normal comes out finite, the same size, and several times closer to the clean
 * image; beauty-only denoising helps too; two CPU runs agree bit for bit (OIDN promises
 * determinism on one device and version); a GPU request runs on CUDA or says why it fell back.
 *
 * The tests run in order in one process: the failing loads come first, because a successful
 * load is kept for the life of the process (core/denoise.h). */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "core/denoise.h"
#include "test_rand.h"

#define W 128u
#define H 96u
#define N ((size_t)W * H * 3)

/* RS_OIDN_LIBRARY as the test found it (a custom OIDN), restored after the failing loads */
static char g_env[1024];

static void restore_env(void)
{
    if (g_env[0])
        setenv("RS_OIDN_LIBRARY", g_env, 1);
    else
        unsetenv("RS_OIDN_LIBRARY");
}

static void test_missing_library(void **state)
{
    const char *path = "/nonexistent/raystream-test/libOpenImageDenoise.so.2";
    char why[512], used[128] = "x";
    float px[3] = {1, 1, 1}, out[3];
    (void)state;
    setenv("RS_OIDN_LIBRARY", path, 1);
    assert_int_equal(rs_denoise_available(why, sizeof why), 0);
    printf("  rs_denoise_available: %s\n", why);
    assert_non_null(strstr(why, path));
    assert_non_null(strstr(why, "RS_OIDN_LIBRARY"));
    assert_null(strchr(why, '\n'));
    /* NULL why is allowed */
    assert_int_equal(rs_denoise_available(NULL, 0), 0);
    rs_error_clear();
    assert_int_equal(rs_denoise(px, NULL, NULL, 1, 1, 0, 0, out, used, sizeof used),
                     RS_ERR_DEVICE_LOST);
    assert_non_null(strstr(rs_error_message(), path));
    assert_string_equal(used, "");
    rs_error_clear();
    restore_env();
}

static void test_not_oidn(void **state)
{
    char why[512];
    (void)state;
    /* a real shared library without OIDN's entry points */
    setenv("RS_OIDN_LIBRARY", "libm.so.6", 1);
    assert_int_equal(rs_denoise_available(why, sizeof why), 0);
    printf("  rs_denoise_available: %s\n", why);
    assert_non_null(strstr(why, "libm.so.6"));
    assert_non_null(strstr(why, "oidnNewDevice"));
    restore_env();
}

static void test_bad_arguments(void **state)
{
    float px[3] = {1, 1, 1}, out[3];
    (void)state;
    rs_error_clear();
    assert_int_equal(rs_denoise(px, NULL, NULL, 0, 1, 0, 0, out, NULL, 0), RS_ERR_ARG);
    assert_non_null(strstr(rs_error_message(), "0x1"));
    rs_error_clear();
    assert_int_equal(rs_denoise(px, NULL, NULL, 1, 0, 0, 0, out, NULL, 0), RS_ERR_ARG);
    rs_error_clear();
    assert_int_equal(rs_denoise(px, NULL, px, 1, 1, 0, 0, out, NULL, 0), RS_ERR_ARG);
    assert_non_null(strstr(rs_error_message(), "albedo"));
    rs_error_clear();
    assert_int_equal(rs_denoise(NULL, NULL, NULL, 1, 1, 0, 0, out, NULL, 0), RS_ERR_ARG);
    rs_error_clear();
    assert_int_equal(rs_denoise(px, NULL, NULL, 0xffffffffu, 0xffffffffu, 0, 0, out, NULL, 0),
                     RS_ERR_ARG);
    rs_error_clear();
}

/* The scene: a disc of one colour on a background of another, lit by a smooth gradient; the
 * noisy beauty adds zero-mean noise proportional to the signal (like a path tracer's). */
typedef struct images {
    float *clean, *noisy, *albedo, *normal, *out;
} images;

static void make_images(images *im)
{
    uint64_t seed = 0x5eed0042u;
    uint32_t x, y;
    im->clean = malloc(N * sizeof(float));
    im->noisy = malloc(N * sizeof(float));
    im->albedo = malloc(N * sizeof(float));
    im->normal = malloc(N * sizeof(float));
    im->out = malloc(N * sizeof(float));
    assert_true(im->clean && im->noisy && im->albedo && im->normal && im->out);
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            size_t p = 3 * ((size_t)y * W + x);
            float dx = (float)x - 0.5f * W, dy = (float)y - 0.5f * H;
            int in_disc = dx * dx + dy * dy < 30.0f * 30.0f;
            float a[3] = {0.7f, 0.3f, 0.2f}, b[3] = {0.2f, 0.5f, 0.8f};
            float light = 0.3f + 1.5f * (float)x / W + 0.5f * (float)y / H;
            int c;
            for (c = 0; c < 3; ++c) {
                float alb = in_disc ? a[c] : b[c];
                /* sum of 4 uniforms: roughly normal, mean 0, sd 0.5 */
                float g = (float)(rnd01(&seed) + rnd01(&seed) + rnd01(&seed) + rnd01(&seed) - 2.0) *
                          0.866f;
                im->albedo[p + c] = alb;
                im->clean[p + c] = alb * light;
                im->noisy[p + c] = alb * light * (1.0f + g);
                if (im->noisy[p + c] < 0.0f)
                    im->noisy[p + c] = 0.0f; /* radiance is never negative */
            }
            im->normal[p] = 0.0f;
            im->normal[p + 1] = 0.0f;
            im->normal[p + 2] = 1.0f;
        }
}

static void free_images(images *im)
{
    free(im->clean);
    free(im->noisy);
    free(im->albedo);
    free(im->normal);
    free(im->out);
}

static double rmse(const float *a, const float *b)
{
    double s = 0;
    size_t i;
    for (i = 0; i < N; ++i)
        s += ((double)a[i] - b[i]) * ((double)a[i] - b[i]);
    return sqrt(s / (double)N);
}

static void assert_finite(const float *v)
{
    size_t i;
    for (i = 0; i < N; ++i)
        assert_true(isfinite(v[i]));
}

static int oidn_here(void)
{
    char why[512];
    if (rs_denoise_available(why, sizeof why))
        return 1;
    printf("  skipped: %s\n", why);
    return 0;
}

static void test_denoise_with_aux(void **state)
{
    images im;
    char used[256];
    double e0, e1;
    float *again;
    (void)state;
    if (!oidn_here())
        skip();
    make_images(&im);
    /* a canary past the end: the output is exactly w*h*3 floats */
    again = malloc((N + 1) * sizeof(float));
    assert_non_null(again);
    again[N] = -12345.0f;
    rs_error_clear();
    assert_int_equal(
        rs_denoise(im.noisy, im.albedo, im.normal, W, H, 1, 0, im.out, used, sizeof used), RS_OK);
    assert_string_equal(rs_error_message(), "");
    printf("  device: %s\n", used);
    assert_memory_equal(used, "CPU (OIDN 2.", 12);
    assert_finite(im.out);
    e0 = rmse(im.noisy, im.clean);
    e1 = rmse(im.out, im.clean);
    printf("  RMSE noisy %.5f, denoised %.5f: %.1fx lower\n", e0, e1, e0 / e1);
    assert_true(e1 * 4.0 < e0);
    /* the same device and version: the same bits */
    assert_int_equal(rs_denoise(im.noisy, im.albedo, im.normal, W, H, 1, 0, again, NULL, 0), RS_OK);
    assert_memory_equal(again, im.out, N * sizeof(float));
    assert_true(again[N] == -12345.0f);
    /* albedo alone, noisy aux mode: still far better than the input */
    assert_int_equal(rs_denoise(im.noisy, im.albedo, NULL, W, H, 0, 0, again, NULL, 0), RS_OK);
    assert_finite(again);
    printf("  albedo only, cleanAux off: RMSE %.5f\n", rmse(again, im.clean));
    assert_true(rmse(again, im.clean) * 2.0 < e0);
    free(again);
    free_images(&im);
}

static void test_denoise_beauty_only_in_place(void **state)
{
    images im;
    double e0, e1;
    (void)state;
    if (!oidn_here())
        skip();
    make_images(&im);
    e0 = rmse(im.noisy, im.clean);
    /* out == beauty is allowed */
    assert_int_equal(rs_denoise(im.noisy, NULL, NULL, W, H, 0, 0, im.noisy, NULL, 0), RS_OK);
    assert_finite(im.noisy);
    e1 = rmse(im.noisy, im.clean);
    printf("  beauty only, in place: RMSE %.5f -> %.5f (%.1fx)\n", e0, e1, e0 / e1);
    assert_true(e1 * 2.0 < e0);
    free_images(&im);
}

/* rs_denoise_split: the denoiser gets beauty - direct and direct_fine is added to its output,
 * exactly; NULL direct images make it rs_denoise.  The scene: the disc above plus a bright
 * square "emitter" (direct: 15 at the render's own noisy coverage of its outline; direct_fine:
 * the exact coverage); the split must beat denoising the whole image. */
static void test_denoise_split(void **state)
{
    images im;
    float *direct, *fine, *clean, *reflected, *expect, *plain;
    uint64_t seed = 0x5eed0077u;
    uint32_t x, y;
    size_t i;
    double e_plain, e_split;
    (void)state;
    if (!oidn_here())
        skip();
    make_images(&im);
    direct = calloc(N, sizeof(float));
    fine = calloc(N, sizeof(float));
    clean = malloc(N * sizeof(float));
    reflected = malloc(N * sizeof(float));
    expect = malloc(N * sizeof(float));
    plain = malloc(N * sizeof(float));
    assert_true(direct && fine && clean && reflected && expect && plain);
    for (y = 0; y < H; ++y)
        for (x = 0; x < W; ++x) {
            /* a square [20.5, 40.5)^2: border pixels a half covered, 16 samples of coverage */
            double cx = (x < 20 || x > 40) ? 0 : (x == 20 || x == 40) ? 0.5 : 1;
            double cy = (y < 20 || y > 40) ? 0 : (y == 20 || y == 40) ? 0.5 : 1;
            double c = cx * cy;
            int k, hits = 0, ch;
            for (k = 0; k < 16; ++k)
                hits += rnd01(&seed) < c;
            for (ch = 0; ch < 3; ++ch) {
                size_t p = 3 * ((size_t)y * W + x) + (size_t)ch;
                fine[p] = (float)(15.0 * c);
                direct[p] = 15.0f * (float)hits / 16.0f;
                clean[p] = im.clean[p] * (float)(1.0 - c) + fine[p];
                im.noisy[p] = im.noisy[p] * (float)(1.0 - c) + direct[p];
                im.albedo[p] = c > 0 ? 1.0f : im.albedo[p];
            }
        }
    /* what it must be: rs_denoise of the reflected light, plus direct_fine */
    for (i = 0; i < N; ++i)
        reflected[i] = im.noisy[i] - direct[i] < 0.0f ? 0.0f : im.noisy[i] - direct[i];
    assert_int_equal(rs_denoise(reflected, im.albedo, im.normal, W, H, 1, 0, expect, NULL, 0),
                     RS_OK);
    for (i = 0; i < N; ++i)
        expect[i] += fine[i];
    assert_int_equal(rs_denoise_split(im.noisy, direct, fine, im.albedo, im.normal, W, H, 1, 0,
                                      im.out, NULL, 0),
                     RS_OK);
    assert_memory_equal(im.out, expect, N * sizeof(float));
    /* no direct images: rs_denoise itself */
    assert_int_equal(rs_denoise(im.noisy, im.albedo, im.normal, W, H, 1, 0, plain, NULL, 0),
                     RS_OK);
    assert_int_equal(rs_denoise_split(im.noisy, NULL, fine, im.albedo, im.normal, W, H, 1, 0,
                                      expect, NULL, 0),
                     RS_OK);
    assert_memory_equal(expect, plain, N * sizeof(float));
    e_plain = rmse(plain, clean);
    e_split = rmse(im.out, clean);
    printf("  a bright square with a noisy outline: RMSE denoised whole %.4f, split %.4f (%.1fx)\n",
           e_plain, e_split, e_plain / e_split);
    assert_true(e_split * 2.0 < e_plain);
    /* out == beauty is allowed */
    assert_int_equal(rs_denoise_split(im.noisy, direct, fine, im.albedo, im.normal, W, H, 1, 0,
                                      im.noisy, NULL, 0),
                     RS_OK);
    assert_memory_equal(im.noisy, im.out, N * sizeof(float));
    free(direct);
    free(fine);
    free(clean);
    free(reflected);
    free(expect);
    free(plain);
    free_images(&im);
}

static void test_gpu_or_fallback(void **state)
{
    images im;
    char used[512];
    (void)state;
    if (!oidn_here())
        skip();
    make_images(&im);
    rs_error_clear();
    assert_int_equal(
        rs_denoise(im.noisy, im.albedo, im.normal, W, H, 1, 1, im.out, used, sizeof used), RS_OK);
    printf("  use_gpu: %s\n", used);
    /* CUDA ran, or the CPU did and says why CUDA did not */
    if (strncmp(used, "CUDA (OIDN 2.", 13) != 0) {
        assert_memory_equal(used, "CPU (OIDN 2.", 12);
        assert_non_null(strstr(used, "CUDA"));
    }
    assert_string_equal(rs_error_message(), "");
    assert_finite(im.out);
    assert_true(rmse(im.out, im.clean) * 4.0 < rmse(im.noisy, im.clean));
    free_images(&im);
}

int main(void)
{
    const char *env = getenv("RS_OIDN_LIBRARY");
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_missing_library),
        cmocka_unit_test(test_not_oidn),
        cmocka_unit_test(test_bad_arguments),
        cmocka_unit_test(test_denoise_with_aux),
        cmocka_unit_test(test_denoise_beauty_only_in_place),
        cmocka_unit_test(test_denoise_split),
        cmocka_unit_test(test_gpu_or_fallback),
    };
    snprintf(g_env, sizeof g_env, "%s", env ? env : "");
    return cmocka_run_group_tests(tests, NULL, NULL);
}
