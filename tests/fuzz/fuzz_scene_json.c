/* tests/fuzz/fuzz_scene_json.c — libFuzzer harness for the JSON scene reader.
 *
 * The bytes are a scene file, read by rs_scene_parse_json (what rs_scene_load_json, and so
 * `raystream render FILE.json`, calls once the file is read), with relative texture names
 * resolved in an empty folder of its own.  Any input must either give a finalized scene or be
 * refused with one line naming the file (scene_json.h); never a crash, a hang, a leak or a
 * sanitizer report.  Built with -DRS_FUZZ=ON (scripts/fuzz.sh). */
#include <stddef.h>
#include <stdint.h>

#include "fuzz_util.h"
#include "scenes/scene_json.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rs_scene *s = NULL;
    rs_status st;
    rs_error_clear();
    st = rs_scene_parse_json((const char *)data, size, "fuzz.json", fz_tmpdir(), &s);
    fz_check_refusal(st, "fuzz.json");
    if ((st == RS_OK) != (s != NULL))
        fz_broken("rs_scene_parse_json returned %s with scene %p", rs_status_name(st), (void *)s);
    rs_scene_destroy(s);
    rs_error_clear();
    return 0;
}
