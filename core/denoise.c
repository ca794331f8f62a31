/* core/denoise.c — see denoise.h.
 *
 * Invariants: `g_oidn` is written only under `g_lock` and only while g_oidn.lib is NULL; once
 * lib is set it (and every function pointer) stays valid, unchanged, until the process ends (the
 * library is never closed: OIDN's TBB threads may outlive a call).  OIDN's messages reach the
 * caller through an error callback set on every device right after it is made, and through
 * oidnGetDeviceError(NULL) for a device that could not be made; OIDN's verbosity is set to 0 so
 * it prints nothing itself. */
#define _POSIX_C_SOURCE 200809L
#include "core/denoise.h"

#include <dlfcn.h>
#include <elf.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "core/file.h"
#include "core/oidn_api.h"

/* The entry points, each once: the struct's fields and the loader's table expand from here. */
#define RS_OIDN_FUNCTIONS(X)                                                                       \
  X(rs_oidn_new_device_fn, new_device, "oidnNewDevice")                                            \
  X(rs_oidn_commit_device_fn, commit_device, "oidnCommitDevice")                                   \
  X(rs_oidn_release_device_fn, release_device, "oidnReleaseDevice")                                \
  X(rs_oidn_set_device_int_fn, set_device_int, "oidnSetDeviceInt")                                 \
  X(rs_oidn_get_device_int_fn, get_device_int, "oidnGetDeviceInt")                                 \
  X(rs_oidn_set_device_error_function_fn, set_device_error_function, "oidnSetDeviceErrorFunction") \
  X(rs_oidn_get_device_error_fn, get_device_error, "oidnGetDeviceError")                           \
  X(rs_oidn_get_num_physical_devices_fn, get_num_physical_devices, "oidnGetNumPhysicalDevices")    \
  X(rs_oidn_new_buffer_fn, new_buffer, "oidnNewBuffer")                                            \
  X(rs_oidn_write_buffer_fn, write_buffer, "oidnWriteBuffer")                                      \
  X(rs_oidn_read_buffer_fn, read_buffer, "oidnReadBuffer")                                         \
  X(rs_oidn_release_buffer_fn, release_buffer, "oidnReleaseBuffer")                                \
  X(rs_oidn_new_filter_fn, new_filter, "oidnNewFilter")                                            \
  X(rs_oidn_set_filter_image_fn, set_filter_image, "oidnSetFilterImage")                           \
  X(rs_oidn_set_shared_filter_image_fn, set_shared_filter_image, "oidnSetSharedFilterImage")       \
  X(rs_oidn_set_filter_bool_fn, set_filter_bool, "oidnSetFilterBool")                              \
  X(rs_oidn_commit_filter_fn, commit_filter, "oidnCommitFilter")                                   \
  X(rs_oidn_execute_filter_fn, execute_filter, "oidnExecuteFilter")                                \
  X(rs_oidn_release_filter_fn, release_filter, "oidnReleaseFilter")

typedef struct oidn_lib {
    void *lib; /* NULL until loaded */
    char path[1024];
#define RS_OIDN_FIELD(type, field, sym) type field;
    RS_OIDN_FUNCTIONS(RS_OIDN_FIELD)
#undef RS_OIDN_FIELD
} oidn_lib;

static pthread_mutex_t g_lock = PTHREAD_MUTEX_INITIALIZER;
static oidn_lib g_oidn;


/* dlerror()'s text without a trailing newline, or "unknown reason". */
static const char *dl_reason(void)
{
    const char *e = dlerror();
    return e ? e : "unknown reason";
}

/* Resolves every entry point of `lib` into *o; 0 with why[n] naming the first one missing. */
static int resolve(void *lib, const char *path, oidn_lib *o, char *why, size_t n)
{
    void *p;
    memset(o, 0, sizeof *o);
#define RS_OIDN_RESOLVE(type, field, sym)                                                          \
  p = dlsym(lib, sym);                                                                             \
  if (!p) {                                                                                        \
    /* 2.0 renamed OIDN 1.x's oidnSetFilter1b/oidnSetDevice1i */                                   \
    if (dlsym(lib, "oidnSetFilter1b"))                                                             \
      rs_say(why, n,                                                                                  \
          "%s is Open Image Denoise 1.x (it has oidnSetFilter1b, not %s); raystream needs "        \
          "2.x: run sh scripts/install-deps.sh, or set RS_OIDN_LIBRARY=PATH to a 2.x "             \
          "libOpenImageDenoise.so.2",                                                              \
          path, sym);                                                                              \
    else                                                                                           \
      rs_say(why, n,                                                                                  \
          "%s lacks %s: not Open Image Denoise 2.x; run sh scripts/install-deps.sh, or set "       \
          "RS_OIDN_LIBRARY=PATH to libOpenImageDenoise.so.2",                                      \
          path, sym);                                                                              \
    return 0;                                                                                      \
  }                                                                                                \
  memcpy(&o->field, &p, sizeof p); /* POSIX: object and function pointers convert */
    RS_OIDN_FUNCTIONS(RS_OIDN_RESOLVE)
#undef RS_OIDN_RESOLVE
    snprintf(o->path, sizeof o->path, "%s", path);
    o->lib = lib;
    return 1;
}

