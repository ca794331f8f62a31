/* app/image_settings.c — the image-defining settings' table (see image_settings.h). */
#include "app/image_settings.h"

#include <stdio.h>
#include <string.h>

#include "core/intersect.h"
#include "shading/light_sampler.h"
#include "shading/texture.h"

static void text_seed(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%llu", (unsigned long long)s->seed);
}
static void text_max_depth(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%u", s->max_depth);
}
static void text_rr_depth(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%u", s->rr_depth);
}
static void text_sampling(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%s", rs_sampling_name(s->sampling));
}
static void text_sampler(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%s", rs_sampler_name(s->sampler));
}
static void text_filter(const rs_image_settings *s, char *b, size_t n)
{
    rs_filter_describe(&s->filter, b, n);
}
static void text_texture_filter(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%s", s->texture_filter == RS_TEXTURE_TRILINEAR ? "trilinear" : "bilinear");
}
static void text_light_sampler(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%s", s->light_sampler == RS_LIGHT_SAMPLER_BVH ? "bvh" : "power");
}
static void text_isect_sphere(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%s", rs_isect_sphere_algo_name(s->isect_sphere));
}
static void text_isect_tri(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%s", rs_isect_tri_algo_name(s->isect_tri));
}
static void text_isect_aabb(const rs_image_settings *s, char *b, size_t n)
{
    snprintf(b, n, "%s", rs_isect_aabb_algo_name(s->isect_aabb));
}
static void text_adaptive(const rs_image_settings *s, char *b, size_t n)
{
    if (s->adaptive > 0)
        snprintf(b, n, "%g", s->adaptive);
    else
        snprintf(b, n, "off");
}
static void text_adaptive_min_spp(const rs_image_settings *s, char *b, size_t n)
{
    if (s->adaptive > 0)
        snprintf(b, n, "%u", s->adaptive_min_spp);
    else
        snprintf(b, n, "-");
}

#define MAX_EXTRA 4

static const rs_setting_desc k_rows[] = {
    {"seed", "--seed", text_seed},
    {"max_depth", "--max-depth", text_max_depth},
    {"rr_depth", "the Russian roulette depth", text_rr_depth},
    {"sampling", "--sampling", text_sampling},
    {"sampler", "--sampler", text_sampler},
    {"filter", "--filter", text_filter},
    {"texture_filter", "--texture-filter", text_texture_filter},
    {"light_sampler", "--light-sampler", text_light_sampler},
    {"isect_sphere", "--isect-sphere", text_isect_sphere},
    {"isect_tri", "--isect-tri", text_isect_tri},
    {"isect_aabb", "--isect-aabb", text_isect_aabb},
    {"adaptive", "--adaptive", text_adaptive},
    {"adaptive_min_spp", "--adaptive-min-spp", text_adaptive_min_spp},
};
#define N_ROWS (sizeof k_rows / sizeof k_rows[0])

static rs_setting_desc g_extra[MAX_EXTRA];
static size_t g_n_extra;

size_t rs_image_settings_count(void) { return N_ROWS + g_n_extra; }

const rs_setting_desc *rs_image_setting(size_t i)
{
    if (i < N_ROWS)
        return &k_rows[i];
    i -= N_ROWS;
    return i < g_n_extra ? &g_extra[i] : NULL;
}

int rs_image_settings_add_row(const rs_setting_desc *d)
{
    if (g_n_extra == MAX_EXTRA)
        return 0;
    g_extra[g_n_extra++] = *d;
    return 1;
}

size_t rs_image_settings_block(const rs_image_settings *s, char *buf, size_t n)
{
    size_t i, used = 0;
    for (i = 0; i < rs_image_settings_count(); ++i) {
        const rs_setting_desc *d = rs_image_setting(i);
        char v[RS_SETTING_TEXT];
        int k;
        d->text(s, v, sizeof v);
        k = snprintf(buf + used, n - used, "%s=%s\n", d->name, v);
        if (k < 0 || (size_t)k >= n - used)
            return 0;
        used += (size_t)k;
    }
    return used;
}

/* The value of `name` in block [block, block + len) into v (vn bytes); 0 when it has none. */
static int block_value(const char *block, size_t len, const char *name, char *v, size_t vn)
{
    size_t nl = strlen(name), at = 0;
    while (at < len) {
        const char *line = block + at, *end = memchr(line, '\n', len - at);
        size_t ll = end ? (size_t)(end - line) : len - at;
        if (ll > nl && memcmp(line, name, nl) == 0 && line[nl] == '=') {
            size_t k = ll - nl - 1 < vn - 1 ? ll - nl - 1 : vn - 1;
            memcpy(v, line + nl + 1, k);
            v[k] = '\0';
            return 1;
        }
        at += ll + 1;
    }
    return 0;
}

/* Whether `name` (n bytes) is a row's name. */
static int known(const char *name, size_t n)
{
    size_t i;
    for (i = 0; i < rs_image_settings_count(); ++i) {
        const char *r = rs_image_setting(i)->name;
        if (strlen(r) == n && memcmp(r, name, n) == 0)
            return 1;
    }
    return 0;
}

int rs_image_settings_match(const rs_image_settings *s, const char *block, size_t len,
                            char *option, size_t on, char *in_file, char *asked, size_t vn)
{
    size_t i, at = 0;
    for (i = 0; i < rs_image_settings_count(); ++i) {
        const rs_setting_desc *d = rs_image_setting(i);
        char mine[RS_SETTING_TEXT], theirs[RS_SETTING_TEXT];
        d->text(s, mine, sizeof mine);
        if (!block_value(block, len, d->name, theirs, sizeof theirs))
            snprintf(theirs, sizeof theirs, "(none)");
        if (strcmp(mine, theirs) != 0) {
            snprintf(option, on, "%s", d->option);
            snprintf(in_file, vn, "%s", theirs);
            snprintf(asked, vn, "%s", mine);
            return 0;
        }
    }
    while (at < len) { /* a setting of a newer raystream decided the file's image */
        const char *line = block + at, *end = memchr(line, '\n', len - at);
        size_t ll = end ? (size_t)(end - line) : len - at;
        const char *eq = memchr(line, '=', ll);
        size_t nl = eq ? (size_t)(eq - line) : ll;
        if (ll > 0 && !known(line, nl)) {
            snprintf(option, on, "the setting '%.*s'", (int)(nl < 40 ? nl : 40), line);
            snprintf(in_file, vn, "%.*s", (int)(ll - nl > 1 ? ll - nl - 1 : 0), eq ? eq + 1 : "");
            snprintf(asked, vn, "(none: this raystream does not know it)");
            return 0;
        }
        at += ll + 1;
    }
    return 1;
}
