/* The viewpoint box a capture covers and a viewpoint's gap to its photos (vf/view_coverage.h). */
#include "vf/view_coverage.h"

#include <math.h>
#include <stdlib.h>

#include "vf/pose.h"
#include "vf/stats.h"

#define FULL_CIRCLE_GAP 60.0 /* a largest yaw gap below this means the cameras surround it */

/* Covered yaw arc [lo, hi] (hi may exceed 180): complement of the largest gap. */
static void yaw_arc(double *psi, int n, double *lo, double *hi)
{
    vf_sort_doubles(psi, n);
    int gap_after = n - 1; /* the wrap-around gap, from the last angle to the first + 360 */
    double gap = psi[0] + 360.0 - psi[n - 1];
    for (int i = 0; i + 1 < n; i++)
        if (psi[i + 1] - psi[i] > gap) {
            gap = psi[i + 1] - psi[i];
            gap_after = i;
        }
    if (gap < FULL_CIRCLE_GAP) {
        *lo = -180.0;
        *hi = 180.0;
        return;
    }
    *lo = psi[(gap_after + 1) % n];
    *hi = psi[gap_after];
    if (*hi < *lo)
        *hi += 360.0;
}

vf_status vf_view_coverage(const double *c2w, int count, vf_view_bounds *out)
{
    if (count < 2)
        return vf_fail(VF_EINPUT, "%d camera(s): the covered viewpoints need at least 2", count);
    double *psi = malloc((size_t)count * sizeof *psi);
    if (!psi)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        out->lo[i] = INFINITY;
        out->hi[i] = -INFINITY;
    }
    for (int j = 0; j < count; j++) {
        vf_viewpoint v;
        double a[VF_VIEW_DIM];
        vf_c2w_to_viewpoint(c2w + 16 * (size_t)j, &v);
        vf_viewpoint_to_array(&v, a);
        psi[j] = a[0];
        for (int i = 1; i < VF_VIEW_DIM; i++) {
            out->lo[i] = fmin(out->lo[i], a[i]);
            out->hi[i] = fmax(out->hi[i], a[i]);
        }
    }
    yaw_arc(psi, count, &out->lo[0], &out->hi[0]);
    free(psi);
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        if (i == 0 && out->hi[0] - out->lo[0] >= 360.0)
            continue;
        double floor = i < 3 ? VF_COVERAGE_MIN_DEG : VF_COVERAGE_MIN_UNITS;
        double margin = fmax(VF_COVERAGE_MARGIN * (out->hi[i] - out->lo[i]), floor);
        out->lo[i] -= margin;
        out->hi[i] += margin;
    }
    if (out->hi[0] - out->lo[0] > 360.0) {
        double mid = 0.5 * (out->lo[0] + out->hi[0]);
        out->lo[0] = mid - 180.0;
        out->hi[0] = mid + 180.0;
    }
    out->lo[1] = fmax(out->lo[1], -89.0);
    out->hi[1] = fmin(out->hi[1], 89.0);
    return VF_OK;
}

/* A camera's centre: its distance from the object and the unit direction to it. */
static double centre_direction(const double c2w[16], double dir[3])
{
    double r = sqrt(c2w[3] * c2w[3] + c2w[7] * c2w[7] + c2w[11] * c2w[11]);
    for (int k = 0; k < 3; k++)
        dir[k] = r > 0 ? c2w[4 * k + 3] / r : 0;
    return r;
}

vf_view_trust vf_view_trust_of_pose(const double *photos, int count, const double c2w[16])
{
    double dir[3], best = INFINITY;
    double r = centre_direction(c2w, dir);
    vf_view_trust t = {.gap_deg = INFINITY, .nearest = -1};
    for (int i = 0; i < count; i++) {
        double d[3];
        double ri = centre_direction(photos + 16 * (size_t)i, d);
        double cosine = fmax(-1.0, fmin(1.0, dir[0] * d[0] + dir[1] * d[1] + dir[2] * d[2]));
        double angle = acos(cosine), scale = log(fmax(r, 1e-9) / fmax(ri, 1e-9));
        double gap = angle * angle + scale * scale;
        if (gap < best) {
            best = gap;
            t = (vf_view_trust){.gap_deg = sqrt(gap) * 180 / M_PI,
                                .nearest = i,
                                .angle_deg = angle * 180 / M_PI,
                                .distance_ratio = ri > 0 ? r / ri : INFINITY};
        }
    }
    return t;
}

vf_view_trust vf_view_trust_of(const double *photos, int count, const double view[VF_VIEW_DIM])
{
    vf_viewpoint v = vf_viewpoint_from_array(view);
    double c2w[16];
    vf_viewpoint_to_c2w(&v, c2w);
    return vf_view_trust_of_pose(photos, count, c2w);
}

int vf_view_trusted(const vf_view_trust *t) { return t->gap_deg <= VF_TRUST_GAP_DEG; }
