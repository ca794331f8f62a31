/* app/checkpoint.c — see checkpoint.h. */
#include "app/checkpoint.h"
#include "app/fail.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/options.h"
#include "core/file.h"
#include "core/intersect.h"
#include "shading/integrator.h"
#include "shading/light_sampler.h"
#include "shading/texture.h"

static const char k_magic[8] = {'R', 'S', 'C', 'K', 'P', 'T', '\r', '\n'};

#define FIXED_HEADER   92u /* up to and including the scene name's length */
#define NAME_MAX_BYTES 4096u
#define SETTINGS_MAX   8192u /* the settings block's bytes (version 7) */
#define FLAG_ADAPTIVE  1u
#define FLAG_PASSES    2u
#define FNV_OFFSET     14695981039346656037ull
#define FNV_PRIME      1099511628211ull

static uint64_t fnv(uint64_t h, const void *p, size_t n)
{
    const unsigned char *b = (const unsigned char *)p;
    size_t i;
    for (i = 0; i < n; ++i)
        h = (h ^ b[i]) * FNV_PRIME;
    return h;
}

static int little_endian(void)
{
    const uint32_t one = 1;
    unsigned char b;
    memcpy(&b, &one, 1);
    return b == 1;
}

uint64_t rs_checkpoint_scene_hash(const rs_scene *s)
{
    uint64_t h = FNV_OFFSET;
    uint32_t i, counts[6];
    counts[0] = s->n_spheres;
    counts[1] = s->n_quads;
    counts[2] = s->n_tris;
    counts[3] = s->n_materials;
    counts[4] = s->n_textures;
    counts[5] = s->n_images;
    h = fnv(h, counts, sizeof counts);
    /* every element type is 4-byte fields without padding (scene.h, core/intersect.h); a NULL
     * array (no motion, no UVs) hashes like an absent one but its count marks it */
#define HASH_ARRAY(field, n)                                                                       \
  {                                                                                                \
    uint32_t present = s->field != NULL;                                                           \
    h = fnv(h, &present, sizeof present);                                                          \
    if (s->field)                                                                                  \
      h = fnv(h, s->field, (n) * sizeof *s->field);                                                \
  }
    RS_SCENE_ARRAYS(HASH_ARRAY, s)
#undef HASH_ARRAY
    for (i = 0; i < s->n_images; ++i) {
        const rs_image *im = &s->images[i];
        h = fnv(h, &im->width, sizeof im->width);
        h = fnv(h, &im->height, sizeof im->height);
        if (im->rgb)
            h = fnv(h, im->rgb, (size_t)im->width * im->height * 3 * sizeof *im->rgb);
    }
    h = fnv(h, &s->camera, sizeof s->camera); /* floats only */
    h = fnv(h, &s->background, sizeof s->background);
    h = fnv(h, &s->background_top, sizeof s->background_top);
    h = fnv(h, &s->background_sky, sizeof s->background_sky);
    h = fnv(h, &s->env_image, sizeof s->env_image);
    h = fnv(h, &s->env_scale, sizeof s->env_scale);
    h = fnv(h, s->env_rot, sizeof s->env_rot);
    h = fnv(h, &s->env_pick, sizeof s->env_pick);
    return h;
}

static void put32(unsigned char *p, uint32_t v) { memcpy(p, &v, 4); }
static void put64(unsigned char *p, uint64_t v) { memcpy(p, &v, 8); }
static uint32_t get32(const unsigned char *p)
{
    uint32_t v;
    memcpy(&v, p, 4);
    return v;
}
static uint64_t get64(const unsigned char *p)
{
    uint64_t v;
    memcpy(&v, p, 8);
    return v;
}

/* The header for `key` with `held` and `nonfinite`; returns its size (at most
 * header_max(held)). */
static size_t header_max(const rs_path_ranges *held)
{
    return FIXED_HEADER + NAME_MAX_BYTES + 8 + 16 * (size_t)held->n + 8 + SETTINGS_MAX;
}

/* The filter word of versions 2 and 4 for the settings img. */
static uint32_t filter_word(const rs_image_settings *img)
{
    return rs_checkpoint_filter_code(&img->filter, img->texture_filter == RS_TEXTURE_TRILINEAR) |
           (img->light_sampler == RS_LIGHT_SAMPLER_BVH ? RS_CHECKPOINT_LIGHT_BVH : 0u);
}

