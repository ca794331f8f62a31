/* scenes/gltf_check.c — see gltf_check.h.  Built with cJSON (gltf_check_none.c otherwise). */
#include "scenes/gltf_check.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "core/alloc.h"
#include "core/file.h"

#define GLB_MAGIC      0x46546C67u /* "glTF" */
#define GLB_CHUNK_JSON 0x4E4F534Au /* "JSON" */

static uint32_t le32(const unsigned char *b)
{
    return (uint32_t)b[0] | (uint32_t)b[1] << 8 | (uint32_t)b[2] << 16 | (uint32_t)b[3] << 24;
}

/* A .glb's JSON chunk into *json (rs_alloc'd, NUL-terminated), after checking the container's
 * framing against the file's size: the header's length and every chunk's length must fit, so a
 * 900-byte file cannot make anyone allocate gigabytes. */
static rs_status read_glb_json(const char *path, FILE *f, uint64_t size, char **json, size_t *n)
{
    unsigned char h[20];
    uint64_t off = 12;
    uint32_t total, len, type;
    if (size < 20 || fread(h, 1, 20, f) != 20)
        return rs_error_set(RS_ERR_ARG, "%s: a glTF binary shorter than its headers", path);
    total = le32(h + 8);
    if (le32(h) != GLB_MAGIC)
        return rs_error_set(RS_ERR_ARG, "%s: not a glTF binary (no 'glTF' magic)", path);
    if (le32(h + 4) != 2)
        return rs_error_set(RS_ERR_ARG, "%s: glTF binary version %u (this reader takes 2)", path,
                            le32(h + 4));
    if (total < 20 || total > size)
        return rs_error_set(RS_ERR_ARG,
                            "%s: its header says %u bytes but the file has %llu (truncated or "
                            "corrupt)",
                            path, total, (unsigned long long)size);
    for (;;) { /* every chunk's length within the file, the first one JSON */
        unsigned char c[8];
        const unsigned char *p = off == 12 ? h + 12 : c;
        if (off != 12 && (fseek(f, (long)off, SEEK_SET) != 0 || fread(c, 1, 8, f) != 8))
            break;
        len = le32(p);
        type = le32(p + 4);
        if (off + 8 > total || (uint64_t)len > total - off - 8)
            return rs_error_set(RS_ERR_ARG,
                                "%s: a chunk at byte %llu claims %u bytes, past the end of the "
                                "file (%u bytes)",
                                path, (unsigned long long)off, len, total);
        if (off == 12 && type != GLB_CHUNK_JSON)
            return rs_error_set(RS_ERR_ARG, "%s: its first chunk is not JSON", path);
        off += 8 + (uint64_t)len;
        if (off + 8 > total)
            break;
    }
    len = le32(h + 12);
    *json = (char *)rs_alloc((size_t)len + 1, 1);
    if (!*json)
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
    if (fseek(f, 20, SEEK_SET) != 0 || fread(*json, 1, len, f) != len) {
        rs_free(*json);
        return rs_error_set(RS_ERR_IO, "%s: cannot read its JSON chunk", path);
    }
    (*json)[len] = 0;
    *n = len;
    return RS_OK;
}

static rs_status read_text(const char *path, FILE *f, uint64_t size, char **json, size_t *n)
{
    *json = (char *)rs_alloc((size_t)size + 1, 1);
    if (!*json)
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
    if (fread(*json, 1, (size_t)size, f) != size) {
        rs_free(*json);
        return rs_error_set(RS_ERR_IO, "%s: cannot read it", path);
    }
    (*json)[size] = 0;
    *n = (size_t)size;
    return RS_OK;
}

/* ---- the node tree ------------------------------------------------------------------------- */

/* Every node's children are nodes, no node has two parents or is its own ancestor, and no chain
 * from a root is deeper than RS_GLTF_MAX_DEPTH: walked with a stack of our own, so that the
 * check cannot overflow the call stack the way a recursive reader does. */
