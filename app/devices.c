/* app/devices.c — one device factory for both integrators; see devices.h. */
#include "app/devices.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app/fail.h"
#include "cpu/cpu_device.h"
#include "gpu/gpu_device.h"

#define RS_AUTO_GPUS 64 /* the CUDA devices --devices auto considers (gpu:INDEX's limit) */

/* The device list the factory works through, with how the cores are shared out. */
typedef struct device_plan {
    rs_device_spec specs[RS_MAX_DEVICES];
    int usable[RS_MAX_DEVICES]; /* a cpu, or a gpu that exists */
    int n, n_gpus, has_cpu, fallback_threads, megakernel;
    int require_gpu;             /* --require-gpu: no CPU fallback */
    int local_rank, local_size;  /* under an MPI launcher (rs_devices_local_rank), else 0, 1 */
    int auto_gpus[RS_AUTO_GPUS]; /* --devices auto: this process's CUDA devices */
    int n_auto_gpus;
    const char *why; /* why there is no CUDA device, where there is none */
} device_plan;

int rs_devices_auto_gpus(int local_rank, int local_size, int n_gpus, int *out)
{
    int g, n = 0, l;
    if (n_gpus <= 0)
        return 0;
    if (local_size <= 1) {
        for (g = 0; g < n_gpus; ++g)
            out[n++] = g;
        return n;
    }
    l = local_rank % local_size;
    if (l < 0)
        l += local_size;
    if (n_gpus < local_size) { /* more ranks than GPUs: one GPU each, some shared */
        out[0] = l % n_gpus;
        return 1;
    }
    for (g = l; g < n_gpus; g += local_size) /* each GPU to one rank, round robin */
        out[n++] = g;
    return n;
}

/* A whole number >= 0 from the environment variable `name`, or -1 (unset, empty, not a
 * number). */
static long env_count(const char *name)
{
    const char *v = getenv(name);
    char *end;
    long n;
    if (!v || !*v)
        return -1;
    errno = 0;
    n = strtol(v, &end, 10);
    return errno || *end || n < 0 || n > 1 << 20 ? -1 : n;
}

int rs_devices_local_rank(int *local_rank, int *local_size)
{
    /* {rank, size} per launcher; the first pair with both set and consistent is taken */
    static const char *const vars[][2] = {
        {"OMPI_COMM_WORLD_LOCAL_RANK", "OMPI_COMM_WORLD_LOCAL_SIZE"},
        {"MPI_LOCALRANKID", "MPI_LOCALNRANKS"},
        {"MV2_COMM_WORLD_LOCAL_RANK", "MV2_COMM_WORLD_LOCAL_SIZE"},
        {"PMI_LOCAL_RANK", "PMI_LOCAL_SIZE"},
        {"SLURM_LOCALID", "SLURM_NTASKS_PER_NODE"}};
    size_t i;
    *local_rank = 0;
    *local_size = 1;
    for (i = 0; i < sizeof vars / sizeof vars[0]; ++i) {
        long r = env_count(vars[i][0]), n = env_count(vars[i][1]);
        if (r >= 0 && n >= 1 && r < n) {
            *local_rank = (int)r;
            *local_size = (int)n;
            return 1;
        }
    }
    return 0;
}

/* --devices auto's CUDA devices for this process (rs_devices_auto_gpus with the launcher's
 * node-local rank) into p->auto_gpus. */
static void plan_auto_gpus(device_plan *p)
{
    int n = p->n_gpus < RS_AUTO_GPUS ? p->n_gpus : RS_AUTO_GPUS;
    rs_devices_local_rank(&p->local_rank, &p->local_size);
    p->n_auto_gpus = rs_devices_auto_gpus(p->local_rank, p->local_size, n, p->auto_gpus);
}

/* The megakernel's one device: auto this process's first CUDA device where there is one, else
 * the CPU. */
