/* python/_raystream.c — the Python module's C part, on CPython's limited API (3.9: one abi3
 * module for every later Python): thin functions over the C API (include/raystream.h) that
 * python/raystream/__init__.py wraps into raystream.load, raystream.render, Scene and Image.
 *
 * Handles travel as capsules that release their object when collected.  Renders run with the
 * GIL released; the progress callback takes it back at most 20 times a second to call the
 * user's callable and to run Python's signal handlers, so Ctrl-C (KeyboardInterrupt) stops the
 * render at its next stage boundary.  Every C failure becomes ValueError (a bad argument),
 * OSError (a file), MemoryError or RuntimeError with the library's one line. */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <string.h>

#include "pixels.h"
#include "raystream.h"

#define SCENE_CAPSULE "raystream.scene"
#define IMAGE_CAPSULE "raystream.image"

/* Raises the exception that fits `st` with the library's message; returns NULL. */
static PyObject *raise_status(raystream_status st)
{
    PyObject *type = st == RAYSTREAM_ERROR_ARGUMENT ? PyExc_ValueError
                     : st == RAYSTREAM_ERROR_IO     ? PyExc_OSError
                     : st == RAYSTREAM_ERROR_MEMORY ? PyExc_MemoryError
                                                    : PyExc_RuntimeError;
    PyErr_SetString(type, raystream_last_error());
    return NULL;
}

static void scene_free(PyObject *cap)
{
    raystream_scene_release((raystream_scene *)PyCapsule_GetPointer(cap, SCENE_CAPSULE));
}

static void image_free(PyObject *cap)
{
    raystream_image_release((raystream_image *)PyCapsule_GetPointer(cap, IMAGE_CAPSULE));
}

static raystream_scene *scene_of(PyObject *cap)
{
    return (raystream_scene *)PyCapsule_GetPointer(cap, SCENE_CAPSULE);
}

static raystream_image *image_of(PyObject *cap)
{
    return (raystream_image *)PyCapsule_GetPointer(cap, IMAGE_CAPSULE);
}

static PyObject *wrap_scene(raystream_status st, raystream_scene *s)
{
    PyObject *cap;
    if (st != RAYSTREAM_OK)
        return raise_status(st);
    if (!(cap = PyCapsule_New(s, SCENE_CAPSULE, scene_free)))
        raystream_scene_release(s);
    return cap;
}

static PyObject *py_version(PyObject *self, PyObject *args)
{
    (void)self, (void)args;
    return Py_BuildValue("(is)", raystream_version(), raystream_version_string());
}

static PyObject *py_scene_load(PyObject *self, PyObject *args)
{
    const char *path;
    raystream_scene *s = NULL;
    raystream_status st;
    (void)self;
    if (!PyArg_ParseTuple(args, "s", &path))
        return NULL;
    Py_BEGIN_ALLOW_THREADS st = raystream_scene_load(path, &s);
    Py_END_ALLOW_THREADS return wrap_scene(st, s);
}

static PyObject *py_scene_from_json(PyObject *self, PyObject *args)
{
    const char *text, *base = NULL;
    raystream_scene *s = NULL;
    raystream_status st;
    (void)self;
    if (!PyArg_ParseTuple(args, "s|z", &text, &base))
        return NULL;
    Py_BEGIN_ALLOW_THREADS st = raystream_scene_from_json(text, base, &s);
    Py_END_ALLOW_THREADS return wrap_scene(st, s);
}

static PyObject *py_scene_create(PyObject *self, PyObject *args)
{
    raystream_scene *s = NULL;
    raystream_status st;
    (void)self, (void)args;
    st = raystream_scene_create(&s);
    return wrap_scene(st, s);
}

static PyObject *py_scene_add_material(PyObject *self, PyObject *args)
{
    PyObject *cap;
    const char *json;
    uint32_t id = 0;
    raystream_status st;
    (void)self;
    if (!PyArg_ParseTuple(args, "Os", &cap, &json) || !scene_of(cap))
        return NULL;
    if ((st = raystream_scene_add_material(scene_of(cap), json, &id)) != RAYSTREAM_OK)
        return raise_status(st);
    return PyLong_FromUnsignedLong(id);
}

