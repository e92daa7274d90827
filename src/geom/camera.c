/* Pinhole camera with COLMAP's OPENCV lens distortion (see vf/camera.h). */
#include "vf/camera.h"

#include <math.h>

vf_camera vf_camera_from_fov(int width, int height, double fov_x)
{
    double f = 0.5 * width / tan(0.5 * fov_x);
    vf_camera cam = {.width = width, .height = height, .fx = f, .fy = f,
                     .cx = 0.5 * width, .cy = 0.5 * height};
    return cam;
}

vf_camera vf_camera_scaled(const vf_camera *cam, int new_width, int new_height)
{
    /* pixel centres at +0.5 and the origin at the image corner make this a pure scaling */
    double sx = (double)new_width / cam->width, sy = (double)new_height / cam->height;
    vf_camera out = *cam;
    out.width = new_width, out.height = new_height;
    out.fx *= sx, out.cx *= sx;
    out.fy *= sy, out.cy *= sy;
    return out;
}

int vf_camera_has_distortion(const vf_camera *cam)
{
    return cam->k1 != 0.0 || cam->k2 != 0.0 || cam->p1 != 0.0 || cam->p2 != 0.0;
}

void vf_camera_distort(const vf_camera *cam, double x, double y, double *xd, double *yd)
{
    double r2 = x * x + y * y;
    double radial = 1.0 + cam->k1 * r2 + cam->k2 * r2 * r2;
    *xd = x * radial + 2.0 * cam->p1 * x * y + cam->p2 * (r2 + 2.0 * x * x);
    *yd = y * radial + cam->p1 * (r2 + 2.0 * y * y) + 2.0 * cam->p2 * x * y;
}

/* Jacobian of vf_camera_distort at (x, y), row-major [dxd/dx dxd/dy; dyd/dx dyd/dy]. */
static void distort_jacobian(const vf_camera *cam, double x, double y, double j[4])
{
    double r2 = x * x + y * y;
    double radial = 1.0 + cam->k1 * r2 + cam->k2 * r2 * r2;
    double dradial = 2.0 * cam->k1 + 4.0 * cam->k2 * r2; /* d radial / dx = dradial * x */
    j[0] = radial + dradial * x * x + 2.0 * cam->p1 * y + 6.0 * cam->p2 * x;
    j[1] = dradial * x * y + 2.0 * cam->p1 * x + 2.0 * cam->p2 * y;
    j[2] = dradial * x * y + 2.0 * cam->p1 * x + 2.0 * cam->p2 * y;
    j[3] = radial + dradial * y * y + 6.0 * cam->p1 * y + 2.0 * cam->p2 * x;
}

/* Newton's method on distort(x, y) = (xd, yd), starting from the distorted point itself. */
void vf_camera_undistort(const vf_camera *cam, double xd, double yd, double *x, double *y)
{
    double ux = xd, uy = yd;
    if (vf_camera_has_distortion(cam)) {
        for (int iter = 0; iter < 100; iter++) {
            double fx, fy, j[4];
            vf_camera_distort(cam, ux, uy, &fx, &fy);
            double ex = fx - xd, ey = fy - yd;
            distort_jacobian(cam, ux, uy, j);
            double det = j[0] * j[3] - j[1] * j[2];
            double step_x = ex, step_y = ey; /* fixed-point step where Newton is ill-posed */
            if (fabs(det) > 1e-12) {
                step_x = (j[3] * ex - j[1] * ey) / det;
                step_y = (j[0] * ey - j[2] * ex) / det;
            }
            ux -= step_x, uy -= step_y;
            if (fabs(step_x) + fabs(step_y) <= 1e-15 * (1.0 + fabs(ux) + fabs(uy)))
                break;
        }
    }
    *x = ux, *y = uy;
}

int vf_camera_project(const vf_camera *cam, const double p_cam[3], double *u, double *v)
{
    if (!(p_cam[2] > 0.0))
        return 0;
    double xd, yd;
    vf_camera_distort(cam, p_cam[0] / p_cam[2], p_cam[1] / p_cam[2], &xd, &yd);
    *u = cam->fx * xd + cam->cx;
    *v = cam->fy * yd + cam->cy;
    return 1;
}

void vf_camera_pixel_ray(const vf_camera *cam, double u, double v, double dir[3])
{
    double x, y;
    vf_camera_undistort(cam, (u - cam->cx) / cam->fx, (v - cam->cy) / cam->fy, &x, &y);
    double norm = sqrt(x * x + y * y + 1.0);
    dir[0] = x / norm, dir[1] = y / norm, dir[2] = 1.0 / norm;
}