static rs_status check_nodes(const char *path, const cJSON *root)
{
    const cJSON *nodes = cJSON_GetObjectItemCaseSensitive(root, "nodes");
    int n = cJSON_IsArray(nodes) ? cJSON_GetArraySize(nodes) : 0, i;
    int *parent, *depth, *order, n_order = 0;
    const cJSON **node;
    rs_status st = RS_OK;
    if (n == 0)
        return RS_OK;
    parent = (int *)rs_alloc((size_t)n, sizeof *parent);
    depth = (int *)rs_alloc((size_t)n, sizeof *depth);
    order = (int *)rs_alloc((size_t)n, sizeof *order);
    node = (const cJSON **)rs_alloc((size_t)n, sizeof *node);
    if (!parent || !depth || !order || !node) {
        st = rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
        goto out;
    }
    i = 0;
    for (const cJSON *nd = nodes->child; nd; nd = nd->next)
        node[i++] = nd;
    for (i = 0; i < n; ++i)
        parent[i] = -1;
    for (i = 0; i < n && st == RS_OK; ++i) {
        const cJSON *kids = cJSON_GetObjectItemCaseSensitive(node[i], "children"), *k;
        cJSON_ArrayForEach(k, kids)
        {
            double v = cJSON_IsNumber(k) ? k->valuedouble : -1;
            int c = (int)v;
            if (!(v >= 0 && v < n && v == c)) {
                st = rs_error_set(RS_ERR_ARG, "%s: nodes[%d].children names no node", path, i);
                break;
            }
            if (parent[c] >= 0 || c == i) {
                st = rs_error_set(RS_ERR_ARG,
                                  "%s: nodes[%d] is a child twice (of nodes[%d] and nodes[%d]) "
                                  "or of itself: glTF nodes form trees",
                                  path, c, parent[c] >= 0 ? parent[c] : i, i);
                break;
            }
            parent[c] = i;
        }
    }
    /* depths from the roots down, breadth first; a node never reached sits on a cycle */
    for (i = 0; i < n && st == RS_OK; ++i)
        if (parent[i] < 0) {
            depth[i] = 0;
            order[n_order++] = i;
        }
    for (int q = 0; q < n_order && st == RS_OK; ++q) {
        const cJSON *kids = cJSON_GetObjectItemCaseSensitive(node[order[q]], "children"), *k;
        cJSON_ArrayForEach(k, kids)
        {
            int c = (int)k->valuedouble;
            depth[c] = depth[order[q]] + 1;
            if (depth[c] > RS_GLTF_MAX_DEPTH) {
                st = rs_error_set(RS_ERR_ARG, "%s: nodes nest deeper than %d levels (nodes[%d])",
                                  path, RS_GLTF_MAX_DEPTH, c);
                break;
            }
            order[n_order++] = c;
        }
    }
    if (st == RS_OK && n_order < n)
        st = rs_error_set(RS_ERR_ARG, "%s: its nodes form a cycle (%d of %d nodes are not in a tree)",
                          path, n - n_order, n);
out:
    rs_free(parent);
    rs_free(depth);
    rs_free(order);
    rs_free(node);
    return st;
}

/* ---- the files a glTF names ---------------------------------------------------------------- */

static int hex(int c)
{
    return c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10
                                          : c >= 'A' && c <= 'F' ? c - 'A' + 10
                                                                 : -1;
}

/* `uri`, a relative reference, as a path beside the scene (percent escapes decoded); 0 if it
 * does not fit or an escape is broken. */
static int uri_path(const char *dir, const char *uri, char *out, size_t n)
{
    size_t k = (size_t)snprintf(out, n, "%s/", dir);
    for (; *uri && k + 1 < n; ++uri) {
        if (*uri == '%') {
            int a = hex(uri[1]), b = a >= 0 ? hex(uri[2]) : -1;
            if (b < 0)
                return 0;
            out[k++] = (char)(a * 16 + b);
            uri += 2;
        } else {
            out[k++] = *uri;
        }
    }
    out[k] = 0;
    return !*uri;
}

/* Each buffers[i].uri and images[i].uri is a data: URI or a file beside the scene that exists:
 * Assimp reads a missing one as any file of the same base name in the scene's folder, and would
 * fetch nothing from a URL. */
