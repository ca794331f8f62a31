/* core/oidn_api.h — the part of Intel Open Image Denoise 2.x's C API (OpenImageDenoise/oidn.h)
 * that core/denoise.c calls, as function-pointer types for dlsym.  No OIDN header or library is
 * needed to build raystream: the library is loaded at run time (core/denoise.h).
 *
 * Written from OIDN's documented API (doc/api.md) and the enum values of its oidn.h, checked
 * against the symbols libOpenImageDenoise.so.2.5.1 exports.  The values are part of OIDN's ABI
 * and stable across 2.x.  OIDN 1.x names its setters oidnSetFilter1b/oidnSetDevice1i; 2.0 renamed
 * them oidnSetFilterBool/oidnSetDeviceInt, which is how core/denoise.c tells 1.x apart.
 *
 * Host only (dlopen): not for RS_HD code. */
#ifndef RS_CORE_OIDN_API_H
#define RS_CORE_OIDN_API_H

#include <stdbool.h>
#include <stddef.h>

/* OIDNDeviceType */
#define RS_OIDN_DEVICE_TYPE_DEFAULT 0 /* OIDN picks (a GPU when it finds a supported one) */
#define RS_OIDN_DEVICE_TYPE_CPU     1
#define RS_OIDN_DEVICE_TYPE_SYCL    2
#define RS_OIDN_DEVICE_TYPE_CUDA    3
#define RS_OIDN_DEVICE_TYPE_HIP     4
#define RS_OIDN_DEVICE_TYPE_METAL   5

/* OIDNError */
#define RS_OIDN_ERROR_NONE                 0
#define RS_OIDN_ERROR_UNKNOWN              1
#define RS_OIDN_ERROR_INVALID_ARGUMENT     2
#define RS_OIDN_ERROR_INVALID_OPERATION    3
#define RS_OIDN_ERROR_OUT_OF_MEMORY        4
#define RS_OIDN_ERROR_UNSUPPORTED_HARDWARE 5
#define RS_OIDN_ERROR_CANCELLED            6

/* OIDNFormat: FLOAT = 1, FLOAT2, FLOAT3, FLOAT4; HALF = 257, ... */
#define RS_OIDN_FORMAT_FLOAT3 3

/* The C enums are passed as int (OIDN's enums are plain C enums: int-sized on every ABI it
 * supports). */
typedef struct rs_oidn_device_impl *rs_oidn_device; /* OIDNDevice */
typedef struct rs_oidn_filter_impl *rs_oidn_filter; /* OIDNFilter */
typedef struct rs_oidn_buffer_impl *rs_oidn_buffer; /* OIDNBuffer */

/* OIDNErrorFunction: called on the thread that made the failing call, with OIDN's message. */
typedef void (*rs_oidn_error_fn)(void *user, int code, const char *message);

/* Device */
typedef rs_oidn_device (*rs_oidn_new_device_fn)(int type);
typedef void (*rs_oidn_commit_device_fn)(rs_oidn_device dev);
typedef void (*rs_oidn_release_device_fn)(rs_oidn_device dev);
typedef void (*rs_oidn_set_device_int_fn)(rs_oidn_device dev, const char *name, int value);
typedef int (*rs_oidn_get_device_int_fn)(rs_oidn_device dev, const char *name); /* "version" */
typedef void (*rs_oidn_set_device_error_function_fn)(rs_oidn_device dev, rs_oidn_error_fn fn,
                                                     void *user);
/* The first error not yet queried for this thread (dev may be NULL: why a device creation
 * failed), with its message when msg is not NULL; clears it. */
typedef int (*rs_oidn_get_device_error_fn)(rs_oidn_device dev, const char **msg);
typedef int (*rs_oidn_get_num_physical_devices_fn)(void); /* 2.x only */

/* Buffers (device memory, for GPU devices that cannot read host memory) */
typedef rs_oidn_buffer (*rs_oidn_new_buffer_fn)(rs_oidn_device dev, size_t bytes);
typedef void (*rs_oidn_write_buffer_fn)(rs_oidn_buffer buf, size_t offset, size_t bytes,
                                        const void *src);
typedef void (*rs_oidn_read_buffer_fn)(rs_oidn_buffer buf, size_t offset, size_t bytes, void *dst);
typedef void (*rs_oidn_release_buffer_fn)(rs_oidn_buffer buf);

/* Filter */
typedef rs_oidn_filter (*rs_oidn_new_filter_fn)(rs_oidn_device dev, const char *type); /* "RT" */
/* Strides of 0 mean packed. */
typedef void (*rs_oidn_set_filter_image_fn)(rs_oidn_filter f, const char *name, rs_oidn_buffer buf,
                                            int format, size_t width, size_t height,
                                            size_t byte_offset, size_t pixel_byte_stride,
                                            size_t row_byte_stride);
typedef void (*rs_oidn_set_shared_filter_image_fn)(rs_oidn_filter f, const char *name, void *ptr,
                                                   int format, size_t width, size_t height,
                                                   size_t byte_offset, size_t pixel_byte_stride,
                                                   size_t row_byte_stride);
typedef void (*rs_oidn_set_filter_bool_fn)(rs_oidn_filter f, const char *name, bool value);
typedef void (*rs_oidn_commit_filter_fn)(rs_oidn_filter f);
typedef void (*rs_oidn_execute_filter_fn)(rs_oidn_filter f); /* synchronous */
typedef void (*rs_oidn_release_filter_fn)(rs_oidn_filter f);

#endif
