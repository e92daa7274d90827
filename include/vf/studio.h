/* vf/studio.h: a simulated studio, a person with a phone around a 3D model.
 *
 * The physical loop (export, reshoot, score) needs a camera that moves and the truth of where
 * it was. The studio films a textured 3D model (vf/object3d.h) standing on a textured floor in
 * a room (Blender, Cycles) the way a person films an object with a phone, and writes what a
 * phone writes: an H.264 video, portrait, stored sideways with a rotation flag. Beside it,
 * VIDEO.truth.json holds the true camera of every frame. Nothing after the studio reads the
 * truth: ingest, poses, train, attack, export, reshoot and score see only the video.
 *
 * What makes it a phone video and not a turntable (all seeded, sums of sines of random phase):
 *   - the walk: one loop around the object a height, the heights joined by a smooth rise,
 *     uneven pace, the distance breathing by a few per cent, the aim wandering around the
 *     object's centre;
 *   - the hand: position shake (~1% of the distance) and rotation tremor (~0.3 deg, up to
 *     9 Hz), a slight roll;
 *   - the camera: Cycles motion blur over the shutter (1/60 s at 30 fps), auto-exposure that
 *     drifts (+-10%), sensor noise (shot and read noise on linear light), few samples a pixel
 *     (Cycles' own noise adds to it), then the phone's denoising (non-local means: a phone's
 *     frames are smooth, not grainy), H.264 at CRF 20 through FFmpeg.
 *
 * The truth file: {"kind": "vfcapture studio truth", "model", "transform" {"center",
 * "scale"} (the model's fit into the unit sphere, as vf_object3d_ingest records it),
 * "camera" {"width", "height", "fx", "fy", "cx", "cy"} (the upright frames), "fps",
 * "frames": [{"index", "time", "c2w"}] (16 numbers row-major, OpenGL axes, the model's
 * object frame of vf/object3d.h: z up, object in the unit sphere)}; a re-shoot adds "target",
 * "alignment" (the similarity from the model's frame to the workspace's) and per frame
 * "c2w_workspace" and "viewpoint" (where the frame truly is in the workspace's terms).
 *
 * Work files (the rendered frames, Blender's log) are in VIDEO.studio/ and are removed when
 * the video is written; an interrupted simulation continues from the frames already there. */
#ifndef VF_STUDIO_H
#define VF_STUDIO_H

#include <jansson.h>
#include <stdint.h>

#include "vf/error.h"
#include "vf/object3d.h"
#include "vf/pose.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The phone and the way it is held, shared by both simulations. */
typedef struct vf_studio_phone {
    int width, height;     /* upright frame (default 360 x 640, portrait; a phone's 1080 x
                              1920 costs 9x the render time) */
    double fov_y;          /* vertical field of view, degrees (default 65: a phone's main
                              camera held upright) */
    double fps;            /* frames a second (default 30) */
    double shutter;        /* open share of the frame interval (default 0.5) */
    int samples;           /* Cycles samples a pixel (default 8; its noise is part of the
                              sensor's) */
    double shake;          /* scale of hand shake and tremor (default 1; 0: a tripod) */
    double noise;          /* scale of sensor noise and exposure drift (default 1; 0: none) */
    double denoise;        /* the phone's image processor removes grain before encoding:
                              vf_rgb8_denoise's strength (default 6; 0: raw frames) */
    uint64_t seed;         /* every random choice (default 0) */
} vf_studio_phone;

typedef struct vf_studio_capture_options {
    vf_studio_phone phone;
    int loops;             /* loops around the object, one a height (default 2) */
    double loop_seconds;   /* time a loop takes (default 8) */
    double elevation_low;  /* degrees above the object's centre, first loop (default 12) */
    double elevation_high; /* last loop (default 35) */
    double distance;       /* camera distance, object radii (default 3.2: the object fills
                              about two thirds of the portrait frame's width) */
} vf_studio_capture_options;

void vf_studio_capture_defaults(vf_studio_capture_options *o);

/* Film the model (a .glb/.gltf/.obj/.blend file) into video (an .mp4 path) and write
 * VIDEO.truth.json. *report (may be NULL) gets {"video", "truth", "frames", "seconds",
 * "render_seconds", "width", "height"} (a new reference). Errors: those of
 * vf_object3d_render_video, FFmpeg missing or failing; the video and the truth file appear
 * only whole. */
vf_status vf_studio_capture(const char *model, const vf_studio_capture_options *o,
                            const char *video, json_t **report);

