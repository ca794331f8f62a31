/* accel/bvh_builder.c — builder names: parsing a --bvh string, canonical names, validation and
 * the list of standard variants (the tests and the benchmark iterate over it).
 *
 * Names: "median", "sah", "sah:BINS", "lbvh", and "AXIS-PARTITION-COMPARATOR" for the thesis grid
 * (Table 6.5).  "largest-nth-centroid" builds the same tree as "median" but is kept as its own
 * name so that the grid is complete. */
#include "accel/bvh.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static const char *const axis_names[] = {"random", "rotational", "largest"};
static const char *const part_names[] = {"sort", "partial", "nth"};
static const char *const key_names[] = {"min", "max", "centroid"};

#define GRID_FORMS                                                                                 \
  "median, sah, sah:BINS (BINS 2..32), lbvh, or AXIS-PARTITION-COMPARATOR with AXIS "              \
  "random|rotational|largest, PARTITION sort|partial|nth, COMPARATOR min|max|centroid"

rs_status rs_bvh_builder_check(const rs_bvh_builder *b)
{
    switch (b->method) {
    case RS_BVH_MEDIAN:
    case RS_BVH_LBVH: return RS_OK;
    case RS_BVH_GRID:
        if (b->axis > RS_BVH_AXIS_LARGEST || b->partition > RS_BVH_PART_NTH ||
            b->key > RS_BVH_KEY_CENTROID)
            return rs_error_set(RS_ERR_ARG,
                                "BVH grid builder: axis %u, partition %u, comparator %u "
                                "(each must be 0..2)",
                                b->axis, b->partition, b->key);
        return RS_OK;
    case RS_BVH_SAH:
        if (b->bins != 0 && (b->bins < RS_BVH_SAH_BINS_MIN || b->bins > RS_BVH_SAH_BINS_MAX))
            return rs_error_set(RS_ERR_ARG, "BVH SAH builder: %u bins (must be %u..%u)", b->bins,
                                RS_BVH_SAH_BINS_MIN, RS_BVH_SAH_BINS_MAX);
        return RS_OK;
    default: return rs_error_set(RS_ERR_ARG, "BVH builder: unknown method %u", b->method);
    }
}

/* Index of `s[0, len)` in names[3], or -1. */
static int find3(const char *const names[3], const char *s, size_t len)
{
    int i;
    for (i = 0; i < 3; ++i)
        if (strlen(names[i]) == len && strncmp(names[i], s, len) == 0)
            return i;
    return -1;
}

rs_status rs_bvh_builder_parse(const char *name, rs_bvh_builder *out)
{
    rs_bvh_builder b;
    memset(&b, 0, sizeof b);
    if (!name)
        return rs_error_set(RS_ERR_ARG, "BVH builder: no name; expected " GRID_FORMS);
    if (strcmp(name, "median") == 0) {
        b.method = RS_BVH_MEDIAN;
    } else if (strcmp(name, "lbvh") == 0) {
        b.method = RS_BVH_LBVH;
    } else if (strcmp(name, "sah") == 0) {
        b.method = RS_BVH_SAH;
        b.bins = RS_BVH_SAH_BINS_DEFAULT;
    } else if (strncmp(name, "sah:", 4) == 0) {
        const char *p = name + 4;
        char *end = NULL;
        unsigned long v;
        if (*p < '0' || *p > '9')
            return rs_error_set(RS_ERR_ARG, "BVH builder '%s': bins must be a number 2..32", name);
        v = strtoul(p, &end, 10);
        if (*end != '\0' || v < RS_BVH_SAH_BINS_MIN || v > RS_BVH_SAH_BINS_MAX)
            return rs_error_set(RS_ERR_ARG, "BVH builder '%s': bins must be a number 2..32", name);
        b.method = RS_BVH_SAH;
        b.bins = (uint32_t)v;
    } else {
        const char *d1 = strchr(name, '-'), *d2 = d1 ? strchr(d1 + 1, '-') : NULL;
        int a, p, k;
        if (!d1 || !d2)
            return rs_error_set(RS_ERR_ARG, "unknown BVH builder '%s'; expected " GRID_FORMS, name);
        a = find3(axis_names, name, (size_t)(d1 - name));
        p = find3(part_names, d1 + 1, (size_t)(d2 - d1 - 1));
        k = find3(key_names, d2 + 1, strlen(d2 + 1));
        if (a < 0 || p < 0 || k < 0)
            return rs_error_set(RS_ERR_ARG, "unknown BVH builder '%s'; expected " GRID_FORMS, name);
        b.method = RS_BVH_GRID;
        b.axis = (uint32_t)a;
        b.partition = (uint32_t)p;
        b.key = (uint32_t)k;
    }
    *out = b;
    return RS_OK;
}

const char *rs_bvh_builder_name(const rs_bvh_builder *b, char *buf, size_t n)
{
    if (n == 0)
        return buf;
    switch (b->method) {
    case RS_BVH_MEDIAN: snprintf(buf, n, "median"); break;
    case RS_BVH_LBVH: snprintf(buf, n, "lbvh"); break;
    case RS_BVH_SAH:
        if (b->bins == 0 || (b->bins >= RS_BVH_SAH_BINS_MIN && b->bins <= RS_BVH_SAH_BINS_MAX))
            snprintf(buf, n, "sah:%u", b->bins ? b->bins : RS_BVH_SAH_BINS_DEFAULT);
        else
            snprintf(buf, n, "?");
        break;
    case RS_BVH_GRID:
        if (b->axis <= 2 && b->partition <= 2 && b->key <= 2)
            snprintf(buf, n, "%s-%s-%s", axis_names[b->axis], part_names[b->partition],
                     key_names[b->key]);
        else
            snprintf(buf, n, "?");
        break;
    default: snprintf(buf, n, "?"); break;
    }
    return buf;
}

uint32_t rs_bvh_builder_variants(rs_bvh_builder *out, uint32_t cap)
{
    rs_bvh_builder v[RS_BVH_N_VARIANTS];
    uint32_t i, n = 0, a, p, k;
    memset(v, 0, sizeof v);
    v[n++].method = RS_BVH_MEDIAN;
    for (a = 0; a < 3; ++a)
        for (p = 0; p < 3; ++p)
            for (k = 0; k < 3; ++k) {
                v[n].method = RS_BVH_GRID;
                v[n].axis = a;
                v[n].partition = p;
                v[n++].key = k;
            }
    v[n].method = RS_BVH_SAH;
    v[n++].bins = RS_BVH_SAH_BINS_DEFAULT;
    v[n++].method = RS_BVH_LBVH;
    for (i = 0; i < n && i < cap; ++i)
        out[i] = v[i];
    return n;
}