/* Before dlopen of a path (not a name the loader searches for): a regular file (a FIFO blocked
 * dlopen for ever) whose ELF header, program headers, segments and section headers all lie
 * within it (the loader maps a truncated library and dies of SIGBUS touching what is missing).
 * 1, or 0 with why[n]. */
static int library_file_ok(const char *path, char *why, size_t n, const char *hint)
{
    Elf64_Ehdr eh;
    uint64_t size = 0;
    char msg[600];
    int fd, ok = 1, i;
    if (!strchr(path, '/'))
        return 1;
    if (rs_file_open_quiet(path, (uint64_t)1 << 32, &fd, &size, msg, sizeof msg) != RS_OK) {
        rs_say(why, n, "Open Image Denoise not loaded: %s%s", msg, hint);
        return 0;
    }
    if (pread(fd, &eh, sizeof eh, 0) != (ssize_t)sizeof eh ||
        memcmp(eh.e_ident, ELFMAG, SELFMAG) != 0 || eh.e_ident[EI_CLASS] != ELFCLASS64)
        ok = 0; /* not a 64-bit ELF file: dlopen says so itself, below */
    else if (eh.e_phentsize != sizeof(Elf64_Phdr) ||
             eh.e_phoff + (uint64_t)eh.e_phnum * sizeof(Elf64_Phdr) > size ||
             (eh.e_shnum && eh.e_shoff + (uint64_t)eh.e_shnum * eh.e_shentsize > size))
        ok = -1;
    for (i = 0; ok == 1 && i < eh.e_phnum; ++i) {
        Elf64_Phdr ph;
        if (pread(fd, &ph, sizeof ph, (off_t)(eh.e_phoff + (uint64_t)i * sizeof ph)) !=
                (ssize_t)sizeof ph ||
            ph.p_offset + ph.p_filesz > size)
            ok = -1;
    }
    close(fd);
    if (ok < 0) {
        rs_say(why, n, "Open Image Denoise not loaded: %s is cut short (%llu bytes: its ELF "
               "headers name data past its end)%s", path, (unsigned long long)size, hint);
        return 0;
    }
    return 1;
}

/* Opens `path` and resolves it: 1 and *o filled; 0 (not opened) or -1 (opened, but not OIDN
 * 2.x) with why[n]. */
static int try_open(const char *path, oidn_lib *o, char *why, size_t n, const char *hint)
{
    void *lib;
    if (!library_file_ok(path, why, n, hint))
        return 0;
    dlerror();
    lib = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!lib) {
        rs_say(why, n, "Open Image Denoise not loaded: %s%s", dl_reason(), hint);
        return 0;
    }
    if (!resolve(lib, path, o, why, n)) {
        dlclose(lib);
        return -1;
    }
    return 1;
}

/* Loads the library (see denoise.h for the order) unless it is loaded; 1, or 0 with why[n]. */
/* AddressSanitizer and ThreadSanitizer builds (gcc's __SANITIZE_ADDRESS__ and
 * __SANITIZE_THREAD__, clang's __has_feature): OIDN's CPU device makes TBB dlopen libtbbbind with
 * RTLD_DEEPBIND, and both runtimes abort the process on that (google/sanitizers#611), so such a
 * build reports OIDN unavailable instead. */
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#  define RS_DENOISE_UNDER_SANITIZER 1
#elif defined(__has_feature)
#  if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#    define RS_DENOISE_UNDER_SANITIZER 1
#  endif
#endif
#ifndef RS_DENOISE_UNDER_SANITIZER
#  define RS_DENOISE_UNDER_SANITIZER 0
#endif

