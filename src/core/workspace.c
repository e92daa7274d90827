#define _GNU_SOURCE
#include "vf/workspace.h"

#include <dirent.h>
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "vf/log.h"

#define MANIFEST "manifest.json"

static int folder_is_empty(const char *path)
{
    DIR *dir = opendir(path);
    if (!dir)
        return 0;
    struct dirent *entry;
    int empty = 1;
    while (empty && (entry = readdir(dir)))
        empty = !strcmp(entry->d_name, ".") || !strcmp(entry->d_name, "..");
    closedir(dir);
    return empty;
}

vf_status vf_workspace_open(const char *root, int create, vf_workspace *ws)
{
    memset(ws, 0, sizeof *ws);
    if (snprintf(ws->root, sizeof ws->root, "%s", root) >= (int)sizeof ws->root)
        return vf_fail(VF_EINPUT, "workspace path too long: %s", root);
    char manifest_path[VF_PATH_MAX];
    vf_status status = vf_path_join(manifest_path, sizeof manifest_path, root, MANIFEST);
    if (status != VF_OK)
        return status;

    if (vf_is_file(manifest_path)) {
        status = vf_json_load(manifest_path, &ws->manifest);
        if (status == VF_OK && !json_is_object(json_object_get(ws->manifest, "stages"))) {
            json_decref(ws->manifest);
            ws->manifest = NULL;
            status = vf_fail(VF_EINPUT, "%s is not a vfcapture manifest", manifest_path);
        }
        return status;
    }
    if (!create) {
        if (!vf_is_dir(root))
            return vf_fail(VF_EINPUT, "workspace %s does not exist (run 'vfcapture ingest' first)",
                           root);
        return vf_fail(VF_EINPUT, "%s is not a vfcapture workspace (no %s)", root, MANIFEST);
    }
    if (vf_is_dir(root) && !folder_is_empty(root))
        return vf_fail(VF_EINPUT,
                       "%s exists and is not a vfcapture workspace; choose a new or empty folder",
                       root);
    if ((status = vf_mkdirs(root)) != VF_OK)
        return status;
    ws->manifest = json_pack("{s:s, s:s, s:{}}", "tool", "vfcapture", "version", VF_VERSION,
                             "stages");
    return vf_json_save(manifest_path, ws->manifest);
}

void vf_workspace_close(vf_workspace *ws)
{
    json_decref(ws->manifest);
    ws->manifest = NULL;
}

json_t *vf_workspace_stage_record(const vf_workspace *ws, const char *stage)
{
    return json_object_get(json_object_get(ws->manifest, "stages"), stage);
}

int vf_workspace_has_stage(const vf_workspace *ws, const char *stage)
{
    char dir[VF_PATH_MAX];
    return vf_workspace_stage_record(ws, stage) &&
           vf_workspace_path(ws, stage, "", dir, sizeof dir) == VF_OK && vf_is_dir(dir);
}

vf_status vf_workspace_path(const vf_workspace *ws, const char *stage, const char *file, char *out,
                            size_t size)
{
    int n = file && file[0] ? snprintf(out, size, "%s/%s/%s", ws->root, stage, file)
                            : snprintf(out, size, "%s/%s", ws->root, stage);
    if (n < 0 || (size_t)n >= size)
        return vf_fail(VF_EINPUT, "path too long in workspace %s", ws->root);
    return VF_OK;
}

