/* vf/ingest.h: from a capture to the frames later stages work on.
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
 * "camera", "transforms", or "" when the report does not say (frames put there by hand).
 * Frames of a video or a webcam are in capture order; photos and unknown frames are not. */
void vf_ingest_source_kind(const char *ws_root, char *kind, size_t size);

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

#ifdef __cplusplus
}
#endif
#endif
