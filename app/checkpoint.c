/* app/checkpoint.c — see checkpoint.h. */
#include "app/checkpoint.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "app/options.h"
#include "core/file.h"
#include "core/intersect.h"
#include "shading/integrator.h"

static const char k_magic[8] = {'R', 'S', 'C', 'K', 'P', 'T', '\r', '\n'};

#define FIXED_HEADER   92u /* up to and including the scene name's length */
#define NAME_MAX_BYTES 4096u
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
    return FIXED_HEADER + NAME_MAX_BYTES + 8 + 16 * (size_t)held->n;
}

static size_t make_header(unsigned char *h, const rs_checkpoint_key *key,
                          const rs_path_ranges *held, uint64_t nonfinite)
{
    size_t name_len = strlen(key->scene), at;
    uint64_t paths = rs_path_ranges_total(held);
    uint32_t u[10];
    int i;
    if (name_len >= NAME_MAX_BYTES)
        name_len = NAME_MAX_BYTES - 1;
    memcpy(h, k_magic, 8);
    put32(h + 8, RS_CHECKPOINT_VERSION);
    put32(h + 12, (uint32_t)(FIXED_HEADER + name_len + 8 + 16 * (size_t)held->n));
    put64(h + 16, key->scene_hash);
    put64(h + 24, key->seed);
    put64(h + 32, paths);
    put64(h + 40, nonfinite);
    u[0] = key->width;
    u[1] = key->height;
    u[2] = key->spp;
    u[3] = key->max_depth;
    u[4] = key->rr_depth;
    u[5] = key->sampling;
    u[6] = key->sampler;
    u[7] = key->isect_sphere;
    u[8] = key->isect_tri;
    u[9] = key->isect_aabb;
    for (i = 0; i < 10; ++i)
        put32(h + 48 + 4 * i, u[i]);
    put32(h + 88, (uint32_t)name_len);
    memcpy(h + FIXED_HEADER, key->scene, name_len);
    at = FIXED_HEADER + name_len;
    put32(h + at, held->n);
    put32(h + at + 4, 0);
    for (i = 0; i < (int)held->n; ++i) {
        put64(h + at + 8 + 16 * (size_t)i, held->r[i][0]);
        put64(h + at + 16 + 16 * (size_t)i, held->r[i][1]);
    }
    return at + 8 + 16 * (size_t)held->n;
}

/* fwrite of n bytes, folded into the checksum. */
static int put(FILE *f, const void *p, size_t n, uint64_t *sum)
{
    *sum = fnv(*sum, p, n);
    return fwrite(p, 1, n, f) == n;
}

int rs_checkpoint_write(const char *path, const char *staged, int rename_now,
                        const rs_checkpoint_key *key, const rs_film *film,
                        const rs_path_ranges *held)
{
    unsigned char *header;
    size_t npix = (size_t)film->width * film->height, n;
    uint64_t sum = FNV_OFFSET;
    FILE *f;
    int ok;
    if (!little_endian()) {
        fprintf(stderr,
                "raystream: --checkpoint %s: checkpoints are written on little-endian "
                "machines only\n",
                path);
        return 0;
    }
    header = (unsigned char *)malloc(header_max(held));
    f = header ? fopen(staged, "wb") : NULL;
    if (!f) {
        fprintf(stderr, "raystream: --checkpoint %s: cannot write %s (%s)\n", path, staged,
                header ? strerror(errno) : "out of memory");
        free(header);
        return 0;
    }
    n = make_header(header, key, held, film->nonfinite);
    ok = put(f, header, n, &sum) && put(f, film->sum, npix * 3 * sizeof *film->sum, &sum) &&
         put(f, film->count, npix * sizeof *film->count, &sum);
    ok = ok && fwrite(&sum, 1, sizeof sum, f) == sizeof sum;
    ok = fflush(f) == 0 && ok;
    ok = fsync(fileno(f)) == 0 && ok; /* on disk before it replaces the last good one */
    if (fclose(f) != 0)
        ok = 0;
    free(header);
    if (ok && (!rename_now || rename(staged, path) == 0))
        return 1;
    fprintf(stderr, "raystream: --checkpoint %s: cannot write the checkpoint (%s)\n", path,
            strerror(errno));
    unlink(staged);
    return 0;
}

/* One line "raystream: --resume PATH: ..." and `code`. */
static int refuse(int code, const char *path, const char *fmt, const char *a, const char *b)
{
    fprintf(stderr, "raystream: --resume %s: ", path);
    fprintf(stderr, fmt, a, b);
    fputc('\n', stderr);
    return code;
}

static int mismatch_u(const char *path, const char *field, uint64_t in_file, uint64_t asked)
{
    char a[32], b[32];
    snprintf(a, sizeof a, "%llu", (unsigned long long)in_file);
    snprintf(b, sizeof b, "%llu", (unsigned long long)asked);
    fprintf(stderr,
            "raystream: --resume %s: made with %s %s, but this render has %s %s (the same "
            "settings are needed to continue it)\n",
            path, field, a, field, b);
    return RS_EXIT_USAGE;
}

