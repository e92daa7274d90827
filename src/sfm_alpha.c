/* Undistorting frames that carry an alpha channel (vf/sfm_images.h). COLMAP's undistorter
 * writes RGB only, so a photo whose background was removed would lose the mask that tells
 * the radiance field where the object ends; this resamples the whole RGBA frame instead. */
#include "vf/sfm_images.h"

#include <math.h>
#include <string.h>

/* Bilinear sample of all channels at pixel position (u, v) (vf/camera.h: centres at +0.5);
 * outside the image every channel is 0 (transparent). */
static void sample_bilinear(const vf_image *img, double u, double v, float *out)
{
    const int c = img->channels;
    double x = u - 0.5, y = v - 0.5;
    int x0 = (int)floor(x), y0 = (int)floor(y);
    double fx = x - x0, fy = y - y0;
    memset(out, 0, (size_t)c * sizeof *out);
    for (int corner = 0; corner < 4; corner++) {
        int xi = x0 + (corner & 1), yi = y0 + (corner >> 1);
        if (xi < 0 || yi < 0 || xi >= img->width || yi >= img->height)
            continue;
        double w = (corner & 1 ? fx : 1 - fx) * (corner >> 1 ? fy : 1 - fy);
        const float *p = img->data + ((size_t)yi * img->width + xi) * c;
        for (int k = 0; k < c; k++)
            out[k] += (float)(w * p[k]);
    }
}

vf_status vf_sfm_undistort_frame(const vf_image *src, const vf_camera *lens,
                                 const vf_camera *pinhole, vf_image *out)
{
    vf_status status = vf_image_alloc(out, pinhole->width, pinhole->height, src->channels);
    if (status != VF_OK)
        return status;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < out->height; y++)
        for (int x = 0; x < out->width; x++) {
            /* the pinhole pixel's ray, through the lens into the source frame */
            double p[3] = {(x + 0.5 - pinhole->cx) / pinhole->fx,
                           (y + 0.5 - pinhole->cy) / pinhole->fy, 1.0},
                   u, v;
            float *dst = out->data + ((size_t)y * out->width + x) * out->channels;
            if (vf_camera_project(lens, p, &u, &v))
                sample_bilinear(src, u, v, dst);
        }
    return VF_OK;
}
