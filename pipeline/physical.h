/* pipeline/physical.h: what the physical-loop commands share (localize, export, reshoot,
 * score): the localization options on the command line, a localization result as JSON and
 * as a line of text, and the viewpoint tolerance box. Private to the pipeline. */
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
    "      --min-inliers N    fewer inliers: not localized (default 30)\n"                 \
    "      --min-inlier-ratio F  fewer inliers per match: not localized (default 0.2)\n"   \
    "      --max-features N   SIFT features per frame (default 4096)\n"                 \
    "      --max-side PX      shrink frames to PX on the longer side first (default 1024;\n" \
    "                         640 is about twice as fast, for live use)\n"

/* Apply one localization option; *handled = 0 when `opt` is not one of them. */
vf_status physical_localize_option(int opt, const char *arg, vf_localize_options *lo,
                                   int *handled);

/* The viewpoint (and, c2w not NULL, the object-frame camera-to-world) of exported target n
 * of WS/export/targets.json. VF_EINPUT when there is no export or no such target. */
vf_status physical_load_target(const char *ws, int n, vf_viewpoint *v, double c2w[16]);

/* {"localized":..., "reason" or the pose, the viewpoint, inliers, ...} for one frame. */
json_t *physical_result_json(const vf_localize_result *r);
json_t *physical_viewpoint_json(const vf_viewpoint *v);
json_t *physical_mat4_json(const double m[16]);

/* "psi 12.3 theta -4.0 phi 101.2 dx 0.02 dy -0.31 dz 0.05" */
void physical_viewpoint_text(const vf_viewpoint *v, char *out, size_t size);

/* Whether viewpoint v lies within +-tolerance (a share, 0.05 for 5%) of each parameter's
 * measurement range (vf_attack_file.range) around `center`; psi differences wrap around 360
 * degrees. *worst (may be NULL) receives the largest |difference| / range. */
int physical_within_box(const vf_viewpoint *v, const vf_viewpoint *center, const double range[6],
                        double tolerance, double *worst);

#endif