/* The header (version 7) into h; its length, or 0 when the settings block does not fit. */
static size_t make_header(unsigned char *h, const rs_checkpoint_key *key,
                          const rs_path_ranges *held, uint64_t nonfinite, int passes)
{
    const rs_image_settings *img = &key->img;
    size_t name_len = strlen(key->scene), at, block;
    uint64_t paths = rs_path_ranges_total(held);
    uint32_t u[10];
    int i;
    if (name_len >= NAME_MAX_BYTES)
        name_len = NAME_MAX_BYTES - 1;
    memcpy(h, k_magic, 8);
    put32(h + 8, RS_CHECKPOINT_VERSION);
    put64(h + 16, key->scene_hash);
    put64(h + 24, img->seed);
    put64(h + 32, paths);
    put64(h + 40, nonfinite);
    u[0] = img->width;
    u[1] = img->height;
    u[2] = img->spp;
    u[3] = img->max_depth;
    u[4] = img->rr_depth;
    u[5] = (uint32_t)img->sampling;
    u[6] = (uint32_t)img->sampler;
    u[7] = img->isect_sphere;
    u[8] = img->isect_tri;
    u[9] = img->isect_aabb;
    for (i = 0; i < 10; ++i)
        put32(h + 48 + 4 * i, u[i]);
    put32(h + 88, (uint32_t)name_len);
    memcpy(h + FIXED_HEADER, key->scene, name_len);
    at = FIXED_HEADER + name_len;
    put32(h + at, held->n);
    put32(h + at + 4, filter_word(img));
    for (i = 0; i < (int)held->n; ++i) {
        put64(h + at + 8 + 16 * (size_t)i, held->r[i][0]);
        put64(h + at + 16 + 16 * (size_t)i, held->r[i][1]);
    }
    at += 8 + 16 * (size_t)held->n;
    put32(h + at, (img->adaptive > 0 ? FLAG_ADAPTIVE : 0u) | (passes ? FLAG_PASSES : 0u));
    block = rs_image_settings_block(img, (char *)h + at + 8, SETTINGS_MAX);
    if (block == 0)
        return 0;
    put32(h + at + 4, (uint32_t)block);
    at += 8 + block;
    put32(h + 12, (uint32_t)at);
    return at;
}

/* fwrite of n bytes, folded into the checksum. */
static int put(FILE *f, const void *p, size_t n, uint64_t *sum)
{
    *sum = fnv(*sum, p, n);
    return fwrite(p, 1, n, f) == n;
}

#define ADAPTIVE_FIXED 48u /* the adaptive section before its per-pixel arrays */

/* The adaptive section's fixed part for *ad. */
static void make_adaptive(unsigned char *q, const rs_checkpoint_key *key,
                          const rs_adaptive_state *ad)
{
    memset(q, 0, ADAPTIVE_FIXED);
    memcpy(q, &key->img.adaptive, 8);
    put32(q + 8, key->img.adaptive_min_spp);
    put32(q + 12, ad->n);
    put32(q + 16, ad->step);
    put32(q + 20, ad->stats.rounds);
    put64(q + 24, ad->round_done);
    put64(q + 32, ad->stats.samples);
    put32(q + 40, ad->stats.stopped);
}

