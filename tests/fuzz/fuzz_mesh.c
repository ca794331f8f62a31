/* tests/fuzz/fuzz_mesh.c — libFuzzer harness for the mesh import.
 *
 * The bytes are written to FUZZ.obj and to FUZZ.ply in a folder of its own, and each is loaded
 * the way `raystream render --mesh FILE` loads it: rs_builtin_create_ex("cornell-mesh") ->
 * rs_scene_add_mesh (the PLY header check or the strip reader, Assimp through our aiFileIO) ->
 * rs_scene_finalize; and to FUZZ.gltf and FUZZ.glb, loaded as `raystream render FUZZ.gltf`
 * loads it (rs_scene_load_gltf: our own check of the container, the node tree and the files it
 * names, then nodes, cameras, lights, materials and textures; seeds in tests/data).
 * Any input must give a scene or be refused with one line naming the file; never a crash, a
 * hang, a leak or a sanitizer report, and every file opened for Assimp must be closed again
 * (tests/fuzz/lsan.supp says why that is checked here).  Built with -DRS_FUZZ=ON (scripts/fuzz.sh).
 */
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "fuzz_util.h"
#include "scenes/builtin.h"
#include "scenes/gltf.h"

/* Writes the bytes to FUZZ.ext and loads that file: as the mesh of builtin:cornell-mesh, or
 * (gltf) as a whole glTF scene.  A refusal must be one line naming the file; every file opened
 * must be closed again. */
static void load_as(const uint8_t *data, size_t size, const char *ext, int gltf)
{
    char path[600];
    rs_builtin_opts o;
    rs_scene *s = NULL;
    rs_status st;
    int fds = fz_open_fds();
    snprintf(path, sizeof path, "%s/fuzz.%s", fz_tmpdir(), ext);
    fz_write_file(path, data, size);
    memset(&o, 0, sizeof o);
    o.mesh_file = path;
    rs_error_clear();
    st = gltf ? rs_scene_load_gltf(path, NULL, &s) : rs_builtin_create_ex("cornell-mesh", &o, &s);
    fz_check_refusal(st, path);
    rs_scene_destroy(s);
    rs_error_clear();
    unlink(path);
    if (fz_open_fds() != fds)
        fz_broken("%s: %d file descriptors open after the import, %d before", path, fz_open_fds(),
                  fds);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    load_as(data, size, "obj", 0);
    load_as(data, size, "ply", 0);
    load_as(data, size, "gltf", 1);
    load_as(data, size, "glb", 1); /* the container's lengths and the JSON inside it */
    return 0;
}
