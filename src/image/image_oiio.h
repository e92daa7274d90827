/* src/image/image_oiio.h (internal): the OpenImageIO calls behind vf/image.h's files. A leaf:
 * it moves raw interleaved float pixels between files and memory, and image.c makes vf_images
 * of them (applying the EXIF orientation it reports). Internal names here and in the other
 * C++ files are vf_<library>_* rather than vf__*: C++ reserves every name with "__". */
#ifndef VF_IMAGE_OIIO_H
#define VF_IMAGE_OIIO_H

#include <stddef.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The stored size and channels from the header, and the EXIF orientation to apply (a JPEG's,
 * as OpenCV's imread applies it; 1 for other formats). VF_EINPUT "cannot read PATH: ...". */
vf_status vf_oiio_info(const char *path, int *width, int *height, int *channels,
                        int *orientation);

/* Decode the file as stored into *pixels (malloc'd, width * height * channels floats, 0..1 for
 * 8/16-bit files, straight alpha), with the same header values as vf_oiio_info. */
vf_status vf_oiio_read(const char *path, float **pixels, int *width, int *height,
                        int *channels, int *orientation);

/* Encode pixels in the format of path's extension (.png, .jpg/.jpeg 8-bit without alpha, .exr
 * float) into *bytes (malloc'd, *size bytes). VF_EINPUT for another extension. */
vf_status vf_oiio_encode(const char *path, const float *pixels, int width, int height,
                          int channels, unsigned char **bytes, size_t *size);

#ifdef __cplusplus
}
#endif
#endif
