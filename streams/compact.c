/* streams/compact.c — rs_stream_pack_runs (stream.h): the survivors of a stage, written packed at
 * the start of each range the stage split the stream into, moved down into one packed stream.
 * The ranges are in slot order and each holds its survivors in slot order, so the result is the
 * valid entries in slot order whatever the split (any thread count, any strategy). */
#include <string.h>

#include "streams/stream.h"

uint32_t rs_stream_pack_runs(rs_ray_soa *s, const rs_stream_runs *runs, int which, uint32_t count)
{
    uint32_t b, o = 0;
    for (b = 0; b < count; b = runs->end[b]) {
        uint32_t k = which == 0 ? runs->first[b] : runs->second[b];
        if (k && o != b) {
            /* o < b: the run moves down; memmove, since a long run overlaps its new place */
#define MOVE_FIELD(type, name) memmove(s->name + o, s->name + b, (size_t)k * sizeof(type));
            RS_RAY_FIELDS(MOVE_FIELD)
#undef MOVE_FIELD
        }
        o += k;
    }
    s->count = o;
    return o;
}
