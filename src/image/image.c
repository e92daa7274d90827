/* vf/image.h: memory, files (the pixels coded by oiio/image_oiio.cpp), EXIF orientation,
 * channel conversion and cropping. */
#include "vf/image.h"

#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "image_oiio.h"
#include "vf/fsutil.h"

vf_status vf_image_alloc(vf_image *img, int width, int height, int channels)
{
    if (width <= 0 || height <= 0 || channels <= 0)
        return vf_fail(VF_EINPUT, "invalid image size %dx%d with %d channels", width, height,
                       channels);
    size_t count = (size_t)width * (size_t)height * (size_t)channels;
    if (count > SIZE_MAX / sizeof(float))
        return vf_fail(VF_EINPUT, "image %dx%d is too large", width, height);
    float *data = calloc(count, sizeof(float));
    if (!data)
        return vf_fail(VF_EINTERNAL, "out of memory for a %dx%d image", width, height);
    *img = (vf_image){width, height, channels, data};
    return VF_OK;
}

void vf_image_free(vf_image *img)
{
    if (!img)
        return;
    free(img->data);
    *img = (vf_image){0, 0, 0, NULL};
}

vf_status vf_image_info(const char *path, int *width, int *height, int *channels)
{
    int w, h, orientation;
    vf_status status = vf_oiio_info(path, &w, &h, channels, &orientation);
    if (status == VF_OK) {
        *width = orientation >= 5 ? h : w;
        *height = orientation >= 5 ? w : h;
    }
    return status;
}

vf_status vf_image_load(const char *path, vf_image *out)
{
    vf_image img;
    int orientation;
    vf_status status =
        vf_oiio_read(path, &img.data, &img.width, &img.height, &img.channels, &orientation);
    if (status != VF_OK || orientation == 1) {
        if (status == VF_OK)
            *out = img;
        return status;
    }
    status = vf_image_reorient(&img, orientation, out);
    vf_image_free(&img);
    return status;
}

vf_status vf_image_save(const char *path, const vf_image *img)
{
    if (!img->data || img->width <= 0 || img->height <= 0 || img->channels <= 0)
        return vf_fail(VF_EINPUT, "cannot write %s: the image is empty", path);
    unsigned char *bytes = NULL;
    size_t size = 0;
    vf_status status =
        vf_oiio_encode(path, img->data, img->width, img->height, img->channels, &bytes, &size);
    if (status == VF_OK)
        status = vf_write_file_atomic(path, bytes, size);
    free(bytes);
    return status;
}

vf_status vf_image_to_rgb(const vf_image *src, const float background[3], vf_image *out)
{
    vf_image rgb;
    vf_status status = vf_image_alloc(&rgb, src->width, src->height, 3);
    if (status != VF_OK)
        return status;
    int nc = src->channels;
    int grey = nc < 3;
    int alpha = nc == 2 ? 1 : nc >= 4 ? 3 : -1; /* which channel holds alpha, if any */
    size_t pixels = (size_t)src->width * (size_t)src->height;
    for (size_t i = 0; i < pixels; i++) {
        const float *s = src->data + i * (size_t)nc;
        float *d = rgb.data + i * 3;
        float a = alpha >= 0 ? s[alpha] : 1.0f;
        for (int c = 0; c < 3; c++) {
            float v = grey ? s[0] : s[c];
            d[c] = alpha >= 0 ? v * a + background[c] * (1.0f - a) : v;
        }
    }
    *out = rgb;
    return VF_OK;
}

vf_status vf_image_load_rgb(const char *path, const float background[3], vf_image *out)
{
    vf_image img;
    vf_status status = vf_image_load(path, &img);
    if (status != VF_OK)
        return status;
    if (img.channels == 3) {
        *out = img;
        return VF_OK;
    }
    status = vf_image_to_rgb(&img, background, out);
    vf_image_free(&img);
    return status;
}

vf_status vf_image_orientation(const char *path, int *orientation)
{
    int w, h, channels;
    return vf_oiio_info(path, &w, &h, &channels, orientation);
}

void vf_orientation_source(int orientation, int w, int h, int u, int v, int *x, int *y)
{
    switch (orientation) {
    case 2: *x = w - 1 - u, *y = v; break;
    case 3: *x = w - 1 - u, *y = h - 1 - v; break;
    case 4: *x = u, *y = h - 1 - v; break;
    case 5: *x = v, *y = u; break;
    case 6: *x = v, *y = h - 1 - u; break;
    case 7: *x = w - 1 - v, *y = h - 1 - u; break;
    case 8: *x = w - 1 - v, *y = u; break;
    default: *x = u, *y = v; break;
    }
}

vf_status vf_image_reorient(const vf_image *src, int orientation, vf_image *out)
{
    if (orientation < 1 || orientation > 8)
        orientation = 1;
    int w = src->width, h = src->height, swap = orientation >= 5;
    vf_image img;
    vf_status status = vf_image_alloc(&img, swap ? h : w, swap ? w : h, src->channels);
    if (status != VF_OK)
        return status;
    size_t c = (size_t)src->channels;
    for (int v = 0; v < img.height; v++)
        for (int u = 0; u < img.width; u++) {
            int x, y;
            vf_orientation_source(orientation, w, h, u, v, &x, &y);
            memcpy(img.data + ((size_t)v * img.width + u) * c,
                   src->data + ((size_t)y * w + x) * c, c * sizeof(float));
        }
    *out = img;
    return VF_OK;
}

