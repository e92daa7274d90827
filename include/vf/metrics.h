/* vf/metrics.h: image quality measures for comparing renders with photos.
 *
 * PSNR and SSIM of two images of the same size and channel count, values in 0..1 (peak 1).
 * SSIM follows Wang et al. 2004: an 11x11 Gaussian window (sigma 1.5), C1 = 0.01^2,
 * C2 = 0.03^2, computed per channel over the valid window positions and averaged.
 * Nothing is allocated that the caller must free, except the error image it asks for. */
#ifndef VF_METRICS_H
#define VF_METRICS_H

#include "vf/error.h"
#include "vf/image.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Mean squared error over all pixels and channels; -1 when the sizes differ. */
double vf_image_mse(const vf_image *a, const vf_image *b);

/* Peak signal-to-noise ratio in dB, -10 log10(MSE); 100 for identical images, -1 when the
 * sizes differ. */
double vf_image_psnr(const vf_image *a, const vf_image *b);
/* PSNR over the pixels where mask (an RGBA image of the same size) is opaque (alpha > 0.5),
 * RGB channels only; -1 when the sizes differ or no pixel is opaque. */
double vf_image_psnr_masked(const vf_image *a, const vf_image *b, const vf_image *mask);

/* Structural similarity in [-1, 1]; -2 when the sizes differ or the image is smaller than
 * the window. */
double vf_image_ssim(const vf_image *a, const vf_image *b);

/* A 3-channel picture of |a - b| (mean over channels, scaled by `gain`, clamped to 1) for
 * looking at where a render is wrong; allocated into out (vf_image_free it). */
vf_status vf_image_error_map(const vf_image *a, const vf_image *b, float gain, vf_image *out);

#ifdef __cplusplus
}
#endif
#endif
