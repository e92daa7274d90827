/* The camera as JSON and its bounds (vf/camera.h): the one reader and writer of intrinsics. */
#include <math.h>

#include "vf/camera.h"
#include "vf/json.h"

vf_status vf_camera_check(const vf_camera *c)
{
    const double M = VF_CAMERA_MAX_PIXELS, D = VF_CAMERA_MAX_DISTORTION;
    if (!(c->width >= 1 && c->height >= 1 && c->width <= VF_CAMERA_MAX_SIDE &&
          c->height <= VF_CAMERA_MAX_SIDE))
        return vf_fail(VF_EINPUT, "the camera's \"w\" and \"h\" must be whole numbers of pixels "
                                  "from 1 to %d, not %dx%d",
                       VF_CAMERA_MAX_SIDE, c->width, c->height);
    const struct {
        const char *key;
        double value, limit; /* |value| < limit; focal lengths above 0 too */
    } checks[] = {{"fl_x", c->fx, M}, {"fl_y", c->fy, M}, {"cx", c->cx, M}, {"cy", c->cy, M},
                  {"k1", c->k1, D},   {"k2", c->k2, D},   {"p1", c->p1, D}, {"p2", c->p2, D}};
    for (size_t i = 0; i < sizeof checks / sizeof checks[0]; i++)
        if (!(fabs(checks[i].value) < checks[i].limit) || (i < 2 && !(checks[i].value > 0)))
            return vf_fail(VF_EINPUT, "the camera's \"%s\" is out of range (%s %g): %g",
                           checks[i].key, i < 2 ? "above 0, below" : "within +-", checks[i].limit,
                           checks[i].value);
    return VF_OK;
}

json_t *vf_camera_json(const vf_camera *c)
{
    return json_pack("{s:o, s:o, s:o, s:o, s:i, s:i, s:o, s:o, s:o, s:o}", "fl_x",
                     vf_json_number(c->fx), "fl_y", vf_json_number(c->fy), "cx",
                     vf_json_number(c->cx), "cy", vf_json_number(c->cy), "w", c->width, "h",
                     c->height, "k1", vf_json_number(c->k1), "k2", vf_json_number(c->k2), "p1",
                     vf_json_number(c->p1), "p2", vf_json_number(c->p2));
}

vf_status vf_camera_from_json(const json_t *obj, const char *where, vf_camera *cam)
{
    static const struct {
        const char *key, *alt;
        int whole, required;
    } keys[10] = {
        {"fl_x", "fx", 0, 1}, {"fl_y", "fy", 0, 1}, {"cx", NULL, 0, 1}, {"cy", NULL, 0, 1},
        {"w", "width", 1, 1}, {"h", "height", 1, 1}, {"k1", NULL, 0, 0}, {"k2", NULL, 0, 0},
        {"p1", NULL, 0, 0},   {"p2", NULL, 0, 0},
    };
    if (!json_is_object(obj))
        return vf_fail(VF_EINPUT, "%s is not a camera (a JSON object with fl_x, fl_y, cx, cy, w, "
                                  "h)",
                       where);
    double v[10];
    for (int i = 0; i < 10; i++) {
        const json_t *x = json_object_get(obj, keys[i].key);
        if (!x && keys[i].alt)
            x = json_object_get(obj, keys[i].alt);
        if (!x && keys[i].required)
            return vf_fail(VF_EINPUT, "%s: \"%s\" is missing (need fl_x, fl_y, cx, cy, w and h, "
                                      "in pixels)",
                           where, keys[i].key);
        v[i] = x ? (json_is_number(x) ? json_number_value(x) : NAN) : 0;
        /* a size is compared as a double before any cast: 1e300 must not reach an int */
        if (!isfinite(v[i]) || (keys[i].whole && (v[i] != floor(v[i]) || fabs(v[i]) > 1e9)))
            return vf_fail(VF_EINPUT, "%s: \"%s\" must be a %s", where, keys[i].key,
                           keys[i].whole ? "whole number of pixels" : "number");
    }
    vf_camera c = {.width = (int)v[4], .height = (int)v[5], .fx = v[0], .fy = v[1], .cx = v[2],
                   .cy = v[3], .k1 = v[6], .k2 = v[7], .p1 = v[8], .p2 = v[9]};
    vf_status status = vf_camera_check(&c);
    if (status != VF_OK) {
        vf_error_prefix("%s", where);
        return status;
    }
    *cam = c;
    return VF_OK;
}
