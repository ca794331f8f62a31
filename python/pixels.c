/* python/pixels.c — raystream's image memory as a Python object with the buffer protocol:
 * `_raystream.Pixels(data, height, width, channels)` over a bytearray of float32s, which
 * memoryview() and numpy.asarray() read as a height x width [x channels] float32 array without
 * a copy (format "f", C order).  The base of raystream.Image and of its layers.
 *
 * The buffer slots entered CPython's limited API in 3.11; the rest of the module is built on
 * 3.9's.  So this file alone is compiled against 3.11's limited API, and the slot is given to
 * the type only where the running Python is 3.11 or later (the module's init checks); on 3.9 and
 * 3.10 the type has no buffer and raystream.Image falls back to the array interface
 * (python/raystream/__init__.py), also without a copy.  PyBuffer_FillInfo, the one function of
 * 3.11's API used here, is exported by every CPython 3. */
#define PY_SSIZE_T_CLEAN
#define Py_LIMITED_API 0x030B0000
#include <Python.h>

#include "pixels.h"

typedef struct pixels {
    PyObject_HEAD PyObject *data; /* a bytearray, never resized */
    Py_ssize_t shape[3];
    Py_ssize_t strides[3];
    int ndim;
} pixels;

static int pixels_init(PyObject *self, PyObject *args, PyObject *kw)
{
    pixels *p = (pixels *)self;
    PyObject *data, *old;
    Py_ssize_t h, w, c;
    (void)kw;
    if (!PyArg_ParseTuple(args, "Onnn", &data, &h, &w, &c))
        return -1;
    if (!PyByteArray_Check(data) || h < 1 || w < 1 || c < 1 ||
        PyByteArray_Size(data) != h * w * c * (Py_ssize_t)sizeof(float)) {
        PyErr_SetString(PyExc_ValueError,
                        "Pixels: a bytearray of height * width * channels floats");
        return -1;
    }
    Py_INCREF(data);
    old = p->data;
    p->data = data;
    Py_XDECREF(old);
    p->ndim = c > 1 ? 3 : 2;
    p->shape[0] = h;
    p->shape[1] = w;
    p->shape[2] = c;
    p->strides[2] = (Py_ssize_t)sizeof(float);
    p->strides[1] = c * (Py_ssize_t)sizeof(float);
    p->strides[0] = w * p->strides[1];
    if (p->ndim == 2)
        p->strides[1] = p->strides[2];
    return 0;
}

static int pixels_getbuffer(PyObject *self, Py_buffer *view, int flags)
{
    pixels *p = (pixels *)self;
    if (!p->data) {
        PyErr_SetString(PyExc_BufferError, "Pixels: not initialised");
        return -1;
    }
    if (PyBuffer_FillInfo(view, self, PyByteArray_AsString(p->data), PyByteArray_Size(p->data), 0,
                          flags) != 0)
        return -1;
    view->itemsize = (Py_ssize_t)sizeof(float);
    view->format = (flags & PyBUF_FORMAT) ? (char *)"f" : NULL;
    if (flags & PyBUF_ND) { /* else one run of bytes, as PyBuffer_FillInfo made it */
        view->ndim = p->ndim;
        view->shape = p->shape;
        view->strides = (flags & PyBUF_STRIDES) == PyBUF_STRIDES ? p->strides : NULL;
    }
    return 0;
}

static void pixels_dealloc(PyObject *self)
{
    PyTypeObject *type = Py_TYPE(self);
    pixels *p = (pixels *)self;
    Py_CLEAR(p->data);
    ((freefunc)PyType_GetSlot(type, Py_tp_free))(self);
    Py_DECREF(type);
}

PyObject *rs_pixels_type(int with_buffer)
{
    PyType_Slot slots[] = {
        {Py_tp_init, (void *)pixels_init},
        {Py_tp_dealloc, (void *)pixels_dealloc},
        {Py_tp_doc, (void *)"float32 pixels over a bytearray, with the buffer protocol"},
        {Py_bf_getbuffer, (void *)pixels_getbuffer},
        {0, NULL}};
    PyType_Spec spec = {"_raystream.Pixels", (int)sizeof(pixels), 0,
                        Py_TPFLAGS_DEFAULT | Py_TPFLAGS_BASETYPE, slots};
    if (!with_buffer) /* the list ends before the buffer's slot */
        slots[3].slot = 0, slots[3].pfunc = NULL;
    return PyType_FromSpec(&spec);
}
