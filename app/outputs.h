/* app/outputs.h — the files one `raystream render` writes (the image, --stats-json FILE,
 * --timeline FILE.svg): checked before any work, written beside their targets under temporary
 * names, and put in place only once every one of them was written, so a run that fails leaves
 * the old file at every output path as it was.
 *
 * Invariants:
 *   - rs_outputs_check refuses, with one line on stderr naming the option and the file, an output
 *     that is a folder, an existing file that cannot be written, a folder that is missing or does
 *     not accept new files (probed by creating and removing the staged name), two outputs naming
 *     the same file, and an output that is one of the input files (but its own may_replace).
 *     It leaves no file behind.
 *   - A staged file is named PATH.tmp-PID, beside PATH.  That is also the name core/image_io's
 *     rs_image_write gives its own temporary file (image_io.cpp: temp_name), so the image's entry
 *     names the file the core is writing.
 *   - Every name that may exist while the outputs are written is tracked (rs_outputs_track)
 *     before the first file is created; rs_outputs_remove_tracked calls only unlink(2) on a fixed
 *     table, so a signal handler may run it. */
#ifndef RS_APP_OUTPUTS_H
#define RS_APP_OUTPUTS_H

#include <stdio.h>

#define RS_OUTPUT_PATH_MAX 4096
#define RS_OUTPUTS_MAX     4

typedef struct rs_output {
    const char *option; /* "-o", "--stats-json", "--timeline", or "the image" (the default name) */
    const char *path;   /* the file the user asked for */
    int may_be_special; /* input: an existing non-regular file (/dev/stdout, a pipe) is allowed */
    const char *may_replace; /* input: an input file this output may replace (the checkpoint
                                over the --resume file it continues), or NULL */
    int in_place;       /* output: path is such a file; written directly, after everything else */
    int dropped;        /* output: not written after all (a checkpoint that keeps its last
                           contents): nothing to rename */
    char staged[RS_OUTPUT_PATH_MAX]; /* output: "path.tmp-PID" */
} rs_output;

/* Checks out[0..n) (option, path, may_be_special filled in) and sets in_place and staged;
 * inputs[0..n_inputs) are files that no output may replace (NULLs skipped).  Returns 0
 * (RS_EXIT_OK) or RS_EXIT_USAGE after printing one line. */
int rs_outputs_check(rs_output *out, int n, const char *const *inputs, int n_inputs);

/* Renames o->staged to o->path.  Returns 1, or 0 after printing why. */
int rs_output_commit(const rs_output *o);

/* Adds `path` to the names removed by rs_outputs_remove_tracked (at most 8; longer names than
 * RS_OUTPUT_PATH_MAX are not taken: the check refuses such outputs).  Not signal-safe. */
void rs_outputs_track(const char *path);
/* Empties the table. */
void rs_outputs_untrack(void);
/* Removes every tracked name that exists.  Async-signal-safe. */
void rs_outputs_remove_tracked(void);

#endif
