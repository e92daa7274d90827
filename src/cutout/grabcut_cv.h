/* src/cutout/grabcut_cv.h (internal): OpenCV's GrabCut behind vf/cutout.h. A leaf: pixels and
 * labels in, labels out. */
#ifndef VF_GRABCUT_CV_H
#define VF_GRABCUT_CV_H

#include <stdint.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* OpenCV's label values. */
enum { VF_GC_BGD = 0, VF_GC_FGD = 1, VF_GC_PR_BGD = 2, VF_GC_PR_FGD = 3 };

/* Segment a width x height RGB image (3 bytes a pixel) from the labels given (width * height,
 * the values above), refining the probable ones in place over `iterations` rounds. */
vf_status vf_cv_grabcut(const uint8_t *rgb, int width, int height, uint8_t *labels, int iterations);

#ifdef __cplusplus
}
#endif
#endif