static int load(char *why, size_t n)
{
    const char *env = getenv("RS_OIDN_LIBRARY");
    oidn_lib o;
    int ok;
    pthread_mutex_lock(&g_lock);
    if (g_oidn.lib) {
        pthread_mutex_unlock(&g_lock);
        rs_say(why, n, "%s", "");
        return 1;
    }
    if (env && env[0]) {
        ok = try_open(env, &o, why, n,
                      " (RS_OIDN_LIBRARY names it; unset it to use the one sh "
                      "scripts/install-deps.sh installs, or point it at libOpenImageDenoise.so.2)");
    } else {
        FILE *f = fopen(RS_DENOISE_DEFAULT_LIBRARY, "rb");
        if (f) {
            /* installed: a failure here is worth its own message (a missing dependency) */
            fclose(f);
            ok = try_open(RS_DENOISE_DEFAULT_LIBRARY, &o, why, n,
                          " (reinstall: rm -r /opt/raystream/oidn; sh scripts/install-deps.sh)");
        } else {
            ok = try_open("libOpenImageDenoise.so.2", &o, why, n, "");
            if (ok == 0) /* not found (a found library's own problem is kept) */
                rs_say(why, n,
                    "Open Image Denoise 2.x not found (neither %s nor libOpenImageDenoise.so.2 on "
                    "the library path): run sh scripts/install-deps.sh as root, or set "
                    "RS_OIDN_LIBRARY=PATH to libOpenImageDenoise.so.2",
                    RS_DENOISE_DEFAULT_LIBRARY);
        }
    }
#if RS_DENOISE_UNDER_SANITIZER
    if (ok == 1) { /* loaded, but its first device would abort the process */
        dlclose(o.lib);
        ok = 0;
        rs_say(why, n, "Open Image Denoise cannot run in this sanitizer build (its TBB opens "
                       "libtbbbind with RTLD_DEEPBIND, which the sanitizer's runtime refuses); "
                       "use a build without -fsanitize=address or thread");
    }
#endif
    if (ok == 1) {
        g_oidn = o;
        rs_say(why, n, "%s", "");
    }
    pthread_mutex_unlock(&g_lock);
    return ok == 1;
}

int rs_denoise_available(char *why, size_t n) { return load(why, n); }

int rs_denoise_probe(char *why, size_t n)
{
    const oidn_lib *L = &g_oidn;
    rs_oidn_device dev;
    rs_oidn_filter f;
    const char *m = NULL;
    int code;
    if (!load(why, n))
        return 0;
    L->get_device_error(NULL, NULL); /* forget an earlier unqueried error of this thread */
    dev = L->new_device(RS_OIDN_DEVICE_TYPE_CPU);
    if (!dev) {
        code = L->get_device_error(NULL, &m);
        rs_say(why, n, "Open Image Denoise (%s) cannot make its CPU device: %s", L->path,
               m && m[0] ? m : code ? "an error without a message" : "no reason given");
        return 0;
    }
    L->set_device_int(dev, "verbose", 0);
    L->commit_device(dev);
    f = (code = L->get_device_error(dev, &m)) == 0 ? L->new_filter(dev, "RT") : NULL;
    if (f)
        L->release_filter(f);
    else if (code == 0)
        code = L->get_device_error(dev, &m);
    if (!f) /* the message, before the device that owns it goes */
        rs_say(why, n, "Open Image Denoise (%s) cannot make the RT filter on its CPU device: %s",
               L->path, m && m[0] ? m : code ? "an error without a message" : "no reason given");
    L->release_device(dev);
    if (!f)
        return 0;
    rs_say(why, n, "%s", "");
    return 1;
}

/* ---- one denoise on one device ---- */

/* What OIDN reported on a device: its first error. */
typedef struct oidn_errors {
    int code;
    char msg[400];
} oidn_errors;

static void on_error(void *user, int code, const char *message)
{
    oidn_errors *e = (oidn_errors *)user;
    if (e->code == RS_OIDN_ERROR_NONE && code != RS_OIDN_ERROR_NONE) {
        e->code = code;
        snprintf(e->msg, sizeof e->msg, "%s", message ? message : "(no message)");
    }
}

typedef struct denoise_job {
    const float *beauty, *albedo, *normal;
    float *out;
    size_t w, h, bytes; /* bytes: one image */
    int clean_aux;
} denoise_job;

