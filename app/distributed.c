/* app/distributed.c — see distributed.h.  Built only with MPI (distributed_none.c otherwise);
 * dist_internal.h lists the files it is split into and the messages between the ranks. */
#include "app/distributed.h"

#include <stdio.h>
#include <string.h>

#include "app/dist_internal.h"
#include "core/alloc.h"

rs_status rs_dist_fault_parse(const char *spec, rs_dist_fault *f)
{
    const char *p = spec;
    memset(f, 0, sizeof *f);
    f->slow_rank = f->die_rank = f->die_start_rank = f->die_init_rank = -1;
    if (!spec || !*spec)
        return RS_OK;
    while (*p) {
        int rank, n = 0;
        double x;
        if (sscanf(p, "slow:%d:%lf%n", &rank, &x, &n) == 2 && n > 0 && rank >= 0 && x >= 1) {
            f->slow_rank = rank;
            f->slow_factor = x;
        } else if (sscanf(p, "die-start:%d%n", &rank, &n) == 1 && n > 0 && rank >= 0) {
            f->die_start_rank = rank;
        } else if (sscanf(p, "die-init:%d%n", &rank, &n) == 1 && n > 0 && rank >= 0) {
            f->die_init_rank = rank;
        } else if (sscanf(p, "die:%d:%lf%n", &rank, &x, &n) == 2 && n > 0 && rank > 0 &&
                   x >= 0 && x < 1e9 && x == (uint32_t)x) {
            f->die_rank = rank;
            f->die_after = (uint32_t)x;
        } else {
            return rs_error_set(RS_ERR_ARG,
                                "RS_MPI_FAULT: cannot read '%s' (slow:RANK:FACTOR, "
                                "die:RANK:PASSES, die-start:RANK or die-init:RANK, "
                                "comma-separated)",
                                p);
        }
        p += n;
        if (*p == ',')
            ++p;
        else if (*p)
            return rs_error_set(RS_ERR_ARG, "RS_MPI_FAULT: junk after '%.*s'", (int)(p - spec),
                                spec);
    }
    return RS_OK;
}

rs_status rs_dist_render(rs_dist *d, const rs_dist_job *job, rs_film *film, rs_dist_result *res)
{
    double timeout_s = job->timeout_s > 0 ? job->timeout_s : 60.0;
    memset(res, 0, sizeof *res);
    rs_dist_cpu0 = rs_dist_thread_cpu_s();
    if (d->rank == 0)
        return rs_dist_run_coordinator(d, job, film, res, timeout_s);
    return rs_dist_run_worker(d, job, film, timeout_s);
}

void rs_dist_result_free(rs_dist_result *res)
{
    rs_free(res->rank);
    rs_path_ranges_free(&res->done);
    res->rank = NULL;
}

int rs_dist_result_add(rs_dist_result *total, const rs_dist_result *job)
{
    int r;
    if (!total->rank) {
        total->rank = (rs_dist_rank_stats *)rs_calloc((size_t)job->ranks, sizeof *total->rank);
        if (!total->rank)
            return 0;
        total->ranks = job->ranks;
        for (r = 0; r < job->ranks; ++r) {
            memcpy(total->rank[r].desc, job->rank[r].desc, RS_DIST_DESC);
            total->rank[r].alive = 1;
        }
    }
    total->pass_spp = job->pass_spp;
    total->passes_total += job->passes_total;
    total->samples_done += job->samples_done;
    total->complete = job->complete;
    total->flushes += job->flushes;
    total->time_limited |= job->time_limited;
    total->stopped |= job->stopped;
    total->dead += job->dead;
    total->reissued += job->reissued;
    total->bytes_received += job->bytes_received;
    total->messages = job->messages; /* counted from the start */
    total->message_bytes = job->message_bytes;
    total->seconds += job->seconds;
    rs_render_stats_add(&total->local, &job->local);
    total->rays_closest += job->rays_closest;
    total->rays_shadow += job->rays_shadow;
    if (job->max_bounce > total->max_bounce)
        total->max_bounce = job->max_bounce;
    for (r = 0; r < job->ranks && r < total->ranks; ++r) {
        rs_dist_rank_stats *t = &total->rank[r];
        const rs_dist_rank_stats *k = &job->rank[r];
        t->passes += k->passes;
        t->paths += k->paths;
        t->busy_s += k->busy_s;
        t->wall_s += k->wall_s;
        t->film_bytes += k->film_bytes;
        t->rays_closest += k->rays_closest;
        t->rays_shadow += k->rays_shadow;
        t->comm_cpu_s += k->comm_cpu_s;
        t->alive &= k->alive;
        t->failed |= k->failed;
    }
    return 1;
}
