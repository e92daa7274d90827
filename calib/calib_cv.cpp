// The OpenCV side of the calibration (vf/calib.h, calib/calib_cv.h): checkerboard
// corners (ChArUco boards: charuco_cv.cpp), calibrateCamera, and rendering a textured plane
// through a lens for synthetic views.
// Pixel coordinates cross this boundary in the vf/camera.h convention (pixel centres at +0.5);
// OpenCV puts pixel centres at integers, so +-0.5 is applied here and nowhere else.
#include "vf/calib.h"
#include "calib_cv.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <new>
#include <vector>

namespace {

const int DETECT_MAX_SIDE = 1280; // larger frames are searched shrunk, then refined at full size

cv::Mat wrap(const vf_rgb8 *img)
{
    return cv::Mat(img->height, img->width, CV_8UC3, img->data);
}

// Smallest distance between neighbouring corners along rows and columns.
double min_corner_spacing(const std::vector<cv::Point2f> &pts, int cols, int rows)
{
    double best = 1e30;
    for (int r = 0; r < rows; r++)
        for (int c = 0; c < cols; c++) {
            const cv::Point2f &p = pts[r * cols + c];
            if (c + 1 < cols)
                best = std::min(best, (double)cv::norm(p - pts[r * cols + c + 1]));
            if (r + 1 < rows)
                best = std::min(best, (double)cv::norm(p - pts[(r + 1) * cols + c]));
        }
    return best;
}

} // namespace

extern "C" vf_status vf_calib_find_board(const vf_rgb8 *frame, const vf_calib_board *board,
                                         double *uv, double quad[8], int *found)
{
    if (board->marker > 0)
        return vf_cv_find_charuco(frame, board, uv, quad, found);
    *found = 0;
    try {
        cv::Mat gray, small;
        cv::cvtColor(wrap(frame), gray, cv::COLOR_RGB2GRAY);
        int longer = std::max(gray.cols, gray.rows);
        double shrink = longer > DETECT_MAX_SIDE ? (double)DETECT_MAX_SIDE / longer : 1.0;
        if (shrink < 1.0)
            cv::resize(gray, small, cv::Size(), shrink, shrink, cv::INTER_AREA);
        else
            small = gray;
        std::vector<cv::Point2f> pts;
        cv::Size pattern(board->cols, board->rows);
        int flags = cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE |
                    cv::CALIB_CB_FAST_CHECK;
        if (!cv::findChessboardCorners(small, pattern, pts, flags))
            return VF_OK;
        if (shrink < 1.0)
            for (cv::Point2f &p : pts) // pixel centres scale about the image corner
                p = cv::Point2f((float)((p.x + 0.5) / shrink - 0.5),
                                (float)((p.y + 0.5) / shrink - 0.5));
        // The refinement window must stay inside one square around each corner.
        int half = (int)std::clamp(0.4 * min_corner_spacing(pts, board->cols, board->rows), 2.0,
                                   11.0);
        cv::cornerSubPix(gray, pts, cv::Size(half, half), cv::Size(-1, -1),
                         cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50,
                                          0.001));
        for (size_t i = 0; i < pts.size(); i++) {
            uv[2 * i] = pts[i].x + 0.5;
            uv[2 * i + 1] = pts[i].y + 0.5;
        }
        int c = board->cols, r = board->rows, outer[4] = {0, c - 1, r * c - 1, (r - 1) * c};
        for (int k = 0; k < 4; k++) {
            quad[2 * k] = uv[2 * outer[k]];
            quad[2 * k + 1] = uv[2 * outer[k] + 1];
        }
        *found = 1;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "checkerboard search failed: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory searching for the checkerboard");
    }
}

