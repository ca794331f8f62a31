/* scenes/mesh_report.c — the words for what a mesh import dropped (scenes/mesh.h); built with
 * or without Assimp. */
#include <stdio.h>
#include <string.h>

#include "scenes/mesh.h"

const char *rs_mesh_dropped_text(const rs_mesh_info *info, char *buf, size_t n)
{
    static const char *const names[4] = {"index out of range", "non-finite vertex", "zero area",
                                         "not a triangle"};
    const uint32_t counts[4] = {info->dropped_index, info->dropped_nonfinite, info->dropped_area,
                                info->dropped_shape};
    size_t used;
    int k, first = 1;
    buf[0] = '\0';
    if (info->dropped == 0 || n == 0)
        return buf;
    snprintf(buf, n, "%u faces dropped (", info->dropped);
    for (k = 0; k < 4; ++k) {
        used = strlen(buf);
        if (counts[k] && used < n)
            snprintf(buf + used, n - used, "%s%u %s", first ? "" : ", ", counts[k], names[k]);
        first &= counts[k] == 0;
    }
    used = strlen(buf);
    if (used < n)
        snprintf(buf + used, n - used, ")");
    return buf;
}
