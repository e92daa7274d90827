#include "vf/metrics.h"

#include <math.h>
#include <stdlib.h>

static int same_shape(const vf_image *a, const vf_image *b)
{
    return a->width == b->width && a->height == b->height && a->channels == b->channels &&
           a->data && b->data;
}

double vf_image_mse(const vf_image *a, const vf_image *b)
{
    if (!same_shape(a, b))
        return -1;
    size_t n = (size_t)a->width * a->height * a->channels;
    double sum = 0;
    for (size_t i = 0; i < n; i++) {
        double d = (double)a->data[i] - (double)b->data[i];
        sum += d * d;
    }
    return n ? sum / n : 0;
}

double vf_image_psnr(const vf_image *a, const vf_image *b)
{
    double mse = vf_image_mse(a, b);
    if (mse < 0)
        return -1;
    return mse <= 1e-10 ? 100.0 : -10.0 * log10(mse);
}

double vf_image_psnr_masked(const vf_image *a, const vf_image *b, const vf_image *mask)
{
    if (a->width != b->width || a->height != b->height || mask->width != a->width ||
        mask->height != a->height || mask->channels != 4 || a->channels < 3 || b->channels < 3)
        return -1;
    double sum = 0;
    size_t count = 0, pixels = (size_t)a->width * a->height;
    for (size_t i = 0; i < pixels; i++) {
        if (!(mask->data[4 * i + 3] > 0.5f))
            continue;
        for (int c = 0; c < 3; c++) {
            double d = a->data[i * a->channels + c] - b->data[i * b->channels + c];
            sum += d * d;
        }
        count += 3;
    }
    if (!count)
        return -1;
    double mse = sum / count;
    return mse <= 1e-10 ? 100.0 : -10.0 * log10(mse);
}

/* Separable Gaussian blur of one channel over the valid region: out is
 * (w - 10) x (h - 10). */
static void blur_valid(const double *in, int w, int h, const double *k, double *tmp, double *out)
{
    int ow = w - 10, oh = h - 10;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < ow; x++) {
            double s = 0;
            for (int i = 0; i < 11; i++)
                s += k[i] * in[(size_t)y * w + x + i];
            tmp[(size_t)y * ow + x] = s;
        }
    for (int y = 0; y < oh; y++)
        for (int x = 0; x < ow; x++) {
            double s = 0;
            for (int i = 0; i < 11; i++)
                s += k[i] * tmp[(size_t)(y + i) * ow + x];
            out[(size_t)y * ow + x] = s;
        }
}

double vf_image_ssim(const vf_image *a, const vf_image *b)
{
    if (!same_shape(a, b) || a->width < 11 || a->height < 11)
        return -2;
    const int w = a->width, h = a->height, ch = a->channels;
    const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
    double k[11], ksum = 0;
    for (int i = 0; i < 11; i++)
        ksum += k[i] = exp(-0.5 * (i - 5) * (i - 5) / (1.5 * 1.5));
    for (int i = 0; i < 11; i++)
        k[i] /= ksum;
    size_t n = (size_t)w * h, m = (size_t)(w - 10) * (h - 10);
    double *buf = malloc(sizeof(double) * (5 * n + n + 5 * m));
    if (!buf)
        return -2;
    double *planes = buf, *tmp = buf + 5 * n, *blurred = tmp + n;
    double total = 0;
    for (int c = 0; c < ch; c++) {
        for (size_t i = 0; i < n; i++) {
            double x = a->data[i * ch + c], y = b->data[i * ch + c];
            planes[i] = x;
            planes[n + i] = y;
            planes[2 * n + i] = x * x;
            planes[3 * n + i] = y * y;
            planes[4 * n + i] = x * y;
        }
        for (int p = 0; p < 5; p++)
            blur_valid(planes + p * n, w, h, k, tmp, blurred + p * m);
        double sum = 0;
        for (size_t i = 0; i < m; i++) {
            double mx = blurred[i], my = blurred[m + i];
            double vx = blurred[2 * m + i] - mx * mx, vy = blurred[3 * m + i] - my * my;
            double cov = blurred[4 * m + i] - mx * my;
            sum += (2 * mx * my + c1) * (2 * cov + c2) / ((mx * mx + my * my + c1) * (vx + vy + c2));
        }
        total += sum / m;
    }
    free(buf);
    return total / ch;
}

vf_status vf_image_error_map(const vf_image *a, const vf_image *b, float gain, vf_image *out)
{
    if (!same_shape(a, b))
        return vf_fail(VF_EINPUT, "cannot compare a %dx%dx%d image with a %dx%dx%d one", a->width,
                       a->height, a->channels, b->width, b->height, b->channels);
    vf_status status = vf_image_alloc(out, a->width, a->height, 3);
    if (status != VF_OK)
        return status;
    size_t n = (size_t)a->width * a->height;
    for (size_t i = 0; i < n; i++) {
        float e = 0;
        for (int c = 0; c < a->channels; c++)
            e += fabsf(a->data[i * a->channels + c] - b->data[i * a->channels + c]);
        e = fminf(1.0f, gain * e / a->channels);
        out->data[3 * i] = out->data[3 * i + 1] = out->data[3 * i + 2] = e;
    }
    return VF_OK;
}
