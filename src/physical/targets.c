/* Adversarial viewpoints as places to stand, and guidance towards them (vf/targets.h). */
#include "vf/targets.h"

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vf/attack_file.h"
#include "vf/json.h"
#include "vf/workspace.h"

#define DEG (180.0 / M_PI)

/* ---- targets.json ---- */

vf_status vf_targets_file_target(const char *path, int n, vf_viewpoint *v)
{
    json_t *doc;
    vf_status status = vf_json_load(path, &doc);
    if (status != VF_OK)
        return status;
    const json_t *targets = json_object_get(doc, "targets");
    size_t count = json_array_size(targets);
    double a[6];
    int ok =
        n >= 0 && (size_t)n < count &&
        vf_json_read_view(json_object_get(json_array_get(targets, (size_t)n), "viewpoint"), a);
    json_decref(doc);
    if (!ok)
        return vf_fail(VF_EINPUT, "%s has no usable target %d (it lists %zu, from 0)", path, n,
                       count);
    *v = vf_viewpoint_from_array(a);
    return VF_OK;
}

vf_status vf_targets_workspace_target(const char *ws_root, int n, vf_viewpoint *v, double c2w[16])
{
    char path[VF_PATH_MAX];
    vf_status status = vf_path_join(path, sizeof path, ws_root, "export/targets.json");
    if (status == VF_OK && !vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s does not exist: run 'vfcapture export %s' first", path,
                       ws_root);
    if (status == VF_OK)
        status = vf_targets_file_target(path, n, v);
    if (status == VF_OK && c2w)
        vf_viewpoint_to_c2w(v, c2w);
    return status;
}

