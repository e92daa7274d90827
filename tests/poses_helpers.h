/* tests/poses_helpers.h: what the poses tests share (header-only, static inline functions).
 *
 * make_ingested_workspace() builds a workspace whose ingest stage holds a folder's images,
 * through the workspace API, as ingest would leave it. run_poses() runs `vfcapture poses` (the
 * tool from $VF_TOOL) with stdout and stderr in files and returns its exit code and wall time.
 * load_json() reads a JSON document. compare_poses() measures how far poses are from reference
 * poses after a similarity alignment of the camera centres. */
#ifndef VF_TEST_POSES_HELPERS_H
#define VF_TEST_POSES_HELPERS_H

#include <dirent.h>
#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/log.h"
#include "vf/pose.h"
#include "vf/workspace.h"

/* Copy every .jpg/.png of `images` (at most `limit`, 0: all) into a new workspace at `ws`. */
static inline int make_ingested_workspace(const char *ws, const char *images, int limit)
{
    vf_workspace w;
    vf_stage stage;
    char dst_dir[VF_PATH_MAX];
    if (vf_workspace_open(ws, 1, &w) != VF_OK || vf_stage_begin(&w, "ingest", &stage) != VF_OK)
        return -1;
    vf_path_join(dst_dir, sizeof dst_dir, stage.dir, "images");
    vf_mkdirs(dst_dir);
    DIR *dir = opendir(images);
    struct dirent *e;
    int copied = 0;
    while (dir && (e = readdir(dir)) && (limit == 0 || copied < limit)) {
        const char *dot = strrchr(e->d_name, '.');
        if (e->d_name[0] == '.' || !dot || (strcmp(dot, ".jpg") && strcmp(dot, ".png")))
            continue;
        char src[VF_PATH_MAX], dst[VF_PATH_MAX];
        vf_path_join(src, sizeof src, images, e->d_name);
        vf_path_join(dst, sizeof dst, dst_dir, e->d_name);
        copied += vf_copy_file(src, dst) == VF_OK;
    }
    if (dir)
        closedir(dir);
    int ok = copied > 0 && vf_stage_commit(&stage, NULL, json_pack("{s:i}", "frames", copied)) ==
                               VF_OK;
    vf_workspace_close(&w);
    return ok ? copied : -1;
}

/* Run `$VF_TOOL poses WS ARGS >out 2>err`; *seconds gets the wall time. */
static inline int run_poses(const char *ws, const char *args, const char *out, const char *err,
                     double *seconds)
{
    const char *tool = getenv("VF_TOOL");
    double start = vf_now();
    int rc = vf_test_system("'%s' poses '%s' %s >'%s' 2>'%s'", tool ? tool : "vfcapture", ws,
                            args, out, err);
    if (seconds)
        *seconds = vf_now() - start;
    return rc;
}

static inline json_t *load_json(const char *path)
{
    json_error_t e;
    return json_load_file(path, 0, &e);
}

static inline int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The q-quantile (0..1) of n values (sorts them). */
static inline double quantile(double *v, int n, double q)
{
    if (n == 0)
        return NAN;
    qsort(v, (size_t)n, sizeof *v, compare_double);
    int i = (int)(q * (n - 1) + 0.5);
    return v[i];
}

typedef struct pose_errors {
    double rot_median, rot_p90; /* degrees */
    double pos_median, pos_p90; /* share of the mean camera distance (4 in the object frame) */
} pose_errors;

/* Align the reference c2w matrices (OpenGL axes) onto ours (Umeyama on the camera centres)
 * and measure per camera the rotation error (degrees) and the position error (share of
 * `distance`, our mean camera distance). ours[i] and ref[i] are the same photo. */
static inline pose_errors compare_poses(const double *const *ours, const double *const *ref,
                                        int n, double distance)
{
    pose_errors e = {NAN, NAN, NAN, NAN};
    double *src = malloc(sizeof(double) * 3 * n), *dst = malloc(sizeof(double) * 3 * n);
    double *rot = malloc(sizeof(double) * n), *pos = malloc(sizeof(double) * n);
    vf_similarity align;
    for (int i = 0; i < n; i++) {
        vf_mat4_translation(ref[i], src + 3 * i);
        vf_mat4_translation(ours[i], dst + 3 * i);
    }
    if (vf_similarity_umeyama(src, dst, n, &align) == VF_OK) {
        for (int i = 0; i < n; i++) {
            double moved[16], r_ours[9], r_ref[9], p[3], d2 = 0;
            vf_similarity_apply_c2w(&align, ref[i], moved);
            vf_mat4_rotation(moved, r_ref);
            vf_mat4_rotation(ours[i], r_ours);
            rot[i] = vf_rot_angle_deg(r_ours, r_ref);
            vf_mat4_translation(moved, p);
            for (int k = 0; k < 3; k++)
                d2 += (p[k] - dst[3 * i + k]) * (p[k] - dst[3 * i + k]);
            pos[i] = sqrt(d2) / distance;
        }
        e = (pose_errors){quantile(rot, n, 0.5), quantile(rot, n, 0.9), quantile(pos, n, 0.5),
                          quantile(pos, n, 0.9)};
    }
    free(src);
    free(dst);
    free(rot);
    free(pos);
    return e;
}

/* compare_poses, printed and checked against limits (degrees; shares of the distance). */
typedef struct pose_limits {
    double rot_median, rot_p90, pos_median, pos_p90;
} pose_limits;

static inline pose_errors check_poses(const double *const *ours, const double *const *ref, int n,
                                      pose_limits limit)
{
    pose_errors e = compare_poses(ours, ref, n, VF_CAMERA_DISTANCE);
    printf("rotation error: median %.3f deg, p90 %.3f deg; position error: median %.3f%%, "
           "p90 %.3f%% of the camera distance\n",
           e.rot_median, e.rot_p90, 100 * e.pos_median, 100 * e.pos_p90);
    CHECK(e.rot_median < limit.rot_median, "rotation error median %.3f deg", e.rot_median);
    CHECK(e.rot_p90 < limit.rot_p90, "rotation error p90 %.3f deg", e.rot_p90);
    CHECK(e.pos_median < limit.pos_median, "position error median %.4f", e.pos_median);
    CHECK(e.pos_p90 < limit.pos_p90, "position error p90 %.4f", e.pos_p90);
    return e;
}

#endif
