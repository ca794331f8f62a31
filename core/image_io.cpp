// core/image_io.cpp — the OpenImageIO shim (see image_io.h).  With core/view_ocio.cpp, one of the
// two C++ files of the project; every entry point catches all exceptions and turns them into
// rs_status + message.
#include "core/image_io.h"
#include "core/srgb.h"

#include <OpenImageIO/imagebuf.h>
#include <OpenImageIO/imagebufalgo.h>
#include <OpenImageIO/imageio.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include <unistd.h>

#include "core/alloc.h"
#include "core/file.h"
#include "core/pfm.h"

namespace
{

// OpenImageIO's readers let some libraries print failures themselves (libpng's default handler
// writes "libpng error: ..." to stderr), before and beside the message it gives us.  While a
// file is read, stderr goes to a temporary file; what landed there becomes the reason in our
// one line (reads happen while a scene loads, with no other thread printing).
class stderr_capture
{
  public:
    stderr_capture()
    {
        std::fflush(stderr);
        tmp_ = std::tmpfile();
        if (tmp_ && (saved_ = dup(2)) >= 0)
            dup2(fileno(tmp_), 2);
    }
    ~stderr_capture() { end(); }
    // Restores stderr; what was printed meanwhile, its lines joined by "; ".
    std::string end()
    {
        std::string text;
        char line[512];
        if (saved_ >= 0) {
            std::fflush(stderr);
            dup2(saved_, 2);
            close(saved_);
            saved_ = -1;
        }
        if (!tmp_)
            return text;
        std::rewind(tmp_);
        while (std::fgets(line, sizeof line, tmp_)) {
            size_t n = std::strlen(line);
            while (n && (line[n - 1] == '\n' || line[n - 1] == '\r'))
                line[--n] = 0;
            if (n && text.size() < 400)
                text += (text.empty() ? "" : "; ") + std::string(line);
        }
        std::fclose(tmp_);
        tmp_ = nullptr;
        return text;
    }

  private:
    FILE *tmp_ = nullptr;
    int saved_ = -1;
};

// A failed read's reason: OpenImageIO's words, or where it has none, what is most likely.
std::string why(const std::string &oiio)
{
    std::string w;
    for (char c : oiio) /* its lines, one after another */
        if (c == '\n')
            w += w.empty() || w.back() == ' ' ? "" : "; ";
        else
            w += c;
    while (!w.empty() && (w.back() == ' ' || w.back() == ';'))
        w.pop_back();
    return w.empty() ? std::string("the file is cut short or corrupt") : w;
}

// `st` from reading `path`, with what the libraries printed during the read (`said`) put into
// our message where the read failed; nothing printed is lost or shown twice.
rs_status with_said(rs_status st, const std::string &said)
{
    if (st == RS_OK || said.empty())
        return st;
    std::string msg = rs_error_message();
    if (msg.find(said) != std::string::npos)
        return st;
    rs_error_clear();
    return rs_error_set(st, "%s (%s)", msg.c_str(), said.c_str());
}

std::string lower_ext(const char *path)
{
    const char *slash = std::strrchr(path, '/');
    const char *dot = std::strrchr(path, '.');
    if (!dot || (slash && dot < slash))
        return "";
    std::string e(dot + 1);
    for (auto &c : e)
        c = (char)std::tolower((unsigned char)c);
    return e;
}

bool is_float_format(const std::string &e) { return e == "exr" || e == "hdr" || e == "pfm"; }

bool is_8bit_format(const std::string &e)
{
    return e == "png" || e == "jpg" || e == "jpeg" || e == "tif" || e == "tiff" || e == "bmp" ||
           e == "tga";
}

std::string dir_of(const char *path)
{
    const char *slash = std::strrchr(path, '/');
    if (!slash)
        return ".";
    if (slash == path)
        return "/";
    return std::string(path, (size_t)(slash - path));
}

std::string temp_name(const char *path)
{
    char buf[4200];
    if (!rs_file_temp_name(path, buf, sizeof buf))
        return std::string(path) + ".tmp";
    return buf;
}

} // namespace