/* bytes of packed floats or uint32s, or None (NULL). */
static int bytes_of(PyObject *o, const char *name, size_t unit, const char **data, size_t *n)
{
    char *p;
    Py_ssize_t len;
    *data = NULL;
    *n = 0;
    if (o == Py_None)
        return 1;
    if (PyBytes_AsStringAndSize(o, &p, &len) != 0)
        return 0;
    if ((size_t)len % unit != 0) {
        PyErr_Format(PyExc_ValueError, "%s: %zd bytes is not a whole number of items", name, len);
        return 0;
    }
    *data = p;
    *n = (size_t)len / unit;
    return 1;
}

/* scene_add_mesh(cap, pos, idx, nrm, uv, material, as_prototype) -> None or the prototype */
static PyObject *py_scene_add_mesh(PyObject *self, PyObject *args)
{
    PyObject *cap, *pos, *idx, *nrm, *uv;
    unsigned long mat;
    const char *p, *i, *n, *u;
    size_t np_, ni, nn, nu;
    raystream_status st;
    uint32_t proto = 0;
    int as_proto = 0;
    (void)self;
    if (!PyArg_ParseTuple(args, "OSSOOk|p", &cap, &pos, &idx, &nrm, &uv, &mat, &as_proto) ||
        !scene_of(cap))
        return NULL;
    if (!bytes_of(pos, "vertices", 12, &p, &np_) || !bytes_of(idx, "indices", 12, &i, &ni) ||
        !bytes_of(nrm, "normals", 12, &n, &nn) || !bytes_of(uv, "uvs", 8, &u, &nu))
        return NULL;
    if ((n && nn != np_) || (u && nu != np_))
        return PyErr_Format(PyExc_ValueError, "%s: %zu rows for %zu vertices",
                            n && nn != np_ ? "normals" : "uvs", n && nn != np_ ? nn : nu, np_);
    if (as_proto)
        st = raystream_scene_add_prototype(scene_of(cap), (const float *)(const void *)p, np_,
                                           (const uint32_t *)(const void *)i, ni,
                                           (const float *)(const void *)n,
                                           (const float *)(const void *)u, (uint32_t)mat, &proto);
    else
        st = raystream_scene_add_mesh(
            scene_of(cap), (const float *)(const void *)p, np_, (const uint32_t *)(const void *)i,
            ni, (const float *)(const void *)n, (const float *)(const void *)u, (uint32_t)mat);
    if (st != RAYSTREAM_OK)
        return raise_status(st);
    if (as_proto)
        return PyLong_FromUnsignedLong(proto);
    Py_RETURN_NONE;
}

static PyObject *py_scene_add_light(PyObject *self, PyObject *args)
{
    PyObject *cap;
    const char *json;
    raystream_status st;
    (void)self;
    if (!PyArg_ParseTuple(args, "Os", &cap, &json) || !scene_of(cap))
        return NULL;
    if ((st = raystream_scene_add_light(scene_of(cap), json)) != RAYSTREAM_OK)
        return raise_status(st);
    Py_RETURN_NONE;
}

/* scene_add_instance(cap, prototype, 12 numbers) */
static PyObject *py_scene_add_instance(PyObject *self, PyObject *args)
{
    PyObject *cap, *m;
    unsigned long proto;
    double mat[12];
    Py_ssize_t k;
    raystream_status st;
    (void)self;
    if (!PyArg_ParseTuple(args, "OkO", &cap, &proto, &m) || !scene_of(cap))
        return NULL;
    if (!PySequence_Check(m) || PySequence_Size(m) != 12) {
        PyErr_Clear();
        return PyErr_Format(PyExc_ValueError, "instance: expected a 3 x 4 or 4 x 4 matrix");
    }
    for (k = 0; k < 12; ++k) {
        PyObject *it = PySequence_GetItem(m, k);
        mat[k] = it ? PyFloat_AsDouble(it) : -1.0;
        Py_XDECREF(it);
        if (PyErr_Occurred()) {
            PyErr_Clear();
            return PyErr_Format(PyExc_ValueError, "instance: the matrix holds a non-number");
        }
    }
    if ((st = raystream_scene_add_instance(scene_of(cap), (uint32_t)proto, mat)) != RAYSTREAM_OK)
        return raise_status(st);
    Py_RETURN_NONE;
}

