/* vf_rgb8_load (vf/rgb8.h): OpenCV decodes the photo as stored, and the project's one
 * orientation rule (vf_image_orientation, OpenImageIO's reading of the header) turns it
 * upright. Its own file so that the OpenCV adapter stays a leaf below it. */
#include <string.h>

#include "rgb8_cv.h"
#include "vf/fsutil.h"
#include "vf/image.h"
#include "vf/rgb8.h"

vf_status vf_rgb8_load(const char *path, vf_rgb8 *out)
{
    if (!vf_is_file(path))
        return vf_fail(VF_EINPUT, "cannot read %s: no such file", path);
    int orientation;
    if (vf_image_orientation(path, &orientation) != VF_OK || orientation < 2 || orientation > 8)
        return vf_cv_read(path, out); /* upright as stored (OpenCV judges what it can read) */
    vf_rgb8 stored = {0};
    vf_status status = vf_cv_read(path, &stored);
    int w = stored.width, h = stored.height, swap = orientation >= 5;
    if (status == VF_OK)
        status = vf_rgb8_resize_buffer(out, swap ? h : w, swap ? w : h);
    for (int v = 0; status == VF_OK && v < out->height; v++)
        for (int u = 0; u < out->width; u++) {
            int x, y;
            vf_orientation_source(orientation, w, h, u, v, &x, &y);
            memcpy(out->data + ((size_t)v * out->width + u) * 3,
                   stored.data + ((size_t)y * w + x) * 3, 3);
        }
    vf_rgb8_free(&stored);
    return status;
}
