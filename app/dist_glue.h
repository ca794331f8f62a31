/* app/dist_glue.h — the `raystream` command under mpirun: the option parse and the render as
 * an MPI job (app/distributed.h does the messages).  Internal to app/. */
#ifndef RS_APP_DIST_GLUE_H
#define RS_APP_DIST_GLUE_H

#include "app/render_run.h"

/* rs_cli_parse; under mpirun every rank parses the same line and only rank 0 tells what is
 * wrong (the others' stderr goes to /dev/null meanwhile). */
int rs_mpi_parse_options(int argc, char **argv, rs_cli_options *o);

/* When an MPI launcher started this process: the whole render as a job of its ranks into the
 * zeroed *r (released here), its exit code in *code, and 1.  Otherwise 0, nothing done. */
int rs_mpi_render(const rs_cli_options *o, int *argc, char ***argv, render_run *r, int *code);

#endif
