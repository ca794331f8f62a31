/* scheduler/engine.c — see render.h: the engine's set-up and its runs of plans.  A run's
 * bookkeeping (its ranges, the time limit's cut, shares, the record of paths on the film) is
 * run.c, the stream engine's waves stream_engine.c, the megakernel's calls passes.c, the path
 * devices' threads wavefront.c. */
#include <float.h>
#include <string.h>

#include "core/alloc.h"
#include "core/clock.h"
#include "scheduler/engine_impl.h"

void rs_render_stats_add(rs_render_stats *sum, const rs_render_stats *r)
{
    int k;
    for (k = 0; k < RS_STAGE_COUNT; ++k)
        sum->stage_s[k] += r->stage_s[k];
    sum->wait_s += r->wait_s;
    sum->host_s += r->host_s;
    sum->paths_total += r->paths_total;
    sum->paths_done += r->paths_done;
    sum->rays_closest += r->rays_closest;
    sum->rays_shadow += r->rays_shadow;
    sum->waves += r->waves;
    if (r->max_bounce > sum->max_bounce)
        sum->max_bounce = r->max_bounce;
    if (r->wave_paths)
        sum->wave_paths = r->wave_paths;
    sum->time_limited |= r->time_limited;
}

rs_status rs_render_constants(const rs_scene *scene, const rs_render_settings *st,
                              rs_render_consts *it)
{
    uint64_t npix;
    if (st->width == 0 || st->height == 0 || st->spp == 0 || st->max_depth == 0)
        return rs_error_set(RS_ERR_ARG, "width, height, spp and max depth must be >= 1");
    npix = (uint64_t)st->width * st->height;
    /* npix and spp are both < 2^32, so npix * spp cannot overflow 64 bits */
    if (npix > UINT32_MAX)
        return rs_error_set(RS_ERR_ARG, "image too large: %ux%u at %u spp", st->width, st->height,
                            st->spp);
    if (st->path_begin > npix * st->spp)
        return rs_error_set(RS_ERR_ARG,
                            "the film already holds %llu samples, more than %ux%u at %u spp",
                            (unsigned long long)st->path_begin, st->width, st->height, st->spp);
    if (st->light_sampler == RS_LIGHT_SAMPLER_BVH && scene->n_lights > 0 &&
        !scene->light_bvh_built)
        return rs_error_set(RS_ERR_ARG, "--light-sampler bvh: the scene was loaded without its "
                                        "light BVH (rs_scene_set_extras)");
    memset(it, 0, sizeof *it);
    it->scene = scene;
    it->camera = rs_camera_make(scene->camera.from, scene->camera.at, scene->camera.up,
                                scene->camera.vfov_deg, scene->camera.aperture,
                                scene->camera.focus_dist, st->width, st->height);
    it->seed = st->seed;
    it->width = st->width;
    it->height = st->height;
    it->npix = (uint32_t)npix;
    it->spp = st->spp;
    it->max_depth = st->max_depth;
    it->rr_depth = st->rr_depth ? st->rr_depth : 3;
    it->sampling = (uint32_t)st->sampling;
    it->sampler = (uint32_t)st->sampler;
    it->light_sampler = st->light_sampler;
    it->passes = st->passes ? 1u : 0u;
    if (st->filter.width > 0.0f)
        it->filter = st->filter;
    else if (!rs_filter_make(RS_FILTER_BOX, 1.0f, &it->filter))
        return RS_ERR_ARG;
    if (st->texture_filter == RS_TEXTURE_TRILINEAR) {
        /* one pixel's angle at the focus plane, where du is laid (docs/textures.md) */
        const rs_camera_desc *cd = &scene->camera;
        float fd =
            cd->focus_dist > 0.0f ? cd->focus_dist : rs_v3_length(rs_v3_sub(cd->from, cd->at));
        float spread = fd > 0.0f ? rs_v3_length(it->camera.du) / fd : 0.0f;
        it->tex_spread = spread > 0.0f && spread <= FLT_MAX ? spread : 0.0f;
    }
    return RS_OK;
}

static rs_status engine_make(const rs_scene *scene, const rs_render_settings *settings,
                             rs_sched *sched, rs_device *mk, rs_device *const *pdev, int n_pdev,
                             rs_engine **out);

