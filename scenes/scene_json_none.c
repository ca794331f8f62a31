/* scenes/scene_json_none.c — scene files in a build without cJSON (RS_DEPS=OPTIONAL on a machine
 * without libcjson-dev): every call says so; the built-in scenes still work. */
#include "scenes/scene_json.h"

rs_status rs_scene_load_json(const char *path, rs_scene **out)
{
    *out = NULL;
    return rs_error_set(RS_ERR_ARG, "%s: this build has no cJSON and reads no scene files", path);
}

rs_status rs_scene_parse_json(const char *text, size_t len, const char *label, const char *base_dir,
                              rs_scene **out)
{
    (void)text, (void)len, (void)base_dir;
    *out = NULL;
    return rs_error_set(RS_ERR_ARG, "%s: this build has no cJSON and reads no scene files", label);
}

rs_status rs_scene_load_json_ex(const char *path, FILE *log, rs_scene **out)
{
    (void)log;
    return rs_scene_load_json(path, out);
}

rs_status rs_scene_parse_json_ex(const char *text, size_t len, const char *label,
                                 const char *base_dir, FILE *log, rs_scene **out)
{
    (void)log;
    return rs_scene_parse_json(text, len, label, base_dir, out);
}

rs_status rs_scene_add_material_json(rs_scene *s, const char *text, const char *label, uint32_t *id)
{
    (void)s, (void)text, (void)id;
    return rs_error_set(RS_ERR_ARG, "%s: this build has no cJSON and reads no JSON materials",
                        label);
}

rs_status rs_scene_add_light_json(rs_scene *s, const char *text, const char *label)
{
    (void)s, (void)text;
    return rs_error_set(RS_ERR_ARG, "%s: this build has no cJSON and reads no JSON lights", label);
}
