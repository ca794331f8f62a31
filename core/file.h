/* core/file.h — opening input files safely.  Every file the renderer reads (scene files, meshes,
 * the files a mesh names, textures) goes through here first, so that no input can hang or
 * exhaust it:
 *
 *   - only regular files are opened: a folder is "PATH: is a folder", anything else (a FIFO,
 *     /dev/zero, a socket, a terminal) "PATH: not a regular file".  The type is read with stat()
 *     before any open(), so a FIFO or a device is never opened at all; the open itself uses
 *     O_NONBLOCK and fstat() checks that the file opened is still the regular file stat() saw;
 *   - a size over the caller's bound is "PATH: larger than N MiB";
 *   - a file that cannot be opened (missing, no permission) is "PATH: cannot open: REASON".
 *
 * Problems with the file's kind or size are RS_ERR_ARG (bad input); failures to open it are
 * RS_ERR_IO.  The *_quiet forms write the message into a buffer and leave the first-error slot
 * alone (for callers such as Assimp's file callbacks, where a missing file may be harmless). */
#ifndef RS_CORE_FILE_H
#define RS_CORE_FILE_H

#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "core/status.h"

/* Bounds on input sizes: far above any real file of the kind, far below what would exhaust a
 * machine's memory. */
#define RS_FILE_MAX_SCENE_BYTES ((uint64_t)256 << 20) /* a JSON scene */
#define RS_FILE_MAX_MESH_BYTES  ((uint64_t)4 << 30)   /* a mesh or a file it names */
#define RS_FILE_MAX_IMAGE_BYTES ((uint64_t)1 << 30)   /* a texture */

#ifdef __cplusplus
extern "C" {
#endif
/* Opens regular file `path` of at most max_bytes for reading: *fd (blocking, close-on-exec) and
 * its size.  On failure returns RS_ERR_IO or RS_ERR_ARG (see above), writes "PATH: reason" into
 * msg[n] and does not touch the first-error slot. */
rs_status rs_file_open_quiet(const char *path, uint64_t max_bytes, int *fd, uint64_t *size,
                             char *msg, size_t n);
/* The same as a stdio stream ("rb"); the message goes to the first-error slot. */
rs_status rs_file_open(const char *path, uint64_t max_bytes, FILE **f, uint64_t *size);
/* Checks that `path` is a regular file of at most max_bytes without reading it (opens and
 * closes it); size may be NULL.  The message goes to the first-error slot. */
rs_status rs_file_check(const char *path, uint64_t max_bytes, uint64_t *size);
/* Reads the whole file into an rs_alloc'd buffer with a NUL after its *len bytes. */
rs_status rs_file_read(const char *path, uint64_t max_bytes, char **text, size_t *len);
/* The temporary file beside `path` that an output is written to before it is renamed over
 * `path` ("PATH.tmp-PID"; the image writers and the CLI's staged outputs use it, and the CLI
 * removes it on a second signal).  Returns 0 when it does not fit in n bytes. */
int rs_file_temp_name(const char *path, char *buf, size_t n);
#ifdef __cplusplus
}
#endif
#endif
