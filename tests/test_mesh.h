/* tests/test_mesh.h — a tiny triangle-soup reader for tests and benchmarks (test-only helper):
 * ascii PLY (vertex x, y, z among any float properties; faces as `list <count> <index>`
 * polygons, fanned into triangles) and OBJ (`v x y z`, `f a b c ...` with a, a/t, a/t/n or
 * a//n and negative indices, fanned).  No materials, normals or texture coordinates: the BVH
 * tests and benchmarks need positions only.  Stands in until scenes/ mesh import is used here.
 *
 * The models shared by the team live in ../shared/models relative to the repository
 * (/work/shared/models); test_models_dir() finds them: $RS_MODELS_DIR if set, else
 * RS_SOURCE_DIR "/../shared/models" when the build defines RS_SOURCE_DIR. */
#ifndef RS_TESTS_TEST_MESH_H
#define RS_TESTS_TEST_MESH_H

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "core/intersect.h"

/* The folder of shared models, or NULL (with *why saying why) if it does not exist. */
static inline const char *test_models_dir(const char **why)
{
    static char buf[4096];
    const char *env = getenv("RS_MODELS_DIR");
    FILE *f;
    if (env && env[0]) {
        snprintf(buf, sizeof buf, "%s", env);
    } else {
#ifdef RS_SOURCE_DIR
        snprintf(buf, sizeof buf, "%s/../shared/models", RS_SOURCE_DIR);
#else
        *why = "RS_MODELS_DIR is not set and the build did not define RS_SOURCE_DIR";
        return NULL;
#endif
    }
    {
        char probe[4200];
        snprintf(probe, sizeof probe, "%s/README.md", buf);
        f = fopen(probe, "r");
    }
    if (!f) {
        *why = "the shared models folder (../shared/models or $RS_MODELS_DIR) does not exist";
        return NULL;
    }
    fclose(f);
    return buf;
}

typedef struct test_mesh {
    rs_tri *tris;
    uint32_t n_tris;
} test_mesh;

static inline void test_mesh_free(test_mesh *m)
{
    free(m->tris);
    m->tris = NULL;
    m->n_tris = 0;
}

/* Appends triangle (a, b, c) of vertex array v[nv]; returns 0 on a bad index or no memory. */
static inline int test_mesh_push(test_mesh *m, uint32_t *cap, const rs_vec3 *v, long nv, long a,
                                 long b, long c)
{
    if (a < 0 || b < 0 || c < 0 || a >= nv || b >= nv || c >= nv)
        return 0;
    if (m->n_tris == *cap) {
        uint32_t nc = *cap ? 2 * *cap : 1024;
        rs_tri *t = (rs_tri *)realloc(m->tris, (size_t)nc * sizeof *t);
        if (!t)
            return 0;
        m->tris = t;
        *cap = nc;
    }
    m->tris[m->n_tris].v0 = v[a];
    m->tris[m->n_tris].v1 = v[b];
    m->tris[m->n_tris].v2 = v[c];
    m->n_tris++;
    return 1;
}

