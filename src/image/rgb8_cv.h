/* src/image/rgb8_cv.h (internal): OpenCV's file decoder behind vf_rgb8_load. A leaf: it
 * returns the pixels as stored (alpha composited onto white, grey expanded, 16-bit scaled to
 * 8), and rgb8.c turns them upright by the project's one orientation rule. */
#ifndef VF_RGB8_CV_H
#define VF_RGB8_CV_H

#include "vf/error.h"
#include "vf/rgb8.h"

#ifdef __cplusplus
extern "C" {
#endif

/* Decode the file at path as stored, into out (reused). VF_EINPUT "cannot read PATH: ...". */
vf_status vf_cv_read(const char *path, vf_rgb8 *out);

#ifdef __cplusplus
}
#endif
#endif