rs_status rs_engine_create(const rs_scene *scene, const rs_render_settings *settings,
                           rs_sched *sched, rs_device *mk, rs_engine **out)
{
    *out = NULL;
    if (!sched == !mk)
        return rs_error_set(RS_ERR_ARG, "an engine traces through a scheduler or a megakernel "
                                        "device, one of them");
    return engine_make(scene, settings, sched, mk, NULL, 0, out);
}

rs_status rs_engine_create_paths(const rs_scene *scene, const rs_render_settings *settings,
                                 rs_sched *sched, rs_device *const *devs, int n, rs_engine **out)
{
    int k;
    *out = NULL;
    if (n < 1 || n > RS_ENGINE_MAX_PATH_DEVICES)
        return rs_error_set(RS_ERR_ARG, "%d devices that run paths whole: 1 to %d", n,
                            RS_ENGINE_MAX_PATH_DEVICES);
    for (k = 0; k < n; ++k)
        if (!devs[k] || !devs[k]->ops->render_paths ||
            (rs_device_owns_memory(devs[k]) && !devs[k]->ops->upload_scene))
            return rs_error_set(RS_ERR_ARG, "device %s cannot run paths whole (no wavefront)",
                                devs[k] ? devs[k]->name : "(none)");
    return engine_make(scene, settings, sched, NULL, devs, n, out);
}

static rs_status engine_make(const rs_scene *scene, const rs_render_settings *settings,
                             rs_sched *sched, rs_device *mk, rs_device *const *pdev, int n_pdev,
                             rs_engine **out)
{
    rs_engine *e;
    rs_status st;
    int k;
    *out = NULL;
    if (settings->waves_in_flight > RS_RENDER_MAX_WAVES)
        return rs_error_set(RS_ERR_ARG, "%u waves in flight: at most %u", settings->waves_in_flight,
                            RS_RENDER_MAX_WAVES);
    if (mk && !mk->ops->render_pass)
        return rs_error_set(RS_ERR_ARG, "device %s cannot run the megakernel", mk->name);
    e = (rs_engine *)rs_calloc(1, sizeof *e);
    if (!e)
        return rs_error_set(RS_ERR_NOMEM, "out of memory for the render engine");
    e->scene = scene;
    e->st = *settings;
    e->sched = sched;
    e->mk = mk;
    for (k = 0; k < n_pdev; ++k)
        e->pdev[k] = pdev[k];
    e->n_pdev = n_pdev;
    e->t_start = rs_now_s();
    if ((st = rs_render_constants(scene, settings, &e->it)) == RS_OK)
        st = mk ? rs_passes_setup(e) : n_pdev ? rs_paths_setup(e) : rs_stream_setup(e);
    if (st != RS_OK) {
        rs_engine_destroy(e);
        return st;
    }
    *out = e;
    return RS_OK;
}

void rs_engine_destroy(rs_engine *e)
{
    int k;
    if (!e)
        return;
    if (e->sched)
        rs_stream_release(e);
    for (k = 0; k < e->n_pdev; ++k)
        rs_film_destroy(e->pfilm[k]);
    rs_path_ranges_free(&e->done);
    rs_free(e);
}

const rs_render_settings *rs_engine_settings(const rs_engine *e) { return &e->st; }

const rs_path_ranges *rs_engine_done(const rs_engine *e) { return &e->done; }

void rs_engine_totals(const rs_engine *e, rs_render_stats *out)
{
    *out = e->total;
    out->seconds = rs_now_s() - e->t_start;
}

/* The plan against the render: its pixels, its ranges inside the render's paths, and what the
 * megakernel can run. */
