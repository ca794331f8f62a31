// core/view_ocio.cpp — the OpenColorIO views of core/view.h, through OpenImageIO's ColorConfig
// (OpenImageIO 2.4's color.h: ColorConfig::getViewNames, createDisplayTransform and
// ColorProcessor::apply, what ImageBufAlgo::ociodisplay runs per pixel).
//
// The config is the one $OCIO names, loaded once (on the first rs_view_ocio_* call, under a
// lock) and kept for the process.  A view is one of its default display's views; the input
// colour space is the config's scene_linear role (else its "linear" role, else a space named
// "linear").  Exceptions stop at this file's extern "C" edge.
#include "core/view.h"

#include <OpenImageIO/color.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>
#include <string>
#include <unistd.h>
#include <vector>

#include "core/file.h"

namespace
{

struct ocio_state {
    std::mutex lock;
    bool tried = false;
    std::unique_ptr<OIIO::ColorConfig> config; // null when $OCIO is unset or does not load
    std::string why;                           // why config is null
    std::string display, input;
};

ocio_state &state()
{
    static ocio_state s;
    return s;
}

// Loads the config once.  Returns it, or null with s.why set.  Call with s.lock held.
OIIO::ColorConfig *load(ocio_state &s)
{
    if (s.tried)
        return s.config.get();
    s.tried = true;
    const char *env = std::getenv("OCIO");
    if (!OIIO::ColorConfig::supportsOpenColorIO()) {
        s.why = "this build's OpenImageIO has no OpenColorIO";
        return nullptr;
    }
    if (!env || !*env) {
        s.why = "set $OCIO to an OpenColorIO config for its views";
        return nullptr;
    }
    {
        // a regular file of a sane size (a FIFO blocked OpenColorIO's reader for ever)
        char msg[600];
        int fd;
        if (rs_file_open_quiet(env, (uint64_t)64 << 20, &fd, nullptr, msg, sizeof msg) != RS_OK) {
            s.why = std::string("$OCIO: ") + msg;
            return nullptr;
        }
        close(fd);
    }
    auto cfg = std::make_unique<OIIO::ColorConfig>(env);
    if (cfg->has_error()) {
        std::string e = cfg->geterror();
        std::replace(e.begin(), e.end(), '\n', ' ');
        s.why = "the $OCIO config '" + std::string(env) + "' does not load: " + e;
        return nullptr;
    }
    const char *disp = cfg->getDefaultDisplayName();
    if (!disp || !*disp) {
        s.why = "the $OCIO config '" + std::string(env) + "' has no display";
        return nullptr;
    }
    s.display = disp;
    const char *in = cfg->getColorSpaceNameByRole("scene_linear");
    if (!in || !*in)
        in = cfg->getColorSpaceNameByRole("linear");
    s.input = in && *in ? in : "linear";
    s.config = std::move(cfg);
    return s.config.get();
}

// One line: OpenColorIO's messages may span several.
std::string one_line(std::string e)
{
    std::replace(e.begin(), e.end(), '\n', ' ');
    std::replace(e.begin(), e.end(), '\r', ' ');
    while (!e.empty() && e.back() == ' ')
        e.pop_back();
    return e;
}

void put(char *why, size_t n, const std::string &text)
{
    if (n)
        std::snprintf(why, n, "%s", one_line(text).c_str());
}

} // namespace

extern "C" int rs_view_ocio_available(void)
{
    try {
        return OIIO::ColorConfig::supportsOpenColorIO() ? 1 : 0;
    } catch (...) {
        return 0;
    }
}

extern "C" int rs_view_ocio_find(const char *name, char *why, size_t n)
{
    try {
        ocio_state &s = state();
        std::lock_guard<std::mutex> g(s.lock);
        OIIO::ColorConfig *cfg = load(s);
        if (!cfg) {
            put(why, n, s.why);
            return 0;
        }
        std::vector<std::string> views = cfg->getViewNames(s.display);
        std::string list;
        for (const std::string &v : views) {
            if (v == name) {
                // its processor made now, not when the image is written after the render (a
                // missing or corrupt LUT, a colour space the config lacks)
                OIIO::ColorProcessorHandle p =
                    cfg->createDisplayTransform(s.display, name, s.input);
                if (p)
                    return 1;
                std::string e = cfg->geterror();
                put(why, n,
                    "view '" + std::string(name) + "' of display '" + s.display + "' in $OCIO " +
                        "cannot be made: " +
                        (e.empty() ? std::string("OpenColorIO cannot make the transform") : e));
                return -1;
            }
            list += (list.empty() ? "" : ", ") + v;
        }
        put(why, n, "views of display '" + s.display + "' in $OCIO: " + list);
        return 0;
    } catch (const std::exception &ex) {
        put(why, n, std::string("OpenColorIO: ") + ex.what());
        return 0;
    } catch (...) {
        put(why, n, "OpenColorIO: unknown error");
        return 0;
    }
}

extern "C" rs_status rs_view_ocio_apply(const char *name, float *rgb, size_t npix)
{
    try {
        OIIO::ColorProcessorHandle p;
        {
            ocio_state &s = state();
            std::lock_guard<std::mutex> g(s.lock);
            OIIO::ColorConfig *cfg = load(s);
            if (!cfg)
                return rs_error_set(RS_ERR_ARG, "view '%s': %s", name, s.why.c_str());
            p = cfg->createDisplayTransform(s.display, name, s.input);
            if (!p) {
                std::string e = cfg->geterror();
                return rs_error_set(RS_ERR_ARG, "view '%s' of display '%s' from '%s': %s", name,
                                    s.display.c_str(), s.input.c_str(),
                                    e.empty() ? "OpenColorIO cannot make the transform"
                                              : one_line(e).c_str());
            }
        }
        // rows of at most `block` pixels (apply counts in int), run in parallel: OCIO's CPU
        // processors are safe to share between threads
        const long long block = 65536, nblocks = (long long)((npix + block - 1) / block);
        const OIIO::ColorProcessor *proc = p.get();
#if defined(_OPENMP)
#  pragma omp parallel for schedule(dynamic) if (nblocks > 1)
#endif
        for (long long b = 0; b < nblocks; ++b) {
            size_t first = (size_t)(b * block);
            size_t count = std::min((size_t)block, npix - first);
            proc->apply(rgb + 3 * first, (int)count, 1, 3, sizeof(float), 3 * sizeof(float),
                        (OIIO::stride_t)(3 * sizeof(float) * count));
        }
        return RS_OK;
    } catch (const std::exception &ex) {
        return rs_error_set(RS_ERR_ARG, "view '%s': %s", name, one_line(ex.what()).c_str());
    } catch (...) {
        return rs_error_set(RS_ERR_ARG, "view '%s': unknown OpenColorIO error", name);
    }
}
