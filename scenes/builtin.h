/* scenes/builtin.h — scenes compiled into the program, named "builtin:NAME" on the command line. */
#ifndef RS_SCENES_BUILTIN_H
#define RS_SCENES_BUILTIN_H

#include "scenes/scene.h"

/* Creates and finalizes built-in scene `name` (without the "builtin:" prefix).  An unknown name
 * is RS_ERR_ARG with a message listing the known ones. */
rs_status rs_builtin_create(const char *name, rs_scene **out);
/* The i-th built-in name and a one-line description; NULL past the end. */
const char *rs_builtin_name(int i, const char **description);

#endif