static void plan_megakernel(const rs_cli_options *o, device_plan *p)
{
    memset(&p->specs[0], 0, sizeof p->specs[0]);
    if (o->devices_auto) {
        p->specs[0].is_gpu = p->n_auto_gpus > 0;
        p->specs[0].index = p->n_auto_gpus > 0 ? p->auto_gpus[0] : 0;
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
    p->require_gpu = o->require_gpu;
    if (o->devices_auto)
        plan_auto_gpus(p);
    if (o->megakernel) {
        plan_megakernel(o, p);
    } else if (o->devices_auto && !o->shade_host && p->n_auto_gpus > 0) {
        /* a GPU runs its paths whole (its wavefront), far ahead of the host: the GPUs alone */
        for (p->n = 0; p->n < p->n_auto_gpus && p->n < RS_MAX_DEVICES; ++p->n) {
            p->specs[p->n].is_gpu = 1;
            p->specs[p->n].index = p->auto_gpus[p->n];
        }
    } else if (o->devices_auto) {
        p->n = 1;
        for (i = 0; i < p->n_auto_gpus && p->n < RS_MAX_DEVICES; ++i) {
            p->specs[p->n].is_gpu = 1;
            p->specs[p->n++].index = p->auto_gpus[i];
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
    co.walk = o->cpu_walk;
    return rs_cpu_device_create_opts(&co, out);
}

/* A CUDA device, or where it cannot be used its CPU fallback after one warning line (with
 * --require-gpu: RS_ERR_DEVICE_LOST, the message naming the device and why). */
static rs_status create_gpu(const device_plan *p, int i, int threads, rs_cores *cores,
                            rs_device **out)
{
    int index = p->specs[i].index, ft = p->has_cpu ? 1 : threads;
    rs_status st = p->usable[i] ? rs_gpu_device_create(index, out) : RS_ERR_DEVICE_LOST;
    const char *why = p->usable[i]    ? rs_error_message()
                      : p->n_gpus > 0 ? "no such CUDA device"
                                      : p->why;
    char reason[320];
    if (st == RS_OK)
        return st;
    if (p->require_gpu) {
        snprintf(reason, sizeof reason, "%s", why);
        rs_error_clear();
        return rs_error_set(RS_ERR_DEVICE_LOST,
                            "--require-gpu: %sgpu:%d cannot be used (no CPU fallback): %s",
                            p->megakernel ? "the megakernel's " : "", index, reason);
    }
    rs_app_print("raystream: warning: %s; %sgpu:%d runs on the CPU fallback (%d thread%s)\n", why,
                 p->megakernel ? "the megakernel for " : "", index, ft, ft == 1 ? "" : "s");
    rs_error_clear();
    return rs_gpu_fallback_create(ft, index, cores, out);
}

/* The plan's own word before any device exists: with --require-gpu and no gpu in it (auto
 * where no CUDA device can be used) an error; under --stats, which GPUs auto took for this rank
 * where a launcher put several ranks on this machine.  Returns 0 after printing an error. */
static int plan_check(const rs_cli_options *o, const device_plan *p)
{
    char list[160] = "";
    size_t used = 0;
    int i, gpus = 0, shared = 0;
    for (i = 0; i < p->n; ++i)
        gpus += p->specs[i].is_gpu;
    if (p->require_gpu && gpus == 0) {
        rs_error_set(RS_ERR_DEVICE_LOST, "--require-gpu: --devices auto found no CUDA device: %s",
                     p->why);
        return 0;
    }
    if (!o->stats || !o->devices_auto || p->local_size <= 1 || p->n_gpus == 0)
        return 1;
    for (i = 0; i < p->n && used < sizeof list; ++i)
        if (p->specs[i].is_gpu) {
            used += (size_t)snprintf(list + used, sizeof list - used, "%scuda:%d", used ? ", " : "",
                                     p->specs[i].index);
            /* fewer GPUs than ranks: rank L + n_gpus (if any) has this one too */
            shared |= p->specs[i].index + p->n_gpus < p->local_size;
        }
    rs_app_print("raystream: local rank %d of %d on this machine: --devices auto takes %s of %d "
                 "GPU%s%s\n",
                 p->local_rank, p->local_size, list, p->n_gpus, p->n_gpus == 1 ? "" : "s",
                 shared ? " (shared with other ranks)" : "");
    return 1;
}

int rs_devices_create(const rs_cli_options *o, const rs_fault_spec *fault, int threads,
                      rs_cores *cores, rs_device **devs)
{
    device_plan p;
    int i, n = 0;
    plan_devices(o, threads, &p);
    if (!plan_check(o, &p)) {
        rs_app_fail(RS_EXIT_RUNTIME, p.megakernel ? "creating the device" : "creating devices");
        return -1;
    }
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
