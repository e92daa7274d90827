// Ceres bundle adjustment of a planar-board calibration (src/ceres/calib_ceres.h): the OPENCV
// lens and every board pose, with a Huber loss so a few badly located corners cannot pull the
// lens the way they pull OpenCV's plain least squares.
#include "calib_ceres.h"

#include <ceres/ceres.h>
#include <ceres/rotation.h>

#include <cmath>
#include <new>

namespace {

// Reprojection residual of one board corner. intrinsics: fx, fy, cx, cy, k1, k2, p1, p2;
// pose: rotation vector, translation.
struct CornerError {
    double X, Y, u, v;

    template <typename T>
    bool operator()(const T *const intrinsics, const T *const pose, T *residual) const
    {
        const T board[3] = {T(X), T(Y), T(0)};
        T p[3];
        ceres::AngleAxisRotatePoint(pose, board, p);
        for (int k = 0; k < 3; k++)
            p[k] += pose[3 + k];
        const T x = p[0] / p[2], y = p[1] / p[2];
        const T &k1 = intrinsics[4], &k2 = intrinsics[5], &p1 = intrinsics[6], &p2 = intrinsics[7];
        const T r2 = x * x + y * y;
        const T radial = T(1) + k1 * r2 + k2 * r2 * r2;
        const T xd = x * radial + T(2) * p1 * x * y + p2 * (r2 + T(2) * x * x);
        const T yd = y * radial + p1 * (r2 + T(2) * y * y) + T(2) * p2 * x * y;
        residual[0] = intrinsics[0] * xd + intrinsics[2] - T(u);
        residual[1] = intrinsics[1] * yd + intrinsics[3] - T(v);
        return true;
    }
};

} // namespace

extern "C" vf_status vf_ceres_refine_calibration(vf_camera *cam, double *poses, int views,
                                                 const double *object_xy, int corners,
                                                 const double *const *uv, double huber_px)
{
    double intrinsics[8] = {cam->fx, cam->fy, cam->cx, cam->cy,
                            cam->k1, cam->k2, cam->p1, cam->p2};
    try {
        ceres::Problem problem;
        for (int v = 0; v < views; v++)
            for (int i = 0; i < corners; i++) {
                if (std::isnan(uv[v][2 * i]))
                    continue; // not seen in this view
                auto *cost = new ceres::AutoDiffCostFunction<CornerError, 2, 8, 6>(
                    new CornerError{object_xy[2 * i], object_xy[2 * i + 1], uv[v][2 * i],
                                    uv[v][2 * i + 1]});
                problem.AddResidualBlock(cost, new ceres::HuberLoss(huber_px), intrinsics,
                                         poses + 6 * v);
            }
        ceres::Solver::Options options;
        options.linear_solver_type = ceres::DENSE_SCHUR;
        options.max_num_iterations = 100;
        options.function_tolerance = 1e-12;
        options.parameter_tolerance = 1e-12;
        options.num_threads = 2;
        options.logging_type = ceres::SILENT;
        ceres::Solver::Summary summary;
        ceres::Solve(options, &problem, &summary);
        if (!summary.IsSolutionUsable())
            return vf_fail(VF_EINTERNAL, "the Ceres refinement failed: %s",
                           summary.message.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory refining the calibration");
    }
    cam->fx = intrinsics[0], cam->fy = intrinsics[1], cam->cx = intrinsics[2];
    cam->cy = intrinsics[3], cam->k1 = intrinsics[4], cam->k2 = intrinsics[5];
    cam->p1 = intrinsics[6], cam->p2 = intrinsics[7];
    return VF_OK;
}
