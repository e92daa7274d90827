// The OpenCV side of localization (src/localize_internal.h): SIFT features of a frame in
// COLMAP's descriptor convention, a FLANN index over the map's descriptors, and PnP with
// RANSAC. Every cv::Exception becomes a vf_status with one line.
#include "localize_internal.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/features2d.hpp>
#include <opencv2/flann.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <new>
#include <vector>

struct vf_loc_index {
    cv::Mat data; // count x 128 float, owned: the index points into it
    cv::flann::Index index;
};

namespace {

const int kNeighbours = 4; // enough to find the nearest row of another 3D point

// OpenCV's SIFT descriptor (L2-normalised, clipped at 0.2, renormalised, times 512) as COLMAP
// stores it: L1-normalise, square root (RootSIFT), times 512, round, clip to 255.
void to_colmap_descriptor(const float *in, unsigned char *out)
{
    double sum = 0;
    for (int i = 0; i < VF_DESC_DIM; i++)
        sum += std::fabs(in[i]);
    for (int i = 0; i < VF_DESC_DIM; i++) {
        double v = sum > 0 ? std::sqrt(std::fabs(in[i]) / sum) : 0;
        out[i] = (unsigned char)std::min(255.0, std::round(512.0 * v));
    }
}

} // namespace

extern "C" vf_status vf_loc_sift(const vf_rgb8 *frame, int max_features, double **xy,
                                 unsigned char **desc, int *count)
{
    *xy = NULL;
    *desc = NULL;
    *count = 0;
    try {
        cv::Mat rgb(frame->height, frame->width, CV_8UC3, frame->data), grey;
        cv::cvtColor(rgb, grey, cv::COLOR_RGB2GRAY);
        cv::Ptr<cv::SIFT> sift = cv::SIFT::create(max_features);
        std::vector<cv::KeyPoint> keypoints;
        cv::Mat descriptors;
        sift->detectAndCompute(grey, cv::noArray(), keypoints, descriptors);
        int n = (int)keypoints.size();
        double *p = (double *)malloc(sizeof(double) * 2 * (n + 1));
        unsigned char *d = (unsigned char *)malloc((size_t)VF_DESC_DIM * (n + 1));
        if (!p || !d) {
            free(p);
            free(d);
            return vf_fail(VF_EINTERNAL, "out of memory for %d features", n);
        }
        for (int i = 0; i < n; i++) {
            // OpenCV puts pixel centres at integers, COLMAP (and vf/camera.h) at +0.5.
            p[2 * i] = keypoints[i].pt.x + 0.5;
            p[2 * i + 1] = keypoints[i].pt.y + 0.5;
            to_colmap_descriptor(descriptors.ptr<float>(i), d + (size_t)VF_DESC_DIM * i);
        }
        *xy = p;
        *desc = d;
        *count = n;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "SIFT failed: %s", e.what());
    } catch (const std::bad_alloc &) {
        return vf_fail(VF_EINTERNAL, "out of memory in SIFT");
    }
}

extern "C" vf_status vf_loc_index_build(const vf_loc_map *map, vf_loc_index **out)
{
    *out = NULL;
    if (map->count < kNeighbours)
        return vf_fail(VF_EINPUT, "the sparse model has only %d observed points", map->count);
    vf_loc_index *ix = new (std::nothrow) vf_loc_index;
    if (!ix)
        return vf_fail(VF_EINTERNAL, "out of memory for the descriptor index");
    try {
        cv::Mat bytes(map->count, VF_DESC_DIM, CV_8U, map->descriptors);
        bytes.convertTo(ix->data, CV_32F);
        ix->index.build(ix->data, cv::flann::KDTreeIndexParams(4), cvflann::FLANN_DIST_L2);
    } catch (const cv::Exception &e) {
        delete ix;
        return vf_fail(VF_EINTERNAL, "cannot index the map's descriptors: %s", e.what());
    } catch (const std::bad_alloc &) {
        delete ix;
        return vf_fail(VF_EINTERNAL, "out of memory for the descriptor index");
    }
    *out = ix;
    return VF_OK;
}

extern "C" void vf_loc_index_free(vf_loc_index *index)
{
    delete index;
}

extern "C" vf_status vf_loc_index_match(const vf_loc_index *index, const vf_loc_map *map,
                                        const unsigned char *desc, int n, double ratio,
                                        int *query, int *point, int *matches)
{
    *matches = 0;
    if (n == 0)
        return VF_OK;
    try {
        cv::Mat bytes(n, VF_DESC_DIM, CV_8U, (void *)desc), q, idx, dist;
        bytes.convertTo(q, CV_32F);
        // knnSearch is logically const; cv::flann::Index does not say so.
        const_cast<cv::flann::Index &>(index->index)
            .knnSearch(q, idx, dist, kNeighbours, cv::flann::SearchParams(64));
        double ratio2 = ratio * ratio; // FLANN gives squared distances
        int kept = 0;
        for (int i = 0; i < n; i++) {
            const int *ni = idx.ptr<int>(i);
            const float *di = dist.ptr<float>(i);
            int best = map->point[ni[0]];
            int other = -1;
            for (int k = 1; k < kNeighbours && other < 0; k++)
                if (ni[k] >= 0 && map->point[ni[k]] != best)
                    other = k;
            // All neighbours on one point: the views agree, which is a distinct match.
            if (other < 0 || di[0] < ratio2 * di[other]) {
                query[kept] = i;
                point[kept] = best;
                kept++;
            }
        }
        *matches = kept;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "descriptor matching failed: %s", e.what());
    }
}

extern "C" vf_status vf_loc_pnp_ransac(const double *xyz, const double *uv, int n,
                                       const vf_camera *pinhole, double threshold_px,
                                       int iterations, double rvec[3], double t[3],
                                       unsigned char *inlier, int *found)
{
    *found = 0;
    memset(inlier, 0, (size_t)n);
    if (n < 4)
        return VF_OK;
    try {
        // Pixel centres are at +0.5 in both uv and (cx, cy), so OpenCV's integer-centre
        // convention gives the same pose.
        cv::Mat object(n, 3, CV_64F, (void *)xyz), image(n, 2, CV_64F, (void *)uv), r, tv;
        cv::Matx33d K(pinhole->fx, 0, pinhole->cx, 0, pinhole->fy, pinhole->cy, 0, 0, 1);
        std::vector<int> inliers;
        bool ok = cv::solvePnPRansac(object, image, K, cv::noArray(), r, tv, false, iterations,
                                     (float)threshold_px, 0.9999, inliers, cv::SOLVEPNP_AP3P);
        if (!ok || inliers.empty())
            return VF_OK;
        for (int k = 0; k < 3; k++) {
            rvec[k] = r.at<double>(k);
            t[k] = tv.at<double>(k);
        }
        for (int i : inliers)
            if (i >= 0 && i < n)
                inlier[i] = 1;
        *found = 1;
        return VF_OK;
    } catch (const cv::Exception &e) {
        return vf_fail(VF_EINTERNAL, "pose estimation failed: %s", e.what());
    }
}
