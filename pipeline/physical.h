/* pipeline/physical.h: what the physical-loop commands share (localize, reshoot, score): the
 * localization options on the command line and a viewpoint as a line of text. Private to the
 * pipeline. */
#ifndef VF_PIPELINE_PHYSICAL_H
#define VF_PIPELINE_PHYSICAL_H

#include <getopt.h>
#include <jansson.h>

#include "cli.h"
#include "vf/localize.h"
#include "vf/pose.h"

/* Long options for localization; add PHYSICAL_LOCALIZE_OPTIONS to a command's table and pass
 * unknown option codes to physical_localize_option(). */
enum {
    PHYS_OPT_CAMERA = 1500,
    PHYS_OPT_MIN_INLIERS,
    PHYS_OPT_MIN_INLIER_RATIO,
    PHYS_OPT_MAX_FEATURES,
    PHYS_OPT_MAX_SIDE,
};
#define PHYSICAL_LOCALIZE_OPTIONS                                                          \
    {"camera", required_argument, NULL, PHYS_OPT_CAMERA},                                  \
        {"min-inliers", required_argument, NULL, PHYS_OPT_MIN_INLIERS},                    \
        {"min-inlier-ratio", required_argument, NULL, PHYS_OPT_MIN_INLIER_RATIO},          \
        {"max-features", required_argument, NULL, PHYS_OPT_MAX_FEATURES},                  \
        {"max-side", required_argument, NULL, PHYS_OPT_MAX_SIDE}
#define PHYSICAL_LOCALIZE_HELP                                                             \
    "      --camera FILE      intrinsics of the camera the frames come from (JSON: fl_x, fl_y,\n" \
    "                         cx, cy, w, h, k1, k2, p1, p2); default: the capture's camera\n" \
    "      --min-inliers N    fewer inliers: not localized (default 20)\n"                 \
    "      --min-inlier-ratio F  fewer inliers per match: not localized (default 0.2)\n"   \
    "      --max-features N   SIFT features per frame (default 4096)\n"                 \
    "      --max-side PX      shrink frames to PX on the longer side first (default 1024;\n" \
    "                         640 is about twice as fast, for live use)\n"

/* Apply one localization option; *handled = 0 when `opt` is not one of them. */
vf_status physical_localize_option(int opt, const char *arg, vf_localize_options *lo,
                                   int *handled);

/* "psi 12.3 theta -4.0 phi 101.2 dx 0.02 dy -0.31 dz 0.05" */
void physical_viewpoint_text(const vf_viewpoint *v, char *out, size_t size);

#endif
