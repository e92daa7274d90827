/* vf/pose.h: rigid and similarity geometry, camera axes, and the ViewFool viewpoint.
 *
 * Everything that places a camera goes through here: rotations, camera-to-world matrices,
 * the similarity transform that normalizes a COLMAP scene, and the 6-number viewpoint the
 * attack searches over. All functions are pure math on caller-owned plain arrays; nothing is
 * allocated. Outputs may alias inputs unless a comment says otherwise.
 *
 * Conventions
 *   - 4x4 matrices are double[16], 3x3 matrices double[9], both row-major: m[4 * row + col].
 *     Points are column vectors: p' = M p.
 *   - Camera-to-world matrices (c2w) use OpenGL camera axes (x right, y up, looking along -z)
 *     unless a name says _cv (OpenCV / COLMAP axes: x right, y down, z forward).
 *     c2w_gl = c2w_cv * diag(1, -1, -1, 1).
 *   - COLMAP stores world-to-camera: x_cam = R x_world + t, in OpenCV axes, with the rotation
 *     as a quaternion (w, x, y, z), Hamilton convention.
 *   - Angles are radians, except the viewpoint and vf_rot_angle_deg (degrees).
 *   - Axis-angle is a rotation vector: unit axis times angle (radians).
 *
 * The viewpoint (../shared/DESIGN.md, "Method"), object frame z up, object at the origin:
 *     c2w(v) = Rz(psi) * Ry(-theta) * Rx(phi - 90deg) * T(dx, dz, 4 + dy)
 * The camera rotation is R = Rz Ry Rx and its position R (dx, dz, 4 + dy). Note that dz sits
 * in the camera's y slot (camera up) and dy in the z slot (distance). What the formula does,
 * worked out and asserted in tests/test_pose.c (all other parameters 0):
 *   - phi = 90: camera at (0, 0, 4) looking straight down (-z) at the origin, image up = +y.
 *   - For any phi the camera sits at (0, 4 cos phi, 4 sin phi): phi is the elevation above
 *     the ground plane for phi <= 90 and 180 - phi for phi >= 90, so phi = 20 and phi = 160
 *     are both low side views 20 degrees above the horizon (z = 4 sin 20deg = 1.368), on the
 *     +y and -y sides respectively. Both look at the origin.
 *   - Surprise: the camera's up vector is (0, sin phi, -cos phi). For phi > 90 the world's up
 *     is up in the image (upright photo); for phi < 90 the camera is rolled 180 degrees, so a
 *     phi = 20 view is an upside-down photo (world up points down in the image). The same
 *     position and gaze with an upright image is (at theta = 0) phi' = 180 - phi,
 *     psi' = psi + 180. So over the default box, half of the phi range gives upside-down
 *     renders of views the other half already covers upright.
 *   - psi turns the camera (position and orientation) about world z; theta turns it about
 *     world y (applied before psi). With dx = dz = 0 the optical axis passes through the
 *     origin and the distance to it is 4 + dy; dx and dz shift the camera sideways and
 *     up/down in its own image plane. */
#ifndef VF_POSE_H
#define VF_POSE_H

#include <jansson.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- 3x3 matrices and rotations ---- */

void vf_mat3_identity(double out[9]);
void vf_mat3_mul(const double a[9], const double b[9], double out[9]); /* out = a * b */
void vf_mat3_transpose(const double a[9], double out[9]);
void vf_mat3_apply(const double a[9], const double p[3], double out[3]); /* out = a * p */
double vf_mat3_det(const double a[9]);

/* Right-handed rotations about the x, y and z axes by `angle` radians. */
void vf_rot_x(double angle, double out[9]);
void vf_rot_y(double angle, double out[9]);
void vf_rot_z(double angle, double out[9]);

/* Rotation vector (axis * angle) <-> matrix. to_axis_angle gives an angle in [0, pi]. */
void vf_rot_from_axis_angle(const double axis_angle[3], double out[9]);
void vf_rot_to_axis_angle(const double rot[9], double axis_angle[3]);

/* Quaternion (w, x, y, z), Hamilton, as COLMAP stores it <-> matrix. from_quat normalizes its
 * input (a zero quaternion gives the identity); to_quat returns a unit quaternion with w >= 0. */
void vf_rot_from_quat(const double q[4], double out[9]);
void vf_rot_to_quat(const double rot[9], double q[4]);

/* The rotation nearest (Frobenius norm) to a drifted, nearly orthonormal matrix. */
void vf_rot_orthonormalize(const double m[9], double out[9]);

/* Geodesic angle between two rotations, in degrees, in [0, 180]. */
double vf_rot_angle_deg(const double a[9], const double b[9]);

/* ---- 4x4 matrices ---- */

