/* app/tev.c — see tev.h. */
#include "app/tev.h"

#include <errno.h>
#include <netdb.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/time.h>
#include <unistd.h>

#include "app/fail.h"
#include "core/alloc.h"
#include "core/clock.h"

struct rs_tev {
    int fd;
    char spec[160];
    char name[96];
    uint32_t width, height;
    float *rgb;         /* the film resolved, which the sender sends */
    unsigned char *pkt; /* one tile's packet */
    size_t pkt_cap;
    pthread_t thread;
    pthread_mutex_t lock;
    pthread_cond_t cond;
    int pending; /* rgb holds an image to send */
    int busy;    /* the sender is sending it */
    int quit;
    int dead;                 /* the viewer went away: nothing more is sent */
    double last;              /* when the last update was handed over */
    double resolve_s, send_s; /* what the last update cost: the film resolved, the image sent */
    double interval;          /* between updates: RS_TEV_INTERVAL_S, or more (rs_tev_film) */
};

int rs_tev_parse(const char *spec, char *host, size_t host_n, int *port, char *why, size_t why_n)
{
    const char *colon = spec ? strrchr(spec, ':') : NULL, *p = colon ? colon + 1 : spec;
    char *end;
    long v;
    if (!spec || !*spec) {
        snprintf(why, why_n, "needs [HOST:]PORT, such as 14158 or 127.0.0.1:14158");
        return 0;
    }
    errno = 0;
    v = strtol(p, &end, 10);
    if (!*p || *end || errno || v < 1 || v > 65535) {
        snprintf(why, why_n, "'%s' is not [HOST:]PORT (a port in 1..65535, such as 14158)", spec);
        return 0;
    }
    *port = (int)v;
    if (!colon || colon == spec) {
        snprintf(host, host_n, "127.0.0.1");
    } else {
        size_t n = (size_t)(colon - spec);
        /* [::1]:14158 */
        if (spec[0] == '[' && n >= 2 && spec[n - 1] == ']')
            snprintf(host, host_n, "%.*s", (int)(n - 2), spec + 1);
        else
            snprintf(host, host_n, "%.*s", (int)n, spec);
    }
    return 1;
}

/* A TCP connection to host:port, or -1 with why. */
static int tcp_connect(const char *host, int port, char *why, size_t why_n)
{
    struct addrinfo hints, *res = NULL, *a;
    struct timeval tv = {2, 0}; /* a viewer that stops reading stalls only the sender */
    char service[16];
    int fd = -1, rc, err = 0;
    memset(&hints, 0, sizeof hints);
    hints.ai_family = AF_UNSPEC;
    hints.ai_socktype = SOCK_STREAM;
    snprintf(service, sizeof service, "%d", port);
    if ((rc = getaddrinfo(host, service, &hints, &res)) != 0) {
        snprintf(why, why_n, "%s", gai_strerror(rc));
        return -1;
    }
    for (a = res; a && fd < 0; a = a->ai_next) {
        fd = socket(a->ai_family, a->ai_socktype, a->ai_protocol);
        if (fd < 0) {
            err = errno;
            continue;
        }
        setsockopt(fd, SOL_SOCKET, SO_SNDTIMEO, &tv, sizeof tv);
        if (connect(fd, a->ai_addr, a->ai_addrlen) != 0) {
            err = errno;
            close(fd);
            fd = -1;
        }
    }
    freeaddrinfo(res);
    if (fd < 0)
        snprintf(why, why_n, "%s", strerror(err ? err : ECONNREFUSED));
    return fd;
}

/* ---- packets ------------------------------------------------------------------------------ */

typedef struct packet {
    unsigned char *b;
    size_t n, cap;
} packet;

static void put(packet *p, const void *v, size_t n)
{
    if (p->n + n <= p->cap)
        memcpy(p->b + p->n, v, n);
    p->n += n;
}
static void put_u8(packet *p, unsigned v)
{
    unsigned char c = (unsigned char)v;
    put(p, &c, 1);
}
static void put_i32(packet *p, int32_t v)
{
    unsigned char b[4];
    uint32_t u = (uint32_t)v;
    b[0] = (unsigned char)u, b[1] = (unsigned char)(u >> 8), b[2] = (unsigned char)(u >> 16),
    b[3] = (unsigned char)(u >> 24);
    put(p, b, 4);
}
static void put_i64(packet *p, int64_t v)
{
    put_i32(p, (int32_t)(uint32_t)((uint64_t)v & 0xffffffffu));
    put_i32(p, (int32_t)(uint32_t)((uint64_t)v >> 32));
}
static void put_str(packet *p, const char *s) { put(p, s, strlen(s) + 1); }
/* The length at the front, once the packet is whole. */
static void seal(packet *p)
{
    size_t n = p->n;
    p->n = 0;
    put_i32(p, (int32_t)n);
    p->n = n;
}