extern "C" rs_status rs_image_check_output(const char *path)
{
    try {
        std::string e = lower_ext(path);
        if (e.empty())
            return rs_error_set(RS_ERR_ARG,
                                "%s: output file has no extension (use .png, .exr or .hdr)", path);
        if (!is_float_format(e) && !is_8bit_format(e))
            return rs_error_set(RS_ERR_ARG,
                                "%s: unsupported output format '.%s' (use .png, .exr, .hdr, .jpg "
                                "or .tif)",
                                path, e.c_str());
        if (e == "pfm") // our own writer (core/pfm.h): OpenImageIO 2.4 cannot write one
            return rs_pfm_check_output(path);
        auto out = OIIO::ImageOutput::create(path);
        if (!out)
            return rs_error_set(RS_ERR_ARG, "%s: OpenImageIO cannot write '.%s' files", path,
                                e.c_str());
        std::string probe = temp_name(path);
        FILE *f = std::fopen(probe.c_str(), "wx");
        if (!f)
            return rs_error_set(RS_ERR_IO, "%s: cannot write to folder '%s': %s", path,
                                dir_of(path).c_str(), std::strerror(errno));
        std::fclose(f);
        std::remove(probe.c_str());
        return RS_OK;
    } catch (const std::exception &ex) {
        return rs_error_set(RS_ERR_IO, "%s: %s", path, ex.what());
    } catch (...) {
        return rs_error_set(RS_ERR_IO, "%s: unknown error checking the output", path);
    }
}

extern "C" rs_status rs_image_write(const char *path, uint32_t w, uint32_t h, const float *rgb)
{
    return rs_image_write_meta(path, w, h, rgb, nullptr, 0);
}

extern "C" rs_status rs_image_write_meta(const char *path, uint32_t w, uint32_t h,
                                         const float *rgb, const rs_image_meta *meta,
                                         size_t n_meta)
{
    return rs_image_write_layers(path, w, h, rgb, nullptr, 0, meta, n_meta);
}

extern "C" rs_status rs_image_write_layers(const char *path, uint32_t w, uint32_t h,
                                           const float *rgb, const rs_image_layer *layers,
                                           size_t n_layers, const rs_image_meta *meta,
                                           size_t n_meta)
{
    return rs_image_write_view(path, w, h, rgb, layers, n_layers, meta, n_meta, nullptr);
}

extern "C" int rs_image_is_display_format(const char *path)
{
    try {
        return is_8bit_format(lower_ext(path)) ? 1 : 0;
    } catch (...) {
        return 0;
    }
}