static rs_status check_uris(const char *path, const char *dir, const cJSON *root,
                            const char *what)
{
    const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, what), *it;
    int i = 0;
    cJSON_ArrayForEach(it, arr)
    {
        const cJSON *u = cJSON_GetObjectItemCaseSensitive(it, "uri");
        const char *uri = cJSON_IsString(u) ? u->valuestring : NULL;
        char file[4096];
        struct stat sb;
        if (uri && strncmp(uri, "data:", 5) != 0) {
            if (strstr(uri, "://") || uri[0] == '/')
                return rs_error_set(RS_ERR_ARG,
                                    "%s: %s[%d].uri '%.200s': only files beside the scene (a "
                                    "relative path) and data: URIs are read",
                                    path, what, i, uri);
            if (!uri_path(dir, uri, file, sizeof file))
                return rs_error_set(RS_ERR_ARG, "%s: %s[%d].uri '%.200s': not a readable path",
                                    path, what, i, uri);
            if (stat(file, &sb) != 0 || !S_ISREG(sb.st_mode))
                return rs_error_set(RS_ERR_ARG, "%s: %s[%d].uri '%.200s': no such file (%s)",
                                    path, what, i, uri, file);
        }
        ++i;
    }
    return RS_OK;
}

/* The file's JSON, parsed (cJSON_Delete it). */
static rs_status parse_json(const char *path, int glb, cJSON **out)
{
    FILE *f;
    uint64_t size;
    char *json = NULL;
    size_t n = 0;
    cJSON *root;
    rs_status st = rs_file_open(path, RS_FILE_MAX_MESH_BYTES, &f, &size);
    *out = NULL;
    if (st != RS_OK)
        return st;
    st = glb ? read_glb_json(path, f, size, &json, &n) : read_text(path, f, size, &json, &n);
    fclose(f);
    if (st != RS_OK)
        return st;
    root = cJSON_ParseWithLength(json, n);
    rs_free(json);
    if (!root || !cJSON_IsObject(root)) {
        cJSON_Delete(root);
        return rs_error_set(RS_ERR_ARG, "%s: its JSON cannot be read (cut short, or not JSON)",
                            path);
    }
    *out = root;
    return RS_OK;
}

/* ---- texture transforms ----------------------------------------------------------------------- */

/* Whether `v` is an array of exactly two finite numbers. */
static int two_numbers(const cJSON *v)
{
    const cJSON *a, *b;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 2)
        return 0;
    a = v->child;
    b = a->next;
    return cJSON_IsNumber(a) && cJSON_IsNumber(b) && isfinite(a->valuedouble) &&
           isfinite(b->valuedouble);
}

/* One KHR_texture_transform object `t` found at `where`: offset and scale two numbers each,
 * rotation a number, texCoord a whole number >= 0 (the extension's schema).  Assimp's reader
 * asserts on them (rapidjson: a SIGABRT and no line of ours), so they are checked first. */
static rs_status check_transform(const char *path, const char *where, const cJSON *t)
{
    static const char *const pairs[2] = {"offset", "scale"};
    const cJSON *v;
    int k;
    if (!cJSON_IsObject(t))
        return rs_error_set(RS_ERR_ARG, "%s: %s.KHR_texture_transform: not an object", path,
                            where);
    for (k = 0; k < 2; ++k)
        if ((v = cJSON_GetObjectItemCaseSensitive(t, pairs[k])) && !two_numbers(v))
            return rs_error_set(RS_ERR_ARG,
                                "%s: %s.KHR_texture_transform.%s: want two numbers, as [x, y]",
                                path, where, pairs[k]);
    v = cJSON_GetObjectItemCaseSensitive(t, "rotation");
    if (v && !(cJSON_IsNumber(v) && isfinite(v->valuedouble)))
        return rs_error_set(RS_ERR_ARG,
                            "%s: %s.KHR_texture_transform.rotation: want a number (radians)", path,
                            where);
    v = cJSON_GetObjectItemCaseSensitive(t, "texCoord");
    if (v && !(cJSON_IsNumber(v) && v->valuedouble >= 0 && v->valuedouble <= 65535 &&
               v->valuedouble == (double)(int)v->valuedouble))
        return rs_error_set(RS_ERR_ARG,
                            "%s: %s.KHR_texture_transform.texCoord: want a whole number >= 0",
                            path, where);
    return RS_OK;
}

