/* The object frame of a reconstructed scene: up, centre, azimuth reference and scale. */
#include "vf/normalize.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vf/stats.h"

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    double c[3] = {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                   a[0] * b[1] - a[1] * b[0]};
    memcpy(out, c, sizeof c);
}

static double normalize3(double v[3])
{
    double n = sqrt(dot3(v, v));
    if (n > 0)
        for (int k = 0; k < 3; k++)
            v[k] /= n;
    return n;
}

/* Column `col` of a c2w matrix's rotation: 0 camera right, 1 camera up, 2 camera back. */
static void c2w_axis(const double *c2w, int col, double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = c2w[4 * k + col];
}

static void c2w_position(const double *c2w, double out[3])
{
    for (int k = 0; k < 3; k++)
        out[k] = c2w[4 * k + 3];
}

/* How many cameras see `p` in front of them. */
static int cameras_facing(const double *c2w, int count, const double p[3])
{
    int facing = 0;
    for (int i = 0; i < count; i++) {
        double back[3], pos[3], d[3];
        c2w_axis(c2w + 16 * i, 2, back);
        c2w_position(c2w + 16 * i, pos);
        for (int k = 0; k < 3; k++)
            d[k] = p[k] - pos[k];
        facing += dot3(d, back) < 0;
    }
    return facing;
}

/* Least-squares point nearest to every optical axis: sum_i (I - d_i d_i^T)(p - c_i) = 0.
 * Returns 0 when the axes are (nearly) parallel or the point is behind most cameras. */
static int center_from_axes(const double *c2w, int count, double center[3])
{
    double a[9] = {0}, b[3] = {0};
    for (int i = 0; i < count; i++) {
        double d[3], c[3];
        c2w_axis(c2w + 16 * i, 2, d);
        c2w_position(c2w + 16 * i, c);
        for (int r = 0; r < 3; r++)
            for (int k = 0; k < 3; k++) {
                double m = (r == k) - d[r] * d[k];
                a[3 * r + k] += m;
                b[r] += m * c[k];
            }
    }
    double det = vf_mat3_det(a);
    if (!(det > 1e-4 * count * count * count))
        return 0;
    /* Cramer's rule: replace column k by b. */
    for (int k = 0; k < 3; k++) {
        double m[9];
        memcpy(m, a, sizeof m);
        for (int r = 0; r < 3; r++)
            m[3 * r + k] = b[r];
        center[k] = vf_mat3_det(m) / det;
    }
    return 2 * cameras_facing(c2w, count, center) > count;
}

/* Per-axis median of the sparse points that at least half of the cameras face. */
static int center_from_points(const double *c2w, int count, const double *points, int point_count,
                              double center[3])
{
    if (point_count <= 0)
        return 0;
    double *axes = malloc((size_t)point_count * 3 * sizeof *axes); /* x values, y values, z values */
    if (!axes)
        return 0;
    int n = 0;
    for (int i = 0; i < point_count; i++) {
        if (2 * cameras_facing(c2w, count, points + 3 * i) < count)
            continue;
        for (int k = 0; k < 3; k++)
            axes[k * point_count + n] = points[3 * i + k];
        n++;
    }
    for (int k = 0; n > 0 && k < 3; k++) {
        vf_sort_doubles(axes + k * point_count, n);
        center[k] = vf_sorted_quantile(axes + k * point_count, n, 0.5);
    }
    free(axes);
    return n > 0;
}

/* The azimuth reference: the horizontal direction from the centre towards the cameras (their
 * mean when they cluster on one side, else the first camera's). It becomes -y, where the
 * viewpoint puts psi = 0 for upright views (phi > 90). */
static void azimuth_reference(const double *c2w, int count, const double center[3],
                              const double up[3], double toward[3])
{
    double mean[3] = {0}, first[3] = {0};
    for (int i = 0; i < count; i++) {
        double d[3];
        c2w_position(c2w + 16 * i, d);
        for (int k = 0; k < 3; k++)
            d[k] -= center[k];
        double along = dot3(d, up);
        for (int k = 0; k < 3; k++)
            d[k] -= along * up[k];
        normalize3(d);
        if (i == 0)
            memcpy(first, d, sizeof first);
        for (int k = 0; k < 3; k++)
            mean[k] += d[k] / count;
    }
    memcpy(toward, sqrt(dot3(mean, mean)) > 0.5 ? mean : first, 3 * sizeof *toward);
    if (normalize3(toward) == 0) { /* every camera straight above: any horizontal axis */
        double helper[3] = {fabs(up[0]) < 0.9, fabs(up[0]) >= 0.9, 0};
        cross3(up, helper, toward);
        normalize3(toward);
    }
}

