/* Sharpness (variance of the Laplacian of a shrunk grey frame) and duplicate thumbnails. */
#include "vf/sharpness.h"

#include <stdint.h>
#include <stdlib.h>

/* Luma of an RGB pixel, BT.601 weights in 8-bit fixed point. */
static inline int luma(const unsigned char *p)
{
    return (77 * p[0] + 150 * p[1] + 29 * p[2] + 128) >> 8;
}

/* The source pixels [*lo, *hi) that output pixel o of n_out covers when n_in pixels are
 * shrunk to n_out (edges rounded to whole pixels; never empty). */
static void box_bounds(int o, int n_out, int n_in, int *lo, int *hi)
{
    *lo = (int)((int64_t)o * n_in / n_out);
    *hi = (int)((int64_t)(o + 1) * n_in / n_out);
    if (*hi <= *lo)
        *hi = *lo + 1;
}

/* Shrink the frame's luma to out_w x out_h, each output pixel the mean of its box. */
static void shrink_luma(const vf_rgb8 *frame, int out_w, int out_h, float *out)
{
    for (int oy = 0; oy < out_h; oy++) {
        int y0, y1;
        box_bounds(oy, out_h, frame->height, &y0, &y1);
        for (int ox = 0; ox < out_w; ox++) {
            int x0, x1;
            box_bounds(ox, out_w, frame->width, &x0, &x1);
            int64_t sum = 0;
            for (int y = y0; y < y1; y++) {
                const unsigned char *p = frame->data + ((size_t)y * frame->width + x0) * 3;
                for (int x = x0; x < x1; x++, p += 3)
                    sum += luma(p);
            }
            out[(size_t)oy * out_w + ox] = (float)sum / (float)((y1 - y0) * (x1 - x0));
        }
    }
}

/* The thumbnail: the grey image shrunk the same way to VF_THUMB_SIDE squared. */
static void make_thumb(const float *grey, int w, int h, unsigned char *thumb)
{
    for (int oy = 0; oy < VF_THUMB_SIDE; oy++) {
        int y0, y1;
        box_bounds(oy, VF_THUMB_SIDE, h, &y0, &y1);
        for (int ox = 0; ox < VF_THUMB_SIDE; ox++) {
            int x0, x1;
            box_bounds(ox, VF_THUMB_SIDE, w, &x0, &x1);
            double sum = 0;
            for (int y = y0; y < y1; y++)
                for (int x = x0; x < x1; x++)
                    sum += grey[(size_t)y * w + x];
            thumb[oy * VF_THUMB_SIDE + ox] = (unsigned char)(sum / ((y1 - y0) * (x1 - x0)) + 0.5);
        }
    }
}

/* Variance of the 4-neighbour Laplacian over the interior of a w x h grey image. */
static double laplacian_variance(const float *grey, int w, int h)
{
    if (w < 3 || h < 3)
        return 0;
    double sum = 0, sum_sq = 0;
    for (int y = 1; y < h - 1; y++) {
        const float *row = grey + (size_t)y * w;
        for (int x = 1; x < w - 1; x++) {
            double lap = 4.0 * row[x] - row[x - 1] - row[x + 1] - row[x - w] - row[x + w];
            sum += lap;
            sum_sq += lap * lap;
        }
    }
    double n = (double)(w - 2) * (double)(h - 2);
    double mean = sum / n;
    return sum_sq / n - mean * mean;
}

vf_status vf_score_frame(const vf_rgb8 *frame, vf_frame_score *out)
{
    int longer = frame->width > frame->height ? frame->width : frame->height;
    double scale = longer > VF_SHARPNESS_SIDE ? (double)VF_SHARPNESS_SIDE / longer : 1.0;
    int w = (int)(frame->width * scale + 0.5), h = (int)(frame->height * scale + 0.5);
    if (w < 1)
        w = 1;
    if (h < 1)
        h = 1;
    float *grey = malloc(sizeof(float) * (size_t)w * (size_t)h);
    if (!grey)
        return vf_fail(VF_EINTERNAL, "out of memory scoring a %dx%d frame", frame->width,
                       frame->height);
    shrink_luma(frame, w, h, grey);
    out->sharpness = laplacian_variance(grey, w, h);
    make_thumb(grey, w, h, out->thumb);
    free(grey);
    return VF_OK;
}

double vf_thumb_difference(const vf_frame_score *a, const vf_frame_score *b)
{
    int sum = 0;
    for (int i = 0; i < VF_THUMB_SIDE * VF_THUMB_SIDE; i++)
        sum += abs((int)a->thumb[i] - (int)b->thumb[i]);
    return (double)sum / (VF_THUMB_SIDE * VF_THUMB_SIDE);
}
