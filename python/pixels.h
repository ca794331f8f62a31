/* python/pixels.h — the type _raystream.Pixels (pixels.c). */
#ifndef RS_PYTHON_PIXELS_H
#define RS_PYTHON_PIXELS_H

/* A new reference to the type, with the buffer protocol where `with_buffer` (Python 3.11+). */
PyObject *rs_pixels_type(int with_buffer);

#endif
