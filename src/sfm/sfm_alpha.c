/* Frames whose background was removed (vf/sfm_images.h): the mask that tells the radiance
 * field where the object ends. COLMAP's undistorter writes RGB only, so the whole RGBA frame
 * is resampled here instead; and a background removed to opaque white (as some phone apps
 * export it) is turned back into a transparent one. */
#include "vf/sfm_images.h"

#include <math.h>
#include <stdlib.h>
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

/* Near-white, as background_share (sfm_images.c) counts it. */
static int near_white(const float *p)
{
    return p[0] >= 0.97f && p[1] >= 0.97f && p[2] >= 0.97f;
}

vf_status vf_sfm_key_white_background(vf_image *img, int *keyed)
{
    *keyed = 0;
    const int w = img->width, h = img->height, c = img->channels;
    const size_t n = (size_t)w * h;
    if (c != 4)
        return VF_OK;
    size_t border = 0, white_border = 0;
    for (size_t i = 0; i < n; i++) {
        const float *p = img->data + i * c;
        if (p[3] < 1.0f)
            return VF_OK; /* a real alpha channel: keep it */
        int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
        if (x == 0 || y == 0 || x == w - 1 || y == h - 1) {
            border++;
            white_border += near_white(p);
        }
    }
    if (2 * white_border < border)
        return VF_OK; /* the frame's edge is mostly not white: no removed background */
    /* flood fill from the white border pixels through near-white ones (4-connected) */
    size_t *stack = malloc(n * sizeof *stack), top = 0;
    unsigned char *seen = calloc(n, 1);
    if (!stack || !seen) {
        free(stack);
        free(seen);
        return vf_fail(VF_EINTERNAL, "out of memory keying a %dx%d frame", w, h);
    }
    for (size_t i = 0; i < n; i++) {
        int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
        if ((x == 0 || y == 0 || x == w - 1 || y == h - 1) && near_white(img->data + i * c))
            seen[i] = 1, stack[top++] = i;
    }
    while (top > 0) {
        size_t i = stack[--top];
        img->data[i * c + 3] = 0.0f;
        int x = (int)(i % (size_t)w), y = (int)(i / (size_t)w);
        const size_t next[4] = {x > 0 ? i - 1 : i, x < w - 1 ? i + 1 : i,
                                y > 0 ? i - (size_t)w : i, y < h - 1 ? i + (size_t)w : i};
        for (int k = 0; k < 4; k++)
            if (!seen[next[k]] && near_white(img->data + next[k] * c))
                seen[next[k]] = 1, stack[top++] = next[k];
    }
    free(stack);
    free(seen);
    *keyed = 1;
    return VF_OK;
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
