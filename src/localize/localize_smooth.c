/* Exponential smoothing of a stream of camera poses (vf/localize.h), so that live guidance
 * does not jitter with every frame's localization noise. */
#include <math.h>
#include <string.h>

#include "vf/localize.h"

void vf_pose_smoother_init(vf_pose_smoother *s, double alpha)
{
    *s = (vf_pose_smoother){.alpha = alpha > 0 && alpha <= 1 ? alpha : 0.4, .reset_deg = 30,
                            .reset_distance = 1};
}

void vf_pose_smoother_add(vf_pose_smoother *s, const double c2w[16], double out[16])
{
    double R_old[9], R_new[9], p_old[3], p_new[3];
    vf_mat4_rotation(s->c2w, R_old);
    vf_mat4_rotation(c2w, R_new);
    vf_mat4_translation(s->c2w, p_old);
    vf_mat4_translation(c2w, p_new);
    double jump = sqrt((p_new[0] - p_old[0]) * (p_new[0] - p_old[0]) +
                       (p_new[1] - p_old[1]) * (p_new[1] - p_old[1]) +
                       (p_new[2] - p_old[2]) * (p_new[2] - p_old[2]));
    if (!s->has_pose || jump > s->reset_distance || vf_rot_angle_deg(R_old, R_new) > s->reset_deg) {
        memcpy(s->c2w, c2w, sizeof s->c2w);
        s->has_pose = 1;
        memcpy(out, s->c2w, sizeof s->c2w);
        return;
    }
    /* R = R_old * exp(alpha * log(R_old^T R_new)) */
    double R_old_t[9], delta[9], aa[3], step[9], R[9], p[3];
    vf_mat3_transpose(R_old, R_old_t);
    vf_mat3_mul(R_old_t, R_new, delta);
    vf_rot_to_axis_angle(delta, aa);
    for (int k = 0; k < 3; k++) {
        aa[k] *= s->alpha;
        p[k] = (1 - s->alpha) * p_old[k] + s->alpha * p_new[k];
    }
    vf_rot_from_axis_angle(aa, step);
    vf_mat3_mul(R_old, step, R);
    vf_mat4_from_rt(R, p, s->c2w);
    memcpy(out, s->c2w, sizeof s->c2w);
}
