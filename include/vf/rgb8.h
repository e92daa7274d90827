/* vf/rgb8.h: 8-bit RGB frames, as video decoders and cameras deliver them.
 *
 * A vf_rgb8 is row-major, tightly packed RGB: pixel (x, y) channel c is
 * data[(y * width + x) * 3 + c]. Capture code keeps frames in this form (a 1080p frame is 6 MB
 * here, 24 MB as a float vf_image); vf/image.h is for the float work that comes later.
 * Decoding, encoding and resizing go through OpenCV (src/image/rgb8_cv.cpp); a photo is turned
 * upright by the same rule as vf/image.h's reader (vf_image_orientation).
 *
 * Memory: a function that fills a vf_rgb8 allocates its pixels; the caller releases them with
 * vf_rgb8_free(). Those marked "reuses" take an output that is either zeroed or a frame from an
 * earlier call, and keep its pixels when the size matches (no allocation per video frame).
 * Outputs are written only on success. */
#ifndef VF_RGB8_H
#define VF_RGB8_H

#include <stddef.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_rgb8 {
    int width, height;
    unsigned char *data;
} vf_rgb8;

/* Make img a width x height frame (contents undefined). Pixels img already holds are reused
 * when the size matches and released otherwise, so a zeroed struct or a frame from an earlier
 * call may be passed. */
vf_status vf_rgb8_resize_buffer(vf_rgb8 *img, int width, int height);

/* Release the pixels and zero the struct; safe on a zeroed or already freed frame. */
void vf_rgb8_free(vf_rgb8 *img);

/* Mean absolute difference of the channel values of two frames of the same size (0..255);
 * -1 when the sizes differ. */
double vf_rgb8_mean_abs_diff(const vf_rgb8 *a, const vf_rgb8 *b);

/* Decode a JPEG or PNG held in memory (an MJPEG camera frame, for example); reuses out.
 * VF_EINPUT "cannot decode ...: not a JPEG or PNG" when it is not one. */
vf_status vf_rgb8_decode(const void *bytes, size_t size, vf_rgb8 *out);

/* Encode as JPEG (quality 1..100) into a malloc'd buffer the caller frees. */
vf_status vf_rgb8_encode_jpeg(const vf_rgb8 *img, int quality, unsigned char **bytes,
                              size_t *size);

/* Read a photo file (JPEG, PNG, and whatever else OpenCV reads) as RGB: grey is expanded,
 * 16-bit scaled to 8, alpha composited onto white, and a JPEG's EXIF orientation applied
 * (vf_image_orientation: a JPEG by its content, whatever its name).
 * Reuses out. VF_EINPUT "cannot read PATH: ..." when it is missing or not an image. */
vf_status vf_rgb8_load(const char *path, vf_rgb8 *out);

/* Write a frame as .jpg/.jpeg (quality 95) or .png, chosen by the extension; the file is
 * replaced atomically. */
vf_status vf_rgb8_save(const char *path, const vf_rgb8 *img);

/* Shrink (area averaging) so that the longer side is at most max_side, keeping the aspect
 * ratio; an exact copy when it already fits. */
vf_status vf_rgb8_fit(const vf_rgb8 *src, int max_side, vf_rgb8 *out);

/* Remove grain and keep edges, as a phone's image processor does before it encodes: OpenCV's
 * non-local means (7x7 patches, 21x21 search) on lightness and colour. strength is its h, in
 * 8-bit levels (3: light, 10: strong; 0 leaves the frame as it is). In place. */
vf_status vf_rgb8_denoise(vf_rgb8 *img, double strength);

#ifdef __cplusplus
}
#endif
#endif
