/* scenes/json_values.c — the JSON scene reader's fields (scenes/json_internal.h): each value
 * against its type and range, each object against the keys it may have (a misspelt key named
 * with the closest known one), and the JSON paths messages name: objects[3].radius,
 * materials.glass.ior. */
#include "scenes/json_internal.h"

#include <float.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/try.h"

/* Control characters (a key may hold an escaped newline) print as '?': one line, always. */
static void one_line(char *s)
{
    for (; *s; ++s)
        if ((unsigned char)*s < 0x20 || *s == 0x7f)
            *s = '?';
}

rs_status rs_json_field_error(const ctx *c, const char *path, const char *fmt, ...)
{
    char msg[384], all[1600];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    snprintf(all, sizeof all, "%s: %s: %s", c->label, path, msg);
    one_line(all);
    return rs_error_set(RS_ERR_ARG, "%s", all);
}

/* Edit distance between a and b (optimal string alignment: insertions, deletions,
 * substitutions and swaps of neighbours each cost 1), capped at 99; keys are short. */
static int key_distance(const char *a, const char *b)
{
    enum { N = 48 };
    int d[N + 1][N + 1], i, j, la = (int)strlen(a), lb = (int)strlen(b);
    if (la > N || lb > N)
        return 99;
    for (i = 0; i <= la; ++i)
        d[i][0] = i;
    for (j = 0; j <= lb; ++j)
        d[0][j] = j;
    for (i = 1; i <= la; ++i)
        for (j = 1; j <= lb; ++j) {
            int cost = a[i - 1] != b[j - 1], v = d[i - 1][j - 1] + cost;
            if (d[i - 1][j] + 1 < v)
                v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v)
                v = d[i][j - 1] + 1;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] &&
                d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[la][lb];
}

/* Fails on any key of `obj` that is not in the NULL-terminated list `keys`, naming the closest
 * known key when one is within a third of its length (at least 2 edits). */
rs_status rs_json_check_keys(const ctx *c, const cJSON *obj, const char *path,
                             const char *const *keys)
{
    const cJSON *it;
    for (it = obj->child; it; it = it->next) {
        int k, known = 0;
        for (k = 0; keys[k]; ++k)
            if (strcmp(it->string, keys[k]) == 0)
                known = 1;
        if (!known) {
            char list[256] = "";
            for (k = 0; keys[k]; ++k) {
                strncat(list, k ? ", " : "", sizeof list - strlen(list) - 1);
                strncat(list, keys[k], sizeof list - strlen(list) - 1);
            }
            {
                int best = -1, best_d = 99, limit = (int)strlen(it->string) / 3;
                if (limit < 2)
                    limit = 2;
                for (k = 0; keys[k]; ++k) {
                    int dk = key_distance(it->string, keys[k]);
                    if (dk < best_d) {
                        best_d = dk;
                        best = k;
                    }
                }
                if (best >= 0 && best_d <= limit)
                    return FAIL(c, path, "unknown key '%s': did you mean '%s'? (allowed: %s)",
                                it->string, keys[best], list);
            }
            return FAIL(c, path, "unknown key '%s' (allowed: %s)", it->string, list);
        }
    }
    return RS_OK;
}

/* out = path.key (key alone at the top level), cut to n - 1 characters. */
void rs_json_subpath(char *out, size_t n, const char *path, const char *key)
{
    size_t k = 0;
    const char *parts[3];
    int i;
    parts[0] = path;
    parts[1] = *path ? "." : "";
    parts[2] = key;
    for (i = 0; i < 3; ++i)
        for (const char *q = parts[i]; *q && k + 1 < n; ++q)
            out[k++] = *q;
    out[k] = '\0';
}

/* Field `key` of obj into *it (NULL: absent, an error when `required`), its JSON path into
 * p[n]. */
static rs_status field_of(const ctx *c, const cJSON *obj, const char *path, const char *key,
                          int required, char *p, size_t n, const cJSON **it)
{
    *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    rs_json_subpath(p, n, path, key);
    if (!*it && required)
        return FAIL(c, path, "missing '%s'", key);
    return RS_OK;
}

/* A number in [lo, hi]; `def` when absent and not required. */
rs_status rs_json_get_num(const ctx *c, const cJSON *obj, const char *path, const char *key,
                          int required, double def, double lo, double hi, float *out)
{
    const cJSON *it;
    char p[256];
    RS_TRY(field_of(c, obj, path, key, required, p, sizeof p, &it));
    if (!it) {
        *out = (float)def;
        return RS_OK;
    }
    if (!cJSON_IsNumber(it) || !isfinite(it->valuedouble))
        return FAIL(c, p, "expected a number");
    if (it->valuedouble < lo || it->valuedouble > hi)
        return FAIL(c, p, "%g is out of range [%g, %g]", it->valuedouble, lo, hi);
    *out = (float)it->valuedouble;
    return RS_OK;
}