typedef struct vf_studio_reshoot_options {
    vf_studio_phone phone;        /* width/height/fov/fps 0: as the capture's truth file */
    int target;                   /* exported target (0: v*) */
    const char *truth;            /* the capture's truth file (NULL: beside the video the
                                     workspace was ingested from) */
    double walk_seconds;          /* from a natural viewpoint to the target (default 4) */
    double hold_seconds;          /* filming around the target (default 6) */
    double jitter;                /* how far around the target the person wanders, a share
                                     of each viewpoint parameter's range (default 0.03) */
    /* The closed loop (follow = 1): the person moves by the advice of `vfcapture reshoot`,
     * which reads their phone as a camera, frame by frame; walk_seconds and jitter are then
     * unused and hold_seconds is how long they film once reshoot says they are on target. */
    int follow;
    int starts;                   /* walks, from natural viewpoints of the capture (3) */
    double give_up_seconds;       /* a walk that has not held the target by then ends (40) */
    double tolerance;             /* reshoot's box, a share of each range (0.10) */
} vf_studio_reshoot_options;

/* The closed loop films at this rate unless told (every frame is rendered, localized and
 * read in turn; a person's reactions need no more). */
#define VF_STUDIO_FOLLOW_FPS 10

void vf_studio_reshoot_defaults(vf_studio_reshoot_options *o);

/* A person walks from the capture's first viewpoint to target o->target of the workspace's
 * export and films around it, into video (+ VIDEO.truth.json). The workspace frame is
 * related to the model's by a similarity fitted between the capture's true camera centres
 * and the poses stage's (the person reads the target as the tool gives it, relative to the
 * object). *report (may be NULL) gets {"video", "truth", "frames", "alignment" {"frames",
 * "rotation_median_deg", "position_median"}} (a new reference). */
vf_status vf_studio_reshoot(vf_workspace *ws, const char *model,
                            const vf_studio_reshoot_options *o, const char *video,
                            json_t **report);

/* With o->follow, the closed loop instead: o->starts walks, each from the capture's viewpoint
 * at an evenly spread moment, the phone rendered live (vf_object3d_live) and read by
 * vf_reshoot_run as a camera (vf_frame_source); the person reads its advice (the words, as
 * the screen shows them) and moves by them after a reaction time, at a person's speeds. The
 * video holds every walk's frames; its truth adds per frame "walk", "advice", "on_target" and
 * "wrong_way" (the advice asked to orbit, raise or step opposite to what the truth needs), and
 * "walks": [{"walk", "from", "from_box_distance", "frames", "localized", "reached" (reshoot
 * said ON TARGET for the hold and most of those frames truly were in the box),
 * "seconds_to_on_target" (reshoot's word), "seconds_to_truly_in_box", "on_target_frames",
 * "on_target_truly_in_box", "final_box_distance", "wrong_way_frames",
 * "wrong_way_longest_seconds"}]; *report gets {"video", "truth", "frames", "seconds", "walks",
 * "reached", "alignment"}. WS/reshoot_tNN holds the last walk's frames on target. Not
 * resumable: an interrupted closed loop starts over. */

/* How a re-shoot fared, against its truth: WS/score/score.json (of `vfcapture score WS VIDEO`)
 * frame by frame beside VIDEO.truth.json. *report gets {"frames", "localized",
 * "rotation_median_deg", "position_median" (localization against the true pose, a share of
 * the camera distance 4), "tolerance", "truly_in_box", "kept"; of the localized frames,
 * "agree" (score kept it exactly when its true pose is in the box) and "at_box_edge" (true
 * box distance within "edge_band" of the tolerance: localization noise decides those; the
 * band is the 90th percentile of how far localization moved the frames' box distances, at
 * least a tenth of the tolerance), "agreement" (agree / localized frames off the edge),
 * "physical" (score's kept frames: frames, misclassified, asr, interval95), "natural", and
 * "real" (the object's own natural_accuracy, asr_v_star, asr_samples from WS/real/real.json,
 * or null before `vfcapture real`)} (a new reference). */
vf_status vf_studio_check(vf_workspace *ws, const char *video, json_t **report);

/* The object a workspace was filmed around, when the studio filmed it (ingested from a video
 * beside its truth file): the model (in the room, or on white when the field was trained in
 * object mode, as the attack and score see it; VF_STUDIO_REAL_SAMPLES a pixel) and the
 * similarity from the workspace's frame to the model's, fitted on the truth's camera centres
 * against the poses stage's. For `vfcapture real` (vf_real_options.object). *filmed = 0 (and
 * VF_OK) when the workspace is not the studio's. */
#define VF_STUDIO_REAL_SAMPLES 32
vf_status vf_studio_object(const vf_workspace *ws, vf_object3d *obj, vf_similarity *to_object,
                           int *filmed);

/* The truth file of a video: VIDEO with its extension replaced by ".truth.json". */
vf_status vf_studio_truth_path(const char *video, char *out, size_t size);

#ifdef __cplusplus
}
#endif
#endif
