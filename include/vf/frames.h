/* vf/frames.h: the one frame source, read by the physical loop (localize, reshoot, score),
 * calibration (calib intrinsics) and webcam ingest.
 *
 * The inputs are a list of image files, video files (anything FFmpeg decodes) and folders
 * (their images and videos, in name order), or one V4L2 webcam, or a camera of the caller's
 * own (vf_frame_source). Frames come out one at a time
 * as RGB, each with a name saying where it came from ("clip.mp4#12", "photos/0003.jpg").
 * A vf_frames is opened by vf_frames_open*(), closed by vf_frames_close(); frames handed out
 * are the caller's (vf_rgb8_free). */
#ifndef VF_FRAMES_H
#define VF_FRAMES_H

#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/rgb8.h"
#include "vf/v4l2.h"
#include "vf/video.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A camera of the caller's own (an application embedding vfcapture; the simulated studio's
 * phone): next() puts the next frame into *frame (reused) and sets *got, 0 when the camera is
 * done. */
typedef struct vf_frame_source {
    vf_status (*next)(void *ctx, vf_rgb8 *frame, int *got);
    void *ctx;
    const char *name; /* what frame names say it is ("NAME#N") */
} vf_frame_source;

typedef struct vf_frames {
    /* The caller may set this after opening, before the first vf_frames_next. */
    int max_video_frames; /* at most this many frames of each video, spread evenly over it
                             (every stride-th, those between skipped without decoding);
                             0: every frame */
    /* The rest is the source's own; callers only read it. */
    char **files;         /* image and video files, in order */
    int count, next;      /* files, and the next one to open */
    vf_video *video;      /* the video being read, or NULL */
    vf_video_info video_info; /* its size, rate and (estimated) frame count, while video is set */
    char video_path[VF_PATH_MAX];
    long video_frame;     /* index of the last frame read or skipped in it */
    long video_stride;    /* frames from one handed out to the next */
    long video_given;     /* frames of it handed out */
    vf_v4l2 *camera;      /* webcam input, or NULL; vf_v4l2_get_info(camera) describes it */
    char device[256];     /* the webcam's or the source's name */
    const vf_frame_source *source; /* the caller's camera, or NULL */
    long source_given;    /* its frames handed out */
} vf_frames;

typedef struct vf_frame_info {
    char name[VF_PATH_MAX + 32]; /* "FILE" or "VIDEO#N" or "DEVICE#N" */
    char source[VF_PATH_MAX];    /* the file or device */
    long index;                  /* frame number in a video or stream, -1 for a photo */
} vf_frame_info;

/* Inputs from command-line arguments (files and folders). VF_EINPUT naming an argument that
 * does not exist or is neither an image nor a video nor a folder, or when there are none. */
vf_status vf_frames_open(char *const *args, int count, vf_frames *in);

/* A V4L2 webcam, opened and streaming. ops NULL: the real device (a test passes its fake);
 * request NULL: 1280x720, MJPEG or YUYV (see vf/v4l2.h). Errors as vf_v4l2_open's. */
vf_status vf_frames_open_v4l2(const char *device, const vf_v4l2_ops *ops,
                              const vf_v4l2_request *request, vf_frames *in);

/* The caller's own camera (kept by the caller until vf_frames_close). */
void vf_frames_open_source(const vf_frame_source *source, vf_frames *in);

/* The next frame into *frame (reused), *got = 0 at the end (a webcam never ends). A file that
 * cannot be read is an error naming it; a webcam silent for VF_CAMERA_TIMEOUT_MS is an
 * error. */
vf_status vf_frames_next(vf_frames *in, vf_rgb8 *frame, vf_frame_info *info, int *got);

/* Close the video or webcam being read and free the list; the vf_frames is zeroed. */
void vf_frames_close(vf_frames *in);

/* Whether a file name looks like a video (by its extension). */
int vf_is_video_name(const char *path);

#ifdef __cplusplus
}
#endif
#endif
