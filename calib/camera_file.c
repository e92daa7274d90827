/* The camera file: written by calibration, read by `poses --camera`, `localize`, `reshoot` and
 * `score --camera` (vf/calib.h). */
#include "vf/calib.h"

#include <math.h>

#include "vf/workspace.h"

static const char *state_name(int state)
{
    return state == VF_VIEW_USED ? "used" : state == VF_VIEW_OUTLIER ? "outlier" : "spare";
}

vf_status vf_calib_save_camera(const char *path, const vf_calib_result *res,
                               const vf_calib_views *set, const vf_calib_board *board)
{
    const vf_camera *c = &res->camera;
    json_t *per_view = json_array();
    for (int i = 0; i < set->count; i++) {
        const vf_calib_view *v = &set->views[i];
        if (v->state != VF_VIEW_SPARE)
            json_array_append_new(per_view, json_pack("{s:s, s:s, s:f}", "frame", v->name,
                                                       "state", state_name(v->state),
                                                       "rms", v->rms));
    }
    json_t *doc = json_pack(
        "{s:s, s:f, s:f, s:f, s:f, s:i, s:i, s:f, s:f, s:f, s:f, s:f, s:f, s:i, s:i, s:i, s:i, "
        "s:{s:i, s:i, s:f}, s:o}",
        "camera_model", "OPENCV", "fl_x", c->fx, "fl_y", c->fy, "cx", c->cx, "cy", c->cy, "w",
        c->width, "h", c->height, "k1", c->k1, "k2", c->k2, "p1", c->p1, "p2", c->p2, "rms",
        res->rms, "rms_opencv", res->rms_opencv, "views", res->used, "outlier_views",
        res->outliers, "boards_found", set->count, "frames_searched", set->frames_seen, "board",
        "cols", board->cols, "rows", board->rows, "square_m", board->square, "per_view",
        per_view);
    if (doc && board->marker > 0)
        json_object_set_new(json_object_get(doc, "board"), "charuco_marker_m",
                            json_real(board->marker));
    if (!doc)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_status status = vf_json_save(path, doc);
    json_decref(doc);
    return status;
}

/* The number under key (or its alternative), checked against [lo, hi]; whole when asked. */
static vf_status camera_value(const json_t *doc, const char *path, const char *key,
                              const char *alt, double lo, double hi, int whole, int required,
                              double *out)
{
    const json_t *x = json_object_get(doc, key);
    if (!x && alt)
        x = json_object_get(doc, alt);
    if (!x && !required) {
        *out = 0;
        return VF_OK;
    }
    if (!x)
        return vf_fail(VF_EINPUT, "%s: \"%s\" is missing (need fl_x, fl_y, cx, cy, w and h, in "
                       "pixels)", path, key);
    double v = json_is_number(x) ? json_number_value(x) : NAN;
    if (!(v >= lo && v <= hi) || (whole && v != floor(v)))
        return vf_fail(VF_EINPUT, "%s: \"%s\" must be a %s from %g to %g", path, key,
                       whole ? "whole number" : "number", lo, hi);
    *out = v;
    return VF_OK;
}

vf_status vf_calib_load_camera(const char *path, vf_camera *cam)
{
    json_t *doc;
    vf_status s = vf_json_load(path, &doc);
    if (s != VF_OK)
        return s;
    if (!json_is_object(doc)) {
        json_decref(doc);
        return vf_fail(VF_EINPUT, "%s is not a camera file (a JSON object with fl_x, fl_y, cx, "
                       "cy, w, h)", path);
    }
    static const struct {
        const char *key, *alt;
        double lo, hi;
        int whole, required;
    } keys[10] = {
        {"fl_x", "fx", 1e-6, 1e6, 0, 1}, {"fl_y", "fy", 1e-6, 1e6, 0, 1},
        {"cx", NULL, 1e-6, 1e6, 0, 1},   {"cy", NULL, 1e-6, 1e6, 0, 1},
        {"w", "width", 1, 100000, 1, 1}, {"h", "height", 1, 100000, 1, 1},
        {"k1", NULL, -100, 100, 0, 0},   {"k2", NULL, -100, 100, 0, 0},
        {"p1", NULL, -100, 100, 0, 0},   {"p2", NULL, -100, 100, 0, 0},
    };
    double v[10];
    for (int i = 0; i < 10 && s == VF_OK; i++)
        s = camera_value(doc, path, keys[i].key, keys[i].alt, keys[i].lo, keys[i].hi,
                         keys[i].whole, keys[i].required, &v[i]);
    json_decref(doc);
    if (s == VF_OK)
        *cam = (vf_camera){.width = (int)v[4], .height = (int)v[5], .fx = v[0], .fy = v[1],
                           .cx = v[2], .cy = v[3], .k1 = v[6], .k2 = v[7], .p1 = v[8],
                           .p2 = v[9]};
    return s;
}