static int write_file(const char *path, const char *staged, int rename_now,
                      const rs_checkpoint_key *key, const rs_film *film, const rs_path_ranges *held,
                      const rs_adaptive_state *ad)
{
    unsigned char *header;
    size_t npix = (size_t)film->width * film->height, n;
    uint64_t sum = FNV_OFFSET;
    FILE *f;
    int ok;
    if (!little_endian()) {
        rs_app_print("raystream: --checkpoint %s: checkpoints are written on little-endian "
                     "machines only\n",
                     path);
        return 0;
    }
    header = (unsigned char *)malloc(header_max(held));
    f = header ? fopen(staged, "wb") : NULL;
    if (!f) {
        rs_app_print("raystream: --checkpoint %s: cannot write %s (%s)\n", path, staged,
                     header ? strerror(errno) : "out of memory");
        free(header);
        return 0;
    }
    n = make_header(header, key, held, film->nonfinite, film->pass != NULL);
    if (n == 0) {
        rs_app_print("raystream: --checkpoint %s: the settings do not fit its header\n", path);
        fclose(f);
        unlink(staged);
        free(header);
        return 0;
    }
    if (ad) /* no ranges: the paths held are the film's samples */
        put64(header + 32, rs_film_samples(film));
    ok = put(f, header, n, &sum) && put(f, film->sum, npix * 3 * sizeof *film->sum, &sum) &&
         put(f, film->count, npix * sizeof *film->count, &sum);
    if (film->pass && ok)
        ok = put(f, film->pass, npix * RS_FILM_PASSES * sizeof *film->pass, &sum) &&
             put(f, film->pass_hits, npix * sizeof *film->pass_hits, &sum);
    if (ad && ok) {
        unsigned char q[ADAPTIVE_FIXED];
        make_adaptive(q, key, ad);
        ok = put(f, q, sizeof q, &sum) && put(f, film->sum_l2, npix * sizeof *film->sum_l2, &sum) &&
             put(f, ad->running, npix, &sum);
    }
    ok = ok && fwrite(&sum, 1, sizeof sum, f) == sizeof sum;
    ok = fflush(f) == 0 && ok;
    ok = fsync(fileno(f)) == 0 && ok; /* on disk before it replaces the last good one */
    if (fclose(f) != 0)
        ok = 0;
    free(header);
    if (ok && (!rename_now || rename(staged, path) == 0))
        return 1;
    rs_app_print("raystream: --checkpoint %s: cannot write the checkpoint (%s)\n", path,
                 strerror(errno));
    unlink(staged);
    return 0;
}

int rs_checkpoint_write(const char *path, const char *staged, int rename_now,
                        const rs_checkpoint_key *key, const rs_film *film,
                        const rs_path_ranges *held)
{
    return write_file(path, staged, rename_now, key, film, held, NULL);
}

int rs_checkpoint_write_adaptive(const char *path, const char *staged, int rename_now,
                                 const rs_checkpoint_key *key, const rs_film *film,
                                 const rs_adaptive_state *ad)
{
    static const rs_path_ranges none = {NULL, 0, 0};
    if (!film->sum_l2) {
        rs_app_print("raystream: --checkpoint %s: the film keeps no variance\n", path);
        return 0;
    }
    return write_file(path, staged, rename_now, key, film, &none, ad);
}

/* One line "raystream: --resume PATH: ..." and `code`. */
static int refuse(int code, const char *path, const char *fmt, const char *a, const char *b)
{
    rs_app_print("raystream: --resume %s: ", path);
    rs_app_print(fmt, a, b);
    rs_app_print("\n");
    return code;
}

static int mismatch_u(const char *path, const char *field, uint64_t in_file, uint64_t asked)
{
    char a[32], b[32];
    snprintf(a, sizeof a, "%llu", (unsigned long long)in_file);
    snprintf(b, sizeof b, "%llu", (unsigned long long)asked);
    rs_app_print("raystream: --resume %s: made with %s %s, but this render has %s %s (the same "
                 "settings are needed to continue it)\n",
                 path, field, a, field, b);
    return RS_EXIT_USAGE;
}

static int mismatch_s(const char *path, const char *field, const char *in_file, const char *asked)
{
    rs_app_print("raystream: --resume %s: made with %s %s, but this render has %s %s (the same "
                 "settings are needed to continue it)\n",
                 path, field, in_file, field, asked);
    return RS_EXIT_USAGE;
}

uint32_t rs_checkpoint_filter_code(const rs_filter *f, int trilinear)
{
    uint32_t tex = trilinear ? 1u << 23 : 0u;
    if (f->kind == RS_FILTER_BOX && f->width == 1.0f)
        return tex;
    return f->kind << 24 | tex | (uint32_t)lrintf(f->width * 1000.0f);
}

