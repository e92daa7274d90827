/* pipeline/frames_in.h: the frames a physical-loop command reads (localize, reshoot, score).
 *
 * The inputs are a list of image files, video files (anything FFmpeg decodes) and folders
 * (their images and videos, in name order), or one V4L2 webcam. Frames come out one at a time
 * as RGB, each with a name saying where it came from ("clip.mp4#12", "photos/0003.jpg").
 * Private to the pipeline. A frames_in is opened by frames_in_open*(), closed by
 * frames_in_close(); frames handed out are the caller's (vf_rgb8_free). */
#ifndef VF_PIPELINE_FRAMES_IN_H
#define VF_PIPELINE_FRAMES_IN_H

#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/rgb8.h"
#include "vf/v4l2.h"
#include "vf/video.h"

typedef struct frames_in {
    char **files;         /* image and video files, in order */
    int count, next;      /* files, and the next one to open */
    vf_video *video;      /* the video being read, or NULL */
    char video_path[VF_PATH_MAX];
    long video_frame;     /* index of the last frame read from it */
    vf_v4l2 *camera;      /* webcam input, or NULL */
    char device[256];
} frames_in;

typedef struct frame_info {
    char name[VF_PATH_MAX + 32]; /* "FILE" or "VIDEO#N" or "DEVICE#N" */
    char source[VF_PATH_MAX];    /* the file or device */
    long index;                  /* frame number in a video or stream, -1 for a photo */
} frame_info;

/* Inputs from command-line arguments (files and folders). VF_EINPUT naming an argument that
 * does not exist or is neither an image nor a video nor a folder, or when there are none. */
vf_status frames_in_open(char *const *args, int count, frames_in *in);
/* A V4L2 webcam (1280x720 asked for). */
vf_status frames_in_open_v4l2(const char *device, frames_in *in);

/* The next frame into *frame (reused), *got = 0 at the end. A file that cannot be read is an
 * error naming it. */
vf_status frames_in_next(frames_in *in, vf_rgb8 *frame, frame_info *info, int *got);

void frames_in_close(frames_in *in);

/* Whether a file name looks like a video (by its extension). */
int frames_in_is_video_name(const char *path);

#endif