/* Three floats from a sequence. */
static int vec3(PyObject *o, const char *name, float *v)
{
    Py_ssize_t k;
    if (!PySequence_Check(o) || PyUnicode_Check(o) || PySequence_Size(o) != 3) {
        PyErr_Clear();
        PyErr_Format(PyExc_ValueError, "%s: expected three numbers", name);
        return 0;
    }
    for (k = 0; k < 3; ++k) {
        PyObject *it = PySequence_GetItem(o, k);
        double d = it ? PyFloat_AsDouble(it) : -1.0;
        Py_XDECREF(it);
        if (d == -1.0 && PyErr_Occurred()) {
            PyErr_Clear();
            PyErr_Format(PyExc_ValueError, "%s: expected three numbers", name);
            return 0;
        }
        v[k] = (float)d;
    }
    return 1;
}

static PyObject *done(raystream_status st)
{
    if (st != RAYSTREAM_OK)
        return raise_status(st);
    Py_RETURN_NONE;
}

static PyObject *py_scene_add_sphere(PyObject *self, PyObject *args)
{
    PyObject *cap, *c;
    float center[3], r;
    unsigned long mat;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOfk", &cap, &c, &r, &mat) || !scene_of(cap) ||
        !vec3(c, "center", center))
        return NULL;
    return done(raystream_scene_add_sphere(scene_of(cap), center, r, (uint32_t)mat));
}

static PyObject *py_scene_add_quad(PyObject *self, PyObject *args)
{
    PyObject *cap, *q, *u, *v;
    float fq[3], fu[3], fv[3];
    unsigned long mat;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOk", &cap, &q, &u, &v, &mat) || !scene_of(cap) ||
        !vec3(q, "q", fq) || !vec3(u, "u", fu) || !vec3(v, "v", fv))
        return NULL;
    return done(raystream_scene_add_quad(scene_of(cap), fq, fu, fv, (uint32_t)mat));
}

static PyObject *py_scene_set_camera(PyObject *self, PyObject *args)
{
    PyObject *cap, *f, *a, *u;
    float ff[3], fa[3], fu[3], vfov, aperture, focus;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOOOfff", &cap, &f, &a, &u, &vfov, &aperture, &focus) ||
        !scene_of(cap) || !vec3(f, "from", ff) || !vec3(a, "at", fa) || !vec3(u, "up", fu))
        return NULL;
    return done(raystream_scene_set_camera(scene_of(cap), ff, fa, fu, vfov, aperture, focus));
}

static PyObject *py_scene_set_background(PyObject *self, PyObject *args)
{
    PyObject *cap, *c;
    float rgb[3];
    (void)self;
    if (!PyArg_ParseTuple(args, "OO", &cap, &c) || !scene_of(cap) || !vec3(c, "background", rgb))
        return NULL;
    return done(raystream_scene_set_background(scene_of(cap), rgb));
}

static PyObject *py_scene_set_image_size(PyObject *self, PyObject *args)
{
    PyObject *cap;
    long long w, h;
    (void)self;
    if (!PyArg_ParseTuple(args, "OLL", &cap, &w, &h) || !scene_of(cap))
        return NULL;
    if (w < 1 || h < 1 || w > 32768 || h > 32768)
        return PyErr_Format(PyExc_ValueError, "image size %lldx%lld: each side in [1, 32768]", w,
                            h);
    return done(raystream_scene_set_image_size(scene_of(cap), (uint32_t)w, (uint32_t)h));
}

static PyObject *py_scene_counts(PyObject *self, PyObject *args)
{
    PyObject *cap;
    uint32_t s, q, t, m;
    (void)self;
    if (!PyArg_ParseTuple(args, "O", &cap) || !scene_of(cap))
        return NULL;
    raystream_scene_counts(scene_of(cap), &s, &q, &t, &m);
    return Py_BuildValue("(kkkk)", (unsigned long)s, (unsigned long)q, (unsigned long)t,
                         (unsigned long)m);
}

/* ---- rendering ---------------------------------------------------------------------------- */

/* What the progress callback shares with the render call. */
typedef struct progress_ctx {
    PyObject *callable;                      /* or NULL */
    PyObject *exc_type, *exc_value, *exc_tb; /* an exception to raise once the render is back */
    int user_cancelled;                      /* the callable returned False */
} progress_ctx;

static int on_progress(void *user, double fraction)
{
    progress_ctx *p = (progress_ctx *)user;
    PyGILState_STATE g = PyGILState_Ensure();
    int stop = 0;
    if (p->exc_type) {
        stop = 1;
    } else if (PyErr_CheckSignals() != 0) { /* Ctrl-C: KeyboardInterrupt */
        PyErr_Fetch(&p->exc_type, &p->exc_value, &p->exc_tb);
        stop = 1;
    } else if (p->callable) {
        PyObject *r = PyObject_CallFunction(p->callable, "d", fraction);
        if (!r) {
            PyErr_Fetch(&p->exc_type, &p->exc_value, &p->exc_tb);
            stop = 1;
        } else {
            if (r == Py_False) {
                p->user_cancelled = 1;
                stop = 1;
            }
            Py_DECREF(r);
        }
    }
    PyGILState_Release(g);
    return stop;
}

