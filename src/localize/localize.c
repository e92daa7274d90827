/* Localizing frames against a workspace's sparse model (vf/localize.h): the flow, the camera
 * for a frame, the acceptance thresholds and the frames the pose is reported in. The feature,
 * matching and PnP calls are in localize_cv.cpp, the refinement in
 * pose_ceres.cpp, the descriptors' source in localize_db.c. */
#include "vf/localize.h"
#include "vf/sfm_export.h"

#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "localize_internal.h"
#include "vf/colmap_model.h"
#include "vf/fsutil.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/targets.h"
#include "vf/workspace.h"

struct vf_localizer {
    vf_localize_options opt;
    vf_colmap_model model;
    vf_similarity object_from_colmap;
    vf_loc_map map;
    vf_loc_index *index;
    double *xyz;               /* the model's points, point_count x 3, COLMAP frame */
};

void vf_localize_defaults(vf_localize_options *opt)
{
    *opt = (vf_localize_options){.max_features = 4096, .max_side = 1024, .ratio = 0.8,
                                 .ransac_px = 6, .ransac_iterations = 2000, .loss_px = 2,
                                 .min_inliers = 20, .min_inlier_ratio = 0.2};
}

/* ---- the map ---- */

static vf_status load_map(vf_localizer *loc, const vf_workspace *ws)
{
    char poses[VF_PATH_MAX], path[VF_PATH_MAX];
    vf_status status = vf_workspace_need(ws, "poses"); /* a folder alone may be half-written */
    if (status == VF_OK)
        status = vf_workspace_path(ws, "poses", "", poses, sizeof poses);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, poses, "sparse");
    if (status == VF_OK)
        status = vf_colmap_model_load(path, &loc->model);
    if (status == VF_OK)
        status = vf_normalization_load_workspace(ws, &loc->object_from_colmap, NULL, NULL);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, poses, "database.db");
    if (status == VF_OK)
        status = vf_loc_map_load(path, &loc->model, &loc->map);
    if (status == VF_OK)
        status = vf_loc_index_build(&loc->map, &loc->index);
    if (status != VF_OK)
        return status;
    int n = loc->model.point_count;
    loc->xyz = malloc(sizeof(double) * 3 * (size_t)(n + 1));
    if (!loc->xyz)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; i < n; i++)
        memcpy(loc->xyz + 3 * i, loc->model.points[i].xyz, 3 * sizeof(double));
    return VF_OK;
}

vf_status vf_localizer_open(const vf_workspace *ws, const vf_localize_options *opt,
                            vf_localizer **out)
{
    *out = NULL;
    vf_localizer *loc = calloc(1, sizeof *loc);
    if (!loc)
        return vf_fail(VF_EINTERNAL, "out of memory");
    if (opt)
        loc->opt = *opt;
    else
        vf_localize_defaults(&loc->opt);
    vf_status status = load_map(loc, ws);
    if (status != VF_OK) {
        vf_localizer_close(loc);
        return status;
    }
    *out = loc;
    return VF_OK;
}

void vf_localizer_close(vf_localizer *loc)
{
    if (!loc)
        return;
    vf_loc_index_free(loc->index);
    vf_loc_map_free(&loc->map);
    vf_colmap_model_free(&loc->model);
    free(loc->xyz);
    free(loc);
}

void vf_localizer_map_size(const vf_localizer *loc, int *points, int *descriptors)
{
    if (points)
        *points = loc->model.point_count;
    if (descriptors)
        *descriptors = loc->map.count;
}

/* ---- one frame ---- */

static int same_aspect(int w1, int h1, int w2, int h2)
{
    long a = (long)w1 * h2, b = (long)w2 * h1;
    return labs(a - b) <= (a > b ? a : b) / 100;
}

vf_status vf_localizer_camera(const vf_localizer *loc, int width, int height, vf_camera *cam)
{
    if (loc->opt.has_camera) {
        const vf_camera *c = &loc->opt.camera;
        if (!same_aspect(c->width, c->height, width, height))
            return vf_fail(VF_EINPUT, "a %dx%d frame does not fit the %dx%d calibration (other "
                                      "aspect ratio or orientation)",
                           width, height, c->width, c->height);
        *cam = vf_camera_scaled(c, width, height);
        return VF_OK;
    }
    for (int i = 0; i < loc->model.camera_count; i++) {
        const vf_colmap_camera *c = &loc->model.cameras[i];
        if (!same_aspect(c->width, c->height, width, height))
            continue;
        vf_camera full;
        vf_status status = vf_colmap_camera_to_vf(c, &full);
        if (status == VF_OK)
            *cam = vf_camera_scaled(&full, width, height);
        return status;
    }
    const vf_colmap_camera *c = &loc->model.cameras[0];
    return vf_fail(VF_EINPUT, "a %dx%d frame does not fit the capture's camera (%dx%d): other "
                              "aspect ratio or orientation; give a calibration for this camera",
                   width, height, c->width, c->height);
}