/* "mitchell:4 with trilinear textures" for a header's filter code. */
static void filter_code_name(uint32_t code, char *buf, size_t n)
{
    rs_filter f;
    uint32_t width = code & 0x3fffffu;
    size_t len;
    memset(&f, 0, sizeof f);
    f.kind = width ? code >> 24 : RS_FILTER_BOX;
    f.width = width ? (float)width / 1000.0f : 1.0f;
    if (f.kind > RS_FILTER_MITCHELL)
        snprintf(buf, n, "an unknown filter (%08x)", code);
    else
        rs_filter_describe(&f, buf, n);
    len = strlen(buf);
    snprintf(buf + len, n - len, " (%s textures, light sampler %s)",
             code & (1u << 23) ? "trilinear" : "bilinear",
             code & RS_CHECKPOINT_LIGHT_BVH ? "bvh" : "power");
}

/* A checkpoint being read: its header and what the header says. */
typedef struct reader {
    const char *path;
    FILE *f;
    uint64_t size, sum; /* the file's size; the checksum of what was read */
    unsigned char *h;   /* the header */
    char name[NAME_MAX_BYTES];
    size_t hdr, name_len;
    uint32_t version, n_ranges;
    int adaptive, passes; /* what the version (7: its flags) says the file holds */
    const char *block;    /* version 7: the settings block (in h), block_len bytes */
    size_t block_len;
    uint64_t end; /* the last range's end */
} reader;

/* The settings of a file of version 2 or 4 (fixed fields and the filter word) against `want`.
 * Returns RS_EXIT_OK or the exit code after one line. */
static int check_legacy(const char *path, const unsigned char *h, const rs_image_settings *want)
{
    uint32_t u[10];
    int i;
    for (i = 0; i < 10; ++i)
        u[i] = get32(h + 48 + 4 * i);
    if (get64(h + 24) != want->seed)
        return mismatch_u(path, "--seed", get64(h + 24), want->seed);
    if (u[3] != want->max_depth)
        return mismatch_u(path, "--max-depth", u[3], want->max_depth);
    if (u[4] != want->rr_depth)
        return mismatch_u(path, "Russian roulette depth", u[4], want->rr_depth);
    if (u[5] != (uint32_t)want->sampling)
        return mismatch_s(path, "--sampling", rs_sampling_name((rs_sampling)u[5]),
                          rs_sampling_name(want->sampling));
    if (u[6] != (uint32_t)want->sampler)
        return mismatch_s(path, "--sampler", rs_sampler_name((rs_sampler)u[6]),
                          rs_sampler_name(want->sampler));
    if (get32(h + FIXED_HEADER + get32(h + 88) + 4) != filter_word(want)) {
        char a[80], b[80];
        filter_code_name(get32(h + FIXED_HEADER + get32(h + 88) + 4), a, sizeof a);
        filter_code_name(filter_word(want), b, sizeof b);
        return mismatch_s(path, "--filter / --texture-filter / --light-sampler", a, b);
    }
    if (u[7] != want->isect_sphere)
        return mismatch_s(path, "--isect-sphere", rs_isect_sphere_algo_name(u[7]),
                          rs_isect_sphere_algo_name(want->isect_sphere));
    if (u[8] != want->isect_tri)
        return mismatch_s(path, "--isect-tri", rs_isect_tri_algo_name(u[8]),
                          rs_isect_tri_algo_name(want->isect_tri));
    if (u[9] != want->isect_aabb)
        return mismatch_s(path, "--isect-aabb", rs_isect_aabb_algo_name(u[9]),
                          rs_isect_aabb_algo_name(want->isect_aabb));
    return RS_EXIT_OK;
}

/* The header against `want`: the scene, the settings (version 7: its block, row for row), the
 * spp.  Returns RS_EXIT_OK or the exit code after one line. */
