/* vf/reshoot.h: the reshoot stage, guided capture at an exported target.
 *
 * Frames come from a webcam, a video file or the caller's own camera (vf/frames.h). Each is
 * localized (vf/localize.h); the pose is smoothed over time (vf_pose_smoother) so the advice
 * does not jitter, compared with the target, and turned into advice ("orbit 12 deg right,
 * raise 5 cm", vf/targets.h).
 * Frames whose raw and smoothed viewpoints both lie within the tolerance box of the target
 * are saved with their poses to WS/reshoot_tNN/frames/ (PNG, lossless) and poses.json
 * {"target", "target_viewpoint", "tolerance_percent", "frames": [{"file", "source",
 * "viewpoint", "c2w_object", "inliers", "reprojection_px", "box_distance"}], "stopped_early"},
 * ready for `vfcapture score`. Where a display exists the advice is also drawn over the
 * frames in a live window (vf/overlay.h; q or Esc stops).
 *
 * A capture that stops early (a webcam unplugged, a frame of another size) keeps the frames
 * already on target: they are committed with "stopped_early", and the error is returned
 * after, naming the folder that holds them. */
#ifndef VF_RESHOOT_H
#define VF_RESHOOT_H

#include <jansson.h>

#include "vf/error.h"
#include "vf/frames.h"
#include "vf/localize.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_reshoot_options {
    int target;         /* exported target, 0 is v* (required: -1 is refused) */
    const char *device; /* a V4L2 webcam, or NULL */
    const char *video;  /* or a video file */
    const vf_frame_source *camera; /* or a camera of the caller's own, which says when it is
                                      done (vf/frames.h; exactly one of the three) */
    double tolerance;   /* box half-width, a share of each parameter's range (0.05) */
    double smoothing;   /* weight of the newest pose, (0, 1] (0.4) */
    double seconds;     /* webcam: stop after this long (60) */
    int window;         /* show the live window where a display exists (1) */
    vf_localize_options loc;
} vf_reshoot_options;

void vf_reshoot_defaults(vf_reshoot_options *o);

/* Called for every frame: entry is {"frame", "localized", and when localized "advice",
 * "on_target", "box_distance", "viewpoint"} (borrowed), line the advice as one line of text. */
typedef void (*vf_reshoot_frame_fn)(const json_t *entry, const char *line, void *ctx);

/* Run the guided capture on an open workspace with an export. fn may be NULL. *result gets
 * poses.json's document plus "seen", "localized", "saved" (a new reference). */
vf_status vf_reshoot_run(vf_workspace *ws, const vf_reshoot_options *o, vf_reshoot_frame_fn fn,
                         void *ctx, json_t **result);

#ifdef __cplusplus
}
#endif
#endif