vf_status vf_image_center_crop(const vf_image *src, int width, int height, vf_image *out)
{
    if (width <= 0 || height <= 0 || width > src->width || height > src->height)
        return vf_fail(VF_EINPUT, "cannot crop %dx%d from a %dx%d image", width, height,
                       src->width, src->height);
    vf_image crop;
    vf_status status = vf_image_alloc(&crop, width, height, src->channels);
    if (status != VF_OK)
        return status;
    int x0 = (src->width - width) / 2, y0 = (src->height - height) / 2;
    size_t row = (size_t)width * (size_t)src->channels;
    for (int y = 0; y < height; y++) {
        const float *s = src->data + ((size_t)(y0 + y) * src->width + x0) * src->channels;
        memcpy(crop.data + (size_t)y * row, s, row * sizeof(float));
    }
    *out = crop;
    return VF_OK;
}

/* ---- resizing ---- */

/* The source pixels (first, count, weights) that make each output pixel along one axis. */
typedef struct resize_axis {
    int taps; /* weights stored per output pixel */
    int *first, *count;
    float *weights;
} resize_axis;

static void free_axis(resize_axis *axis)
{
    free(axis->first);
    free(axis->count);
    free(axis->weights);
}

/* A tent filter widened by the shrink factor: area-weighted averaging when shrinking, linear
 * interpolation when enlarging (PIL's antialiased bilinear, which torchvision's Resize uses).
 * Weights are renormalised at the borders, so a constant image stays constant. */
static vf_status axis_weights(int in, int out, resize_axis *axis)
{
    double scale = (double)in / out;
    double radius = scale > 1 ? scale : 1; /* in source pixels */
    axis->taps = 2 * (int)ceil(radius) + 1;
    axis->first = malloc((size_t)out * sizeof(int));
    axis->count = malloc((size_t)out * sizeof(int));
    axis->weights = malloc((size_t)out * (size_t)axis->taps * sizeof(float));
    if (!axis->first || !axis->count || !axis->weights) {
        free_axis(axis);
        return vf_fail(VF_EINTERNAL, "out of memory resizing to %d pixels", out);
    }
    for (int i = 0; i < out; i++) {
        double center = (i + 0.5) * scale;
        int lo = (int)floor(center - radius + 0.5), hi = (int)floor(center + radius + 0.5);
        lo = lo < 0 ? 0 : lo;
        hi = hi > in ? in : hi;
        float *w = axis->weights + (size_t)i * axis->taps;
        double sum = 0;
        for (int x = lo; x < hi; x++) {
            double d = fabs((x + 0.5 - center) / radius);
            w[x - lo] = (float)(d < 1 ? 1 - d : 0);
            sum += w[x - lo];
        }
        for (int x = lo; x < hi; x++)
            w[x - lo] = sum > 0 ? (float)(w[x - lo] / sum) : 1.0f / (float)(hi - lo);
        axis->first[i] = lo;
        axis->count[i] = hi - lo;
    }
    return VF_OK;
}

/* Horizontal pass: every source row to out_w pixels. */
static void resize_rows(const vf_image *src, const resize_axis *ax, int out_w, float *dst)
{
    int nc = src->channels;
#pragma omp parallel for schedule(static) if ((size_t)src->height * out_w > 65536)
    for (int y = 0; y < src->height; y++) {
        const float *row = src->data + (size_t)y * src->width * nc;
        float *o = dst + (size_t)y * out_w * nc;
        for (int i = 0; i < out_w; i++) {
            const float *w = ax->weights + (size_t)i * ax->taps;
            const float *s = row + (size_t)ax->first[i] * nc;
            for (int c = 0; c < nc; c++) {
                float sum = 0;
                for (int k = 0; k < ax->count[i]; k++)
                    sum += w[k] * s[k * nc + c];
                o[i * nc + c] = sum;
            }
        }
    }
}

/* Vertical pass: rows of `row_len` floats, src_h of them, to dst_h weighted sums of rows. */
static void resize_columns(const float *src, size_t row_len, const resize_axis *ax, int dst_h,
                           float *dst)
{
#pragma omp parallel for schedule(static) if ((size_t)dst_h * row_len > 65536)
    for (int j = 0; j < dst_h; j++) {
        float *o = dst + (size_t)j * row_len;
        const float *w = ax->weights + (size_t)j * ax->taps;
        memset(o, 0, row_len * sizeof(float));
        for (int k = 0; k < ax->count[j]; k++) {
            const float *s = src + (size_t)(ax->first[j] + k) * row_len;
            for (size_t i = 0; i < row_len; i++)
                o[i] += w[k] * s[i];
        }
    }
}

vf_status vf_image_resize(const vf_image *src, int width, int height, vf_image *out)
{
    if (width <= 0 || height <= 0 || !src->data)
        return vf_fail(VF_EINPUT, "cannot resize a %dx%d image to %dx%d", src->width,
                       src->height, width, height);
    vf_image tmp = {0}, dst = {0};
    if (width == src->width && height == src->height) {
        vf_status status = vf_image_alloc(&dst, width, height, src->channels);
        if (status == VF_OK) {
            memcpy(dst.data, src->data, (size_t)width * height * src->channels * sizeof(float));
            *out = dst;
        }
        return status;
    }
    resize_axis ax = {0}, ay = {0};
    vf_status status = axis_weights(src->width, width, &ax);
    if (status == VF_OK)
        status = axis_weights(src->height, height, &ay);
    if (status == VF_OK)
        status = vf_image_alloc(&tmp, width, src->height, src->channels);
    if (status == VF_OK)
        status = vf_image_alloc(&dst, width, height, src->channels);
    if (status == VF_OK) {
        resize_rows(src, &ax, width, tmp.data);
        resize_columns(tmp.data, (size_t)width * src->channels, &ay, height, dst.data);
        *out = dst;
    }
    free_axis(&ax);
    free_axis(&ay);
    vf_image_free(&tmp);
    return status;
}