static int check_header(const reader *r, rs_checkpoint_key *want)
{
    const char *path = r->path;
    const unsigned char *h = r->h;
    uint32_t spp = get32(h + 56);
    rs_image_settings *img = &want->img;
    int rc;
    /* the size was compared before the film was read */
    if (get64(h + 16) != want->scene_hash) {
        rs_app_print(
            "raystream: --resume %s: made for another scene (%s; its content hash %016llx, "
            "this scene %s has %016llx)\n",
            path, r->name, (unsigned long long)get64(h + 16), want->scene,
            (unsigned long long)want->scene_hash);
        return RS_EXIT_USAGE;
    }
    if (r->version == RS_CHECKPOINT_VERSION) {
        char option[64], a[RS_SETTING_TEXT + 48], b[RS_SETTING_TEXT + 48];
        if (!rs_image_settings_match(img, r->block, r->block_len, option, sizeof option, a, b,
                                     sizeof a))
            return mismatch_s(path, option, a, b);
    } else if ((rc = check_legacy(path, h, img)) != RS_EXIT_OK) {
        return rc;
    }
    if (img->spp == 0)
        img->spp = spp;
    /* zsobol's points depend on spp: its sequence cannot be continued to another count */
    if (img->sampler == RS_SAMPLER_ZSOBOL && spp != img->spp)
        return mismatch_u(path, "--spp (the zsobol sampler's points depend on it)", spp,
                          img->spp);
    if (r->end > (uint64_t)img->width * img->height * img->spp) {
        char a[48], b[48];
        snprintf(a, sizeof a, "%llu", (unsigned long long)r->end);
        snprintf(b, sizeof b, "%u", img->spp);
        return refuse(RS_EXIT_USAGE, path, "holds paths up to %s, more than --spp %s asks for", a,
                      b);
    }
    return RS_EXIT_OK;
}

/* Every pixel's count is what the ranges give it: paths g of [lo, hi) with g mod P = i, which
 * is (hi / P + (i < hi mod P)) - (lo / P + (i < lo mod P)). */
static int counts_agree(const rs_film *film, const rs_path_ranges *held)
{
    size_t i, npix = (size_t)film->width * film->height;
    int64_t base = 0, run = 0, *d = (int64_t *)calloc(npix + 1, sizeof *d);
    uint32_t k;
    int ok = 1;
    if (!d)
        return 0;
    for (k = 0; k < held->n; ++k) {
        uint64_t lo = held->r[k][0], hi = held->r[k][1];
        base += (int64_t)(hi / npix) - (int64_t)(lo / npix);
        d[0] += 1; /* +1 below hi mod P, -1 below lo mod P */
        d[hi % npix] -= 1;
        d[0] -= 1;
        d[lo % npix] += 1;
    }
    for (i = 0; i < npix && ok; ++i) {
        run += d[i];
        ok = (int64_t)film->count[i] == base + run;
    }
    free(d);
    return ok;
}


/* Version 7's flags and settings block after the ranges (at r->h + at), read into r->h. */
static int read_settings(reader *r, size_t at)
{
    uint32_t flags, len;
    if (fread(r->h + at, 1, 8, r->f) != 8)
        return 0;
    flags = get32(r->h + at);
    len = get32(r->h + at + 4);
    if ((flags & ~(FLAG_ADAPTIVE | FLAG_PASSES)) || len >= SETTINGS_MAX ||
        r->hdr != at + 8 + len || fread(r->h + at + 8, 1, len, r->f) != len)
        return 0;
    r->adaptive = (flags & FLAG_ADAPTIVE) != 0;
    r->passes = (flags & FLAG_PASSES) != 0;
    r->block = (const char *)r->h + at + 8;
    r->block_len = len;
    return 1;
}

/* The fixed header, the scene name, the ranges and (version 7) the settings.  RS_EXIT_OK or
 * RS_EXIT_RUNTIME after one line. */