static int send_all(int fd, const unsigned char *b, size_t n)
{
    while (n) {
        ssize_t k = send(fd, b, n, MSG_NOSIGNAL);
        if (k < 0 && errno == EINTR)
            continue;
        if (k <= 0)
            return 0;
        b += k;
        n -= (size_t)k;
    }
    return 1;
}

static const char *const k_channels[3] = {"R", "G", "B"};

/* CreateImage: the name, the size, channels R, G, B. */
static int send_create(rs_tev *t)
{
    unsigned char buf[512];
    packet p = {buf, 4, sizeof buf};
    int c;
    put_u8(&p, 4);
    put_u8(&p, 1); /* grab focus */
    put_str(&p, t->name);
    put_i32(&p, (int32_t)t->width);
    put_i32(&p, (int32_t)t->height);
    put_i32(&p, 3);
    for (c = 0; c < 3; ++c)
        put_str(&p, k_channels[c]);
    seal(&p);
    return p.n <= p.cap && send_all(t->fd, p.b, p.n);
}

/* UpdateImage of the tile at (x, y), w x h: channels R, G, B interleaved (offsets 0, 1, 2,
 * strides 3). */
static int send_tile(rs_tev *t, uint32_t x, uint32_t y, uint32_t w, uint32_t h)
{
    packet p = {t->pkt, 4, t->pkt_cap};
    uint32_t row;
    int c;
    put_u8(&p, 6);
    put_u8(&p, 0);
    put_str(&p, t->name);
    put_i32(&p, 3);
    for (c = 0; c < 3; ++c)
        put_str(&p, k_channels[c]);
    put_i32(&p, (int32_t)x);
    put_i32(&p, (int32_t)y);
    put_i32(&p, (int32_t)w);
    put_i32(&p, (int32_t)h);
    for (c = 0; c < 3; ++c)
        put_i64(&p, c);
    for (c = 0; c < 3; ++c)
        put_i64(&p, 3);
    for (row = 0; row < h; ++row) /* little-endian floats: x86-64 and arm64 are */
        put(&p, t->rgb + 3 * ((size_t)(y + row) * t->width + x), (size_t)w * 3 * sizeof(float));
    seal(&p);
    return p.n <= p.cap && send_all(t->fd, p.b, p.n);
}

static int send_image(rs_tev *t)
{
    uint32_t x, y;
    for (y = 0; y < t->height; y += RS_TEV_TILE)
        for (x = 0; x < t->width; x += RS_TEV_TILE)
            if (!send_tile(t, x, y, t->width - x < RS_TEV_TILE ? t->width - x : RS_TEV_TILE,
                           t->height - y < RS_TEV_TILE ? t->height - y : RS_TEV_TILE))
                return 0;
    return 1;
}

/* The sender: waits for an image, sends it; a failed send ends the preview (one warning). */
static void *sender(void *arg)
{
    rs_tev *t = (rs_tev *)arg;
    pthread_mutex_lock(&t->lock);
    for (;;) {
        double t0, t1;
        int ok;
        while (!t->pending && !t->quit)
            pthread_cond_wait(&t->cond, &t->lock);
        if (!t->pending)
            break;
        t->pending = 0;
        t->busy = 1;
        pthread_mutex_unlock(&t->lock);
        t0 = rs_now_s();
        ok = send_image(t);
        t1 = rs_now_s();
        pthread_mutex_lock(&t->lock);
        t->send_s = t1 - t0;
        t->busy = 0;
        if (!ok) {
            t->dead = errno ? errno : EPIPE;
            pthread_cond_broadcast(&t->cond);
            break;
        }
        pthread_cond_broadcast(&t->cond);
    }
    pthread_mutex_unlock(&t->lock);
    return NULL;
}