static inline int test_mesh_read_ply(FILE *f, test_mesh *m)
{
    char line[1024], name[64];
    long nv = -1, nf = -1, i;
    int n_props = 0, ix = -1, iy = -1, iz = -1, in_vertex = 0, ok = 1;
    uint32_t cap = 0;
    rs_vec3 *v;
    if (!fgets(line, sizeof line, f) || strncmp(line, "ply", 3) != 0)
        return 0;
    while (fgets(line, sizeof line, f)) {
        long count;
        if (strncmp(line, "format", 6) == 0 && !strstr(line, "ascii"))
            return 0; /* binary PLY: not supported here */
        if (sscanf(line, "element %63s %ld", name, &count) == 2) {
            in_vertex = strcmp(name, "vertex") == 0;
            if (in_vertex)
                nv = count;
            else if (strcmp(name, "face") == 0)
                nf = count;
            else if (count > 0)
                return 0; /* other elements would sit between vertices and faces */
        } else if (strncmp(line, "property", 8) == 0 && in_vertex) {
            char type[32];
            if (sscanf(line, "property %31s %63s", type, name) == 2) {
                if (strcmp(name, "x") == 0)
                    ix = n_props;
                else if (strcmp(name, "y") == 0)
                    iy = n_props;
                else if (strcmp(name, "z") == 0)
                    iz = n_props;
            }
            ++n_props;
        } else if (strncmp(line, "end_header", 10) == 0) {
            break;
        }
    }
    if (nv <= 0 || nf < 0 || ix < 0 || iy < 0 || iz < 0 || n_props > 32)
        return 0;
    v = (rs_vec3 *)malloc((size_t)nv * sizeof *v);
    if (!v)
        return 0;
    for (i = 0; i < nv && ok; ++i) {
        double p[32] = {0};
        int k;
        for (k = 0; k < n_props && ok; ++k)
            ok = fscanf(f, "%lf", &p[k]) == 1;
        v[i] = rs_v3((float)p[ix], (float)p[iy], (float)p[iz]);
    }
    for (i = 0; i < nf && ok; ++i) {
        long cnt, first, prev, cur, k;
        ok = fscanf(f, "%ld %ld %ld", &cnt, &first, &prev) == 3 && cnt >= 3;
        for (k = 2; k < cnt && ok; ++k) {
            ok = fscanf(f, "%ld", &cur) == 1 && test_mesh_push(m, &cap, v, nv, first, prev, cur);
            prev = cur;
        }
    }
    free(v);
    return ok;
}

/* The vertex index of an OBJ face token ("7", "7/1", "7//3", "-1"), 0-based, or -1. */
static inline long test_mesh_obj_index(const char *tok, long nv)
{
    long k = strtol(tok, NULL, 10);
    return k > 0 ? k - 1 : (k < 0 ? nv + k : -1);
}

static inline int test_mesh_read_obj(FILE *f, test_mesh *m)
{
    char line[4096];
    rs_vec3 *v = NULL;
    long nv = 0, vcap = 0;
    uint32_t cap = 0;
    int ok = 1;
    while (ok && fgets(line, sizeof line, f)) {
        if (line[0] == 'v' && line[1] == ' ') {
            float x, y, z;
            if (sscanf(line + 2, "%f %f %f", &x, &y, &z) != 3) {
                ok = 0;
                break;
            }
            if (nv == vcap) {
                long nc = vcap ? 2 * vcap : 4096;
                rs_vec3 *t = (rs_vec3 *)realloc(v, (size_t)nc * sizeof *t);
                if (!t) {
                    ok = 0;
                    break;
                }
                v = t;
                vcap = nc;
            }
            v[nv++] = rs_v3(x, y, z);
        } else if (line[0] == 'f' && line[1] == ' ') {
            long idx[3], n = 0;
            char *tok = strtok(line + 2, " \t\r\n");
            for (; tok && ok; tok = strtok(NULL, " \t\r\n")) {
                long k = test_mesh_obj_index(tok, nv);
                if (n < 2) {
                    idx[n++] = k;
                    continue;
                }
                idx[2] = k;
                ok = test_mesh_push(m, &cap, v, nv, idx[0], idx[1], idx[2]);
                idx[1] = idx[2];
            }
        }
    }
    free(v);
    return ok;
}

/* Reads `path` (.ply or .obj) into *m; returns 1 on success, 0 (and an empty mesh) otherwise. */
static inline int test_mesh_load(const char *path, test_mesh *m)
{
    FILE *f = fopen(path, "r");
    size_t len = strlen(path);
    int ok;
    m->tris = NULL;
    m->n_tris = 0;
    if (!f)
        return 0;
    if (len > 4 && strcmp(path + len - 4, ".obj") == 0)
        ok = test_mesh_read_obj(f, m);
    else
        ok = test_mesh_read_ply(f, m);
    fclose(f);
    if (!ok || m->n_tris == 0) {
        test_mesh_free(m);
        return 0;
    }
    return 1;
}

#endif