/* The options from a list of (name, text) pairs. */
static raystream_options *make_options(PyObject *list)
{
    raystream_options *o = NULL;
    Py_ssize_t i, n;
    raystream_status st;
    if (!PyList_Check(list)) {
        PyErr_SetString(PyExc_TypeError, "options must be a list of (name, value) pairs");
        return NULL;
    }
    if (raystream_options_create(&o) != RAYSTREAM_OK)
        return (raystream_options *)raise_status(RAYSTREAM_ERROR_MEMORY);
    n = PyList_Size(list);
    for (i = 0; i < n; ++i) {
        const char *name, *value;
        if (!PyArg_ParseTuple(PyList_GetItem(list, i), "sz", &name, &value)) {
            raystream_options_release(o);
            return NULL;
        }
        if ((st = raystream_options_set(o, name, value)) != RAYSTREAM_OK) {
            raystream_options_release(o);
            return (raystream_options *)raise_status(st);
        }
    }
    return o;
}

/* A bytearray holding n floats from `src`. */
static PyObject *floats(const float *src, size_t n)
{
    return PyByteArray_FromStringAndSize((const char *)src, (Py_ssize_t)(n * sizeof(float)));
}

/* (capsule, width, height, spp, cancelled, pixels, {layer: (channels, bytes)}) */
static PyObject *image_tuple(raystream_image *img, int cancelled)
{
    uint32_t w = raystream_image_width(img), h = raystream_image_height(img);
    size_t npix = (size_t)w * h;
    PyObject *cap, *pixels, *layers, *out;
    int i;
    if (!(cap = PyCapsule_New(img, IMAGE_CAPSULE, image_free))) {
        raystream_image_release(img);
        return NULL;
    }
    pixels = floats(raystream_image_pixels(img), npix * 3);
    layers = PyDict_New();
    for (i = 0; pixels && layers && i < raystream_image_layer_count(img); ++i) {
        const char *name = raystream_image_layer_name(img, i);
        int ch;
        const float *data = raystream_image_layer(img, name, &ch);
        PyObject *t = Py_BuildValue("(iN)", ch, floats(data, npix * (size_t)ch));
        if (!t || PyDict_SetItemString(layers, name, t) != 0) {
            Py_XDECREF(t);
            Py_CLEAR(layers);
            break;
        }
        Py_DECREF(t);
    }
    if (!pixels || !layers) {
        Py_DECREF(cap);
        Py_XDECREF(pixels);
        Py_XDECREF(layers);
        return NULL;
    }
    out = Py_BuildValue("(NkkdiNN)", cap, (unsigned long)w, (unsigned long)h,
                        raystream_image_spp(img), cancelled, pixels, layers);
    return out;
}

/* render(scene_capsule_or_name, options, progress) */
static PyObject *py_render(PyObject *self, PyObject *args)
{
    PyObject *scene, *opts, *callable, *utf8 = NULL;
    raystream_options *o;
    raystream_image *img = NULL;
    raystream_status st;
    progress_ctx p;
    const char *name = NULL;
    raystream_scene *s = NULL;
    (void)self;
    if (!PyArg_ParseTuple(args, "OOO", &scene, &opts, &callable))
        return NULL;
    if (PyUnicode_Check(scene)) {
        if (!(utf8 = PyUnicode_AsUTF8String(scene)) || !(name = PyBytes_AsString(utf8))) {
            Py_XDECREF(utf8);
            return NULL;
        }
    } else if (!(s = scene_of(scene))) {
        return NULL;
    }
    if (!(o = make_options(opts))) {
        Py_XDECREF(utf8);
        return NULL;
    }
    memset(&p, 0, sizeof p);
    p.callable = callable == Py_None ? NULL : callable;
    raystream_options_set_progress(o, on_progress, &p);
    if (s)
        raystream_scene_retain(s);
    Py_BEGIN_ALLOW_THREADS st =
        s ? raystream_render(s, o, &img) : raystream_render_scene(name, o, &img);
    Py_END_ALLOW_THREADS raystream_scene_release(s);
    raystream_options_release(o);
    Py_XDECREF(utf8);
    if (p.exc_type) { /* Ctrl-C, or the callable raised */
        raystream_image_release(img);
        PyErr_Restore(p.exc_type, p.exc_value, p.exc_tb);
        return NULL;
    }
    if (st != RAYSTREAM_OK && st != RAYSTREAM_CANCELLED)
        return raise_status(st);
    return image_tuple(img, st == RAYSTREAM_CANCELLED);
}

