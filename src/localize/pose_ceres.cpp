// Robust refinement of one camera pose with Ceres (src/localize_internal.h): the 3D points
// and the lens are fixed, the world-to-camera rotation (angle-axis) and translation move to
// minimise the reprojection error in pixels through the full OPENCV lens, each residual under
// a Cauchy loss so that outlier matches lose their pull instead of bending the pose.
#include "localize_internal.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <new>

namespace {

struct Reprojection {
    Reprojection(const vf_camera &cam, const double *xyz, const double *uv)
        : cam(cam), X{xyz[0], xyz[1], xyz[2]}, u(uv[0]), v(uv[1])
    {
    }

    template <typename T> bool operator()(const T *rvec, const T *t, T *residual) const
    {
        T X_world[3] = {T(X[0]), T(X[1]), T(X[2])}, p[3];
        ceres::AngleAxisRotatePoint(rvec, X_world, p);
        p[0] += t[0];
        p[1] += t[1];
        p[2] += t[2];
        if (p[2] <= T(1e-9)) { // behind the camera: a large constant error, no gradient trap
            residual[0] = T(1e3);
            residual[1] = T(1e3);
            return true;
        }
        T x = p[0] / p[2], y = p[1] / p[2];
        T r2 = x * x + y * y;
        T radial = T(1) + T(cam.k1) * r2 + T(cam.k2) * r2 * r2;
        T xd = x * radial + T(2 * cam.p1) * x * y + T(cam.p2) * (r2 + T(2) * x * x);
        T yd = y * radial + T(cam.p1) * (r2 + T(2) * y * y) + T(2 * cam.p2) * x * y;
        residual[0] = T(cam.fx) * xd + T(cam.cx) - T(u);
        residual[1] = T(cam.fy) * yd + T(cam.cy) - T(v);
        return true;
    }

    vf_camera cam;
    double X[3];
    double u, v;
};

} // namespace

extern "C" vf_status vf_loc_refine_pose(const vf_camera *cam, const double *xyz, const double *uv,
                                        int n, double loss_px, double rvec[3], double t[3])
{
    if (n < 3)
        return vf_fail(VF_EINPUT, "pose refinement needs at least 3 points, got %d", n);
    try {
        ceres::Problem problem;
        for (int i = 0; i < n; i++) {
            auto *cost = new ceres::AutoDiffCostFunction<Reprojection, 2, 3, 3>(
                new Reprojection(*cam, xyz + 3 * i, uv + 2 * i));
            problem.AddResidualBlock(cost, new ceres::CauchyLoss(loss_px), rvec, t);
        }
        ceres::Solver::Options options;
        options.linear_solver_type = ceres::DENSE_QR;
        options.max_num_iterations = 50;
        options.num_threads = 1; // 6 unknowns: threads cost more than they save
        options.logging_type = ceres::SILENT;
        ceres::Solver::Summary summary;
        ceres::Solve(options, &problem, &summary);
        if (!summary.IsSolutionUsable())
            return vf_fail(VF_EINTERNAL, "pose refinement failed: %s", summary.message.c_str());
        return VF_OK;
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory in pose refinement");
    }
}
