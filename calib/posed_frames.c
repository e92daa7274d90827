/* A workspace's posed frames, and rays through their pixels (calib/calib_internal.h). */
#include "calib_internal.h"
#include "vf/pose.h"

vf_status vf__calib_load_posed_frames(const vf_workspace *ws, vf_dataset *out)
{
    char path[VF_PATH_MAX];
    const char *stage = vf_workspace_has_stage(ws, "poses") ? "poses" : "ingest";
    vf_status status = vf_workspace_path(ws, stage, "transforms.json", path, sizeof path);
    if (status != VF_OK)
        return status;
    if (!vf_workspace_has_stage(ws, stage) || !vf_is_file(path))
        return vf_fail(VF_EINPUT, "workspace %s has no posed frames: run 'vfcapture poses %s' "
                                  "first",
                       ws->root, ws->root);
    return vf_dataset_load(path, out);
}

void vf__calib_frame_ray(const vf_frame *frame, double u, double v, double origin[3],
                         double dir[3])
{
    double c2w_cv[16], rot[9], ray[3];
    vf_c2w_gl_to_cv(frame->c2w, c2w_cv);
    vf_mat4_rotation(c2w_cv, rot);
    vf_mat4_translation(c2w_cv, origin);
    vf_camera_pixel_ray(&frame->camera, u, v, ray);
    vf_mat3_apply(rot, ray, dir);
}
