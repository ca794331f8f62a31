/* app/dist_wire.c — the messages between the ranks (dist_internal.h has the tags and the film's
 * header): small messages counted, rank 0's messages polled and requests waited on without
 * spinning a core, a film sent and received in pieces of at most DIST_CHUNK values. */
#include <errno.h>
#include <string.h>
#include <time.h>

#include "app/dist_internal.h"
#include "core/alloc.h"
#include "core/clock.h"

uint64_t rs_dist_msgs, rs_dist_msg_bytes;
double rs_dist_cpu0;

void rs_dist_sleep_s(double s)
{
    struct timespec t;
    t.tv_sec = (time_t)s;
    t.tv_nsec = (long)((s - (double)t.tv_sec) * 1e9);
    while (nanosleep(&t, &t) != 0 && errno == EINTR) {
    }
}

uint64_t rs_dist_dbits(double v)
{
    uint64_t u;
    memcpy(&u, &v, sizeof u);
    return u;
}

double rs_dist_bitsd(uint64_t u)
{
    double v;
    memcpy(&v, &u, sizeof v);
    return v;
}

double rs_dist_thread_cpu_s(void)
{
    struct timespec t;
    if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t) != 0)
        return 0.0;
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

void rs_dist_idle_nap(double *nap, int active)
{
    if (active) {
        *nap = 1e-4;
        return;
    }
    rs_dist_sleep_s(*nap);
    if (*nap < 2e-3)
        *nap *= 2;
}

/* Waits for `req` without spinning a core; gives up (cancelling it) after timeout_s. */
static int wait_req(MPI_Request *req, double timeout_s)
{
    double t0 = rs_now_s(), nap = 1e-4;
    for (;;) {
        int flag = 0;
        if (MPI_Test(req, &flag, MPI_STATUS_IGNORE) != MPI_SUCCESS)
            return 0;
        if (flag)
            return 1;
        if (rs_now_s() - t0 > timeout_s) {
            MPI_Cancel(req);
            MPI_Request_free(req);
            return 0;
        }
        rs_dist_idle_nap(&nap, 0);
    }
}

int rs_dist_send_small(const uint64_t *v, int n, int to, int tag)
{
    uint64_t none = 0;
    rs_dist_msgs++;
    rs_dist_msg_bytes += 8u * (uint64_t)n;
    return MPI_Send(v ? (void *)v : (void *)&none, n, MPI_UINT64_T, to, tag, MPI_COMM_WORLD) ==
           MPI_SUCCESS;
}

