/* vf/sfm_images.h: the image folder a reconstruction starts from.
 *
 * COLMAP reads every image as grey, ignores alpha, and gives one camera to each folder. So the
 * frames chosen by ingest are laid out for it first: an image with an alpha channel (a photo
 * with its background removed) is composited onto a plain background and written as PNG; any
 * other image is hard-linked (copied when linking fails). When the frames come in more than one
 * size (portrait and landscape photos), each size gets its own subfolder "WxH/", so its own
 * camera. While it reads the frames it also measures how much of them is plain white or
 * transparent: a removed background, which leaves few features and calls for a simpler lens.
 *
 * Memory: vf_sfm_images owns its frame array; release it with vf_sfm_images_free. */
#ifndef VF_SFM_IMAGES_H
#define VF_SFM_IMAGES_H

#include "vf/camera.h"
#include "vf/error.h"
#include "vf/image.h"
#include "vf/fsutil.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_sfm_frame {
    char source[VF_PATH_MAX]; /* the input image */
    char name[512];           /* path under the prepared folder, as COLMAP names the image */
    int width, height;
    int had_alpha;            /* composited onto the background */
} vf_sfm_frame;

typedef struct vf_sfm_images {
    int count;
    vf_sfm_frame *frames;     /* in file-name order */
    int size_groups;          /* distinct image sizes = COLMAP cameras */
    int with_alpha;           /* frames that had an alpha channel */
    double background_fraction; /* mean share of pixels that are near-white or transparent */
} vf_sfm_images;

/* List the JPEG and PNG images in src_dir (name order) and lay them out in dst_dir (created)
 * as described above, with alpha composited onto `background` (RGB, 0..1). Uses every core.
 * VF_EINPUT when src_dir is missing, holds no images, or an image cannot be read. */
vf_status vf_sfm_images_prepare(const char *src_dir, const char *dst_dir,
                                const float background[3], vf_sfm_images *out);

void vf_sfm_images_free(vf_sfm_images *images);

/* A frame with an alpha channel that is opaque everywhere but whose edge is mostly
 * near-white (a background removed to white): make the near-white region connected to the
 * edge transparent. *keyed says whether it did; other frames are left as they are. */
vf_status vf_sfm_key_white_background(vf_image *img, int *keyed);

/* Undistort a frame with all its channels (sfm_alpha.c): out gets the frame as the pinhole
 * camera `pinhole` sees it, sampled bilinearly from src, which camera `lens` (with distortion)
 * took; pixels that fall outside src are 0, so transparent. out is allocated here (pass a
 * zeroed or freed image). Uses every core. */
vf_status vf_sfm_undistort_frame(const vf_image *src, const vf_camera *lens,
                                 const vf_camera *pinhole, vf_image *out);

#ifdef __cplusplus
}
#endif
#endif
