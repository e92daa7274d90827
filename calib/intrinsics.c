/* Intrinsics from the found boards (vf/calib.h): choose spread views, OpenCV's estimate, drop
 * outlier views, Ceres refinement under a robust loss. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calib_ceres.h"
#include "calib_cv.h"
#include "calib_internal.h"
#include "vf/log.h"
#include "vf/pose.h"

void vf_calib_defaults(vf_calib_options *opt)
{
    *opt = (vf_calib_options){.max_views = 40, .min_views = 6, .outlier_factor = 3.0,
                              .outlier_floor = 0.5, .huber_px = 1.0};
}

double vf__calib_view_rms(const vf_camera *cam, const double pose[6], const double *object_xy,
                          const double *uv, int corners)
{
    double rot[9], sum = 0;
    int seen = 0;
    vf_rot_from_axis_angle(pose, rot);
    for (int i = 0; i < corners; i++) {
        if (isnan(uv[2 * i]))
            continue; /* not seen in this view */
        seen++;
        double board[3] = {object_xy[2 * i], object_xy[2 * i + 1], 0}, p[3], u, v;
        vf_mat3_apply(rot, board, p);
        for (int k = 0; k < 3; k++)
            p[k] += pose[3 + k];
        if (!vf_camera_project(cam, p, &u, &v))
            return 1e9; /* behind the camera: as wrong as it gets */
        sum += (u - uv[2 * i]) * (u - uv[2 * i]) + (v - uv[2 * i + 1]) * (v - uv[2 * i + 1]);
    }
    return seen ? sqrt(sum / seen) : 0.0;
}

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The calibration in progress: the views in use and their poses. */
typedef struct solve_state {
    vf_calib_views *set;
    double *object_xy;
    int corners;
    int *used; /* indices into set->views */
    int count;
    const double **uv;
    double *poses;
    vf_camera cam;
} solve_state;

static double update_errors(solve_state *s)
{
    double sum = 0;
    for (int k = 0; k < s->count; k++) {
        vf_calib_view *view = &s->set->views[s->used[k]];
        view->rms =
            vf__calib_view_rms(&s->cam, s->poses + 6 * k, s->object_xy, view->uv, s->corners);
        sum += view->rms * view->rms;
    }
    return sqrt(sum / s->count);
}

/* Drop views whose error is far above the median (never below min_views); returns how many
 * were dropped. */
static int drop_outliers(solve_state *s, const vf_calib_options *opt)
{
    double *errors = malloc((size_t)s->count * sizeof *errors);
    if (!errors)
        return 0;
    for (int k = 0; k < s->count; k++)
        errors[k] = s->set->views[s->used[k]].rms;
    qsort(errors, (size_t)s->count, sizeof *errors, compare_doubles);
    double median = errors[s->count / 2];
    free(errors);
    double limit = opt->outlier_factor * median;
    if (limit < opt->outlier_floor)
        limit = opt->outlier_floor;
    int dropped = 0;
    while (s->count > opt->min_views) {
        int worst = 0;
        for (int k = 1; k < s->count; k++)
            if (s->set->views[s->used[k]].rms > s->set->views[s->used[worst]].rms)
                worst = k;
        vf_calib_view *view = &s->set->views[s->used[worst]];
        if (view->rms <= limit)
            break;
        view->state = VF_VIEW_OUTLIER;
        s->count--;
        s->used[worst] = s->used[s->count];
        s->uv[worst] = s->uv[s->count];
        memcpy(s->poses + 6 * worst, s->poses + 6 * s->count, 6 * sizeof *s->poses);
        dropped++;
    }
    return dropped;
}

static vf_status solve(solve_state *s, const vf_calib_options *opt, vf_calib_result *out)
{
    s->count = vf__calib_select_views(s->set, opt->max_views, s->used);
    for (int k = 0; k < s->count; k++)
        s->uv[k] = s->set->views[s->used[k]].uv;
    double start = vf_now();
    vf_status status = vf_cv_calibrate(s->object_xy, s->corners, s->uv, s->count, s->set->width,
                                       s->set->height, &s->cam, s->poses);
    if (status != VF_OK)
        return status;
    out->rms_opencv = update_errors(s);
    /* a dropped view changes the lens the others agree on: re-estimate, then look again */
    for (int round = 0; round < 3 && drop_outliers(s, opt) > 0; round++) {
        if ((status = vf_cv_calibrate(s->object_xy, s->corners, s->uv, s->count, s->set->width,
                                      s->set->height, &s->cam, s->poses)) != VF_OK)
            return status;
        update_errors(s);
    }
    out->seconds_opencv = vf_now() - start;
    start = vf_now();
    status = vf_ceres_refine_calibration(&s->cam, s->poses, s->count, s->object_xy, s->corners,
                                         s->uv, opt->huber_px);
    out->seconds_ceres = vf_now() - start;
    if (status != VF_OK)
        return status;
    out->rms = update_errors(s);
    out->camera = s->cam;
    out->used = s->count;
    out->outliers = 0;
    for (int i = 0; i < s->set->count; i++)
        out->outliers += s->set->views[i].state == VF_VIEW_OUTLIER;
    for (int k = 0; k < s->count; k++)
        s->set->views[s->used[k]].state = VF_VIEW_USED;
    return VF_OK;
}

vf_status vf_calib_solve(vf_calib_views *set, const vf_calib_board *board,
                         const vf_calib_options *opt, vf_calib_result *out)
{
    memset(out, 0, sizeof *out);
    if (set->count < opt->min_views || set->count < 3)
        return vf_fail(VF_EINPUT,
                       "the %dx%d board was found in only %d of %d frames, and calibration needs "
                       "at least %d: check that --board counts inner corners (a board of 10 x 7 "
                       "squares is 9x6), and film the whole board, tilted different ways, in "
                       "more frames",
                       board->cols, board->rows, set->count, set->frames_seen,
                       opt->min_views > 3 ? opt->min_views : 3);
    for (int i = 0; i < set->count; i++)
        set->views[i].state = VF_VIEW_SPARE, set->views[i].rms = 0;
    int max = opt->max_views < set->count ? opt->max_views : set->count;
    solve_state s = {.set = set, .corners = vf_calib_board_corners(board)};
    s.object_xy = vf__calib_board_points(board);
    s.used = malloc((size_t)max * sizeof *s.used);
    s.uv = malloc((size_t)max * sizeof *s.uv);
    s.poses = malloc((size_t)max * 6 * sizeof *s.poses);
    vf_status status = s.object_xy && s.used && s.uv && s.poses
                           ? solve(&s, opt, out)
                           : vf_fail(VF_EINTERNAL, "out of memory");
    free(s.object_xy);
    free(s.used);
    free(s.uv);
    free(s.poses);
    return status;
}
