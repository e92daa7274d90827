/* JSON files and the number arrays every workspace file is made of (vf/json.h). */
#include "vf/json.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vf/fsutil.h"

vf_status vf_json_save(const char *path, const json_t *doc)
{
    char *text = json_dumps(doc, JSON_INDENT(2) | JSON_PRESERVE_ORDER | JSON_REAL_PRECISION(17));
    if (!text)
        return vf_fail(VF_EINTERNAL, "cannot encode JSON for %s", path);
    size_t len = strlen(text);
    text[len] = '\n'; /* replace the terminator: files end with a newline */
    vf_status status = vf_write_file_atomic(path, text, len + 1);
    free(text);
    return status;
}

vf_status vf_json_load(const char *path, json_t **out)
{
    if (!vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s does not exist", path);
    json_error_t err;
    *out = json_load_file(path, 0, &err);
    if (!*out)
        return vf_fail(VF_EINPUT, "%s is not valid JSON (line %d: %s)", path, err.line, err.text);
    return VF_OK;
}

json_t *vf_json_number(double x) { return isfinite(x) ? json_real(x) : json_null(); }

json_t *vf_json_doubles(const double *x, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, vf_json_number(x[i]));
    return a;
}

json_t *vf_json_mat4(const double m[16])
{
    json_t *rows = json_array();
    for (int r = 0; r < 4; r++)
        json_array_append_new(rows, vf_json_doubles(m + 4 * r, 4));
    return rows;
}

int vf_json_read_doubles(const json_t *array, double *out, int n)
{
    if (!json_is_array(array) || json_array_size(array) != (size_t)n)
        return 0;
    for (int i = 0; i < n; i++) {
        const json_t *x = json_array_get(array, (size_t)i);
        if (!json_is_number(x) || !isfinite(json_number_value(x)))
            return 0;
        out[i] = json_number_value(x);
    }
    return 1;
}