/* Every KHR_texture_transform under `node` (a material: its textures and its extensions'
 * textures, at any depth), `where` naming node. */
static rs_status check_transforms_in(const char *path, const char *where, const cJSON *node,
                                     int depth)
{
    const cJSON *c;
    char sub[512];
    int i = 0;
    if (depth > 16 || !(cJSON_IsObject(node) || cJSON_IsArray(node)))
        return RS_OK;
    for (c = node->child; c; c = c->next, ++i) {
        rs_status st;
        if (cJSON_IsObject(node) && c->string && strcmp(c->string, "KHR_texture_transform") == 0) {
            if ((st = check_transform(path, where, c)) != RS_OK)
                return st;
            continue;
        }
        if (cJSON_IsObject(node))
            snprintf(sub, sizeof sub, "%.400s.%.64s", where, c->string ? c->string : "?");
        else
            snprintf(sub, sizeof sub, "%.400s[%d]", where, i);
        if ((st = check_transforms_in(path, sub, c, depth + 1)) != RS_OK)
            return st;
    }
    return RS_OK;
}

static rs_status check_transforms(const char *path, const cJSON *root)
{
    const cJSON *mats = cJSON_GetObjectItemCaseSensitive(root, "materials"), *m;
    int i = 0;
    cJSON_ArrayForEach(m, mats)
    {
        char where[32];
        rs_status st;
        snprintf(where, sizeof where, "materials[%d]", i++);
        if ((st = check_transforms_in(path, where, m, 0)) != RS_OK)
            return st;
    }
    return RS_OK;
}

rs_status rs_gltf_preflight(const char *path, int glb)
{
    char dir[4096];
    const char *slash = strrchr(path, '/');
    cJSON *root;
    rs_status st = parse_json(path, glb, &root);
    if (st != RS_OK)
        return st;
    snprintf(dir, sizeof dir, "%.*s", slash ? (int)(slash - path) : 1, slash ? path : ".");
    st = check_nodes(path, root);
    if (st == RS_OK)
        st = check_uris(path, dir, root, "buffers");
    if (st == RS_OK)
        st = check_uris(path, dir, root, "images");
    if (st == RS_OK)
        st = check_transforms(path, root);
    cJSON_Delete(root);
    return st;
}

/* ---- the material extensions ---- */

/* One number of an extension: 0 (absent: the default stays), 1 (read into *out), -1 (outside
 * [lo, hi], or (lo, hi] when lo_open, or not a number: an error naming it, set). */
static int read_number(const char *path, int mat, const char *ext, const cJSON *obj,
                       const char *key, float lo, float hi, int lo_open, float *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    double d;
    char want[64];
    if (!v)
        return 0;
    d = cJSON_IsNumber(v) ? v->valuedouble : NAN;
    if ((d >= lo && d <= hi) && (!lo_open || d > lo)) {
        *out = (float)d;
        return 1;
    }
    if (hi < INFINITY)
        snprintf(want, sizeof want, "a number from %g to %g", (double)lo, (double)hi);
    else
        snprintf(want, sizeof want, "a number %s %g", lo_open ? "above" : "of at least",
                 (double)lo);
    rs_error_set(RS_ERR_ARG, "%s: materials[%d].extensions.%s.%s: %s (want %s)", path, mat, ext,
                 key, cJSON_IsNumber(v) ? "out of range" : "not a number", want);
    return -1;
}

static int read_colour(const char *path, int mat, const char *ext, const cJSON *obj,
                       const char *key, double hi, float *out)
{
    const cJSON *v = cJSON_GetObjectItemCaseSensitive(obj, key);
    int i;
    if (!v)
        return 0;
    if (!cJSON_IsArray(v) || cJSON_GetArraySize(v) != 3) {
        rs_error_set(RS_ERR_ARG, "%s: materials[%d].extensions.%s.%s: not 3 numbers", path, mat,
                     ext, key);
        return -1;
    }
    for (i = 0; i < 3; ++i) {
        const cJSON *c = cJSON_GetArrayItem(v, i);
        if (!cJSON_IsNumber(c) || !(c->valuedouble >= 0.0 && c->valuedouble <= hi) ||
            !isfinite(c->valuedouble)) {
            if (hi < INFINITY)
                rs_error_set(RS_ERR_ARG, "%s: materials[%d].extensions.%s.%s[%d]: not a number in "
                             "[0, %g]", path, mat, ext, key, i, hi);
            else
                rs_error_set(RS_ERR_ARG, "%s: materials[%d].extensions.%s.%s[%d]: not a finite "
                             "number >= 0", path, mat, ext, key, i);
            return -1;
        }
        out[i] = (float)c->valuedouble;
    }
    return 1;
}

