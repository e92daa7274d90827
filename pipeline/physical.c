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

json_t *physical_mat4_json(const double m[16])
{
    json_t *rows = json_array();
    for (int r = 0; r < 4; r++)
        json_array_append_new(rows, json_pack("[f,f,f,f]", m[4 * r], m[4 * r + 1], m[4 * r + 2],
                                              m[4 * r + 3]));
    return rows;
}

json_t *physical_viewpoint_json(const vf_viewpoint *v)
{
    return json_pack("[f,f,f,f,f,f]", v->psi, v->theta, v->phi, v->dx, v->dy, v->dz);
}

json_t *physical_result_json(const vf_localize_result *r)
{
    json_t *o = json_pack("{s:b, s:i, s:i, s:i, s:f, s:f, s:f}", "localized", r->localized,
                          "features", r->features, "matches", r->matches, "inliers", r->inliers,
                          "inlier_ratio", r->inlier_ratio, "reprojection_px", r->reprojection_px,
                          "seconds", r->seconds);
    if (!r->localized) {
        json_object_set_new(o, "reason", json_string(r->reason));
        return o;
    }
    json_object_set_new(o, "viewpoint", physical_viewpoint_json(&r->viewpoint));
    json_object_set_new(o, "c2w_object", physical_mat4_json(r->c2w_object));
    json_object_set_new(o, "c2w_colmap", physical_mat4_json(r->c2w_colmap));
    return o;
}

void physical_viewpoint_text(const vf_viewpoint *v, char *out, size_t size)
{
    snprintf(out, size, "psi %.1f theta %.1f phi %.1f dx %.3f dy %.3f dz %.3f", v->psi, v->theta,
             v->phi, v->dx, v->dy, v->dz);
}

int physical_within_box(const vf_viewpoint *v, const vf_viewpoint *center, const double range[6],
                        double tolerance, double *worst)
{
    double a[6], c[6], largest = 0;
    vf_viewpoint_to_array(v, a);
    vf_viewpoint_to_array(center, c);
    for (int i = 0; i < 6; i++) {
        double d = a[i] - c[i];
        if (i == 0)
            d = remainder(d, 360.0);
        double share = fabs(d) / range[i];
        largest = share > largest ? share : largest;
    }
    if (worst)
        *worst = largest;
    return largest <= tolerance;
}

vf_status physical_load_target(const char *ws, int n, vf_viewpoint *v, double c2w[16])
{
    char path[VF_PATH_MAX];
    vf_status status = vf_path_join(path, sizeof path, ws, "export/targets.json");
    if (status == VF_OK && !vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s does not exist: run 'vfcapture export %s' first", path, ws);
    if (status == VF_OK)
        status = vf_targets_file_target(path, n, v);
    if (status == VF_OK && c2w)
        vf_viewpoint_to_c2w(v, c2w);
    return status;
}