/* Squared reprojection error of point X at pixel uv under w2c (R, t) through the lens; a
 * point behind the camera counts as infinitely far off. */
static double reprojection_error2(const vf_camera *cam, const double R[9], const double t[3],
                                  const double X[3], const double uv[2])
{
    double p[3], u, v;
    vf_mat3_apply(R, X, p);
    for (int k = 0; k < 3; k++)
        p[k] += t[k];
    if (!vf_camera_project(cam, p, &u, &v))
        return INFINITY;
    return (u - uv[0]) * (u - uv[0]) + (v - uv[1]) * (v - uv[1]);
}

/* Mark the matches within threshold under (rvec, t); returns their count, *mean_px their
 * mean error. */
static int count_inliers(const vf_camera *cam, const double rvec[3], const double t[3],
                         const double *xyz, const double *uv, int n, double threshold,
                         unsigned char *inlier, double *mean_px)
{
    double R[9], sum = 0, limit = threshold * threshold;
    vf_rot_from_axis_angle(rvec, R);
    int count = 0;
    for (int i = 0; i < n; i++) {
        double e2 = reprojection_error2(cam, R, t, xyz + 3 * i, uv + 2 * i);
        inlier[i] = e2 < limit;
        if (inlier[i]) {
            count++;
            sum += sqrt(e2);
        }
    }
    *mean_px = count ? sum / count : 0;
    return count;
}

/* The inlier rows of xyz / uv, packed to the front of the `pack` arrays. */
static int pack_inliers(const double *xyz, const double *uv, int n, const unsigned char *inlier,
                        double *pxyz, double *puv)
{
    int m = 0;
    for (int i = 0; i < n; i++)
        if (inlier[i]) {
            memcpy(pxyz + 3 * m, xyz + 3 * i, 3 * sizeof(double));
            memcpy(puv + 2 * m, uv + 2 * i, 2 * sizeof(double));
            m++;
        }
    return m;
}

typedef struct frame_work {
    double *xy;                /* features, pixels */
    unsigned char *desc;
    int features;
    int *query, *point;        /* matches */
    int matches;
    double *xyz, *uv, *uv_pinhole, *pxyz, *puv;
    unsigned char *inlier;
} frame_work;

static void frame_work_free(frame_work *w)
{
    free(w->xy);
    free(w->desc);
    free(w->query);
    free(w->point);
    free(w->xyz);
    free(w->uv);
    free(w->uv_pinhole);
    free(w->pxyz);
    free(w->puv);
    free(w->inlier);
}

static vf_status match_features(const vf_localizer *loc, const vf_camera *cam, frame_work *w)
{
    int n = w->features;
    w->query = malloc(sizeof(int) * (n + 1));
    w->point = malloc(sizeof(int) * (n + 1));
    w->xyz = malloc(sizeof(double) * 3 * (n + 1));
    w->uv = malloc(sizeof(double) * 2 * (n + 1));
    w->uv_pinhole = malloc(sizeof(double) * 2 * (n + 1));
    w->pxyz = malloc(sizeof(double) * 3 * (n + 1));
    w->puv = malloc(sizeof(double) * 2 * (n + 1));
    w->inlier = malloc((size_t)n + 1);
    if (!w->query || !w->point || !w->xyz || !w->uv || !w->uv_pinhole || !w->pxyz || !w->puv ||
        !w->inlier)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_status status = vf_loc_index_match(loc->index, &loc->map, w->desc, n, loc->opt.ratio,
                                          w->query, w->point, &w->matches);
    for (int m = 0; status == VF_OK && m < w->matches; m++) {
        const double *p = w->xy + 2 * w->query[m];
        double x, y;
        memcpy(w->xyz + 3 * m, loc->xyz + 3 * w->point[m], 3 * sizeof(double));
        memcpy(w->uv + 2 * m, p, 2 * sizeof(double));
        vf_camera_undistort(cam, (p[0] - cam->cx) / cam->fx, (p[1] - cam->cy) / cam->fy, &x, &y);
        w->uv_pinhole[2 * m] = cam->fx * x + cam->cx;
        w->uv_pinhole[2 * m + 1] = cam->fy * y + cam->cy;
    }
    return status;
}