static const cJSON *ext_of(const cJSON *mat, const char *name)
{
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(mat, "extensions");
    const cJSON *x = cJSON_IsObject(e) ? cJSON_GetObjectItemCaseSensitive(e, name) : NULL;
    return cJSON_IsObject(x) ? x : NULL;
}

/* Material i's "extensions" and each extension in it objects, as the schema says (one that was
 * a string or an array was skipped without a word). */
static rs_status check_ext_objects(const char *path, int i, const cJSON *mat)
{
    const cJSON *e = cJSON_GetObjectItemCaseSensitive(mat, "extensions"), *x;
    if (!e)
        return RS_OK;
    if (!cJSON_IsObject(e))
        return rs_error_set(RS_ERR_ARG, "%s: materials[%d].extensions: not an object", path, i);
    for (x = e->child; x; x = x->next)
        if (!cJSON_IsObject(x))
            return rs_error_set(RS_ERR_ARG, "%s: materials[%d].extensions.%.80s: not an object",
                                path, i, x->string ? x->string : "?");
    return RS_OK;
}

static rs_status read_material(const char *path, int i, const cJSON *mat, rs_gltf_mat_ext *m)
{
    const cJSON *x;
    *m = rs_gltf_mat_ext_default();
    if (!cJSON_IsObject(mat))
        return RS_OK;
    if (check_ext_objects(path, i, mat) != RS_OK)
        return RS_ERR_ARG;
    if ((x = ext_of(mat, "KHR_materials_emissive_strength")) &&
        read_number(path, i, "KHR_materials_emissive_strength", x, "emissiveStrength", 0.0f,
                    INFINITY, 0, &m->emissive_strength) < 0)
        return RS_ERR_ARG;
    if ((x = ext_of(mat, "KHR_materials_ior"))) {
        /* 0 is allowed by the extension (a "no refraction" flag); taken as the default */
        float ior = m->ior;
        if (read_number(path, i, "KHR_materials_ior", x, "ior", 0.0f, 100.0f, 0, &ior) < 0)
            return RS_ERR_ARG;
        if (ior != 0.0f && ior < 1.0f)
            return rs_error_set(RS_ERR_ARG, "%s: materials[%d].extensions.KHR_materials_ior.ior:"
                                " %g is below 1", path, i, (double)ior);
        if (ior >= 1.0f)
            m->ior = ior;
    }
    if ((x = ext_of(mat, "KHR_materials_specular")) &&
        (read_number(path, i, "KHR_materials_specular", x, "specularFactor", 0.0f, 1.0f, 0,
                     &m->specular) < 0 ||
         /* the schema bounds it below only: F0 = ((ior - 1) / (ior + 1))^2 times it, held
          * to 1 where it is used */
         read_colour(path, i, "KHR_materials_specular", x, "specularColorFactor", INFINITY,
                     m->specular_color) < 0))
        return RS_ERR_ARG;
    if ((x = ext_of(mat, "KHR_materials_volume")) &&
        (read_number(path, i, "KHR_materials_volume", x, "attenuationDistance", 0.0f, INFINITY, 1,
                     &m->attenuation_distance) < 0 ||
         read_colour(path, i, "KHR_materials_volume", x, "attenuationColor", 1.0,
                     m->attenuation_color) < 0))
        return RS_ERR_ARG;
    if ((x = ext_of(mat, "KHR_materials_clearcoat")) &&
        (read_number(path, i, "KHR_materials_clearcoat", x, "clearcoatFactor", 0.0f, 1.0f, 0,
                     &m->clearcoat) < 0 ||
         read_number(path, i, "KHR_materials_clearcoat", x, "clearcoatRoughnessFactor", 0.0f,
                     1.0f, 0, &m->clearcoat_roughness) < 0))
        return RS_ERR_ARG;
    if ((x = ext_of(mat, "KHR_materials_sheen")) &&
        (read_colour(path, i, "KHR_materials_sheen", x, "sheenColorFactor", 1.0,
                     m->sheen_color) < 0 ||
         read_number(path, i, "KHR_materials_sheen", x, "sheenRoughnessFactor", 0.0f, 1.0f, 0,
                     &m->sheen_roughness) < 0))
        return RS_ERR_ARG;
    m->unlit = ext_of(mat, "KHR_materials_unlit") != NULL;
    return RS_OK;
}

