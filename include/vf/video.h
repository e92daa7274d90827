/* vf/video.h: reading video files frame by frame, upright.
 *
 * Anything FFmpeg decodes (MP4/MOV/MKV with H.264, HEVC, ...) is read through OpenCV's FFmpeg
 * backend (src/capture/video_cv.cpp). Phone videos are usually stored sideways with a rotation
 * in the container's display matrix; frames come out rotated as a player would show them.
 * (OpenCV 4.6's own CAP_PROP_ORIENTATION_AUTO turns +-90 degree videos the wrong way, see
 * opencv/opencv#22088, so the reader applies the rotation itself.)
 *
 * A vf_video is opened by vf_video_open() and released by vf_video_close(). */
#ifndef VF_VIDEO_H
#define VF_VIDEO_H

#include "vf/error.h"
#include "vf/rgb8.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_video vf_video;

typedef struct vf_video_info {
    double fps;                     /* frames per second from the container (0 when unknown) */
    long frame_count;               /* the container's count: an estimate, may be 0 */
    int width, height;              /* size of the frames delivered, after rotation */
    int coded_width, coded_height;  /* size as stored in the file */
    int rotation;                   /* clockwise degrees applied to display it: 0/90/180/270 */
    char codec[8];                  /* FourCC of the codec, e.g. "h264" ("" when unknown) */
} vf_video_info;

/* Open a video file and describe it. VF_EINPUT, naming the file, when it does not exist or
 * FFmpeg cannot read it (not a video, empty, damaged). */
vf_status vf_video_open(const char *path, vf_video **out, vf_video_info *info);

/* Decode the next frame into *frame (its pixels are reused when the size matches; the
 * caller frees them with vf_rgb8_free). *got is 1 with a frame, 0 at the end of the video. */
vf_status vf_video_read(vf_video *video, vf_rgb8 *frame, int *got);

/* Decode the next frame and drop it (cheaper than vf_video_read). *got as above. */
vf_status vf_video_skip(vf_video *video, int *got);

/* Close the file; NULL is fine. */
void vf_video_close(vf_video *video);

#ifdef __cplusplus
}
#endif
#endif
