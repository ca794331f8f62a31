/* tests/fake_oidn.c — a stand-in libOpenImageDenoise.so.2 for app_picture_test: every entry
 * point raystream resolves is here (so it loads as OIDN 2.x), but no device can be made, as when
 * the real library is installed without its CPU device module (libOpenImageDenoise_device_cpu).
 * Issue 39: such a library failed --denoise only after the render.  With FAKE_OIDN_LATE=1 in the
 * environment a device and a filter are made and the filter fails when it runs: a denoise that
 * fails after the render in spite of the check before it. */
#include <stdbool.h>
#include <stddef.h>
#include <stdlib.h>

#define EXPORT __attribute__((visibility("default")))

static const char *k_msg = "no supported devices found (fake_oidn: no CPU device module)";
static int g_dummy;
static void (*g_fn)(void *, int, const char *);
static void *g_user;

static int late(void) { return getenv("FAKE_OIDN_LATE") != NULL; }

EXPORT void *oidnNewDevice(int type)
{
    (void)type;
    return late() ? &g_dummy : NULL;
}
EXPORT void oidnCommitDevice(void *dev) { (void)dev; }
EXPORT void oidnReleaseDevice(void *dev) { (void)dev; }
EXPORT void oidnSetDeviceInt(void *dev, const char *name, int value)
{
    (void)dev, (void)name, (void)value;
}
EXPORT int oidnGetDeviceInt(void *dev, const char *name)
{
    (void)dev, (void)name;
    return 0;
}
EXPORT void oidnSetDeviceErrorFunction(void *dev, void (*fn)(void *, int, const char *), void *user)
{
    (void)dev;
    g_fn = fn;
    g_user = user;
}
EXPORT int oidnGetDeviceError(void *dev, const char **msg)
{
    (void)dev;
    if (msg)
        *msg = late() ? "" : k_msg;
    return late() ? 0 : 1; /* OIDN_ERROR_NONE, OIDN_ERROR_UNKNOWN */
}
EXPORT int oidnGetNumPhysicalDevices(void) { return 0; }
EXPORT void *oidnNewBuffer(void *dev, size_t bytes)
{
    (void)dev, (void)bytes;
    return late() ? &g_dummy : NULL;
}
EXPORT void oidnWriteBuffer(void *b, size_t o, size_t n, const void *src)
{
    (void)b, (void)o, (void)n, (void)src;
}
EXPORT void oidnReadBuffer(void *b, size_t o, size_t n, void *dst)
{
    (void)b, (void)o, (void)n, (void)dst;
}
EXPORT void oidnReleaseBuffer(void *b) { (void)b; }
EXPORT void *oidnNewFilter(void *dev, const char *type)
{
    (void)dev, (void)type;
    return late() ? &g_dummy : NULL;
}
EXPORT void oidnSetFilterImage(void *f, const char *name, void *buf, int fmt, size_t w, size_t h,
                               size_t off, size_t ps, size_t rs)
{
    (void)f, (void)name, (void)buf, (void)fmt, (void)w, (void)h, (void)off, (void)ps, (void)rs;
}
EXPORT void oidnSetSharedFilterImage(void *f, const char *name, void *ptr, int fmt, size_t w,
                                     size_t h, size_t off, size_t ps, size_t rs)
{
    (void)f, (void)name, (void)ptr, (void)fmt, (void)w, (void)h, (void)off, (void)ps, (void)rs;
}
EXPORT void oidnSetFilterBool(void *f, const char *name, bool v) { (void)f, (void)name, (void)v; }
EXPORT void oidnCommitFilter(void *f) { (void)f; }
EXPORT void oidnExecuteFilter(void *f)
{
    (void)f;
    if (g_fn)
        g_fn(g_user, 1, "fake_oidn: the filter failed as it ran");
}
EXPORT void oidnReleaseFilter(void *f) { (void)f; }