static const char *type_name(int type) { return type == RS_OIDN_DEVICE_TYPE_CUDA ? "CUDA" : "CPU"; }

/* Sets image `name` from host memory: shared on the CPU device, through a device buffer
 * otherwise (a CUDA device cannot be assumed to read pageable host memory).  *buf receives the
 * buffer to release (NULL when shared). */
static void set_image(const oidn_lib *L, rs_oidn_device dev, rs_oidn_filter f, int on_cpu,
                      const char *name, const float *src, const denoise_job *j, rs_oidn_buffer *buf)
{
    *buf = NULL;
    if (on_cpu) {
        L->set_shared_filter_image(f, name, (void *)src, RS_OIDN_FORMAT_FLOAT3, j->w, j->h, 0, 0,
                                   0);
        return;
    }
    *buf = L->new_buffer(dev, j->bytes);
    if (!*buf)
        return; /* the error callback has the reason */
    if (src)
        L->write_buffer(*buf, 0, j->bytes, src);
    L->set_filter_image(f, name, *buf, RS_OIDN_FORMAT_FLOAT3, j->w, j->h, 0, 0, 0);
}

/* Runs the job on a new device of `type`.  Returns RS_OK with the version in *version, or the
 * status with "what: OIDN's message" in msg[n]. */
static rs_status run_on(const oidn_lib *L, int type, const denoise_job *j, int *version, char *msg,
                        size_t n)
{
    oidn_errors e;
    rs_oidn_device dev;
    rs_oidn_filter f = NULL;
    rs_oidn_buffer b_color = NULL, b_albedo = NULL, b_normal = NULL, b_out = NULL;
    int on_cpu = type == RS_OIDN_DEVICE_TYPE_CPU;
    rs_status st = RS_OK;
    const char *step = "making the device";
    memset(&e, 0, sizeof e);
    L->get_device_error(NULL, NULL); /* forget an earlier unqueried error of this thread */
    dev = L->new_device(type);
    if (!dev) {
        const char *m = NULL;
        int code = L->get_device_error(NULL, &m);
        snprintf(msg, n, "OIDN %s device: %s", type_name(type),
                 m && m[0] ? m
                 : code    ? "cannot be made"
                           : "not available");
        return code == RS_OIDN_ERROR_OUT_OF_MEMORY ? RS_ERR_NOMEM : RS_ERR_DEVICE_LOST;
    }
    L->set_device_error_function(dev, on_error, &e);
    L->set_device_int(dev, "verbose", 0);
    L->commit_device(dev);
    if (e.code)
        goto done;
    *version = L->get_device_int(dev, "version");
    step = "making the RT filter";
    f = L->new_filter(dev, "RT");
    if (!f || e.code)
        goto done;
    step = "setting the images";
    set_image(L, dev, f, on_cpu, "color", j->beauty, j, &b_color);
    if (j->albedo)
        set_image(L, dev, f, on_cpu, "albedo", j->albedo, j, &b_albedo);
    if (j->normal)
        set_image(L, dev, f, on_cpu, "normal", j->normal, j, &b_normal);
    set_image(L, dev, f, on_cpu, "output", on_cpu ? j->out : NULL, j, &b_out);
    L->set_filter_bool(f, "hdr", 1);
    if (j->albedo)
        L->set_filter_bool(f, "cleanAux", j->clean_aux != 0);
    if (e.code)
        goto done;
    step = "preparing the filter";
    L->commit_filter(f);
    if (e.code)
        goto done;
    step = "denoising";
    L->execute_filter(f);
    if (e.code)
        goto done;
    if (!on_cpu) {
        step = "reading the result back";
        L->read_buffer(b_out, 0, j->bytes, j->out);
    }
done:
    if (e.code) {
        snprintf(msg, n, "OIDN %s device, %s: %s", type_name(type), step, e.msg);
        st = e.code == RS_OIDN_ERROR_OUT_OF_MEMORY ? RS_ERR_NOMEM : RS_ERR_DEVICE_LOST;
    } else if (!f) {
        snprintf(msg, n, "OIDN %s device: no RT filter", type_name(type));
        st = RS_ERR_DEVICE_LOST;
    }
    if (b_color)
        L->release_buffer(b_color);
    if (b_albedo)
        L->release_buffer(b_albedo);
    if (b_normal)
        L->release_buffer(b_normal);
    if (b_out)
        L->release_buffer(b_out);
    if (f)
        L->release_filter(f);
    L->release_device(dev);
    return st;
}

