/* vf/image.h: float images in memory, and reading/writing them as files.
 *
 * A vf_image is row-major and interleaved: pixel (x, y) channel c is
 * data[(y * width + x) * channels + c]. Values are floats, 0..1 for 8/16-bit files, exactly as
 * stored in the file: no colour management, no gamma, and alpha is straight (unassociated), as
 * in PNG. Files are read and written through OpenImageIO (PNG, JPEG, OpenEXR and whatever else
 * it reads); resizing and cropping are plain C. A JPEG's EXIF orientation is applied on reading
 * (pixels and size as a photo viewer shows them), as vf/rgb8.h's OpenCV decoder does, so every
 * stage sees a phone photo the same way up.
 *
 * Memory: every function that fills a vf_image allocates its pixels; the caller owns them and
 * releases them with vf_image_free(). Outputs are written only on success. Functions taking a
 * source and an output never modify the source; source and output must be different structs. */
#ifndef VF_IMAGE_H
#define VF_IMAGE_H

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_image {
    int width, height, channels;
    float *data;
} vf_image;

/* Allocate a zero-filled width x height image with `channels` channels (1..4 or more). */
vf_status vf_image_alloc(vf_image *img, int width, int height, int channels);

/* Release the pixels and zero the struct; safe on a zeroed or already freed image. */
void vf_image_free(vf_image *img);

/* Read an image file, keeping its channels (grey 1, grey+alpha 2, RGB 3, RGBA 4, ...).
 * VF_EINPUT "cannot read PATH: ..." when the file is missing, not an image, or corrupt. */
vf_status vf_image_load(const char *path, vf_image *out);

/* Read an image file as 3-channel RGB: grey is expanded, alpha (channel 1 of grey+alpha,
 * channel 3 of RGBA or more) is composited as rgb * a + background * (1 - a). */
vf_status vf_image_load_rgb(const char *path, const float background[3], vf_image *out);

/* Convert an image in memory to RGB the way vf_image_load_rgb does. */
vf_status vf_image_to_rgb(const vf_image *src, const float background[3], vf_image *out);

/* Size (after the EXIF orientation) and channel count from the file header, without decoding
 * the pixels. */
vf_status vf_image_info(const char *path, int *width, int *height, int *channels);

/* The EXIF orientation (1..8) a file's pixels must be turned by to show it upright: a JPEG's
 * (recognised by its content, not its name), 1 for every other format. The one rule of the
 * project: vf_image_load and vf_rgb8_load both apply it. VF_EINPUT when it cannot be read. */
vf_status vf_image_orientation(const char *path, int *orientation);

/* Where the stored pixel shown at (u, v) lies, (*x, *y), for a width x height stored image
 * under EXIF orientation `orientation`. */
void vf_orientation_source(int orientation, int width, int height, int u, int v, int *x, int *y);

/* src as EXIF orientation `orientation` (1..8) says to show it: 1 as stored, 2 mirrored, 3
 * turned 180 degrees, 4 flipped, 5 transposed, 6 turned 90 degrees clockwise, 7 transversed,
 * 8 turned 90 degrees counter-clockwise (5..8 swap width and height). Other values: a copy. */
vf_status vf_image_reorient(const vf_image *src, int orientation, vf_image *out);

/* Write img to path, the format chosen by the extension: .png (8-bit), .jpg/.jpeg (8-bit,
 * alpha dropped), .exr (32-bit float). Values are clamped to 0..1 for 8-bit formats. The file
 * is replaced atomically (temporary name beside it, then rename), so a failure (disk full,
 * no permission) leaves any earlier file intact. */
vf_status vf_image_save(const char *path, const vf_image *img);

/* Resize to width x height, all channels, with a tent filter: area-weighted averaging when
 * shrinking (no aliasing), linear interpolation when enlarging, as PIL/torchvision's
 * antialiased bilinear resize. Same size gives an exact copy. Uses every core. */
vf_status vf_image_resize(const vf_image *src, int width, int height, vf_image *out);

/* The centred width x height window of src (width <= src->width, height <= src->height); when
 * the margin is odd the extra pixel is dropped on the right/bottom. */
vf_status vf_image_center_crop(const vf_image *src, int width, int height, vf_image *out);

#ifdef __cplusplus
}
#endif
#endif
