/* vf/ingest.h: from a capture to the frames later stages work on; the ingest stage.
 *
 * The stage (vf_ingest_run) takes one input into WS/ingest/ through a staging folder: a
 * capture (below), a posed set (a NeRF transforms.json: every image decoded once to check
 * it, copied into WS/ingest/images/ and listed with its camera in WS/ingest/transforms.json,
 * so later stages never depend on the original folder) or a 3D model (rendered by Blender
 * into a posed set, the paper's capture, vf/object3d.h). A workspace the stage created is
 * removed again when it fails; an existing one keeps its earlier output. A model's renders
 * that stop half-way (interrupted, not refused) stay in the staging folder for the next run.
 *
 * Three sources, one result. A video file, a folder of photos or a V4L2 webcam is read, every
 * frame is scored for sharpness, the frames to keep are chosen (vf/frame_select.h), shrunk to
 * at most max_size pixels on the longer side, and written as JPEG (quality 95) into
 * OUT/images/. OUT/report.json records the source, its frame rate, frame count and size, the
 * rotation applied, the chosen frames, every frame's sharpness and each rejected frame with
 * its reason. No poses are written: the poses stage reads OUT/images and the report.
 *
 * OUT is normally a workspace's staging folder (vf/workspace.h), so a failure leaves nothing
 * behind; these functions write only inside it. The report returned through *report (when not
 * NULL) is a new reference the caller releases with json_decref. */
#ifndef VF_INGEST_H
#define VF_INGEST_H

#include <jansson.h>
#include <stdint.h>

#include "vf/error.h"
#include "vf/frame_select.h"
#include "vf/object3d.h"
#include "vf/v4l2.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_ingest_options {
    vf_select_params select;   /* how many frames to keep, blur and duplicate rules */
    int max_size;              /* longer side of the written frames (default 1024) */
    /* Photos only: a photo is blurry below this times the median sharpness of all the photos
     * (default 0.2: only the truly unusable; a person expects the photos they took used, and
     * a folder has no capture order, so there are no neighbours to compare with). */
    double photo_blur_ratio;
    /* Webcam only: */
    double seconds;            /* how long to capture (default 10) */
    int width, height;         /* requested frame size (default 1280 x 720; the driver may
                                  answer with the nearest it has) */
    uint32_t pixel_format;     /* V4L2_PIX_FMT_MJPEG or _YUYV preferred; 0: MJPEG, then YUYV */
    long frame_limit;          /* stop after this many frames as well (0: no limit) */
    const vf_v4l2_ops *ops;    /* device access; NULL: the system calls */
} vf_ingest_options;

/* The defaults above. */
void vf_ingest_defaults(vf_ingest_options *options);

/* What a workspace's frames came from, as its ingest report says: "video", "photos",
 * "camera", or "" when there is no report (a posed set, a 3D model, frames put there by hand).
 * Frames of a video or a webcam are in capture order; photos and unknown frames are not. */
void vf_ingest_source_kind(const char *ws_root, char *kind, size_t size);
/* The file or folder the frames came from (absolute), or "" as above. */
void vf_ingest_source_path(const char *ws_root, char *path, size_t size);

/* A video file FFmpeg decodes (two passes: score every frame, then decode again and write the
 * chosen ones). Errors name the file: not a video, no frames, no usable frame. */
vf_status vf_ingest_video(const char *path, const vf_ingest_options *options, const char *out_dir,
                          json_t **report);

/* A folder of photos (.jpg, .jpeg, .png, in name order; alpha composited onto white). All are
 * kept unless blurry (photo_blur_ratio) or duplicates (at most select.max_frames, spread over
 * the set); the report names each dropped photo with its reason and counts portrait and
 * landscape photos. */
vf_status vf_ingest_photos(const char *folder, const vf_ingest_options *options,
                           const char *out_dir, json_t **report);

/* Capture from a V4L2 device for options->seconds, showing how many usable frames it has so
 * far, then choose among them. */
vf_status vf_ingest_camera(const char *device, const vf_ingest_options *options,
                           const char *out_dir, json_t **report);

/* ---- the stage ---- */

typedef enum {
    VF_INGEST_VIDEO = 0,
    VF_INGEST_PHOTOS = 1,
    VF_INGEST_CAMERA = 2,     /* a V4L2 device */
    VF_INGEST_TRANSFORMS = 3, /* a posed set */
    VF_INGEST_MODEL = 4       /* a 3D model (vf_object3d_is_model) */
} vf_ingest_kind;

/* "video", "photos", "camera", "transforms", "model". */
const char *vf_ingest_kind_name(vf_ingest_kind kind);

/* What an input path is: a folder is photos, a .json file a posed set, a model file a 3D
 * model, any other file a video. VF_EINPUT when the path does not exist. */
vf_status vf_ingest_input_kind(const char *path, vf_ingest_kind *kind);

/* An input by content, so a workspace knows when it was made from another one (a path
 * says nothing: the same name may hold a new video): *identity (a new reference) gets
 * {"bytes", "files", "mtime", "hash"}, the hash over the file's bytes, or over a folder's
 * files (names and bytes, in name order). A posed set is its transforms file alone. The
 * ingest stage records it in its params as "input_identity"; run compares by it. */
vf_status vf_ingest_input_identity(const char *path, json_t **identity);

typedef struct vf_ingest_request {
    vf_ingest_kind kind;
    const char *input;         /* the file, folder or device */
    vf_ingest_options capture; /* video, photos, camera */
    vf_object3d_capture model; /* a 3D model */
} vf_ingest_request;

/* Zero input, the defaults of both option sets. */
void vf_ingest_request_defaults(vf_ingest_request *r);

/* Run the stage into the workspace at ws_root (created when missing). *summary gets the
 * manifest's summary of the stage (a new reference): frames, size, and per kind what was
 * kept and why (captures), the background (posed sets), or views and seconds (models). */
vf_status vf_ingest_run(const char *ws_root, const vf_ingest_request *r, json_t **summary);

#ifdef __cplusplus
}
#endif
#endif
