/* tests/poses_helpers.h: what the poses tests share (header-only, static inline functions).
 *
 * make_ingested_workspace() builds a workspace whose ingest stage holds a folder's images,
 * through the workspace API, as ingest would leave it. run_poses() runs `vfcapture poses` (the
 * tool from $VF_TOOL) with stdout and stderr in files and returns its exit code and wall time.
 * load_json() reads a JSON document. compare_poses() measures how far poses are from reference
 * poses after a similarity alignment of the camera centres; find_by_file_name() pairs our frames
 * with a reference set's by file name. */
#ifndef VF_TEST_POSES_HELPERS_H
#define VF_TEST_POSES_HELPERS_H

#include <dirent.h>
#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/dataset.h"
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

/* The frame of `set` whose image file name ends ours ("0001.jpg" in "0003_0001.jpg", as
 * `ingest --transforms` names it), or NULL. */
static inline const vf_frame *find_by_file_name(const vf_dataset *set, const char *path)
{
    char name[256], other[256];
    vf_path_basename(name, sizeof name, path, 0);
    size_t len = strlen(name);
    for (int i = 0; i < set->count; i++) {
        vf_path_basename(other, sizeof other, set->frames[i].image_path, 0);
        size_t olen = strlen(other);
        if (olen <= len && !strcmp(name + len - olen, other))
            return &set->frames[i];
    }
    return NULL;
}

/* vf_pose_compare against the object frame's camera distance (NaNs when it cannot align). */
static inline vf_pose_agreement compare_poses(const double *const *ours, const double *const *ref,
                                              int n)
{
    vf_pose_agreement e;
    if (vf_pose_compare(ours, ref, n, VF_CAMERA_DISTANCE, &e) != VF_OK)
        e.rot_median = e.rot_p90 = e.pos_median = e.pos_p90 = NAN;
    return e;
}

/* compare_poses, printed and checked against limits (degrees; shares of the distance). */
typedef struct pose_limits {
    double rot_median, rot_p90, pos_median, pos_p90;
} pose_limits;

static inline vf_pose_agreement check_poses(const double *const *ours, const double *const *ref,
                                            int n, pose_limits limit)
{
    vf_pose_agreement e = compare_poses(ours, ref, n);
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
