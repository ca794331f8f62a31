/* scenes/builtin.h — scenes compiled into the program, named "builtin:NAME" on the command line. */
#ifndef RS_SCENES_BUILTIN_H
#define RS_SCENES_BUILTIN_H

#include <stdio.h>

#include "scenes/scene.h"

typedef struct rs_builtin_opts {
    const char *models_dir; /* the test models (bunny/, teapot/, ...); NULL: $RS_MODELS_DIR,
                               else the shared/models folder beside the source tree */
    const char *mesh_file;  /* for "cornell-mesh": the mesh dropped into the Cornell box */
    FILE *log;              /* a line of what the mesh import loaded, or NULL (then only a
                               warning, on stderr, if it dropped faces) */
} rs_builtin_opts;

/* Creates and finalizes built-in scene `name` (without the "builtin:" prefix).  An unknown name
 * is RS_ERR_ARG with a message listing the known ones; a scene whose model file is missing is
 * RS_ERR_IO naming the file and --models. */
rs_status rs_builtin_create(const char *name, rs_scene **out);
rs_status rs_builtin_create_ex(const char *name, const rs_builtin_opts *opts, rs_scene **out);
/* The models folder that rs_builtin_create would use with `dir` (which may be NULL). */
const char *rs_builtin_models_dir(const char *dir);
/* The i-th built-in name and a one-line description; NULL past the end. */
const char *rs_builtin_name(int i, const char **description);

#endif
