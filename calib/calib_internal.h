/* calib/calib_internal.h: helpers shared inside calib/ (not part of the public API). */
#ifndef VF_CALIB_INTERNAL_H
#define VF_CALIB_INTERNAL_H

#include "vf/calib.h"
#include "vf/dataset.h"

/* Board corner positions on its plane: 2 * cols * rows doubles, row by row, square apart. */
double *vf__calib_board_points(const vf_calib_board *board);

/* Choose at most max of the views, spread over position, size and tilt of the board in the
 * frame (greedy farthest-point). chosen gets their indices; returns how many. */
int vf__calib_select_views(const vf_calib_views *set, int max, int *chosen);

/* RMS reprojection error of one view: board points through pose (rotation vector,
 * translation) and cam, against uv. */
double vf__calib_view_rms(const vf_camera *cam, const double pose[6], const double *object_xy,
                          const double *uv, int corners);

/* The posed frames of a workspace: WS/poses/transforms.json, else a posed import's
 * WS/ingest/transforms.json. VF_EINPUT saying what to run when neither exists. */
vf_status vf__calib_load_posed_frames(const vf_workspace *ws, vf_dataset *out);

/* The ray through pixel (u, v) of a posed frame, in the frame's world (object frame). */
void vf__calib_frame_ray(const vf_frame *frame, double u, double v, double origin[3],
                         double dir[3]);

#endif
