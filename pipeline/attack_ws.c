/* Reading the trained field and its cameras from a workspace (attack_ws.h). */
#include "attack_ws.h"

#include <stdlib.h>
#include <string.h>

#include "vf/dataset.h"

vf_status attack_ws_open(const char *root, vf_workspace *ws, vf_field **field)
{
    char path[VF_PATH_MAX];
    if (!vf_is_dir(root))
        return vf_fail(VF_EINPUT, "workspace %s does not exist (create it with 'vfcapture "
                       "ingest')", root);
    vf_status status = vf_workspace_open(root, 0, ws);
    if (status != VF_OK)
        return status;
    if (!vf_workspace_has_stage(ws, "train")) {
        vf_workspace_close(ws);
        return vf_fail(VF_EINPUT, "workspace %s has no trained radiance field: run 'vfcapture "
                       "train %s' first", root, root);
    }
    status = vf_workspace_path(ws, "train", "model.vff", path, sizeof path);
    if (status == VF_OK)
        status = vf_field_load(path, field);
    if (status != VF_OK)
        vf_workspace_close(ws);
    return status;
}

vf_status attack_ws_training_poses(const vf_workspace *ws, double **c2w, int *count,
                                   int *real_capture)
{
    char path[VF_PATH_MAX];
    vf_status status = vf_workspace_training_views(ws, path, sizeof path, real_capture);
    vf_dataset ds;
    if (status == VF_OK)
        status = vf_dataset_load(path, &ds);
    if (status != VF_OK)
        return status;
    *c2w = malloc((size_t)ds.count * 16 * sizeof **c2w);
    if (!*c2w) {
        vf_dataset_free(&ds);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
    for (int i = 0; i < ds.count; i++)
        memcpy(*c2w + 16 * i, ds.frames[i].c2w, 16 * sizeof **c2w);
    *count = ds.count;
    vf_dataset_free(&ds);
    return VF_OK;
}
