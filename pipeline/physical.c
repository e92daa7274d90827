/* What the physical-loop commands share: localization options, results as JSON and text,
 * and the tolerance box around a viewpoint. */
#include "physical.h"

#include <math.h>
#include <stdio.h>

#include "vf/calib.h"
#include "vf/targets.h"
#include "vf/workspace.h"

vf_status physical_localize_option(int opt, const char *arg, vf_localize_options *lo,
                                   int *handled)
{
    long n;
    double x;
    *handled = 1;
    switch (opt) {
    case PHYS_OPT_CAMERA:
        lo->has_camera = 1;
        return vf_calib_load_camera(arg, &lo->camera);
    case PHYS_OPT_MIN_INLIERS:
        if (cli_count("--min-inliers", arg, 6, 100000, &n) != VF_OK)
            return VF_EINPUT;
        lo->min_inliers = (int)n;
        return VF_OK;
    case PHYS_OPT_MIN_INLIER_RATIO:
        if (cli_number_above("--min-inlier-ratio", arg, 0, 1, &x) != VF_OK)
            return VF_EINPUT;
        lo->min_inlier_ratio = x;
        return VF_OK;
    case PHYS_OPT_MAX_FEATURES:
        if (cli_count("--max-features", arg, 100, 100000, &n) != VF_OK)
            return VF_EINPUT;
        lo->max_features = (int)n;
        return VF_OK;
    case PHYS_OPT_MAX_SIDE:
        if (cli_count("--max-side", arg, 160, 100000, &n) != VF_OK)
            return VF_EINPUT;
        lo->max_side = (int)n;
        return VF_OK;
    }
    *handled = 0;
    return VF_OK;
}

void physical_viewpoint_text(const vf_viewpoint *v, char *out, size_t size)
{
    snprintf(out, size, "psi %.1f theta %.1f phi %.1f dx %.3f dy %.3f dz %.3f", v->psi, v->theta,
             v->phi, v->dx, v->dy, v->dz);
}