int vf_viewpoint_within(const vf_viewpoint *v, const vf_viewpoint *center, const double range[6],
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

/* ---- words ---- */

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

/* Camera position, forward (-z column) and up (y column) of a c2w. */
static void camera_axes(const double c2w[16], double p[3], double f[3], double u[3])
{
    for (int k = 0; k < 3; k++) {
        p[k] = c2w[4 * k + 3];
        f[k] = -c2w[4 * k + 2];
        u[k] = c2w[4 * k + 1];
    }
}

static double azimuth_of(const double p[3])
{
    return atan2(p[0], -p[1]) * DEG;
}

/* Roll: the angle about the forward axis from world up (projected) to the camera's up. */
static double roll_of(const double f[3], const double u[3])
{
    static const double z[3] = {0, 0, 1};
    double w[3], c[3], fz = dot3(z, f);
    for (int k = 0; k < 3; k++)
        w[k] = z[k] - fz * f[k];
    if (dot3(w, w) < 1e-12) /* looking straight up or down: no upright, no roll */
        return 0;
    cross3(w, u, c);
    return atan2(dot3(f, c), dot3(w, u)) * DEG;
}

void vf_target_describe(const double c2w[16], vf_target_words *out)
{
    double p[3], f[3], u[3];
    camera_axes(c2w, p, f, u);
    double d = sqrt(dot3(p, p));
    out->distance = d;
    out->height = p[2];
    out->azimuth_deg = azimuth_of(p);
    out->elevation_deg = d > 0 ? asin(p[2] / d) * DEG : 0;
    out->roll_deg = roll_of(f, u);
    double along = -dot3(p, f); /* the optical axis passes nearest the origin here */
    for (int k = 0; k < 3; k++)
        out->look_at[k] = p[k] + along * f[k];
    out->aim_offset = sqrt(dot3(out->look_at, out->look_at));
}

/* ---- spreading samples ---- */

static double view_distance(const double *a, const double *b, const double range[6])
{
    double s = 0;
    for (int i = 0; i < 6; i++) {
        double d = a[i] - b[i];
        if (i == 0)
            d = remainder(d, 360.0);
        d /= range[i];
        s += d * d;
    }
    return sqrt(s);
}

vf_status vf_targets_spread(const double *views, int n, const double range[6], int m,
                            int *picked)
{
    if (m > n)
        m = n;
    if (m <= 0)
        return VF_OK;
    double *nearest = malloc(sizeof(double) * (size_t)n);
    if (!nearest)
        return vf_fail(VF_EINTERNAL, "out of memory spreading %d viewpoints", n);
    int medoid = 0;
    double best = INFINITY;
    for (int i = 0; i < n; i++) {
        double sum = 0;
        for (int j = 0; j < n; j++)
            sum += view_distance(views + 6 * i, views + 6 * j, range);
        if (sum < best) {
            best = sum;
            medoid = i;
        }
    }
    picked[0] = medoid;
    for (int i = 0; i < n; i++)
        nearest[i] = view_distance(views + 6 * i, views + 6 * medoid, range);
    for (int k = 1; k < m; k++) {
        int far = 0;
        for (int i = 1; i < n; i++)
            if (nearest[i] > nearest[far])
                far = i;
        picked[k] = far;
        for (int i = 0; i < n; i++) {
            double d = view_distance(views + 6 * i, views + 6 * far, range);
            nearest[i] = d < nearest[i] ? d : nearest[i];
        }
    }
    free(nearest);
    return VF_OK;
}

/* ---- guidance ---- */

/* Where a camera aims, as angles off aiming at the object's centre from where it stands:
 * right and up of the line to the centre (with world up as up). */
static void aim_angles(const double c2w[16], double *pan_deg, double *tilt_deg)
{
    static const double z[3] = {0, 0, 1};
    double p[3], f[3], u[3], f0[3], r0[3], u0[3];
    camera_axes(c2w, p, f, u);
    double d = sqrt(dot3(p, p));
    for (int k = 0; k < 3; k++)
        f0[k] = d > 0 ? -p[k] / d : 0;
    cross3(f0, z, r0);
    double rn = sqrt(dot3(r0, r0));
    if (rn < 1e-9) { /* straight above or below the centre: no left or right */
        *pan_deg = 0;
        *tilt_deg = acos(fmax(-1, fmin(1, dot3(f, f0)))) * DEG;
        return;
    }
    for (int k = 0; k < 3; k++)
        r0[k] /= rn;
    cross3(r0, f0, u0);
    *pan_deg = atan2(dot3(f, r0), dot3(f, f0)) * DEG;
    *tilt_deg = atan2(dot3(f, u0), sqrt(dot3(f, f0) * dot3(f, f0) + dot3(f, r0) * dot3(f, r0))) *
                DEG;
}

void vf_advice_compute(const double current[16], const double target[16], vf_advice *out)
{
    vf_target_words now, goal;
    vf_target_describe(current, &now);
    vf_target_describe(target, &goal);
    out->orbit_deg = remainder(goal.azimuth_deg - now.azimuth_deg, 360.0);
    out->raise = goal.height - now.height;
    out->back = goal.distance - now.distance;
    out->roll_deg = remainder(goal.roll_deg - now.roll_deg, 360.0);
    /* Pan and tilt as aim off the object: a person keeps the object in view while orbiting,
     * rising and stepping, so "tilt up" must not count the tilt that lowering the camera
     * already gives (measured in the studio's closed loop: "lower 2.2 units, tilt 30 deg up"
     * from a camera aimed at the object turned the camera off it). */
    double pan_now, tilt_now, pan_goal, tilt_goal;
    aim_angles(current, &pan_now, &tilt_now);
    aim_angles(target, &pan_goal, &tilt_goal);
    out->pan_deg = remainder(pan_goal - pan_now, 360.0);
    out->tilt_deg = tilt_goal - tilt_now;
}

static size_t add_step(char *out, size_t size, size_t used, const char *text)
{
    if (used >= size)
        return used;
    int n = snprintf(out + used, size - used, "%s%s", used ? ", " : "", text);
    return n > 0 ? used + (size_t)n : used;
}

static void distance_text(double units, double metres_per_unit, char *out, size_t size)
{
    if (metres_per_unit > 0)
        snprintf(out, size, "%.0f cm", fabs(units) * metres_per_unit * 100);
    else
        snprintf(out, size, "%.2f units", fabs(units));
}

void vf_advice_text(const vf_advice *a, double metres_per_unit, double min_deg,
                    double min_distance, char *out, size_t size)
{
    char step[96], d[48];
    size_t used = 0;
    out[0] = 0;
    if (fabs(a->orbit_deg) >= min_deg) {
        snprintf(step, sizeof step, "orbit %.0f deg %s", fabs(a->orbit_deg),
                 a->orbit_deg > 0 ? "right" : "left");
        used = add_step(out, size, used, step);
    }
    if (fabs(a->raise) >= min_distance) {
        distance_text(a->raise, metres_per_unit, d, sizeof d);
        snprintf(step, sizeof step, "%s %s", a->raise > 0 ? "raise" : "lower", d);
        used = add_step(out, size, used, step);
    }
    if (fabs(a->back) >= min_distance) {
        distance_text(a->back, metres_per_unit, d, sizeof d);
        snprintf(step, sizeof step, "%s %s", a->back > 0 ? "step back" : "step closer", d);
        used = add_step(out, size, used, step);
    }
    if (fabs(a->pan_deg) >= min_deg) {
        snprintf(step, sizeof step, "turn %.0f deg %s", fabs(a->pan_deg),
                 a->pan_deg > 0 ? "right" : "left");
        used = add_step(out, size, used, step);
    }
    if (fabs(a->tilt_deg) >= min_deg) {
        snprintf(step, sizeof step, "tilt %.0f deg %s", fabs(a->tilt_deg),
                 a->tilt_deg > 0 ? "up" : "down");
        used = add_step(out, size, used, step);
    }
    if (fabs(a->roll_deg) >= min_deg) {
        snprintf(step, sizeof step, "roll %.0f deg %s", fabs(a->roll_deg),
                 a->roll_deg > 0 ? "clockwise" : "counterclockwise");
        used = add_step(out, size, used, step);
    }
    if (used == 0)
        snprintf(out, size, "hold still: on target");
}
