/* tests/poses_helpers.h: what the poses tests share (header-only, static functions).
 *
 * make_ingested_workspace() builds a workspace whose ingest stage holds a folder's images,
 * through the workspace API, as ingest would leave it. run_poses() runs `vfcapture poses` (the
 * tool from $VF_TOOL) with stdout and stderr in files and returns its exit code and wall time.
 * load_json() reads a JSON document. */
#ifndef VF_TEST_POSES_HELPERS_H
#define VF_TEST_POSES_HELPERS_H

#include <dirent.h>
#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/log.h"
#include "vf/workspace.h"

/* Copy every .jpg/.png of `images` (at most `limit`, 0: all) into a new workspace at `ws`. */
static int make_ingested_workspace(const char *ws, const char *images, int limit)
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
static int run_poses(const char *ws, const char *args, const char *out, const char *err,
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

static json_t *load_json(const char *path)
{
    json_error_t e;
    return json_load_file(path, 0, &e);
}

static int compare_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The q-quantile (0..1) of n values (sorts them). */
static double quantile(double *v, int n, double q)
{
    if (n == 0)
        return NAN;
    qsort(v, (size_t)n, sizeof *v, compare_double);
    int i = (int)(q * (n - 1) + 0.5);
    return v[i];
}

#endif
