/* Writing a calibration as the camera file `poses --camera` reads (vf/calib.h). */
#include "vf/calib.h"

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