static int read_header(reader *r)
{
    const int rc = RS_EXIT_RUNTIME;
    uint64_t prev = 0;
    uint32_t k;
    size_t at;
    if (r->size < FIXED_HEADER + 8 || fread(r->h, 1, FIXED_HEADER, r->f) != FIXED_HEADER)
        return refuse(rc, r->path, "truncated: not a raystream checkpoint (%s%s)",
                      r->size < FIXED_HEADER + 8 ? "too short" : "cannot read", "");
    if (memcmp(r->h, k_magic, 8) != 0)
        return refuse(rc, r->path, "not a raystream checkpoint (no RSCKPT magic)%s%s", "", "");
    r->version = get32(r->h + 8);
    r->adaptive = r->version == RS_CHECKPOINT_VERSION_ADAPTIVE;
    if (r->version != RS_CHECKPOINT_VERSION && r->version != RS_CHECKPOINT_VERSION_PLAIN &&
        r->version != RS_CHECKPOINT_VERSION_ADAPTIVE) {
        char v[16], want_v[24];
        snprintf(v, sizeof v, "%u", r->version);
        snprintf(want_v, sizeof want_v, "%u, %u and %u", RS_CHECKPOINT_VERSION_PLAIN,
                 RS_CHECKPOINT_VERSION_ADAPTIVE, RS_CHECKPOINT_VERSION);
        return refuse(rc, r->path, "checkpoint version %s; this raystream reads versions %s", v,
                      want_v);
    }
    r->name_len = get32(r->h + 88);
    r->hdr = get32(r->h + 12);
    if (r->name_len >= NAME_MAX_BYTES ||
        fread(r->h + FIXED_HEADER, 1, r->name_len + 8, r->f) != r->name_len + 8)
        return refuse(rc, r->path, "corrupt header (scene name of %s bytes)%s",
                      r->name_len >= NAME_MAX_BYTES ? "too many" : "a wrong number of", "");
    memcpy(r->name, r->h + FIXED_HEADER, r->name_len);
    r->name[r->name_len] = '\0';
    r->n_ranges = get32(r->h + FIXED_HEADER + r->name_len);
    at = FIXED_HEADER + r->name_len + 8 + 16 * (size_t)r->n_ranges;
    if (r->n_ranges > RS_CHECKPOINT_MAX_RANGES ||
        (r->version == RS_CHECKPOINT_VERSION ? r->hdr < at + 8 : r->hdr != at) ||
        fread(r->h + FIXED_HEADER + r->name_len + 8, 16, r->n_ranges, r->f) != r->n_ranges)
        return refuse(rc, r->path, "corrupt header (the list of paths held)%s%s", "", "");
    if (r->version == RS_CHECKPOINT_VERSION && !read_settings(r, at))
        return refuse(rc, r->path, "corrupt header (its settings)%s%s", "", "");
    if (r->adaptive && r->n_ranges != 0)
        return refuse(rc, r->path, "corrupt header (the list of paths held)%s%s", "", "");
    for (k = 0; k < r->n_ranges; ++k) {
        const unsigned char *q = r->h + FIXED_HEADER + r->name_len + 8 + 16 * (size_t)k;
        uint64_t lo = get64(q), hi = get64(q + 8);
        if (lo >= hi || (k > 0 && lo <= prev) || hi > ((uint64_t)1 << 62))
            return refuse(rc, r->path, "corrupt header (the paths held are not sorted ranges)%s%s",
                          "", "");
        prev = r->end = hi;
    }
    return RS_EXIT_OK;
}

/* The file's size against its header (a mismatch is reported only for a file that is whole),
 * then the image size against the render's. */
static int check_size(const reader *r, const rs_checkpoint_key *want, size_t npix)
{
    uint32_t fw = get32(r->h + 48), fh = get32(r->h + 52);
    uint64_t per_pixel = 3 * sizeof(rs_film_sum) + sizeof(uint32_t), expect;
    if (fw == 0 || fh == 0 || fw > 65536 || fh > 65536)
        return refuse(RS_EXIT_RUNTIME, r->path, "corrupt header (image size %s)%s", "out of range",
                      "");
    if (r->adaptive)
        per_pixel += sizeof(rs_film_sq) + 1;
    if (r->passes)
        per_pixel += RS_FILM_PASSES * sizeof(rs_film_sum) + sizeof(uint32_t);
    expect = (uint64_t)r->hdr + (uint64_t)fw * fh * per_pixel + 8 +
             (r->adaptive ? ADAPTIVE_FIXED : 0);
    if (r->size != expect) {
        char a[32], b[32];
        snprintf(a, sizeof a, "%llu", (unsigned long long)r->size);
        snprintf(b, sizeof b, "%llu", (unsigned long long)expect);
        return refuse(RS_EXIT_RUNTIME, r->path,
                      "%s bytes where its header makes %s: truncated or corrupt", a, b);
    }
    if ((uint64_t)fw * fh != npix || fw != want->img.width) {
        char a[32], b[32];
        snprintf(a, sizeof a, "%ux%u", fw, fh);
        snprintf(b, sizeof b, "%ux%u", want->img.width, want->img.height);
        return mismatch_s(r->path, "size", a, b);
    }
    return RS_EXIT_OK;
}

