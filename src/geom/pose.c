/* Rigid and similarity geometry, camera axes and the ViewFool viewpoint (see vf/pose.h). */
#include "vf/pose.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vf/json.h"
#include "vf/stats.h"

static const double PI = 3.14159265358979323846;

static double deg2rad(double deg) { return deg * (PI / 180.0); }
static double rad2deg(double rad) { return rad * (180.0 / PI); }

/* ---- 3x3 ---- */

void vf_mat3_identity(double out[9])
{
    memset(out, 0, 9 * sizeof *out);
    out[0] = out[4] = out[8] = 1.0;
}

void vf_mat3_mul(const double a[9], const double b[9], double out[9])
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[3 * i + j] = a[3 * i] * b[j] + a[3 * i + 1] * b[3 + j] + a[3 * i + 2] * b[6 + j];
    memcpy(out, r, sizeof r);
}

void vf_mat3_transpose(const double a[9], double out[9])
{
    double r[9];
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            r[3 * i + j] = a[3 * j + i];
    memcpy(out, r, sizeof r);
}

void vf_mat3_apply(const double a[9], const double p[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = a[3 * i] * p[0] + a[3 * i + 1] * p[1] + a[3 * i + 2] * p[2];
    memcpy(out, r, sizeof r);
}

double vf_mat3_det(const double a[9])
{
    return a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) +
           a[2] * (a[3] * a[7] - a[4] * a[6]);
}

static void set3x3(double out[9], double a, double b, double c, double d, double e, double f,
                   double g, double h, double i)
{
    out[0] = a, out[1] = b, out[2] = c;
    out[3] = d, out[4] = e, out[5] = f;
    out[6] = g, out[7] = h, out[8] = i;
}

void vf_rot_x(double angle, double out[9])
{
    double c = cos(angle), s = sin(angle);
    set3x3(out, 1, 0, 0, 0, c, -s, 0, s, c);
}

void vf_rot_y(double angle, double out[9])
{
    double c = cos(angle), s = sin(angle);
    set3x3(out, c, 0, s, 0, 1, 0, -s, 0, c);
}

void vf_rot_z(double angle, double out[9])
{
    double c = cos(angle), s = sin(angle);
    set3x3(out, c, -s, 0, s, c, 0, 0, 0, 1);
}

void vf_rot_from_quat(const double q[4], double out[9])
{
    double n = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    if (n == 0.0) {
        vf_mat3_identity(out);
        return;
    }
    double w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
    set3x3(out, 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
           2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
           2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y));
}

/* Shepperd's method: build the quaternion from its largest component, which is never small,
 * so the division is well conditioned for every rotation. */
void vf_rot_to_quat(const double r[9], double q[4])
{
    double trace = r[0] + r[4] + r[8];
    double w, x, y, z;
    if (trace >= r[0] && trace >= r[4] && trace >= r[8]) {
        double s = 2.0 * sqrt(1.0 + trace); /* s = 4w */
        w = s / 4, x = (r[7] - r[5]) / s, y = (r[2] - r[6]) / s, z = (r[3] - r[1]) / s;
    } else if (r[0] >= r[4] && r[0] >= r[8]) {
        double s = 2.0 * sqrt(1.0 + r[0] - r[4] - r[8]); /* s = 4x */
        w = (r[7] - r[5]) / s, x = s / 4, y = (r[1] + r[3]) / s, z = (r[2] + r[6]) / s;
    } else if (r[4] >= r[8]) {
        double s = 2.0 * sqrt(1.0 + r[4] - r[0] - r[8]); /* s = 4y */
        w = (r[2] - r[6]) / s, x = (r[1] + r[3]) / s, y = s / 4, z = (r[5] + r[7]) / s;
    } else {
        double s = 2.0 * sqrt(1.0 + r[8] - r[0] - r[4]); /* s = 4z */
        w = (r[3] - r[1]) / s, x = (r[2] + r[6]) / s, y = (r[5] + r[7]) / s, z = s / 4;
    }
    double sign = w < 0 ? -1.0 : 1.0;
    double n = sqrt(w * w + x * x + y * y + z * z);
    q[0] = sign * w / n, q[1] = sign * x / n, q[2] = sign * y / n, q[3] = sign * z / n;
}

