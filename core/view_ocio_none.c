/* core/view_ocio_none.c — the OpenColorIO half of core/view.h in builds without OpenImageIO
 * (RS_DEPS=OPTIONAL): no OCIO views, only the built-in ones. */
#include <stdio.h>

#include "core/view.h"

int rs_view_ocio_available(void) { return 0; }

int rs_view_ocio_find(const char *name, char *why, size_t n)
{
    (void)name;
    snprintf(why, n, "this build has no OpenImageIO, so no OpenColorIO views");
    return 0;
}

rs_status rs_view_ocio_apply(const char *name, float *rgb, size_t npix)
{
    (void)rgb;
    (void)npix;
    return rs_error_set(RS_ERR_ARG, "view '%s': this build has no OpenColorIO", name);
}