/* RANSAC, then two rounds of robust refinement, each followed by a fresh inlier count. */
static vf_status solve_pose(const vf_localizer *loc, const vf_camera *cam, frame_work *w,
                            double rvec[3], double t[3], int *found, double *mean_px)
{
    vf_camera pinhole = *cam;
    pinhole.k1 = pinhole.k2 = pinhole.p1 = pinhole.p2 = 0;
    vf_status status = vf_loc_pnp_ransac(w->xyz, w->uv_pinhole, w->matches, &pinhole,
                                         loc->opt.ransac_px, loc->opt.ransac_iterations, rvec, t,
                                         w->inlier, found);
    if (status != VF_OK || !*found)
        return status;
    for (int round = 0; round < 2; round++) {
        int m = pack_inliers(w->xyz, w->uv, w->matches, w->inlier, w->pxyz, w->puv);
        /* OpenCV's RANSAC can hand back a pose of NaNs on a degenerate sample (a studio
         * re-shoot frame of 20-odd inliers did): no pose, not a failed run */
        int finite = 1;
        for (int k = 0; k < 3; k++)
            finite &= isfinite(rvec[k]) && isfinite(t[k]);
        if (m < 3 || !finite) {
            *found = 0;
            return VF_OK;
        }
        if ((status = vf_loc_refine_pose(cam, w->pxyz, w->puv, m, loc->opt.loss_px, rvec, t)))
            return status;
        count_inliers(cam, rvec, t, w->xyz, w->uv, w->matches, loc->opt.ransac_px, w->inlier,
                      mean_px);
    }
    return VF_OK;
}

static void fill_pose(const vf_localizer *loc, const double rvec[3], const double t[3],
                      vf_localize_result *r)
{
    double R[9];
    vf_rot_from_axis_angle(rvec, R);
    vf_w2c_cv_to_c2w_gl(R, t, r->c2w_colmap);
    vf_similarity_apply_c2w(&loc->object_from_colmap, r->c2w_colmap, r->c2w_object);
    vf_c2w_to_viewpoint(r->c2w_object, &r->viewpoint);
}

static vf_status localize_working_frame(vf_localizer *loc, const vf_rgb8 *frame, double to_frame,
                                        vf_localize_result *r)
{
    vf_camera cam;
    frame_work w = {0};
    vf_status status = vf_localizer_camera(loc, frame->width, frame->height, &cam);
    if (status == VF_OK)
        status = vf_loc_sift(frame, loc->opt.max_features, &w.xy, &w.desc, &w.features);
    if (status == VF_OK)
        status = match_features(loc, &cam, &w);
    double rvec[3] = {0}, t[3] = {0}, mean_px = 0;
    int found = 0;
    if (status == VF_OK)
        status = solve_pose(loc, &cam, &w, rvec, t, &found, &mean_px);
    if (status == VF_OK) {
        r->features = w.features;
        r->matches = w.matches;
        r->inliers = 0;
        if (found)
            for (int i = 0; i < w.matches; i++)
                r->inliers += w.inlier[i];
        r->inlier_ratio = w.matches ? (double)r->inliers / w.matches : 0;
        r->reprojection_px = mean_px * to_frame;
        if (r->inliers < loc->opt.min_inliers)
            snprintf(r->reason, sizeof r->reason, "not localized: %d inliers (need %d; %d of %d "
                     "features matched the model)", r->inliers, loc->opt.min_inliers, w.matches,
                     w.features);
        else if (r->inlier_ratio < loc->opt.min_inlier_ratio)
            snprintf(r->reason, sizeof r->reason, "not localized: %d inliers, only %.0f%% of %d "
                     "matches (need %.0f%%)", r->inliers, 100 * r->inlier_ratio, w.matches,
                     100 * loc->opt.min_inlier_ratio);
        else {
            r->localized = 1;
            fill_pose(loc, rvec, t, r);
        }
    }
    frame_work_free(&w);
    return status;
}

vf_status vf_localize_frame(vf_localizer *loc, const vf_rgb8 *frame, vf_localize_result *result)
{
    double start = vf_now();
    memset(result, 0, sizeof *result);
    vf_rgb8 small = {0};
    const vf_rgb8 *work = frame;
    int longer = frame->width > frame->height ? frame->width : frame->height;
    vf_status status = VF_OK;
    if (loc->opt.max_side > 0 && longer > loc->opt.max_side) {
        status = vf_rgb8_fit(frame, loc->opt.max_side, &small);
        work = &small;
    }
    if (status == VF_OK)
        status = localize_working_frame(loc, work, (double)frame->width / work->width, result);
    vf_rgb8_free(&small);
    result->seconds = vf_now() - start;
    return status;
}

json_t *vf_localize_result_json(const vf_localize_result *r)
{
    json_t *o =
        json_pack("{s:b, s:i, s:i, s:i, s:o, s:o, s:o}", "localized", r->localized, "features",
                  r->features, "matches", r->matches, "inliers", r->inliers, "inlier_ratio",
                  vf_json_number(r->inlier_ratio), "reprojection_px",
                  vf_json_number(r->reprojection_px), "seconds", vf_json_number(r->seconds));
    if (!r->localized) {
        json_object_set_new(o, "reason", json_string(r->reason));
        return o;
    }
    json_object_set_new(o, "viewpoint", vf_viewpoint_json(&r->viewpoint));
    json_object_set_new(o, "c2w_object", vf_json_mat4(r->c2w_object));
    json_object_set_new(o, "c2w_colmap", vf_json_mat4(r->c2w_colmap));
    return o;
}