extern "C" vf_status vf_cv_calibrate(const double *object_xy, int corners, const double *const *uv,
                                     int views, int width, int height, vf_camera *cam,
                                     double *poses)
{
    try {
        std::vector<std::vector<cv::Point3f>> object(views);
        std::vector<std::vector<cv::Point2f>> image(views);
        for (int v = 0; v < views; v++)
            for (int i = 0; i < corners; i++)
                if (!std::isnan(uv[v][2 * i])) { // a corner this view saw
                    object[v].emplace_back((float)object_xy[2 * i], (float)object_xy[2 * i + 1],
                                           0.0f);
                    image[v].emplace_back((float)uv[v][2 * i], (float)uv[v][2 * i + 1]);
                }
        cv::Mat K, dist;
        std::vector<cv::Mat> rvecs, tvecs;
        int flags = cv::CALIB_FIX_K3; // COLMAP's OPENCV model: k1, k2, p1, p2
        cv::calibrateCamera(object, image, cv::Size(width, height), K, dist, rvecs, tvecs, flags,
                            cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS,
                                             100, 1e-12));
        *cam = vf_camera{};
        cam->width = width;
        cam->height = height;
        cam->fx = K.at<double>(0, 0);
        cam->fy = K.at<double>(1, 1);
        cam->cx = K.at<double>(0, 2);
        cam->cy = K.at<double>(1, 2);
        cam->k1 = dist.at<double>(0);
        cam->k2 = dist.at<double>(1);
        cam->p1 = dist.at<double>(2);
        cam->p2 = dist.at<double>(3);
        for (int v = 0; v < views; v++)
            for (int k = 0; k < 3; k++) {
                poses[6 * v + k] = rvecs[v].at<double>(k);
                poses[6 * v + 3 + k] = tvecs[v].at<double>(k);
            }
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINPUT, "OpenCV could not calibrate from these views (%s): use views "
                                  "with the board tilted in different directions",
                       e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory calibrating");
    }
}

extern "C" vf_status vf_calib_render_plane(const vf_camera *cam, const double rot[9],
                                           const double t[3], const vf_rgb8 *texture,
                                           double texel_size, unsigned char background,
                                           int supersample, vf_rgb8 *out)
{
    if (supersample < 1 || supersample > 4 || !(texel_size > 0) || !texture->data)
        return vf_fail(VF_EINPUT, "render: bad texture, texel size or supersampling");
    vf_camera big = vf_camera_scaled(cam, cam->width * supersample, cam->height * supersample);
    // The camera centre and the rays in the plane's frame: o = -R^T t, d = R^T ray.
    double origin[3];
    for (int k = 0; k < 3; k++)
        origin[k] = -(rot[k] * t[0] + rot[3 + k] * t[1] + rot[6 + k] * t[2]);
    try {
        cv::Mat map_x(big.height, big.width, CV_32F), map_y(big.height, big.width, CV_32F);
#pragma omp parallel for schedule(static)
        for (int y = 0; y < big.height; y++) {
            float *mx = map_x.ptr<float>(y), *my = map_y.ptr<float>(y);
            for (int x = 0; x < big.width; x++) {
                double ray[3], d[3];
                vf_camera_pixel_ray(&big, x + 0.5, y + 0.5, ray);
                for (int k = 0; k < 3; k++)
                    d[k] = rot[k] * ray[0] + rot[3 + k] * ray[1] + rot[6 + k] * ray[2];
                double s = d[2] != 0.0 ? -origin[2] / d[2] : -1.0;
                mx[x] = my[x] = -1e6f; // behind the camera: outside the texture
                if (s > 0) {
                    mx[x] = (float)((origin[0] + s * d[0]) / texel_size - 0.5);
                    my[x] = (float)((origin[1] + s * d[1]) / texel_size - 0.5);
                }
            }
        }
        cv::Mat rendered, shrunk;
        cv::remap(wrap(texture), rendered, map_x, map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT,
                  cv::Scalar::all(background));
        if (supersample > 1)
            cv::resize(rendered, shrunk, cv::Size(cam->width, cam->height), 0, 0, cv::INTER_AREA);
        else
            shrunk = rendered;
        vf_status status = vf_rgb8_resize_buffer(out, cam->width, cam->height);
        if (status != VF_OK)
            return status;
        cv::Mat dst = wrap(out);
        shrunk.copyTo(dst);
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "rendering a plane failed: %s", e.err.c_str());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory rendering a plane");
    }
}
