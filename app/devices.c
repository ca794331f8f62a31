/* app/devices.c — one device factory for both integrators; see devices.h. */
#include "app/devices.h"

#include <stdio.h>
#include <string.h>

#include "app/render_run.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"

/* The device list the factory works through, with how the cores are shared out. */
typedef struct device_plan {
    rs_device_spec specs[RS_MAX_DEVICES];
    int usable[RS_MAX_DEVICES]; /* a cpu, or a gpu that exists */
    int n, n_gpus, has_cpu, fallback_threads, megakernel;
    const char *why; /* why there is no CUDA device, where there is none */
} device_plan;

/* The megakernel's one device: auto CUDA device 0 where there is one, else the CPU. */
static void plan_megakernel(const rs_cli_options *o, device_plan *p)
{
    memset(&p->specs[0], 0, sizeof p->specs[0]);
    if (o->devices_auto) {
        p->specs[0].is_gpu = p->n_gpus > 0;
    } else {
        p->specs[0] = o->devices[0];
        if (!p->specs[0].is_gpu)
            p->specs[0].threads = 0; /* its threads are the render's (rs_run_settings) */
    }
    p->n = 1;
}

static void plan_devices(const rs_cli_options *o, int threads, device_plan *p)
{
    int i;
    memset(p, 0, sizeof *p);
    p->why = "";
    p->n_gpus = rs_gpu_count(&p->why);
    p->megakernel = o->megakernel;
    if (o->megakernel) {
        plan_megakernel(o, p);
    } else if (o->devices_auto) {
        p->n = 1;
        for (i = 0; i < p->n_gpus && p->n < RS_MAX_DEVICES; ++i) {
            p->specs[p->n].is_gpu = 1;
            p->specs[p->n++].index = i;
        }
    } else {
        p->n = o->n_devices;
        memcpy(p->specs, o->devices, (size_t)p->n * sizeof p->specs[0]);
    }
    for (i = 0; i < p->n; ++i)
        p->has_cpu |= !p->specs[i].is_gpu;
    for (i = 0; i < p->n; ++i) {
        p->usable[i] = !p->specs[i].is_gpu || p->specs[i].index < p->n_gpus;
        if (!p->usable[i])
            p->fallback_threads += p->has_cpu ? 1 : threads;
    }
}

static rs_status create_cpu(const rs_cli_options *o, const device_plan *p, int i, int threads,
                            rs_cores *cores, rs_device **out)
{
    rs_cpu_device_opts co;
    int rest = threads - p->fallback_threads > 1 ? threads - p->fallback_threads : 1;
    memset(&co, 0, sizeof co);
    co.threads = p->specs[i].threads ? p->specs[i].threads : rest;
    co.name = "cpu";
    co.bvh_width = o->no_bvh ? 2 : o->bvh_width; /* 4-wide leaves hold < 2^15 */
    co.cores = cores;
    co.strategy = o->strategy;
    return rs_cpu_device_create_opts(&co, out);
}

/* A CUDA device, or where it cannot be used its CPU fallback after one warning line. */
static rs_status create_gpu(const device_plan *p, int i, int threads, rs_cores *cores,
                            rs_device **out)
{
    int index = p->specs[i].index, ft = p->has_cpu ? 1 : threads;
    rs_status st = p->usable[i] ? rs_gpu_device_create(index, out) : RS_ERR_DEVICE_LOST;
    const char *why = p->usable[i]                     ? rs_error_message()
                      : p->megakernel && p->n_gpus > 0 ? "no such CUDA device"
                                                       : p->why;
    if (st == RS_OK)
        return st;
    fprintf(stderr, "raystream: warning: %s; %sgpu:%d runs on the CPU fallback (%d thread%s)\n",
            why, p->megakernel ? "the megakernel for " : "", index, ft, ft == 1 ? "" : "s");
    rs_error_clear();
    return rs_gpu_fallback_create(ft, index, cores, out);
}

int rs_devices_create(const rs_cli_options *o, const rs_fault_spec *fault, int threads,
                      rs_cores *cores, rs_device **devs)
{
    device_plan p;
    int i, n = 0;
    plan_devices(o, threads, &p);
    for (i = 0; i < p.n; ++i) {
        int is_gpu = p.specs[i].is_gpu, after = is_gpu ? fault->gpu_after : fault->cpu_after;
        rs_status st = is_gpu ? create_gpu(&p, i, threads, cores, &devs[n])
                              : create_cpu(o, &p, i, threads, cores, &devs[n]);
        if (st == RS_OK && after >= 0 && (st = rs_fault_wrap(&devs[n], after)) != RS_OK) {
            rs_device_destroy(devs[n]);
            devs[n] = NULL; /* the megakernel's slot is released again with the run */
        }
        if (st != RS_OK) {
            while (n > 0)
                rs_device_destroy(devs[--n]);
            rs_app_fail(RS_EXIT_RUNTIME, p.megakernel ? "creating the device" : "creating devices");
            return -1;
        }
        n++;
    }
    return n;
}