extern "C" rs_status rs_image_write_view(const char *path, uint32_t w, uint32_t h,
                                         const float *rgb, const rs_image_layer *layers,
                                         size_t n_layers, const rs_image_meta *meta,
                                         size_t n_meta, const rs_view *view)
{
    if (view && rs_view_is_default(view))
        view = nullptr; // today's clamp + sRGB curve, byte for byte
    std::string tmp = temp_name(path);
    try {
        std::string e = lower_ext(path);
        size_t n = (size_t)w * h * 3;
        if (n_layers > 0 && e != "exr")
            return rs_error_set(RS_ERR_ARG, "%s: only an .exr file holds extra layers (AOVs)",
                                path);
        if (e == "pfm") // linear floats, no header for metadata or the view
            return rs_pfm_write(path, w, h, rgb);
        auto out = OIIO::ImageOutput::create(path);
        if (!out)
            return rs_error_set(RS_ERR_ARG, "%s: OpenImageIO cannot write this format", path);
        bool ok;
        if (is_float_format(e)) {
            std::vector<std::string> names = {"R", "G", "B"};
            for (size_t l = 0; l < n_layers; ++l)
                for (const char *c = layers[l].channels; *c; ++c)
                    names.push_back(std::string(layers[l].name) + "." + *c);
            int nc = (int)names.size();
            OIIO::ImageSpec spec((int)w, (int)h, nc, OIIO::TypeDesc::FLOAT);
            spec.channelnames = names;
            spec.alpha_channel = -1;
            spec.z_channel = -1;
            spec.attribute("oiio:ColorSpace", "Linear");
            if (e == "exr")
                for (size_t i = 0; i < n_meta; ++i)
                    spec.attribute(meta[i].key, meta[i].value);
            if (e == "exr" && view) { // the pixels stay linear: the view is only recorded
                char ev[32];
                std::snprintf(ev, sizeof ev, "%g", (double)view->exposure);
                spec.attribute("raystream:view", view->name);
                spec.attribute("raystream:exposure", ev);
            }
            if (n_layers == 0) {
                ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::FLOAT, rgb);
            } else {
                // interleave: R G B, then each layer's channels
                std::vector<float> px((size_t)w * h * (size_t)nc);
                size_t npix = (size_t)w * h;
                for (size_t i = 0; i < npix; ++i) {
                    float *o = &px[i * (size_t)nc];
                    o[0] = rgb[3 * i], o[1] = rgb[3 * i + 1], o[2] = rgb[3 * i + 2];
                    int k = 3;
                    for (size_t l = 0; l < n_layers; ++l) {
                        size_t lc = std::strlen(layers[l].channels);
                        for (size_t c = 0; c < lc; ++c)
                            o[k++] = layers[l].data[i * lc + c];
                    }
                }
                ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::FLOAT, px.data());
            }
        } else {
            std::vector<unsigned char> px(n);
            if (!view) {
                for (size_t i = 0; i < n; ++i)
                    px[i] = (unsigned char)std::lround(255.0f * rs_srgb_encode(rgb[i]));
            } else { // display values in [0, 1]: no second encoding
                std::vector<float> disp(n);
                rs_status st = rs_view_apply(view, rgb, (size_t)w * h, disp.data());
                if (st != RS_OK)
                    return st;
                for (size_t i = 0; i < n; ++i)
                    px[i] = (unsigned char)std::lround(255.0f * disp[i]);
            }
            OIIO::ImageSpec spec((int)w, (int)h, 3, OIIO::TypeDesc::UINT8);
            spec.attribute("oiio:ColorSpace", "sRGB");
            ok = out->open(tmp, spec) && out->write_image(OIIO::TypeDesc::UINT8, px.data());
        }
        ok = out->close() && ok;
        if (!ok) {
            std::string msg = out->geterror();
            std::remove(tmp.c_str());
            return rs_error_set(RS_ERR_IO, "%s: write failed: %s", path, msg.c_str());
        }
        if (std::rename(tmp.c_str(), path) != 0) {
            int err = errno;
            std::remove(tmp.c_str());
            return rs_error_set(RS_ERR_IO, "%s: cannot rename the finished file into place: %s",
                                path, std::strerror(err));
        }
        return RS_OK;
    } catch (const std::exception &ex) {
        std::remove(tmp.c_str());
        return rs_error_set(RS_ERR_IO, "%s: %s", path, ex.what());
    } catch (...) {
        std::remove(tmp.c_str());
        return rs_error_set(RS_ERR_IO, "%s: unknown error writing the image", path);
    }
}

static rs_status read_image(const char *path, uint32_t *w, uint32_t *h, float **rgb, bool linear);

extern "C" rs_status rs_image_read(const char *path, uint32_t *w, uint32_t *h, float **rgb)
{
    stderr_capture cap;
    rs_status st = read_image(path, w, h, rgb, false);
    return with_said(st, cap.end());
}

extern "C" rs_status rs_image_read_linear(const char *path, uint32_t *w, uint32_t *h, float **rgb)
{
    stderr_capture cap;
    rs_status st = read_image(path, w, h, rgb, true);
    return with_said(st, cap.end());
}