static int mismatch_s(const char *path, const char *field, const char *in_file, const char *asked)
{
    fprintf(stderr,
            "raystream: --resume %s: made with %s %s, but this render has %s %s (the same "
            "settings are needed to continue it)\n",
            path, field, in_file, field, asked);
    return RS_EXIT_USAGE;
}

/* The header against `want`.  Returns RS_EXIT_OK or the exit code after one line. */
static int check_header(const char *path, const unsigned char *h, const char *name,
                        uint64_t end, rs_checkpoint_key *want)
{
    uint32_t u[10];
    int i;
    for (i = 0; i < 10; ++i)
        u[i] = get32(h + 48 + 4 * i);
    /* the size was compared before the film was read */
    if (get64(h + 16) != want->scene_hash) {
        fprintf(stderr,
                "raystream: --resume %s: made for another scene (%s; its content hash %016llx, "
                "this scene %s has %016llx)\n",
                path, name, (unsigned long long)get64(h + 16), want->scene,
                (unsigned long long)want->scene_hash);
        return RS_EXIT_USAGE;
    }
    if (get64(h + 24) != want->seed)
        return mismatch_u(path, "--seed", get64(h + 24), want->seed);
    if (u[3] != want->max_depth)
        return mismatch_u(path, "--max-depth", u[3], want->max_depth);
    if (u[4] != want->rr_depth)
        return mismatch_u(path, "Russian roulette depth", u[4], want->rr_depth);
    if (u[5] != want->sampling)
        return mismatch_s(path, "--sampling", rs_sampling_name((rs_sampling)u[5]),
                          rs_sampling_name((rs_sampling)want->sampling));
    if (u[6] != want->sampler)
        return mismatch_s(path, "--sampler", rs_sampler_name((rs_sampler)u[6]),
                          rs_sampler_name((rs_sampler)want->sampler));
    if (u[7] != want->isect_sphere)
        return mismatch_s(path, "--isect-sphere", rs_isect_sphere_algo_name(u[7]),
                          rs_isect_sphere_algo_name(want->isect_sphere));
    if (u[8] != want->isect_tri)
        return mismatch_s(path, "--isect-tri", rs_isect_tri_algo_name(u[8]),
                          rs_isect_tri_algo_name(want->isect_tri));
    if (u[9] != want->isect_aabb)
        return mismatch_s(path, "--isect-aabb", rs_isect_aabb_algo_name(u[9]),
                          rs_isect_aabb_algo_name(want->isect_aabb));
    if (want->spp == 0)
        want->spp = u[2];
    /* zsobol's points depend on spp: its sequence cannot be continued to another count */
    if (want->sampler == RS_SAMPLER_ZSOBOL && u[2] != want->spp)
        return mismatch_u(path, "--spp (the zsobol sampler's points depend on it)", u[2],
                          want->spp);
    if (end > (uint64_t)want->width * want->height * want->spp) {
        char a[48], b[48];
        snprintf(a, sizeof a, "%llu", (unsigned long long)end);
        snprintf(b, sizeof b, "%u", want->spp);
        return refuse(RS_EXIT_USAGE, path, "holds paths up to %s, more than --spp %s asks for",
                      a, b);
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

int rs_checkpoint_read(const char *path, rs_checkpoint_key *want, rs_film *film,
                       rs_path_ranges *held)
{
    unsigned char *h = (unsigned char *)malloc(FIXED_HEADER + NAME_MAX_BYTES + 8 +
                                               16 * (size_t)RS_CHECKPOINT_MAX_RANGES);
    char name[NAME_MAX_BYTES];
    size_t npix = (size_t)film->width * film->height, hdr, name_len;
    uint64_t size, expect, sum = FNV_OFFSET, stored, end = 0, prev = 0;
    uint32_t fw, fh, n_ranges, k;
    FILE *f;
    int rc;
    if (!h) {
        fprintf(stderr, "raystream: --resume %s: out of memory\n", path);
        return RS_EXIT_RUNTIME;
    }
    if (rs_file_open(path, (uint64_t)1 << 46, &f, &size) != RS_OK) {
        fprintf(stderr, "raystream: --resume %s\n", rs_error_message());
        rs_error_clear();
        free(h);
        return RS_EXIT_USAGE;
    }
    rc = RS_EXIT_RUNTIME;
    if (size < FIXED_HEADER + 8 || fread(h, 1, FIXED_HEADER, f) != FIXED_HEADER) {
        refuse(rc, path, "truncated: not a raystream checkpoint (%s%s)",
               size < FIXED_HEADER + 8 ? "too short" : "cannot read", "");
        goto out;
    }
    if (memcmp(h, k_magic, 8) != 0) {
        refuse(rc, path, "not a raystream checkpoint (no RSCKPT magic)%s%s", "", "");
        goto out;
    }
    if (get32(h + 8) != RS_CHECKPOINT_VERSION) {
        char v[16], want_v[16];
        snprintf(v, sizeof v, "%u", get32(h + 8));
        snprintf(want_v, sizeof want_v, "%u", RS_CHECKPOINT_VERSION);
        refuse(rc, path, "checkpoint version %s; this raystream reads version %s", v, want_v);
        goto out;
    }
    name_len = get32(h + 88);
    hdr = get32(h + 12);
    if (name_len >= NAME_MAX_BYTES || fread(h + FIXED_HEADER, 1, name_len + 8, f) != name_len + 8) {
        refuse(rc, path, "corrupt header (scene name of %s bytes)%s",
               name_len >= NAME_MAX_BYTES ? "too many" : "a wrong number of", "");
        goto out;
    }
    memcpy(name, h + FIXED_HEADER, name_len);
    name[name_len] = '\0';
    n_ranges = get32(h + FIXED_HEADER + name_len);
    if (n_ranges > RS_CHECKPOINT_MAX_RANGES ||
        hdr != FIXED_HEADER + name_len + 8 + 16 * (size_t)n_ranges ||
        fread(h + FIXED_HEADER + name_len + 8, 16, n_ranges, f) != n_ranges) {
        refuse(rc, path, "corrupt header (the list of paths held)%s%s", "", "");
        goto out;
    }
    for (k = 0; k < n_ranges; ++k) {
        const unsigned char *q = h + FIXED_HEADER + name_len + 8 + 16 * (size_t)k;
        uint64_t lo = get64(q), hi = get64(q + 8);
        if (lo >= hi || (k > 0 && lo <= prev) || hi > ((uint64_t)1 << 62)) {
            refuse(rc, path, "corrupt header (the paths held are not sorted ranges)%s%s", "",
                   "");
            goto out;
        }
        prev = end = hi;
    }
    /* the file's own size first: a mismatch is reported only for a file that is whole */
    fw = get32(h + 48);
    fh = get32(h + 52);
    if (fw == 0 || fh == 0 || fw > 65536 || fh > 65536) {
        refuse(rc, path, "corrupt header (image size %s)%s", "out of range", "");
        goto out;
    }
    expect = (uint64_t)hdr + (uint64_t)fw * fh * (3 * sizeof *film->sum + sizeof *film->count) + 8;
    if (size != expect) {
        char a[32], b[32];
        snprintf(a, sizeof a, "%llu", (unsigned long long)size);
        snprintf(b, sizeof b, "%llu", (unsigned long long)expect);
        refuse(rc, path, "%s bytes where its header makes %s: truncated or corrupt", a, b);
        goto out;
    }
    if ((uint64_t)fw * fh != npix || fw != want->width) {
        char a[32], b[32];
        snprintf(a, sizeof a, "%ux%u", fw, fh);
        snprintf(b, sizeof b, "%ux%u", want->width, want->height);
        rc = mismatch_s(path, "size", a, b);
        goto out;
    }
    sum = fnv(sum, h, hdr);
    if (fread(film->sum, sizeof *film->sum, npix * 3, f) != npix * 3 ||
        fread(film->count, sizeof *film->count, npix, f) != npix ||
        fread(&stored, 1, sizeof stored, f) != sizeof stored) {
        refuse(rc, path, "truncated while reading the film%s%s", "", "");
        goto out;
    }
    sum = fnv(sum, film->sum, npix * 3 * sizeof *film->sum);
    sum = fnv(sum, film->count, npix * sizeof *film->count);
    if (sum != stored) {
        refuse(rc, path, "corrupt: the checksum does not match its content%s%s", "", "");
        goto out;
    }
    if ((rc = check_header(path, h, name, end, want)) != RS_EXIT_OK)
        goto out;
    rc = RS_EXIT_RUNTIME;
    for (k = 0; k < n_ranges; ++k) {
        const unsigned char *q = h + FIXED_HEADER + name_len + 8 + 16 * (size_t)k;
        if (get64(q) % npix != 0) { /* every range starts at a whole sample */
            refuse(rc, path, "corrupt header (a range of paths starts within a sample)%s%s", "",
                   "");
            goto out;
        }
        if (!rs_path_ranges_add(held, get64(q), get64(q + 8))) {
            refuse(rc, path, "out of memory for its list of paths%s%s", "", "");
            goto out;
        }
    }
    if (rs_path_ranges_total(held) != get64(h + 32) || !counts_agree(film, held)) {
        refuse(rc, path, "corrupt: the sample counts do not match its header%s%s", "", "");
        goto out;
    }
    film->nonfinite = get64(h + 40);
    rc = RS_EXIT_OK;
out:
    fclose(f);
    free(h);
    if (rc != RS_EXIT_OK) {
        memset(film->count, 0, npix * sizeof *film->count);
        rs_path_ranges_free(held);
    }
    return rc;
}
