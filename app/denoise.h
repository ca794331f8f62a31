/* app/denoise.h — the denoiser lives in core/ (core/denoise.h: Open Image Denoise 2.x loaded at
 * run time), where the tests and benchmarks link it too; this header is the app's name for it. */
#ifndef RS_APP_DENOISE_H
#define RS_APP_DENOISE_H

#include "core/denoise.h"

#endif