void vf_mat4_identity(double out[16]);
void vf_mat4_mul(const double a[16], const double b[16], double out[16]); /* out = a * b */
/* [rot t; 0 0 0 1] from a 3x3 block and a translation; and the two blocks back. */
void vf_mat4_from_rt(const double rot[9], const double t[3], double out[16]);
void vf_mat4_rotation(const double m[16], double rot[9]);
void vf_mat4_translation(const double m[16], double t[3]);
/* out = M (p, 1) and out = M (d, 0). */
void vf_mat4_transform_point(const double m[16], const double p[3], double out[3]);
void vf_mat4_transform_dir(const double m[16], const double d[3], double out[3]);
/* Inverse of [R t] with R a rotation: [R^T, -R^T t]. */
void vf_mat4_rigid_inverse(const double m[16], double out[16]);
/* Inverse of [s R, t] (uniform scale s > 0 read from the first column). */
void vf_mat4_similarity_inverse(const double m[16], double out[16]);
/* General inverse by Gauss-Jordan elimination; VF_EINPUT when m is singular. */
vf_status vf_mat4_inverse(const double m[16], double out[16]);

/* ---- camera axes ---- */

/* OpenCV <-> OpenGL camera axes on a camera-to-world matrix (flip the camera's y and z
 * columns). The operation is its own inverse; both names are given for readability. */
void vf_c2w_cv_to_gl(const double c2w_cv[16], double c2w_gl[16]);
void vf_c2w_gl_to_cv(const double c2w_gl[16], double c2w_cv[16]);

/* COLMAP's world-to-camera (R, t), OpenCV axes <-> camera-to-world, OpenGL axes. */
void vf_w2c_cv_to_c2w_gl(const double rot[9], const double t[3], double c2w_gl[16]);
void vf_c2w_gl_to_w2c_cv(const double c2w_gl[16], double rot[9], double t[3]);

/* ---- similarity transforms: x' = scale * R x + t ---- */

typedef struct vf_similarity {
    double scale;
    double R[9];
    double t[3];
} vf_similarity;

vf_similarity vf_similarity_identity(void);
void vf_similarity_apply(const vf_similarity *s, const double p[3], double out[3]);
/* Move a camera: rotation R * Rc (stays orthonormal, scale does not enter it), position
 * scale * R c + t. c2w must be rigid. */
void vf_similarity_apply_c2w(const vf_similarity *s, const double c2w[16], double out[16]);
vf_similarity vf_similarity_inverse(const vf_similarity *s);
/* The transform that applies `first`, then `second`. */
vf_similarity vf_similarity_compose(const vf_similarity *second, const vf_similarity *first);
void vf_similarity_to_mat4(const vf_similarity *s, double out[16]);

/* Least-squares similarity mapping src[i] onto dst[i] (Umeyama 1991, rotation by Horn's
 * quaternion method): points are n x 3 arrays. VF_EINPUT when n < 3 or the source points are
 * (nearly) collinear, so the rotation is not determined. */
vf_status vf_similarity_umeyama(const double *src, const double *dst, int n, vf_similarity *out);

/* How far two sets of poses of the same n cameras disagree (ours[i] and ref[i] are the same
 * camera; c2w matrices, either axis convention as long as both use it): ref is aligned onto
 * ours by a similarity of the camera centres, then per camera the rotation error (degrees)
 * and the position error as a share of `distance` (<= 0: the mean distance of our cameras
 * from their centroid). VF_EINPUT as vf_similarity_umeyama; out of memory VF_EINTERNAL. */
typedef struct vf_pose_agreement {
    int count;
    double rot_median, rot_p90, rot_max; /* degrees */
    double pos_median, pos_p90;          /* shares of the distance */
    int rot_over_5deg;                   /* cameras more than 5 degrees off */
} vf_pose_agreement;

vf_status vf_pose_compare(const double *const *ours, const double *const *ref, int n,
                          double distance, vf_pose_agreement *out);

/* ---- the ViewFool viewpoint ---- */

#define VF_CAMERA_DISTANCE 4.0 /* nominal camera distance to the object, scene units */
#define VF_VIEW_DIM 6          /* psi, theta, phi, dx, dy, dz: a viewpoint as an array */

/* Degrees for the angles, scene units for the offsets; array order is the field order. */
typedef struct vf_viewpoint {
    double psi, theta, phi, dx, dy, dz;
} vf_viewpoint;

/* c2w(v) = Rz(psi) * Ry(-theta) * Rx(phi - 90deg) * T(dx, dz, 4 + dy); see the top comment. */
void vf_viewpoint_to_c2w(const vf_viewpoint *v, double c2w[16]);

/* The inverse for any rigid c2w of that form (|theta| < 90). Angles come back with psi in
 * (-180, 180] (so psi = -180 returns as 180) and phi in (-90, 270]. */
void vf_c2w_to_viewpoint(const double c2w[16], vf_viewpoint *out);

void vf_viewpoint_to_array(const vf_viewpoint *v, double a[VF_VIEW_DIM]);
/* [psi, theta, phi, dx, dy, dz] as JSON (a new reference; nan and inf as null). */
json_t *vf_viewpoint_json(const vf_viewpoint *v);
vf_viewpoint vf_viewpoint_from_array(const double a[VF_VIEW_DIM]);

#ifdef __cplusplus
}
#endif
#endif