rs_status rs_denoise(const float *beauty, const float *albedo, const float *normal, uint32_t w,
                     uint32_t h, int clean_aux, int use_gpu, float *out, char *device_used,
                     size_t n)
{
    char why[512], gpu_msg[400], msg[512];
    denoise_job j;
    int version = 0;
    rs_status st = RS_ERR_DEVICE_LOST;
    rs_say(device_used, n, "%s", "");
    if (!beauty || !out)
        return rs_error_set(RS_ERR_ARG, "denoise: no %s image", beauty ? "output" : "beauty");
    if (w == 0 || h == 0)
        return rs_error_set(RS_ERR_ARG, "denoise: empty image (%ux%u)", (unsigned)w, (unsigned)h);
    if (normal && !albedo)
        return rs_error_set(RS_ERR_ARG, "denoise: a normal image needs an albedo image too "
                                        "(OIDN's RT filter takes albedo, or albedo and normal)");
    /* w*h*3 floats, checked (both are below 2^32, so the product fits 64 bits) */
    if ((uint64_t)w * h > SIZE_MAX / (3 * sizeof(float)))
        return rs_error_set(RS_ERR_ARG, "denoise: %ux%u is too large", (unsigned)w, (unsigned)h);
    if (!load(why, sizeof why))
        return rs_error_set(RS_ERR_DEVICE_LOST, "denoise: %s", why);
    j.beauty = beauty;
    j.albedo = albedo;
    j.normal = normal;
    j.out = out;
    j.w = w;
    j.h = h;
    j.bytes = (size_t)w * h * 3 * sizeof(float);
    j.clean_aux = clean_aux;
    gpu_msg[0] = '\0';
    if (use_gpu) {
        /* g_oidn is never written again once loaded (see the top of the file) */
        st = run_on(&g_oidn, RS_OIDN_DEVICE_TYPE_CUDA, &j, &version, gpu_msg, sizeof gpu_msg);
        if (st == RS_OK) {
            rs_say(device_used, n, "CUDA (OIDN %d.%d.%d)", version / 10000, version / 100 % 100,
                version % 100);
            return RS_OK;
        }
    }
    st = run_on(&g_oidn, RS_OIDN_DEVICE_TYPE_CPU, &j, &version, msg, sizeof msg);
    if (st != RS_OK) {
        if (gpu_msg[0])
            return rs_error_set(st, "denoise: %s (and %s)", msg, gpu_msg);
        return rs_error_set(st, "denoise: %s", msg);
    }
    if (gpu_msg[0])
        rs_say(device_used, n, "CPU (OIDN %d.%d.%d; %s)", version / 10000, version / 100 % 100,
            version % 100, gpu_msg);
    else
        rs_say(device_used, n, "CPU (OIDN %d.%d.%d)", version / 10000, version / 100 % 100,
            version % 100);
    return RS_OK;
}

rs_status rs_denoise_split(const float *beauty, const float *direct, const float *direct_fine,
                           const float *albedo, const float *normal, uint32_t w, uint32_t h,
                           int clean_aux, int use_gpu, float *out, char *device_used, size_t n)
{
    size_t i, len;
    float *reflected;
    rs_status st;
    if (!direct || !direct_fine)
        return rs_denoise(beauty, albedo, normal, w, h, clean_aux, use_gpu, out, device_used, n);
    if (!beauty || !out || w == 0 || h == 0 || (uint64_t)w * h > SIZE_MAX / (3 * sizeof(float)))
        return rs_denoise(beauty, albedo, normal, w, h, clean_aux, use_gpu, out, device_used, n);
    len = (size_t)w * h * 3;
    reflected = (float *)malloc(len * sizeof(float));
    if (!reflected)
        return rs_error_set(RS_ERR_NOMEM, "denoise: out of memory (%ux%u)", (unsigned)w,
                            (unsigned)h);
    for (i = 0; i < len; ++i) {
        /* what arrived by reflection; a positive filter's rounding kept from going below 0 */
        float r = beauty[i] - direct[i];
        reflected[i] = beauty[i] >= 0.0f && r < 0.0f ? 0.0f : r;
    }
    st = rs_denoise(reflected, albedo, normal, w, h, clean_aux, use_gpu, out, device_used, n);
    if (st == RS_OK)
        for (i = 0; i < len; ++i)
            out[i] += direct_fine[i];
    free(reflected);
    return st;
}
