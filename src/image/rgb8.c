/* The plain-C half of vf/rgb8.h: memory and comparison. Codecs and resizing are in
 * rgb8_cv.cpp, reading a photo upright in rgb8_load.c. */
#include "vf/rgb8.h"

#include <stdint.h>
#include <stdlib.h>

vf_status vf_rgb8_resize_buffer(vf_rgb8 *img, int width, int height)
{
    if (width <= 0 || height <= 0 || (size_t)width > SIZE_MAX / 3 / (size_t)height)
        return vf_fail(VF_EINPUT, "invalid frame size %dx%d", width, height);
    if (img->data && img->width == width && img->height == height)
        return VF_OK;
    unsigned char *data = malloc((size_t)width * (size_t)height * 3);
    if (!data)
        return vf_fail(VF_EINTERNAL, "out of memory for a %dx%d frame", width, height);
    free(img->data);
    *img = (vf_rgb8){width, height, data};
    return VF_OK;
}

void vf_rgb8_free(vf_rgb8 *img)
{
    if (!img)
        return;
    free(img->data);
    *img = (vf_rgb8){0, 0, NULL};
}

double vf_rgb8_mean_abs_diff(const vf_rgb8 *a, const vf_rgb8 *b)
{
    if (a->width != b->width || a->height != b->height || !a->data || !b->data)
        return -1;
    size_t n = (size_t)a->width * (size_t)a->height * 3;
    uint64_t sum = 0;
    for (size_t i = 0; i < n; i++)
        sum += (uint64_t)abs((int)a->data[i] - (int)b->data[i]);
    return (double)sum / (double)n;
}