// Opens `path` for reading; a file OpenImageIO cannot open is the status `fail`.  OpenImageIO
// gets regular files of a sane size only: its format probing keeps reading a /dev/zero, and
// opening a FIFO blocks until someone writes to it.  May throw (callers catch).
static rs_status open_input(const char *path, rs_status fail, OIIO::ImageInput::unique_ptr *in)
{
    rs_status st = rs_file_check(path, RS_FILE_MAX_IMAGE_BYTES, nullptr);
    if (st != RS_OK)
        return st;
    // colours as stored: PNG, TIFF and the rest keep colour and alpha apart (glTF's images
    // among them: not premultiplied), and OpenImageIO would otherwise multiply the colour by
    // the alpha on reading (a white texel of alpha 128 read as 0.5, 0.215 once decoded)
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    *in = OIIO::ImageInput::open(path, &config);
    if (!*in)
        return rs_error_set(fail, "%s: cannot open image: %s", path, OIIO::geterror().c_str());
    return RS_OK;
}

// open_input, then the header checked: not empty, and bounded before anything is allocated (a
// header may claim any size: a small file can decode to gigabytes).  May throw.
static rs_status open_image(const char *path, OIIO::ImageInput::unique_ptr *in)
{
    rs_status st = open_input(path, RS_ERR_IO, in);
    if (st != RS_OK)
        return st;
    const OIIO::ImageSpec &spec = (*in)->spec();
    if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0)
        return rs_error_set(RS_ERR_IO, "%s: empty image", path);
    if (spec.width > RS_IMAGE_MAX_SIDE || spec.height > RS_IMAGE_MAX_SIDE)
        return rs_error_set(RS_ERR_ARG, "%s: image of %dx%d has a side over %d pixels, the most "
                                        "either side may have",
                            path, spec.width, spec.height, RS_IMAGE_MAX_SIDE);
    if ((uint64_t)spec.width * (uint64_t)spec.height > RS_IMAGE_MAX_PIXELS)
        return rs_error_set(RS_ERR_ARG, "%s: image of %dx%d has %llu pixels, more than the %llu "
                                        "an image may have",
                            path, spec.width, spec.height,
                            (unsigned long long)spec.width * (unsigned long long)spec.height,
                            (unsigned long long)RS_IMAGE_MAX_PIXELS);
    return RS_OK;
}

// One channel of an open image into a new block of width * height floats at *out.
static rs_status read_one_channel(const char *path, OIIO::ImageInput *in, int ch, float **out)
{
    const OIIO::ImageSpec &spec = in->spec();
    size_t npix = (size_t)spec.width * (size_t)spec.height;
    float *o = (float *)rs_alloc(npix, sizeof(float));
    if (!o)
        return rs_error_set(RS_ERR_NOMEM, "%s: out of memory reading the image", path);
    if (!in->read_image(0, 0, ch, ch + 1, OIIO::TypeDesc::FLOAT, o)) {
        rs_free(o);
        return rs_error_set(RS_ERR_IO, "%s: read failed: %s", path, why(in->geterror()).c_str());
    }
    *out = o;
    return RS_OK;
}