rs_tev *rs_tev_open(const char *spec, const char *name, uint32_t width, uint32_t height)
{
    char host[128], why[256];
    int port, fd;
    rs_tev *t;
    if (!rs_tev_parse(spec, host, sizeof host, &port, why, sizeof why)) {
        rs_app_print("raystream: warning: --tev: %s; the render goes on without the preview\n",
                     why);
        return NULL;
    }
    if ((fd = tcp_connect(host, port, why, sizeof why)) < 0) {
        rs_app_print("raystream: warning: --tev %s: cannot reach tev (%s); the render goes on "
                     "without the preview\n",
                     spec, why);
        return NULL;
    }
    t = (rs_tev *)rs_calloc(1, sizeof *t);
    if (t) {
        t->fd = fd;
        t->width = width;
        t->height = height;
        snprintf(t->spec, sizeof t->spec, "%s", spec);
        snprintf(t->name, sizeof t->name, "raystream: %s", name && *name ? name : "render");
        t->pkt_cap = 512 + (size_t)RS_TEV_TILE * RS_TEV_TILE * 3 * sizeof(float);
        t->pkt = (unsigned char *)rs_alloc(t->pkt_cap, 1);
        t->rgb = (float *)rs_alloc((size_t)width * height * 3, sizeof(float));
        pthread_mutex_init(&t->lock, NULL);
        pthread_cond_init(&t->cond, NULL);
    }
    if (!t || !t->pkt || !t->rgb || !send_create(t) ||
        pthread_create(&t->thread, NULL, sender, t) != 0) {
        rs_app_print("raystream: warning: --tev %s: %s; the render goes on without the "
                     "preview\n",
                     spec, t && t->pkt && t->rgb ? "tev closed the connection" : "out of memory");
        if (t) {
            pthread_mutex_destroy(&t->lock);
            pthread_cond_destroy(&t->cond);
            rs_free(t->pkt);
            rs_free(t->rgb);
            rs_free(t);
        }
        close(fd);
        return NULL;
    }
    t->last = rs_now_s();
    t->interval = RS_TEV_INTERVAL_S;
    return t;
}

/* The warning for a viewer that went away, once. */
static void report_dead(rs_tev *t)
{
    if (t->dead > 0) {
        rs_app_print("raystream: warning: --tev %s: tev went away (%s); the render goes on "
                     "without the preview\n",
                     t->spec, strerror(t->dead));
        t->dead = -1;
    }
}

void rs_tev_film(rs_tev *t, const rs_film *film, int final)
{
    double now;
    if (!t)
        return;
    pthread_mutex_lock(&t->lock);
    if (final)
        while ((t->busy || t->pending) && !t->dead)
            pthread_cond_wait(&t->cond, &t->lock);
    now = rs_now_s();
    if (t->dead) {
        report_dead(t);
    } else if (final || (!t->busy && !t->pending && now - t->last >= t->interval)) {
        rs_film_resolve(film, t->rgb); /* the sender is idle: the buffer is free */
        t->pending = 1;
        t->last = now;
        t->resolve_s = rs_now_s() - now;
        /* what the last update cost (the resolve here, the send on the sender's thread, both
         * taken from the render's cores) at most 1/RS_TEV_COST_SHARE of the time */
        t->interval = RS_TEV_COST_SHARE * (t->resolve_s + t->send_s);
        if (t->interval < RS_TEV_INTERVAL_S)
            t->interval = RS_TEV_INTERVAL_S;
        pthread_cond_broadcast(&t->cond);
        if (final) {
            while ((t->busy || t->pending) && !t->dead)
                pthread_cond_wait(&t->cond, &t->lock);
            report_dead(t);
        }
    }
    pthread_mutex_unlock(&t->lock);
}

void rs_tev_close(rs_tev *t)
{
    if (!t)
        return;
    pthread_mutex_lock(&t->lock);
    t->quit = 1;
    pthread_cond_broadcast(&t->cond);
    pthread_mutex_unlock(&t->lock);
    pthread_join(t->thread, NULL);
    close(t->fd);
    pthread_mutex_destroy(&t->lock);
    pthread_cond_destroy(&t->cond);
    rs_free(t->pkt);
    rs_free(t->rgb);
    rs_free(t);
}