static PyObject *py_image_write(PyObject *self, PyObject *args)
{
    PyObject *cap;
    const char *path;
    raystream_status st;
    (void)self;
    if (!PyArg_ParseTuple(args, "Os", &cap, &path) || !image_of(cap))
        return NULL;
    Py_BEGIN_ALLOW_THREADS st = raystream_image_write(image_of(cap), path);
    Py_END_ALLOW_THREADS return done(st);
}

static PyObject *py_image_read(PyObject *self, PyObject *args)
{
    const char *path;
    raystream_image *img = NULL;
    raystream_status st;
    (void)self;
    if (!PyArg_ParseTuple(args, "s", &path))
        return NULL;
    Py_BEGIN_ALLOW_THREADS st = raystream_image_read(path, &img);
    Py_END_ALLOW_THREADS if (st != RAYSTREAM_OK) return raise_status(st);
    return image_tuple(img, 0);
}

static PyMethodDef k_methods[] = {
    {"version", py_version, METH_NOARGS, "(number, text) of the library"},
    {"scene_load", py_scene_load, METH_VARARGS, "scene_load(name) -> capsule"},
    {"scene_from_json", py_scene_from_json, METH_VARARGS, "scene_from_json(text, base_dir)"},
    {"scene_create", py_scene_create, METH_NOARGS, "scene_create() -> capsule"},
    {"scene_add_material", py_scene_add_material, METH_VARARGS, "-> material id"},
    {"scene_add_mesh", py_scene_add_mesh, METH_VARARGS, "(cap, pos, idx, nrm, uv, material)"},
    {"scene_add_light", py_scene_add_light, METH_VARARGS, "(cap, json)"},
    {"scene_add_instance", py_scene_add_instance, METH_VARARGS, "(cap, prototype, 12 numbers)"},
    {"scene_add_sphere", py_scene_add_sphere, METH_VARARGS, "(cap, center, radius, material)"},
    {"scene_add_quad", py_scene_add_quad, METH_VARARGS, "(cap, q, u, v, material)"},
    {"scene_set_camera", py_scene_set_camera, METH_VARARGS, "(cap, from, at, up, vfov, ap, fd)"},
    {"scene_set_background", py_scene_set_background, METH_VARARGS, "(cap, rgb)"},
    {"scene_set_image_size", py_scene_set_image_size, METH_VARARGS, "(cap, w, h)"},
    {"scene_counts", py_scene_counts, METH_VARARGS, "-> (spheres, quads, triangles, materials)"},
    {"render", py_render, METH_VARARGS, "render(scene, options, progress) -> image tuple"},
    {"image_write", py_image_write, METH_VARARGS, "image_write(cap, path)"},
    {"image_read", py_image_read, METH_VARARGS, "image_read(path) -> image tuple"},
    {NULL, NULL, 0, NULL}};

static struct PyModuleDef k_module = {PyModuleDef_HEAD_INIT,
                                      "_raystream",
                                      "raystream's C part (use the package raystream)",
                                      -1,
                                      k_methods,
                                      NULL,
                                      NULL,
                                      NULL,
                                      NULL};

/* Whether the running Python is 3.11 or later (the buffer slots of the limited API). */
static int python_3_11(void)
{
    int major = 0, minor = 0;
    return sscanf(Py_GetVersion(), "%d.%d", &major, &minor) == 2 &&
           (major > 3 || (major == 3 && minor >= 11));
}

PyMODINIT_FUNC PyInit__raystream(void)
{
    PyObject *m = PyModule_Create(&k_module), *pixels;
    if (!m)
        return NULL;
    if (!(pixels = rs_pixels_type(python_3_11())) || PyModule_AddObject(m, "Pixels", pixels) != 0) {
        Py_XDECREF(pixels);
        Py_DECREF(m);
        return NULL;
    }
    if (PyModule_AddIntConstant(m, "PIXELS_HAVE_BUFFER", python_3_11()) != 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
