/* vf/frames.h: the frames the physical loop reads (localize, reshoot, score).
 *
 * The inputs are a list of image files, video files (anything FFmpeg decodes) and folders
 * (their images and videos, in name order), or one V4L2 webcam. Frames come out one at a time
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

typedef struct vf_frames {
    char **files;         /* image and video files, in order */
    int count, next;      /* files, and the next one to open */
    vf_video *video;      /* the video being read, or NULL */
    char video_path[VF_PATH_MAX];
    long video_frame;     /* index of the last frame read from it */
    vf_v4l2 *camera;      /* webcam input, or NULL */
    char device[256];
} vf_frames;

typedef struct vf_frame_info {
    char name[VF_PATH_MAX + 32]; /* "FILE" or "VIDEO#N" or "DEVICE#N" */
    char source[VF_PATH_MAX];    /* the file or device */
    long index;                  /* frame number in a video or stream, -1 for a photo */
} vf_frame_info;

/* Inputs from command-line arguments (files and folders). VF_EINPUT naming an argument that
 * does not exist or is neither an image nor a video nor a folder, or when there are none. */
vf_status vf_frames_open(char *const *args, int count, vf_frames *in);
/* A V4L2 webcam (1280x720 asked for). */
vf_status vf_frames_open_v4l2(const char *device, vf_frames *in);

/* The next frame into *frame (reused), *got = 0 at the end. A file that cannot be read is an
 * error naming it. */
vf_status vf_frames_next(vf_frames *in, vf_rgb8 *frame, vf_frame_info *info, int *got);

void vf_frames_close(vf_frames *in);

/* Whether a file name looks like a video (by its extension). */
int vf_is_video_name(const char *path);

#ifdef __cplusplus
}
#endif
#endif
