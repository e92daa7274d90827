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
        if (cli_parse_int(arg, 6, 100000, &n))
            return vf_fail(VF_EINPUT, "--min-inliers: give a number from 6 to 100000");
        lo->min_inliers = (int)n;
        return VF_OK;
    case PHYS_OPT_MIN_INLIER_RATIO:
        if (cli_parse_doubles(arg, &x, 1) != 1 || !(x > 0 && x <= 1))
            return vf_fail(VF_EINPUT, "--min-inlier-ratio: give a share in (0, 1], e.g. 0.2");
        lo->min_inlier_ratio = x;
        return VF_OK;
    case PHYS_OPT_MAX_FEATURES:
        if (cli_parse_int(arg, 100, 100000, &n))
            return vf_fail(VF_EINPUT, "--max-features: give a number from 100 to 100000");
        lo->max_features = (int)n;
        return VF_OK;
    case PHYS_OPT_MAX_SIDE:
        if (cli_parse_int(arg, 160, 100000, &n))
            return vf_fail(VF_EINPUT, "--max-side: give a number of pixels from 160 up");
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