/* n bytes into p, folded into the checksum; 0 when the file ends first. */
static int take(reader *r, void *p, size_t n)
{
    if (fread(p, 1, n, r->f) != n)
        return 0;
    r->sum = fnv(r->sum, p, n);
    return 1;
}

/* n bytes read and folded into the checksum, not kept (a film's passes the render does not
 * write); 0 when the file ends first. */
static int skip(reader *r, uint64_t n)
{
    unsigned char buf[4096];
    while (n > 0) {
        size_t k = n < sizeof buf ? (size_t)n : sizeof buf;
        if (!take(r, buf, k))
            return 0;
        n -= k;
    }
    return 1;
}

/* The film (its passes where it keeps them, and an adaptive section into q, ad and the film's
 * squared luminance), then the checksum. */
static int read_film(reader *r, rs_film *film, unsigned char *q, rs_adaptive_state *ad)
{
    size_t npix = (size_t)film->width * film->height;
    uint64_t stored;
    int ok;
    r->sum = fnv(FNV_OFFSET, r->h, r->hdr);
    ok = take(r, film->sum, npix * 3 * sizeof *film->sum) &&
         take(r, film->count, npix * sizeof *film->count);
    if (ok && r->passes && film->pass)
        ok = take(r, film->pass, npix * RS_FILM_PASSES * sizeof *film->pass) &&
             take(r, film->pass_hits, npix * sizeof *film->pass_hits);
    else if (ok && r->passes)
        ok = skip(r, npix * (RS_FILM_PASSES * sizeof(rs_film_sum) + sizeof(uint32_t)));
    if (ok && r->adaptive)
        ok = take(r, q, ADAPTIVE_FIXED) && take(r, film->sum_l2, npix * sizeof *film->sum_l2) &&
             take(r, ad->running, npix);
    if (!ok || fread(&stored, 1, sizeof stored, r->f) != sizeof stored)
        return refuse(RS_EXIT_RUNTIME, r->path, "truncated while reading the film%s%s", "", "");
    if (r->sum != stored)
        return refuse(RS_EXIT_RUNTIME, r->path,
                      "corrupt: the checksum does not match its content%s%s", "", "");
    return RS_EXIT_OK;
}

/* The ranges into *held, checked against the counts. */
static int take_ranges(const reader *r, const rs_film *film, rs_path_ranges *held)
{
    const int rc = RS_EXIT_RUNTIME;
    uint32_t k;
    for (k = 0; k < r->n_ranges; ++k) {
        const unsigned char *q = r->h + FIXED_HEADER + r->name_len + 8 + 16 * (size_t)k;
        /* a range may start and end anywhere (a GPU's wavefront beside the CPU leaves gaps
         * within samples); counts_agree checks the film against the ranges */
        if (!rs_path_ranges_add(held, get64(q), get64(q + 8)))
            return refuse(rc, r->path, "out of memory for its list of paths%s%s", "", "");
    }
    if (rs_path_ranges_total(held) != get64(r->h + 32) || !counts_agree(film, held))
        return refuse(rc, r->path, "corrupt: the sample counts do not match its header%s%s", "",
                      "");
    return RS_EXIT_OK;
}

/* The adaptive section against the render's --adaptive and the film. */
static int take_adaptive(const reader *r, const unsigned char *q, const rs_checkpoint_key *want,
                         const rs_film *film, rs_adaptive_state *ad)
{
    size_t i, npix = (size_t)film->width * film->height;
    double t;
    memcpy(&t, q, 8);
    if (t != want->img.adaptive || get32(q + 8) != want->img.adaptive_min_spp) {
        char a[48], b[48];
        snprintf(a, sizeof a, "%g and --adaptive-min-spp %u", t, get32(q + 8));
        snprintf(b, sizeof b, "%g and --adaptive-min-spp %u", want->img.adaptive,
                 want->img.adaptive_min_spp);
        return mismatch_s(r->path, "--adaptive", a, b);
    }
    ad->n = get32(q + 12);
    ad->step = get32(q + 16);
    ad->stats.rounds = get32(q + 20);
    ad->round_done = get64(q + 24);
    ad->stats.samples = get64(q + 32);
    ad->stats.stopped = get32(q + 40);
    for (i = 0; i < npix; ++i)
        if (!(rs_film_pixel_sq(film, (uint32_t)i) <= (double)film->count[i] * 0x1p96))
            break;
    if (i < npix || rs_film_samples(film) != get64(r->h + 32) ||
        !rs_adaptive_state_fits(ad, film->count, (uint32_t)npix, want->img.spp))
        return refuse(RS_EXIT_RUNTIME, r->path,
                      "corrupt: the sample counts do not match its adaptive state%s%s", "", "");
    return RS_EXIT_OK;
}