vf_status vf_workspace_training_views(const vf_workspace *ws, char *path, size_t size,
                                      int *real_capture)
{
    int capture = vf_workspace_has_stage(ws, "poses");
    vf_status status = capture ? vf_workspace_path(ws, "poses", "transforms_undistorted.json",
                                                   path, size)
                               : vf_workspace_path(ws, "ingest", "transforms.json", path, size);
    if (status == VF_OK && capture && !vf_is_file(path)) /* poses --no-undistort */
        status = vf_workspace_path(ws, "poses", "transforms.json", path, size);
    if (status == VF_OK && !vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s has no posed images: run 'vfcapture poses %s' first (or "
                                  "import a posed set with 'vfcapture ingest --transforms')",
                       ws->root, ws->root);
    if (real_capture)
        *real_capture = capture;
    return status;
}

vf_status vf_workspace_posed_frames(const vf_workspace *ws, char *path, size_t size)
{
    const char *stage = vf_workspace_has_stage(ws, "poses") ? "poses" : "ingest";
    vf_status status = vf_workspace_path(ws, stage, "transforms.json", path, size);
    if (status == VF_OK && (!vf_workspace_has_stage(ws, stage) || !vf_is_file(path)))
        return vf_fail(VF_EINPUT, "workspace %s has no posed frames: run 'vfcapture poses %s' "
                                  "first",
                       ws->root, ws->root);
    return status;
}

static vf_status stage_start(vf_workspace *ws, const char *stage, int keep, vf_stage *s)
{
    memset(s, 0, sizeof *s);
    s->ws = ws;
    s->start_time = vf_now();
    snprintf(s->name, sizeof s->name, "%s", stage);
    if (snprintf(s->dir, sizeof s->dir, "%s/.%s.partial", ws->root, stage) >= (int)sizeof s->dir)
        return vf_fail(VF_EINPUT, "workspace path too long: %s", ws->root);
    /* What an interrupted run left: thrown away unless resuming, and said so. */
    if (!keep && vf_is_dir(s->dir) && !folder_is_empty(s->dir))
        vf_info("%s: discarding what an interrupted run left in %s", stage, s->dir);
    vf_status status = keep ? VF_OK : vf_remove_tree(s->dir);
    if (status == VF_OK)
        status = vf_mkdirs(s->dir);
    return status;
}

vf_status vf_stage_begin(vf_workspace *ws, const char *stage, vf_stage *s)
{
    return stage_start(ws, stage, 0, s);
}

vf_status vf_stage_resume(vf_workspace *ws, const char *stage, vf_stage *s)
{
    return stage_start(ws, stage, 1, s);
}

static void utc_timestamp(char *out, size_t size)
{
    time_t now = time(NULL);
    struct tm tm;
    gmtime_r(&now, &tm);
    strftime(out, size, "%Y-%m-%dT%H:%M:%SZ", &tm);
}

vf_status vf_stage_commit(vf_stage *s, json_t *params, json_t *summary)
{
    char final_dir[VF_PATH_MAX], old_dir[VF_PATH_MAX], manifest_path[VF_PATH_MAX], when[32];
    vf_workspace *ws = s->ws;
    vf_status status = VF_OK;
    if (snprintf(old_dir, sizeof old_dir, "%s/.%s.old", ws->root, s->name) >= (int)sizeof old_dir)
        status = vf_fail(VF_EINPUT, "workspace path too long: %s", ws->root);
    if (status == VF_OK)
        status = vf_workspace_path(ws, s->name, "", final_dir, sizeof final_dir);
    if (status == VF_OK)
        status = vf_path_join(manifest_path, sizeof manifest_path, ws->root, MANIFEST);
    if (status == VF_OK)
        status = vf_remove_tree(old_dir);
    if (status != VF_OK)
        goto fail;

    /* Swap: final -> old, partial -> final, then drop old. On any failure the staging folder
     * keeps the new output (a stage that resumes finds it again) and the old output goes
     * back where it was. */
    int had_final = vf_is_dir(final_dir);
    if (had_final && rename(final_dir, old_dir) != 0) {
        status = vf_fail(VF_EINTERNAL, "cannot replace %s: %s", final_dir, strerror(errno));
        goto fail;
    }
    if (rename(s->dir, final_dir) != 0) {
        status = vf_fail(VF_EINTERNAL, "cannot move %s into place: %s", s->dir, strerror(errno));
        if (had_final && rename(old_dir, final_dir) != 0)
            status = vf_fail(VF_EINTERNAL, "%s; the previous output is in %s", vf_error_message(),
                             old_dir);
        goto fail;
    }

    utc_timestamp(when, sizeof when);
    json_t *stages = json_object_get(ws->manifest, "stages");
    json_t *previous = json_incref(json_object_get(stages, s->name));
    json_t *record = json_pack("{s:s, s:s, s:f, s:o, s:o}", "completed", when, "version",
                               VF_VERSION, "seconds", vf_now() - s->start_time, "params",
                               params ? params : json_object(), "summary",
                               summary ? summary : json_object());
    params = summary = NULL;
    json_object_set_new(stages, s->name, record);
    status = vf_json_save(manifest_path, ws->manifest);
    if (status != VF_OK) {
        /* The manifest must describe what is on disk: the new output back to staging, the old
         * folder and record back in place. */
        if (previous)
            json_object_set(stages, s->name, previous);
        else
            json_object_del(stages, s->name);
        if (rename(final_dir, s->dir) != 0)
            status = vf_fail(VF_EINTERNAL, "%s; the new output stays in %s", vf_error_message(),
                             final_dir);
        else if (had_final && rename(old_dir, final_dir) != 0)
            status = vf_fail(VF_EINTERNAL, "%s; the previous output is in %s", vf_error_message(),
                             old_dir);
    } else {
        vf_remove_tree(old_dir);
    }
    json_decref(previous);
    return status;

fail:
    json_decref(params);
    json_decref(summary);
    return status;
}

void vf_stage_abort(vf_stage *s)
{
    vf_remove_tree(s->dir);
}