static rs_status check_plan(const rs_engine *e, const rs_work_plan *p, const rs_film *film)
{
    uint64_t n = p->pixels ? p->n_pixels : e->it.npix;
    uint32_t i;
    if (film->width != e->st.width || film->height != e->st.height)
        return rs_error_set(RS_ERR_ARG, "film is %ux%u but the render is %ux%u", film->width,
                            film->height, e->st.width, e->st.height);
    if (!e->it.passes != !film->pass)
        return rs_error_set(RS_ERR_ARG, e->it.passes ? "the render writes passes the film does "
                                                       "not keep (rs_film_keep_passes)"
                                                     : "the film keeps passes the render does "
                                                       "not write (settings.passes)");
    if (p->pixels && (p->n_pixels == 0 || p->n_pixels > e->it.npix))
        return rs_error_set(RS_ERR_ARG, "a plan over %u of %u pixels", p->n_pixels, e->it.npix);
    if (p->todo.n && p->todo.r[p->todo.n - 1][1] > n * e->st.spp)
        return rs_error_set(RS_ERR_ARG, "a plan up to path %llu of a render of %llu",
                            (unsigned long long)p->todo.r[p->todo.n - 1][1],
                            (unsigned long long)(n * e->st.spp));
    if (!e->mk)
        return RS_OK;
    if (p->pixels)
        return rs_error_set(RS_ERR_ARG, "the megakernel renders whole images only: adaptive "
                                        "sampling needs --integrator stream");
    for (i = 0; i < p->todo.n; ++i)
        if (p->todo.r[i][0] % n || p->todo.r[i][1] % n)
            return rs_error_set(
                RS_ERR_ARG,
                "the megakernel renders whole passes only, and a plan starts "
                "or ends %llu paths into one (use --integrator stream)",
                (unsigned long long)(p->todo.r[i][p->todo.r[i][0] % n ? 0 : 1] % n));
    return RS_OK;
}

rs_status rs_engine_run(rs_engine *e, const rs_work_plan *plan, const rs_render_hooks *hooks,
                        rs_film *film, rs_render_stats *stats)
{
    rs_run c;
    rs_status st;
    double t0 = rs_now_s();
    memset(stats, 0, sizeof *stats);
    if ((st = check_plan(e, plan, film)) != RS_OK)
        return st;
    memset(&c, 0, sizeof c);
    c.e = e;
    c.map.pixel_of = NULL;
    c.map.n_active = e->it.npix;
    if (plan->pixels) {
        c.map.pixel_of = plan->pixels;
        c.map.n_active = plan->n_pixels;
    }
    c.plan = plan;
    c.hooks = hooks;
    c.stats = stats;
    c.film = film;
    e->done.n = 0;
    c.n_ranges = plan->todo.n;
    c.cut = UINT64_MAX;
    if (c.n_ranges) {
        c.next_path = plan->todo.r[0][0];
        c.end_path = plan->todo.r[0][1];
    }
    stats->paths_total = rs_path_ranges_total(&plan->todo);
    e->plan_id++;
    st = e->n_pdev ? rs_paths_run(&c) : e->mk ? rs_passes_run(&c) : rs_stream_run(&c);
    stats->seconds = rs_now_s() - t0;
    if (stats->paths_done)
        e->any_done = 1;
    rs_render_stats_add(&e->total, stats);
    return st;
}

/* One plan: [path_begin, all) of every pixel. */
static rs_status render_once(const rs_scene *scene, rs_sched *sched, rs_device *mk,
                             const rs_render_settings *settings, const rs_render_hooks *hooks,
                             rs_film *film, rs_render_stats *stats)
{
    rs_engine *e;
    rs_work_plan plan;
    rs_status st;
    uint64_t all = (uint64_t)settings->width * settings->height * settings->spp;
    memset(stats, 0, sizeof *stats);
    if ((st = rs_engine_create(scene, settings, sched, mk, &e)) != RS_OK)
        return st;
    memset(&plan, 0, sizeof plan);
    plan.time_limit_s = settings->time_limit_s;
    if (!rs_path_ranges_add(&plan.todo, settings->path_begin, all))
        st = rs_error_set(RS_ERR_NOMEM, "out of memory");
    else
        st = rs_engine_run(e, &plan, hooks, film, stats);
    rs_work_plan_free(&plan);
    rs_engine_destroy(e);
    return st;
}

rs_status rs_render(const rs_scene *scene, rs_sched *sched, const rs_render_settings *settings,
                    const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    return render_once(scene, sched, NULL, settings, hooks, film, stats);
}

rs_status rs_render_passes(const rs_scene *scene, rs_device *d, const rs_render_settings *settings,
                           const rs_render_hooks *hooks, rs_film *film, rs_render_stats *stats)
{
    return render_once(scene, NULL, d, settings, hooks, film, stats);
}