/* Up. Photos are taken level: each camera's x axis (image right) is horizontal however the
 * camera is tilted, so up is perpendicular to all of them: the sum of r_i x r_j over pairs,
 * each turned to agree with the mean camera up. That needs cameras facing different ways
 * (mean |r_i x r_j| = sine of the spread); for a narrow arc the mean camera up is used, which
 * leans towards the object when the cameras look down on it. Returns the method. */
static const char *find_up(const double *c2w, int count, double up[3])
{
    double mean_up[3] = {0}, sum[3] = {0}, spread = 0;
    for (int i = 0; i < count; i++) {
        double u[3], ri[3];
        c2w_axis(c2w + 16 * i, 1, u);
        c2w_axis(c2w + 16 * i, 0, ri);
        for (int k = 0; k < 3; k++)
            mean_up[k] += u[k];
        for (int j = i + 1; j < count; j++) {
            double rj[3], x[3];
            c2w_axis(c2w + 16 * j, 0, rj);
            cross3(ri, rj, x);
            spread += sqrt(dot3(x, x));
            double sign = dot3(x, u) < 0 ? -1 : 1; /* camera i's up decides the sign */
            for (int k = 0; k < 3; k++)
                sum[k] += sign * x[k];
        }
    }
    normalize3(mean_up);
    spread /= 0.5 * count * (count - 1);
    memcpy(up, mean_up, sizeof mean_up);
    if (spread < 0.25 || normalize3(sum) == 0 || dot3(sum, mean_up) < 0.5)
        return "mean camera up";
    memcpy(up, sum, sizeof sum);
    return "level camera x axes";
}

vf_status vf_normalize_scene(const double *c2w_gl, int count, const double *points,
                             int point_count, vf_normalization *out)
{
    memset(out, 0, sizeof *out);
    if (count < 2)
        return vf_fail(VF_EINPUT, "need at least 2 cameras to find the object frame");
    double up[3], mean_up[3] = {0};
    for (int i = 0; i < count; i++) {
        double u[3];
        c2w_axis(c2w_gl + 16 * i, 1, u);
        for (int k = 0; k < 3; k++)
            mean_up[k] += u[k] / count;
    }
    if (normalize3(mean_up) < 0.1)
        return vf_fail(VF_EINPUT, "the cameras' up directions cancel out: cannot tell which way "
                                  "is up (were the photos taken upright?)");
    out->up_method = find_up(c2w_gl, count, up);
    out->center_method = "optical axes";
    if (!center_from_axes(c2w_gl, count, out->center_world)) {
        out->center_method = "sparse points";
        if (!center_from_points(c2w_gl, count, points, point_count, out->center_world))
            return vf_fail(VF_EINPUT, "cannot find the object: the cameras' optical axes do not "
                                      "converge and no sparse point lies in front of them");
    }
    double distance = 0;
    for (int i = 0; i < count; i++) {
        double c[3];
        c2w_position(c2w_gl + 16 * i, c);
        for (int k = 0; k < 3; k++)
            c[k] -= out->center_world[k];
        distance += sqrt(dot3(c, c)) / count;
    }
    if (!(distance > 0))
        return vf_fail(VF_EINPUT, "all cameras sit at the same point: cannot set the scale");

    double x_axis[3], y_axis[3], toward[3];
    azimuth_reference(c2w_gl, count, out->center_world, up, toward);
    for (int k = 0; k < 3; k++)
        y_axis[k] = -toward[k];
    cross3(y_axis, up, x_axis);
    vf_similarity *s = &out->object_from_world;
    s->scale = VF_CAMERA_DISTANCE / distance;
    for (int k = 0; k < 3; k++) {
        s->R[k] = x_axis[k];
        s->R[3 + k] = y_axis[k];
        s->R[6 + k] = up[k];
    }
    double rc[3];
    vf_mat3_apply(s->R, out->center_world, rc);
    for (int k = 0; k < 3; k++)
        s->t[k] = -s->scale * rc[k];
    memcpy(out->up_world, up, sizeof up);
    out->world_distance = distance;
    return VF_OK;
}