int rs_dist_poll_rank0(int *tag, uint64_t v[2])
{
    int flag = 0, cnt = 0;
    MPI_Status ms;
    if (MPI_Iprobe(0, MPI_ANY_TAG, MPI_COMM_WORLD, &flag, &ms) != MPI_SUCCESS)
        return -1;
    if (!flag)
        return 0;
    v[0] = v[1] = 0;
    MPI_Get_count(&ms, MPI_UINT64_T, &cnt);
    MPI_Recv(v, cnt > 2 ? 2 : cnt, MPI_UINT64_T, 0, ms.MPI_TAG, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    *tag = ms.MPI_TAG;
    return 1;
}

static int sums_fit_int64(const rs_film *f)
{
    size_t i, n = (size_t)f->width * f->height * 3;
    for (i = 0; i < n; ++i)
        if (f->sum[i] != (rs_film_sum)(int64_t)f->sum[i])
            return 0;
    return 1;
}

int rs_dist_send_chunks(const void *data, size_t n, size_t elem, MPI_Datatype type, int to,
                        int tag, double timeout_s)
{
    size_t off;
    int ok = 1;
    for (off = 0; ok && off < n; off += DIST_CHUNK) {
        MPI_Request rq;
        int k = (int)(n - off < DIST_CHUNK ? n - off : DIST_CHUNK);
        ok = MPI_Isend((const char *)data + off * elem, k, type, to, tag, MPI_COMM_WORLD, &rq) ==
                 MPI_SUCCESS &&
             wait_req(&rq, timeout_s);
    }
    return ok;
}

int rs_dist_recv_chunks(void *data, size_t n, size_t elem, MPI_Datatype type, int from, int tag,
                        double timeout_s)
{
    size_t off;
    int ok = 1;
    for (off = 0; ok && off < n; off += DIST_CHUNK) {
        MPI_Request rq;
        int k = (int)(n - off < DIST_CHUNK ? n - off : DIST_CHUNK);
        ok = MPI_Irecv((char *)data + off * elem, k, type, from, tag, MPI_COMM_WORLD, &rq) ==
                 MPI_SUCCESS &&
             wait_req(&rq, timeout_s);
    }
    return ok;
}

int rs_dist_is_film_data(int tag)
{
    return tag == T_FILM_SUMS || tag == T_FILM_COUNTS || tag == T_FILM_SQ ||
           tag == T_FILM_PASSES;
}

int rs_dist_send_film(const rs_film *f, uint64_t h[H_COUNT], double timeout_s)
{
    size_t npix = (size_t)f->width * f->height, n_sum, i;
    int enc = sums_fit_int64(f) ? 0 : 1;
    int64_t *wide = NULL;
    const void *sums;
    int ok;
    h[H_ENC] = (uint64_t)enc;
    h[H_NONFINITE] = f->nonfinite;
    h[H_SQ] = f->sum_l2 != NULL;
    h[H_PASS_DATA] = f->pass != NULL;
    /* this runs on the messaging thread */
    h[H_COMM_CPU] = rs_dist_dbits(rs_dist_thread_cpu_s() - rs_dist_cpu0);
    if (!rs_dist_send_small(h, H_COUNT, 0, T_FILM))
        return 0;
    n_sum = npix * 3 * (enc ? 2 : 1);
    if (enc) {
        sums = f->sum; /* two little-endian words each, low first */
    } else {
        wide = (int64_t *)rs_alloc(npix * 3, sizeof *wide);
        if (!wide)
            return 0;
        for (i = 0; i < npix * 3; ++i)
            wide[i] = (int64_t)f->sum[i];
        sums = wide;
    }
    ok = rs_dist_send_chunks(sums, n_sum, sizeof(int64_t), MPI_INT64_T, 0, T_FILM_SUMS,
                             timeout_s) &&
         rs_dist_send_chunks(f->count, npix, sizeof *f->count, MPI_UINT32_T, 0, T_FILM_COUNTS,
                             timeout_s) &&
         (!f->sum_l2 || rs_dist_send_chunks(f->sum_l2, npix * 3, sizeof(uint64_t), MPI_UINT64_T,
                                            0, T_FILM_SQ, timeout_s)) &&
         (!f->pass ||
          (rs_dist_send_chunks(f->pass, npix * 2 * RS_FILM_PASSES, sizeof(uint64_t), MPI_UINT64_T,
                               0, T_FILM_PASSES, timeout_s) &&
           rs_dist_send_chunks(f->pass_hits, npix, sizeof *f->pass_hits, MPI_UINT32_T, 0,
                               T_FILM_PASSES, timeout_s)));
    rs_free(wide);
    return ok;
}

int rs_dist_recv_film(int r, const uint64_t *h, rs_film *tmp, double timeout_s,
                      uint64_t *bytes)
{
    size_t npix = (size_t)tmp->width * tmp->height, n_sum = npix * 3 * (h[H_ENC] ? 2 : 1), off;
    int64_t *buf = NULL;
    int ok = 1;
    rs_film_clear(tmp);
    if (!h[H_ENC]) {
        buf = (int64_t *)rs_alloc(n_sum < DIST_CHUNK ? n_sum : DIST_CHUNK, sizeof *buf);
        if (!buf)
            return 0;
    }
    for (off = 0; ok && off < n_sum; off += DIST_CHUNK) {
        MPI_Request rq;
        int k = (int)(n_sum - off < DIST_CHUNK ? n_sum - off : DIST_CHUNK), i;
        void *dst = h[H_ENC] ? (void *)((int64_t *)tmp->sum + off) : (void *)buf;
        ok = MPI_Irecv(dst, k, MPI_INT64_T, r, T_FILM_SUMS, MPI_COMM_WORLD, &rq) ==
                 MPI_SUCCESS &&
             wait_req(&rq, timeout_s);
        if (ok && !h[H_ENC])
            for (i = 0; i < k; ++i)
                tmp->sum[off + (size_t)i] = buf[i];
    }
    ok = ok && rs_dist_recv_chunks(tmp->count, npix, sizeof *tmp->count, MPI_UINT32_T, r,
                                   T_FILM_COUNTS, timeout_s);
    /* squared-luminance sums come exactly when both films keep them (an adaptive job's) */
    ok = ok && !h[H_SQ] == !tmp->sum_l2 &&
         (!h[H_SQ] || rs_dist_recv_chunks(tmp->sum_l2, npix * 3, sizeof(uint64_t), MPI_UINT64_T,
                                          r, T_FILM_SQ, timeout_s));
    /* the passes likewise: when both films keep them (a job whose outputs read them) */
    ok = ok && !h[H_PASS_DATA] == !tmp->pass &&
         (!h[H_PASS_DATA] ||
          (rs_dist_recv_chunks(tmp->pass, npix * 2 * RS_FILM_PASSES, sizeof(uint64_t),
                               MPI_UINT64_T, r, T_FILM_PASSES, timeout_s) &&
           rs_dist_recv_chunks(tmp->pass_hits, npix, sizeof *tmp->pass_hits, MPI_UINT32_T, r,
                               T_FILM_PASSES, timeout_s)));
    rs_free(buf);
    if (!ok)
        return 0;
    tmp->nonfinite = h[H_NONFINITE];
    *bytes = H_COUNT * 8 + n_sum * 8 + npix * 4 + (h[H_SQ] ? npix * 24 : 0) +
             (h[H_PASS_DATA] ? npix * (16 * RS_FILM_PASSES + 4) : 0);
    return 1;
}

void rs_dist_drop_data(const MPI_Status *ms)
{
    int bytes = 0;
    void *junk;
    MPI_Get_count(ms, MPI_BYTE, &bytes);
    junk = rs_alloc((size_t)bytes + 1, 1);
    MPI_Recv(junk, bytes, MPI_BYTE, ms->MPI_SOURCE, ms->MPI_TAG, MPI_COMM_WORLD,
             MPI_STATUS_IGNORE);
    rs_free(junk);
}