rs_status rs_json_vec3_of(const ctx *c, const cJSON *it, const char *p, rs_vec3 *out)
{
    float v[3];
    int i;
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != 3)
        return FAIL(c, p, "expected an array of 3 numbers");
    for (i = 0; i < 3; ++i) {
        const cJSON *e = cJSON_GetArrayItem(it, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
            return FAIL(c, p, "expected an array of 3 finite numbers");
        v[i] = (float)e->valuedouble;
    }
    *out = rs_v3(v[0], v[1], v[2]);
    return RS_OK;
}

rs_status rs_json_get_vec3(const ctx *c, const cJSON *obj, const char *path, const char *key,
                           int required, rs_vec3 def, rs_vec3 *out)
{
    const cJSON *it;
    char p[256];
    RS_TRY(field_of(c, obj, path, key, required, p, sizeof p, &it));
    if (!it) {
        *out = def;
        return RS_OK;
    }
    return rs_json_vec3_of(c, it, p, out);
}

/* A colour: 3 numbers >= 0. */
rs_status rs_json_get_color(const ctx *c, const cJSON *obj, const char *path, const char *key,
                            int required, rs_vec3 def, rs_vec3 *out)
{
    char p[256];
    rs_status st = rs_json_get_vec3(c, obj, path, key, required, def, out);
    rs_json_subpath(p, sizeof p, path, key);
    if (st == RS_OK && (out->x < 0 || out->y < 0 || out->z < 0))
        return FAIL(c, p, "colour components must be >= 0");
    return st;
}

/* A reflectance (or transmittance): a colour with every component in [0, 1]. */
rs_status rs_json_get_reflectance(const ctx *c, const cJSON *obj, const char *path, const char *key,
                                  int required, rs_vec3 def, rs_vec3 *out)
{
    char p[256];
    rs_status st = rs_json_get_color(c, obj, path, key, required, def, out);
    rs_json_subpath(p, sizeof p, path, key);
    if (st == RS_OK && (out->x > 1 || out->y > 1 || out->z > 1))
        return FAIL(c, p, "reflectance must be in [0, 1]");
    return st;
}

rs_status rs_json_get_bool(const ctx *c, const cJSON *obj, const char *path, const char *key,
                           int def, int *out)
{
    const cJSON *it;
    char p[256];
    RS_TRY(field_of(c, obj, path, key, 0, p, sizeof p, &it));
    if (!it) {
        *out = def;
        return RS_OK;
    }
    if (!cJSON_IsBool(it))
        return FAIL(c, p, "expected true or false");
    *out = cJSON_IsTrue(it);
    return RS_OK;
}

rs_status rs_json_get_string(const ctx *c, const cJSON *obj, const char *path, const char *key,
                             const char **out)
{
    const cJSON *it;
    char p[256];
    RS_TRY(field_of(c, obj, path, key, 1, p, sizeof p, &it));
    if (!cJSON_IsString(it) || !*it->valuestring)
        return FAIL(c, p, "expected a non-empty string");
    *out = it->valuestring;
    return RS_OK;
}

int rs_json_lookup(const named *list, uint32_t n, const char *name, uint32_t *id)
{
    uint32_t i;
    for (i = 0; i < n; ++i)
        if (strcmp(list[i].name, name) == 0) {
            *id = list[i].id;
            return 1;
        }
    return 0;
}

rs_status rs_json_resolve_path(const ctx *c, const char *file, char *out, size_t n)
{
    if (file[0] == '/' || !c->base_dir || !*c->base_dir)
        snprintf(out, n, "%s", file);
    else
        snprintf(out, n, "%s/%s", c->base_dir, file);
    return RS_OK;
}
/* `n` finite numbers (|x| <= 1e30) from array `a` into out. */
rs_status rs_json_read_floats(ctx *c, const cJSON *a, const char *p, int n, const char *what,
                              float *out)
{
    int i;
    if (!cJSON_IsArray(a) || cJSON_GetArraySize(a) != n)
        return FAIL(c, p, "expected %d numbers %s", n, what);
    for (i = 0; i < n; ++i) {
        const cJSON *e = cJSON_GetArrayItem(a, i);
        if (!cJSON_IsNumber(e) || !isfinite(e->valuedouble) || fabs(e->valuedouble) > 1e30)
            return FAIL(c, p, "expected %d finite numbers %s", n, what);
        out[i] = (float)e->valuedouble;
    }
    return RS_OK;
}
