/* The camera file: written by calibration, read by `poses --camera`, `localize`, `reshoot` and
 * `score --camera` (vf/calib.h). */
#include "vf/calib.h"

#include <math.h>

#include "vf/json.h"
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
            json_array_append_new(per_view,
                                  json_pack("{s:s, s:s, s:o}", "frame", v->name, "state",
                                            state_name(v->state), "rms", vf_json_number(v->rms)));
    }
    json_t *doc = json_pack("{s:s}", "camera_model", "OPENCV");
    json_object_update_new(doc, vf_camera_json(c));
    json_object_update_new(
        doc, json_pack("{s:o, s:o, s:i, s:i, s:i, s:i, s:{s:i, s:i, s:o}, s:o}", "rms",
                       vf_json_number(res->rms), "rms_opencv", vf_json_number(res->rms_opencv),
                       "views", res->used, "outlier_views", res->outliers, "boards_found",
                       set->count, "frames_searched", set->frames_seen, "board", "cols",
                       board->cols, "rows", board->rows, "square_m", vf_json_number(board->square),
                       "per_view", per_view));
    if (doc && board->marker > 0)
        json_object_set_new(json_object_get(doc, "board"), "charuco_marker_m",
                            vf_json_number(board->marker));
    if (!doc)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_status status = vf_json_save(path, doc);
    json_decref(doc);
    return status;
}

vf_status vf_calib_load_camera(const char *path, vf_camera *cam)
{
    json_t *doc = NULL;
    vf_status s = vf_json_load(path, &doc);
    if (s == VF_OK)
        s = vf_camera_from_json(doc, path, cam);
    json_decref(doc);
    return s;
}