/* Whether the file's kind (adaptive or not; with the passes where the render writes them) is
 * the render's; one line when not. */
static int same_kind(const reader *r, const rs_checkpoint_key *want, const rs_film *film)
{
    int file_adaptive = r->adaptive;
    if (film->pass && !r->passes)
        return refuse(RS_EXIT_USAGE, r->path,
                      "made without the passes --aov and --denoise read (%s%s); continue it "
                      "without them, or start again",
                      "albedo, normal, depth, direct emission", "");
    if (file_adaptive == (want->img.adaptive > 0))
        return RS_EXIT_OK;
    return refuse(RS_EXIT_USAGE, r->path,
                  "made %s --adaptive, but this render is %s (the same "
                  "settings are needed to continue it)",
                  file_adaptive ? "with" : "without", file_adaptive ? "not adaptive" : "adaptive");
}

static int read_any(const char *path, rs_checkpoint_key *want, rs_film *film, rs_path_ranges *held,
                    rs_adaptive_state *ad)
{
    reader r;
    unsigned char q[ADAPTIVE_FIXED];
    size_t npix = (size_t)film->width * film->height;
    int rc;
    memset(&r, 0, sizeof r);
    r.path = path;
    r.h = (unsigned char *)malloc(FIXED_HEADER + NAME_MAX_BYTES + 8 +
                                  16 * (size_t)RS_CHECKPOINT_MAX_RANGES + 8 + SETTINGS_MAX);
    if (!r.h) {
        rs_app_print("raystream: --resume %s: out of memory\n", path);
        return RS_EXIT_RUNTIME;
    }
    if (rs_file_open(path, (uint64_t)1 << 46, &r.f, &r.size) != RS_OK) {
        rs_app_print("raystream: --resume %s\n", rs_error_message());
        rs_error_clear();
        free(r.h);
        return RS_EXIT_USAGE;
    }
    if ((rc = read_header(&r)) == RS_EXIT_OK && (rc = check_size(&r, want, npix)) == RS_EXIT_OK &&
        (rc = same_kind(&r, want, film)) == RS_EXIT_OK &&
        (rc = read_film(&r, film, q, ad)) == RS_EXIT_OK &&
        (rc = check_header(&r, want)) == RS_EXIT_OK) {
        if (ad && want->img.spp != get32(r.h + 56)) /* the last round's size depends on it */
            rc = mismatch_u(path, "--spp (adaptive sampling's rounds depend on it)",
                            get32(r.h + 56), want->img.spp);
        else
            rc = ad ? take_adaptive(&r, q, want, film, ad) : take_ranges(&r, film, held);
    }
    if (rc == RS_EXIT_OK)
        film->nonfinite = get64(r.h + 40);
    fclose(r.f);
    free(r.h);
    if (rc != RS_EXIT_OK) {
        memset(film->count, 0, npix * sizeof *film->count);
        if (held)
            rs_path_ranges_free(held);
    }
    return rc;
}

int rs_checkpoint_read(const char *path, rs_checkpoint_key *want, rs_film *film,
                       rs_path_ranges *held)
{
    return read_any(path, want, film, held, NULL);
}

int rs_checkpoint_read_adaptive(const char *path, rs_checkpoint_key *want, rs_film *film,
                                rs_adaptive_state *ad)
{
    int rc;
    memset(ad, 0, sizeof *ad);
    if (rs_film_track_variance(film) != RS_OK ||
        rs_adaptive_state_init(ad, film->width * film->height) != RS_OK) {
        rs_app_print("raystream: --resume %s: out of memory\n", path);
        rs_error_clear();
        return RS_EXIT_RUNTIME;
    }
    if ((rc = read_any(path, want, film, NULL, ad)) != RS_EXIT_OK)
        rs_adaptive_state_free(ad);
    return rc;
}