/* Appends `name` to list[n], ", "-separated (a name that does not fit is left off, with "...") */
static void append_name(char *list, size_t n, const char *name)
{
    size_t used = strlen(list);
    if (used + strlen(name) + 8 < n)
        snprintf(list + used, n - used, "%s%s", used ? ", " : "", name);
    else if (used + 6 < n && !strstr(list, "..."))
        snprintf(list + used, n - used, ", ...");
}

/* Whether `name` is one of names[0..n). */
static int name_in(const char *name, const char *const *names, size_t n)
{
    size_t k;
    for (k = 0; k < n; ++k)
        if (strcmp(name, names[k]) == 0)
            return 1;
    return 0;
}

rs_status rs_gltf_read_ext(const char *path, int glb, rs_gltf_ext *out)
{
    static const char *const known[] = {RS_GLTF_READ_EXTENSIONS};
    const cJSON *mats, *used, *u;
    cJSON *root;
    rs_status st;
    int i, n;
    memset(out, 0, sizeof *out);
    st = parse_json(path, glb, &root);
    if (st != RS_OK)
        return st;
    used = cJSON_GetObjectItemCaseSensitive(root, "extensionsUsed");
    if (cJSON_IsArray(used))
        for (u = used->child; u; u = u->next) {
            int ours;
            if (!cJSON_IsString(u))
                continue;
            ours = name_in(u->valuestring, known, sizeof known / sizeof *known);
            append_name(ours ? out->used : out->unread, ours ? sizeof out->used
                                                             : sizeof out->unread,
                        u->valuestring);
        }
    /* an extension the file requires and raystream does not read: the file must not load
     * (glTF 2.0, 3.12); Assimp decodes the two geometry ones itself */
    used = cJSON_GetObjectItemCaseSensitive(root, "extensionsRequired");
    if (cJSON_IsArray(used))
        for (u = used->child; u && st == RS_OK; u = u->next) {
            static const char *const decoded[] = {"KHR_mesh_quantization",
                                                  "KHR_draco_mesh_compression"};
            if (!cJSON_IsString(u))
                continue;
            if (!name_in(u->valuestring, known, sizeof known / sizeof *known) &&
                !name_in(u->valuestring, decoded, sizeof decoded / sizeof *decoded))
                st = rs_error_set(RS_ERR_ARG,
                                  "%s: requires the extension %.80s (extensionsRequired), which "
                                  "raystream does not read; a file that requires one must not "
                                  "load without it",
                                  path, u->valuestring);
        }
    mats = cJSON_GetObjectItemCaseSensitive(root, "materials");
    n = st == RS_OK && cJSON_IsArray(mats) ? cJSON_GetArraySize(mats) : 0;
    if (n > 0) {
        out->materials = (rs_gltf_mat_ext *)rs_alloc((size_t)n, sizeof *out->materials);
        if (!out->materials)
            st = rs_error_set(RS_ERR_NOMEM, "%s: out of memory", path);
        else
            out->n_materials = (uint32_t)n;
        i = 0;
        for (u = mats->child; u && st == RS_OK; u = u->next, ++i)
            st = read_material(path, i, u, &out->materials[i]);
    }
    cJSON_Delete(root);
    if (st != RS_OK)
        rs_gltf_ext_free(out);
    return st;
}

void rs_gltf_ext_free(rs_gltf_ext *e)
{
    rs_free(e->materials);
    e->materials = NULL;
    e->n_materials = 0;
}
