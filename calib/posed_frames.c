/* A workspace's posed frames, and rays through their pixels (calib/calib_internal.h). */
#include "calib_internal.h"
#include "vf/pose.h"

vf_status vf__calib_load_posed_frames(const vf_workspace *ws, vf_dataset *out)
{
    char path[VF_PATH_MAX];
    vf_status status = vf_workspace_posed_frames(ws, path, sizeof path);
    return status == VF_OK ? vf_dataset_load(path, out) : status;
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