static rs_status read_image(const char *path, uint32_t *w, uint32_t *h, float **rgb, bool linear)
{
    *rgb = nullptr;
    try {
        OIIO::ImageInput::unique_ptr in;
        rs_status st = open_image(path, &in);
        if (st != RS_OK)
            return st;
        const OIIO::ImageSpec &spec = in->spec();
        size_t npix = (size_t)spec.width * (size_t)spec.height;
        int nc = spec.nchannels < 3 ? spec.nchannels : 3; // only RGB is kept
        // scanline files are read a strip of rows at a time into the result (a whole copy of
        // the file's channels beside it doubled the memory: 6.4 GB for a 0.8 MB PNG of 16384^2)
        size_t strip = spec.tile_width == 0 ? (size_t)64 : (size_t)spec.height;
        size_t need = npix * 3 * sizeof(float) + strip * (size_t)spec.width * nc * sizeof(float);
        uint64_t budget = rs_memory_budget();
        if (budget && need > budget)
            return rs_error_set(RS_ERR_NOMEM,
                                "%s: a %dx%d image takes %.0f MB as floats, more than the %.0f MB "
                                "this process may use",
                                path, spec.width, spec.height, (double)need / 1048576.0,
                                (double)budget / 1048576.0);
        std::vector<float> all(std::min(strip, (size_t)spec.height) * (size_t)spec.width *
                               (size_t)nc);
        float *o = (float *)rs_alloc(npix * 3, sizeof(float));
        if (!o)
            return rs_error_set(RS_ERR_NOMEM, "%s: out of memory reading the image", path);
        bool decode = linear && !spec.format.is_floating_point();
        // An integer file has few distinct values (k / (2^bits - 1)): each is decoded once and
        // remembered by k, checked against the value itself, so the result is rs_srgb_decode's
        // bit for bit (a powf per texel was 3% of loading the living room)
        size_t levels = spec.format.size() <= 2 ? ((size_t)1 << (8 * spec.format.size())) : 0;
        std::vector<float> seen_in(levels, -1.0f), seen_out(levels);
        for (size_t y0 = 0; y0 < (size_t)spec.height; y0 += strip) {
            size_t rows = std::min(strip, (size_t)spec.height - y0);
            bool got = strip == (size_t)spec.height
                           ? in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, all.data())
                           : in->read_scanlines(0, 0, spec.y + (int)y0, spec.y + (int)(y0 + rows),
                                                0, 0, nc, OIIO::TypeDesc::FLOAT, all.data());
            if (!got) {
                rs_free(o);
                return rs_error_set(RS_ERR_IO, "%s: read failed: %s", path,
                                    why(in->geterror()).c_str());
            }
            size_t first = y0 * (size_t)spec.width, end = first + rows * (size_t)spec.width;
        for (size_t i = first; i < end; ++i)
            for (int c = 0; c < 3; ++c) {
                float v = all[(i - first) * nc + (c < nc ? c : 0)];
                if (!decode) {
                    o[3 * i + c] = v;
                    continue;
                }
                if (levels && v >= 0.0f && v <= 1.0f) {
                    size_t k = (size_t)((double)v * (double)(levels - 1) + 0.5);
                    if (seen_in[k] != v) {
                        seen_in[k] = v;
                        seen_out[k] = rs_srgb_decode(v);
                    }
                    o[3 * i + c] = seen_out[k];
                } else {
                    o[3 * i + c] = rs_srgb_decode(v);
                }
            }
        }
        *w = (uint32_t)spec.width;
        *h = (uint32_t)spec.height;
        *rgb = o;
        return RS_OK;
    } catch (const std::exception &ex) {
        return rs_error_set(RS_ERR_IO, "%s: %s", path, ex.what());
    } catch (...) {
        return rs_error_set(RS_ERR_IO, "%s: unknown error reading the image", path);
    }
}

static rs_status rs_image_read_alpha_inner(const char *path, uint32_t *w, uint32_t *h, float **alpha)
{
    *alpha = nullptr;
    try {
        OIIO::ImageInput::unique_ptr in;
        rs_status st = open_image(path, &in);
        if (st != RS_OK)
            return st;
        const OIIO::ImageSpec &spec = in->spec();
        int ch = spec.alpha_channel;
        if (ch < 0 && (spec.nchannels == 2 || spec.nchannels == 4))
            ch = spec.nchannels - 1;
        *w = (uint32_t)spec.width;
        *h = (uint32_t)spec.height;
        if (ch < 0 || ch >= spec.nchannels)
            return RS_OK; // no alpha: opaque
        return read_one_channel(path, in.get(), ch, alpha);
    } catch (const std::exception &ex) {
        return rs_error_set(RS_ERR_IO, "%s: %s", path, ex.what());
    } catch (...) {
        return rs_error_set(RS_ERR_IO, "%s: unknown error reading the image", path);
    }
}

extern "C" rs_status rs_image_read_alpha(const char *path, uint32_t *w, uint32_t *h,
                                         float **alpha)
{
    stderr_capture cap;
    rs_status st = rs_image_read_alpha_inner(path, w, h, alpha);
    return with_said(st, cap.end());
}