void vf_rot_from_axis_angle(const double v[3], double out[9])
{
    double angle = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    /* sin(angle/2)/angle, by its Taylor series where the division would lose precision */
    double k = angle < 1e-4 ? 0.5 - angle * angle / 48.0 : sin(angle / 2) / angle;
    double q[4] = {cos(angle / 2), k * v[0], k * v[1], k * v[2]};
    vf_rot_from_quat(q, out);
}

void vf_rot_to_axis_angle(const double rot[9], double v[3])
{
    double q[4];
    vf_rot_to_quat(rot, q); /* w >= 0, so the angle is in [0, pi] */
    double sin_half = sqrt(q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    double angle = 2.0 * atan2(sin_half, q[0]);
    double k = sin_half < 1e-12 ? 2.0 / q[0] : angle / sin_half;
    v[0] = k * q[1], v[1] = k * q[2], v[2] = k * q[3];
}

double vf_rot_angle_deg(const double a[9], const double b[9])
{
    double at[9], rel[9];
    vf_mat3_transpose(a, at);
    vf_mat3_mul(at, b, rel);
    /* atan2(2 sin, 2 cos) stays accurate near 0 and 180 degrees, where acos does not */
    double sx = rel[7] - rel[5], sy = rel[2] - rel[6], sz = rel[3] - rel[1];
    double two_sin = sqrt(sx * sx + sy * sy + sz * sz);
    double two_cos = rel[0] + rel[4] + rel[8] - 1.0;
    return rad2deg(atan2(two_sin, two_cos));
}

/* ---- symmetric eigenvectors (Jacobi), for Horn's method and the collinearity test ---- */

/* Eigen-decomposition of a symmetric n x n matrix (n <= 4, row-major, destroyed): eigenvalues
 * in `values`, eigenvector k in column k of `vectors`. */
static void jacobi_eigen(double *a, int n, double *values, double *vectors)
{
    for (int i = 0; i < n; i++)
        for (int j = 0; j < n; j++)
            vectors[n * i + j] = i == j;
    for (int sweep = 0; sweep < 64; sweep++) {
        double off = 0.0, total = 0.0;
        for (int i = 0; i < n; i++)
            for (int j = 0; j < n; j++) {
                double sq = a[n * i + j] * a[n * i + j];
                if (i == j)
                    total += sq;
                else
                    off += sq;
            }
        if (off <= 1e-30 * (total + off) || off == 0.0)
            break;
        for (int p = 0; p < n; p++) {
            for (int q = p + 1; q < n; q++) {
                double apq = a[n * p + q];
                if (apq == 0.0)
                    continue;
                /* the rotation angle that zeroes a[p][q] */
                double tau = (a[n * q + q] - a[n * p + p]) / (2.0 * apq);
                double t = (tau >= 0 ? 1.0 : -1.0) / (fabs(tau) + sqrt(1.0 + tau * tau));
                double c = 1.0 / sqrt(1.0 + t * t), s = t * c;
                for (int k = 0; k < n; k++) { /* columns p, q */
                    double akp = a[n * k + p], akq = a[n * k + q];
                    a[n * k + p] = c * akp - s * akq;
                    a[n * k + q] = s * akp + c * akq;
                }
                for (int k = 0; k < n; k++) { /* rows p, q */
                    double apk = a[n * p + k], aqk = a[n * q + k];
                    a[n * p + k] = c * apk - s * aqk;
                    a[n * q + k] = s * apk + c * aqk;
                }
                for (int k = 0; k < n; k++) {
                    double vkp = vectors[n * k + p], vkq = vectors[n * k + q];
                    vectors[n * k + p] = c * vkp - s * vkq;
                    vectors[n * k + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    for (int i = 0; i < n; i++)
        values[i] = a[n * i + i];
}

/* The rotation R maximizing trace(R^T m) = sum m_ij R_ij (Horn 1987): the eigenvector of the
 * largest eigenvalue of a symmetric 4x4 matrix built from m is R's quaternion. This is the
 * nearest rotation to m and, with m a cross-covariance, the best-fit rotation; unlike a plain
 * SVD it never returns a reflection. */
static void best_rotation(const double m[9], double out[9])
{
    /* s = m^T, so that s[a][b] pairs source axis a with target axis b as in Horn's paper */
    double xx = m[0], xy = m[3], xz = m[6];
    double yx = m[1], yy = m[4], yz = m[7];
    double zx = m[2], zy = m[5], zz = m[8];
    double n[16] = {xx + yy + zz, yz - zy,       zx - xz,       xy - yx,
                    yz - zy,      xx - yy - zz,  xy + yx,       zx + xz,
                    zx - xz,      xy + yx,       -xx + yy - zz, yz + zy,
                    xy - yx,      zx + xz,       yz + zy,       -xx - yy + zz};
    double values[4], vectors[16];
    jacobi_eigen(n, 4, values, vectors);
    int best = 0;
    for (int k = 1; k < 4; k++)
        if (values[k] > values[best])
            best = k;
    double q[4] = {vectors[best], vectors[4 + best], vectors[8 + best], vectors[12 + best]};
    vf_rot_from_quat(q, out);
}

void vf_rot_orthonormalize(const double m[9], double out[9]) { best_rotation(m, out); }

/* ---- 4x4 ---- */

void vf_mat4_identity(double out[16])
{
    memset(out, 0, 16 * sizeof *out);
    out[0] = out[5] = out[10] = out[15] = 1.0;
}

void vf_mat4_mul(const double a[16], const double b[16], double out[16])
{
    double r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double sum = 0.0;
            for (int k = 0; k < 4; k++)
                sum += a[4 * i + k] * b[4 * k + j];
            r[4 * i + j] = sum;
        }
    memcpy(out, r, sizeof r);
}

void vf_mat4_from_rt(const double rot[9], const double t[3], double out[16])
{
    double r[16] = {rot[0], rot[1], rot[2], t[0], rot[3], rot[4], rot[5], t[1],
                    rot[6], rot[7], rot[8], t[2], 0,      0,      0,      1};
    memcpy(out, r, sizeof r);
}

void vf_mat4_rotation(const double m[16], double rot[9])
{
    for (int i = 0; i < 3; i++)
        for (int j = 0; j < 3; j++)
            rot[3 * i + j] = m[4 * i + j];
}

void vf_mat4_translation(const double m[16], double t[3])
{
    t[0] = m[3], t[1] = m[7], t[2] = m[11];
}

void vf_mat4_transform_point(const double m[16], const double p[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = m[4 * i] * p[0] + m[4 * i + 1] * p[1] + m[4 * i + 2] * p[2] + m[4 * i + 3];
    memcpy(out, r, sizeof r);
}

void vf_mat4_transform_dir(const double m[16], const double d[3], double out[3])
{
    double r[3];
    for (int i = 0; i < 3; i++)
        r[i] = m[4 * i] * d[0] + m[4 * i + 1] * d[1] + m[4 * i + 2] * d[2];
    memcpy(out, r, sizeof r);
}

/* [a t] -> [a_inv, -a_inv t] for a 3x3 block whose inverse is given. */
static void inverse_from_block(const double m[16], const double block_inv[9], double out[16])
{
    double t[3], t_inv[3];
    vf_mat4_translation(m, t);
    vf_mat3_apply(block_inv, t, t_inv);
    for (int i = 0; i < 3; i++)
        t_inv[i] = -t_inv[i];
    vf_mat4_from_rt(block_inv, t_inv, out);
}

void vf_mat4_rigid_inverse(const double m[16], double out[16])
{
    double rot[9], rot_t[9];
    vf_mat4_rotation(m, rot);
    vf_mat3_transpose(rot, rot_t);
    inverse_from_block(m, rot_t, out);
}

void vf_mat4_similarity_inverse(const double m[16], double out[16])
{
    double block[9], block_inv[9];
    vf_mat4_rotation(m, block);
    double s2 = block[0] * block[0] + block[3] * block[3] + block[6] * block[6]; /* scale^2 */
    vf_mat3_transpose(block, block_inv); /* (s R)^-1 = R^T / s = (s R)^T / s^2 */
    for (int i = 0; i < 9; i++)
        block_inv[i] /= s2;
    inverse_from_block(m, block_inv, out);
}

vf_status vf_mat4_inverse(const double m[16], double out[16])
{
    double a[16], inv[16];
    memcpy(a, m, sizeof a);
    vf_mat4_identity(inv);
    for (int col = 0; col < 4; col++) {
        int pivot = col;
        for (int row = col + 1; row < 4; row++)
            if (fabs(a[4 * row + col]) > fabs(a[4 * pivot + col]))
                pivot = row;
        if (fabs(a[4 * pivot + col]) < 1e-300)
            return vf_fail(VF_EINPUT, "cannot invert a singular 4x4 matrix");
        for (int k = 0; k < 4; k++) { /* swap rows col and pivot */
            double t = a[4 * col + k];
            a[4 * col + k] = a[4 * pivot + k], a[4 * pivot + k] = t;
            t = inv[4 * col + k];
            inv[4 * col + k] = inv[4 * pivot + k], inv[4 * pivot + k] = t;
        }
        double d = a[4 * col + col];
        for (int k = 0; k < 4; k++)
            a[4 * col + k] /= d, inv[4 * col + k] /= d;
        for (int row = 0; row < 4; row++) {
            if (row == col)
                continue;
            double f = a[4 * row + col];
            for (int k = 0; k < 4; k++)
                a[4 * row + k] -= f * a[4 * col + k], inv[4 * row + k] -= f * inv[4 * col + k];
        }
    }
    memcpy(out, inv, sizeof inv);
    return VF_OK;
}

/* ---- camera axes ---- */

void vf_c2w_cv_to_gl(const double c2w_cv[16], double c2w_gl[16])
{
    double r[16];
    memcpy(r, c2w_cv, sizeof r);
    for (int row = 0; row < 3; row++) /* times diag(1, -1, -1, 1) on the right */
        r[4 * row + 1] = -r[4 * row + 1], r[4 * row + 2] = -r[4 * row + 2];
    memcpy(c2w_gl, r, sizeof r);
}

void vf_c2w_gl_to_cv(const double c2w_gl[16], double c2w_cv[16])
{
    vf_c2w_cv_to_gl(c2w_gl, c2w_cv);
}

void vf_w2c_cv_to_c2w_gl(const double rot[9], const double t[3], double c2w_gl[16])
{
    double w2c[16], c2w_cv[16];
    vf_mat4_from_rt(rot, t, w2c);
    vf_mat4_rigid_inverse(w2c, c2w_cv);
    vf_c2w_cv_to_gl(c2w_cv, c2w_gl);
}

void vf_c2w_gl_to_w2c_cv(const double c2w_gl[16], double rot[9], double t[3])
{
    double c2w_cv[16], w2c[16];
    vf_c2w_gl_to_cv(c2w_gl, c2w_cv);
    vf_mat4_rigid_inverse(c2w_cv, w2c);
    vf_mat4_rotation(w2c, rot);
    vf_mat4_translation(w2c, t);
}

/* ---- similarity transforms ---- */

vf_similarity vf_similarity_identity(void)
{
    vf_similarity s = {.scale = 1.0};
    vf_mat3_identity(s.R);
    return s;
}

void vf_similarity_apply(const vf_similarity *s, const double p[3], double out[3])
{
    double r[3];
    vf_mat3_apply(s->R, p, r);
    for (int i = 0; i < 3; i++)
        out[i] = s->scale * r[i] + s->t[i];
}

void vf_similarity_apply_c2w(const vf_similarity *s, const double c2w[16], double out[16])
{
    double rot[9], pos[3];
    vf_mat4_rotation(c2w, rot);
    vf_mat4_translation(c2w, pos);
    vf_mat3_mul(s->R, rot, rot);
    vf_similarity_apply(s, pos, pos);
    vf_mat4_from_rt(rot, pos, out);
}

vf_similarity vf_similarity_inverse(const vf_similarity *s)
{
    /* x = (1/s) R^T (x' - t) */
    vf_similarity inv = {.scale = 1.0 / s->scale};
    vf_mat3_transpose(s->R, inv.R);
    vf_mat3_apply(inv.R, s->t, inv.t);
    for (int i = 0; i < 3; i++)
        inv.t[i] = -inv.scale * inv.t[i];
    return inv;
}

vf_similarity vf_similarity_compose(const vf_similarity *second, const vf_similarity *first)
{
    /* s2 R2 (s1 R1 x + t1) + t2 */
    vf_similarity c = {.scale = second->scale * first->scale};
    vf_mat3_mul(second->R, first->R, c.R);
    vf_similarity_apply(second, first->t, c.t);
    return c;
}

void vf_similarity_to_mat4(const vf_similarity *s, double out[16])
{
    double block[9];
    for (int i = 0; i < 9; i++)
        block[i] = s->scale * s->R[i];
    vf_mat4_from_rt(block, s->t, out);
}

static void centroid(const double *p, int n, double c[3])
{
    c[0] = c[1] = c[2] = 0.0;
    for (int i = 0; i < n; i++)
        for (int k = 0; k < 3; k++)
            c[k] += p[3 * i + k] / n;
}

vf_status vf_similarity_umeyama(const double *src, const double *dst, int n, vf_similarity *out)
{
    if (n < 3)
        return vf_fail(VF_EINPUT, "need at least 3 point pairs to fit a similarity, got %d", n);
    double mu_src[3], mu_dst[3];
    centroid(src, n, mu_src);
    centroid(dst, n, mu_dst);

    /* cross-covariance m = sum (dst - mu_dst)(src - mu_src)^T, spread of src, and its
     * covariance (to reject collinear sources) */
    double m[9] = {0}, cov[9] = {0}, var_src = 0.0;
    for (int i = 0; i < n; i++) {
        double a[3], b[3];
        for (int k = 0; k < 3; k++)
            a[k] = src[3 * i + k] - mu_src[k], b[k] = dst[3 * i + k] - mu_dst[k];
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++)
                m[3 * r + c] += b[r] * a[c], cov[3 * r + c] += a[r] * a[c];
        var_src += a[0] * a[0] + a[1] * a[1] + a[2] * a[2];
    }
    double values[3], vectors[9];
    jacobi_eigen(cov, 3, values, vectors);
    double largest = fmax(values[0], fmax(values[1], values[2]));
    double middle = values[0] + values[1] + values[2] - largest -
                    fmin(values[0], fmin(values[1], values[2]));
    if (!(largest > 0.0) || middle <= 1e-12 * largest)
        return vf_fail(VF_EINPUT, "the %d source points are collinear or coincide: cannot fit a "
                                  "rotation to them", n);

    vf_similarity s;
    best_rotation(m, s.R);
    double fit = 0.0; /* trace(R^T m), the maximized correlation */
    for (int i = 0; i < 9; i++)
        fit += s.R[i] * m[i];
    s.scale = fit / var_src;
    double r_mu[3];
    vf_mat3_apply(s.R, mu_src, r_mu);
    for (int k = 0; k < 3; k++)
        s.t[k] = mu_dst[k] - s.scale * r_mu[k];
    *out = s;
    return VF_OK;
}

static double distance3(const double a[3], const double b[3])
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

vf_status vf_pose_compare(const double *const *ours, const double *const *ref, int n,
                          double distance, vf_pose_agreement *out)
{
    *out = (vf_pose_agreement){.count = n};
    if (n < 3)
        return vf_fail(VF_EINPUT, "need at least 3 cameras to compare poses, got %d", n);
    double *src = malloc(sizeof(double) * 3 * (size_t)n);
    double *dst = malloc(sizeof(double) * 3 * (size_t)n);
    double *rot = malloc(sizeof(double) * (size_t)n), *pos = malloc(sizeof(double) * (size_t)n);
    vf_similarity align;
    vf_status status = src && dst && rot && pos ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < n; i++) {
        vf_mat4_translation(ref[i], src + 3 * i);
        vf_mat4_translation(ours[i], dst + 3 * i);
    }
    if (status == VF_OK)
        status = vf_similarity_umeyama(src, dst, n, &align);
    if (status == VF_OK && distance <= 0) {
        double c[3];
        centroid(dst, n, c);
        distance = 0;
        for (int i = 0; i < n; i++)
            distance += distance3(dst + 3 * i, c) / n;
    }
    for (int i = 0; status == VF_OK && i < n; i++) {
        double moved[16], r_ours[9], r_ref[9], p[3];
        vf_similarity_apply_c2w(&align, ref[i], moved);
        vf_mat4_rotation(moved, r_ref);
        vf_mat4_rotation(ours[i], r_ours);
        rot[i] = vf_rot_angle_deg(r_ours, r_ref);
        out->rot_over_5deg += rot[i] > 5.0;
        vf_mat4_translation(moved, p);
        pos[i] = distance > 0 ? distance3(p, dst + 3 * i) / distance : 0;
    }
    if (status == VF_OK) {
        vf_sort_doubles(rot, n);
        vf_sort_doubles(pos, n);
        out->rot_median = vf_sorted_quantile(rot, n, 0.5);
        out->rot_p90 = vf_sorted_quantile(rot, n, 0.9);
        out->rot_max = rot[n - 1];
        out->pos_median = vf_sorted_quantile(pos, n, 0.5);
        out->pos_p90 = vf_sorted_quantile(pos, n, 0.9);
    }
    free(src);
    free(dst);
    free(rot);
    free(pos);
    return status;
}

/* ---- viewpoint ---- */

void vf_viewpoint_to_c2w(const vf_viewpoint *v, double c2w[16])
{
    double rz[9], ry[9], rx[9], rot[9];
    vf_rot_z(deg2rad(v->psi), rz);
    vf_rot_y(deg2rad(-v->theta), ry);
    vf_rot_x(deg2rad(v->phi - 90.0), rx);
    vf_mat3_mul(rz, ry, rot);
    vf_mat3_mul(rot, rx, rot);
    double local[3] = {v->dx, v->dz, VF_CAMERA_DISTANCE + v->dy}; /* T(dx, dz, 4 + dy) */
    double pos[3];
    vf_mat3_apply(rot, local, pos);
    vf_mat4_from_rt(rot, pos, c2w);
}

void vf_c2w_to_viewpoint(const double c2w[16], vf_viewpoint *out)
{
    /* rot = Rz(a) Ry(b) Rx(c): row 2 is (-sin b, cos b sin c, cos b cos c) and column 0 is
     * cos b (cos a, sin a, .); cos b > 0 because |theta| < 90 */
    double rot[9], pos[3], local[3], rot_t[9];
    vf_mat4_rotation(c2w, rot);
    vf_mat4_translation(c2w, pos);
    double cos_b = hypot(rot[7], rot[8]);
    double a = atan2(rot[3], rot[0]);
    double b = atan2(-rot[6], cos_b);
    double c = atan2(rot[7], rot[8]);
    out->psi = rad2deg(a);
    out->theta = -rad2deg(b);
    out->phi = rad2deg(c) + 90.0;
    vf_mat3_transpose(rot, rot_t);
    vf_mat3_apply(rot_t, pos, local); /* = (dx, dz, 4 + dy) */
    out->dx = local[0];
    out->dz = local[1];
    out->dy = local[2] - VF_CAMERA_DISTANCE;
}

void vf_viewpoint_to_array(const vf_viewpoint *v, double a[VF_VIEW_DIM])
{
    a[0] = v->psi, a[1] = v->theta, a[2] = v->phi;
    a[3] = v->dx, a[4] = v->dy, a[5] = v->dz;
}

vf_viewpoint vf_viewpoint_from_array(const double a[VF_VIEW_DIM])
{
    vf_viewpoint v = {a[0], a[1], a[2], a[3], a[4], a[5]};
    return v;
}

json_t *vf_viewpoint_json(const vf_viewpoint *v)
{
    double a[VF_VIEW_DIM];
    vf_viewpoint_to_array(v, a);
    return vf_json_doubles(a, VF_VIEW_DIM);
}
