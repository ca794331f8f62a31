/* scheduler/device.c — thin wrappers over the device function table. */
#include "scheduler/device.h"

rs_status rs_device_upload(rs_device *d, const rs_geom *g, const rs_bvh *bvh)
{
    /* the instances' bottom levels travel with the geometry (core/geom.h) */
    rs_geom a = *g;
    rs_bvh_attach(bvh, &a);
    return d->ops->upload(d, &a, bvh);
}

void rs_device_destroy(rs_device *d)
{
    if (d)
        d->ops->destroy(d);
}

int rs_device_owns_memory(const rs_device *d) { return (d->flags & RS_DEVICE_OWN_MEMORY) != 0; }