static rs_status rs_image_read_channel_inner(const char *path, const char *channel, uint32_t *w,   uint32_t *h, float **data)
{
    *data = nullptr;
    try {
        OIIO::ImageInput::unique_ptr in;
        rs_status st = open_image(path, &in);
        if (st != RS_OK)
            return st;
        const OIIO::ImageSpec &spec = in->spec();
        int ch = -1;
        for (int c = 0; c < spec.nchannels; ++c)
            if (spec.channel_name(c) == channel)
                ch = c;
        if (ch < 0)
            return rs_error_set(RS_ERR_ARG, "%s: no channel %s", path, channel);
        *w = (uint32_t)spec.width;
        *h = (uint32_t)spec.height;
        return read_one_channel(path, in.get(), ch, data);
    } catch (const std::exception &ex) {
        return rs_error_set(RS_ERR_IO, "%s: %s", path, ex.what());
    } catch (...) {
        return rs_error_set(RS_ERR_IO, "%s: unknown error reading the image", path);
    }
}

extern "C" rs_status rs_image_read_channel(const char *path, const char *channel, uint32_t *w,
                                           uint32_t *h, float **data)
{
    stderr_capture cap;
    rs_status st = rs_image_read_channel_inner(path, channel, w, h, data);
    return with_said(st, cap.end());
}

extern "C" rs_status rs_image_read_meta(const char *path, const char *key, char *value, size_t n)
{
    try {
        OIIO::ImageInput::unique_ptr in;
        rs_status st = open_input(path, RS_ERR_ARG, &in);
        if (st != RS_OK)
            return st;
        const OIIO::ParamValue *p = in->spec().find_attribute(key, OIIO::TypeDesc::STRING);
        if (!p)
            return rs_error_set(RS_ERR_ARG, "%s: no attribute %s", path, key);
        std::snprintf(value, n, "%s", p->get_string().c_str());
        return RS_OK;
    } catch (const std::exception &ex) {
        return rs_error_set(RS_ERR_ARG, "%s: %s", path, ex.what());
    } catch (...) {
        return rs_error_set(RS_ERR_ARG, "%s: unknown error reading the image", path);
    }
}

extern "C" const char *rs_image_library_version(void) { return OIIO_VERSION_STRING; }

extern "C" int rs_image_can_downsample(void) { return 1; }

// One mip level from the one above (scenes/scene.c builds the pyramids): OpenImageIO's resize
// with a box filter one destination pixel wide, so a 2:1 reduction is the exact mean of each 2x2
// block (the image's mean is kept, and no texel goes negative as under lanczos3's lobes).
extern "C" rs_status rs_image_downsample(const float *rgb, uint32_t w, uint32_t h, float *out,
                                         uint32_t w2, uint32_t h2)
{
    try {
        if (w == 0 || h == 0 || w2 == 0 || h2 == 0 || w2 > w || h2 > h)
            return rs_error_set(RS_ERR_ARG, "downsampling a %ux%u image to %ux%u", w, h, w2, h2);
        OIIO::ImageSpec sspec((int)w, (int)h, 3, OIIO::TypeDesc::FLOAT);
        OIIO::ImageSpec dspec((int)w2, (int)h2, 3, OIIO::TypeDesc::FLOAT);
        // wraps the caller's memory: nothing is copied in or out but through these two buffers
        OIIO::ImageBuf src(sspec, const_cast<float *>(rgb));
        OIIO::ImageBuf dst(dspec, out);
        if (!OIIO::ImageBufAlgo::resize(dst, src, "box", 1.0f, OIIO::ROI(), 0))
            return rs_error_set(RS_ERR_IO, "downsampling a %ux%u image: %s", w, h,
                                dst.geterror().c_str());
        return RS_OK;
    } catch (const std::exception &ex) {
        return rs_error_set(RS_ERR_IO, "downsampling a %ux%u image: %s", w, h, ex.what());
    } catch (...) {
        return rs_error_set(RS_ERR_IO, "downsampling a %ux%u image: unknown error", w, h);
    }
}
