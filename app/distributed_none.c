/* app/distributed_none.c — distributed.h without MPI (RS_MPI=OFF, or no MPI found): the
 * launcher is still recognised, so that `mpirun -n 4 raystream ...` says why it cannot work
 * instead of rendering the whole frame four times. */
#include <stdlib.h>
#include <string.h>

#include "app/distributed.h"

int rs_dist_built(void)
{
    return 0;
}

int rs_dist_launched(int *ranks, int *rank, int *local_ranks)
{
    const char *v = getenv("OMPI_COMM_WORLD_SIZE"), *r = getenv("OMPI_COMM_WORLD_RANK");
    if (!v)
        v = getenv("PMI_SIZE");
    if (!r)
        r = getenv("PMI_RANK");
    if (!v)
        return 0;
    *ranks = atoi(v);
    *rank = r ? atoi(r) : 0;
    *local_ranks = 1;
    return 1;
}

rs_status rs_dist_init(int *argc, char ***argv, rs_dist **out)
{
    (void)argc;
    (void)argv;
    *out = NULL;
    return rs_error_set(RS_ERR_ARG, "this raystream was built without MPI (RS_MPI)");
}

int rs_dist_rank(const rs_dist *d)
{
    (void)d;
    return 0;
}

int rs_dist_size(const rs_dist *d)
{
    (void)d;
    return 1;
}

int rs_dist_start(rs_dist *d, int (*setup)(void *user, char *desc, size_t n), void *user,
                  double timeout_s, int *who)
{
    char desc[RS_DIST_DESC];
    (void)d, (void)timeout_s;
    *who = 0;
    return setup(user, desc, sizeof desc);
}

int rs_dist_lost(const rs_dist *d)
{
    (void)d;
    return 0;
}

void rs_dist_finish(rs_dist *d)
{
    (void)d;
}

rs_status rs_dist_fault_parse(const char *spec, rs_dist_fault *out)
{
    (void)spec;
    memset(out, 0, sizeof *out);
    out->slow_rank = out->die_rank = out->die_start_rank = out->die_init_rank = -1;
    return RS_OK;
}

rs_status rs_dist_render(rs_dist *d, const rs_dist_job *job, rs_film *film, rs_dist_result *res)
{
    (void)d;
    (void)job;
    (void)film;
    memset(res, 0, sizeof *res);
    return rs_error_set(RS_ERR_ARG, "this raystream was built without MPI (RS_MPI)");
}

void rs_dist_result_free(rs_dist_result *res)
{
    (void)res;
}

int rs_dist_result_add(rs_dist_result *total, const rs_dist_result *job)
{
    (void)total, (void)job;
    return 0;
}

int rs_dist_job_begin(rs_dist *d, const uint32_t *pixels, uint32_t n_pixels, double timeout_s)
{
    (void)d, (void)pixels, (void)n_pixels, (void)timeout_s;
    return 0;
}

void rs_dist_jobs_end(rs_dist *d) { (void)d; }

int rs_dist_job_wait(rs_dist *d, uint32_t **pixels, uint32_t *n_pixels, double timeout_s)
{
    (void)d, (void)timeout_s;
    *pixels = NULL;
    *n_pixels = 0;
    return -1;
}
