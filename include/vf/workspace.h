/* vf/workspace.h: the folder a capture lives in, one subfolder per stage.
 *
 *   WS/manifest.json   which stages ran, when, with which parameters and tool version
 *   WS/ingest/ ...     each stage writes only its own folder
 *
 * A stage never writes its folder in place. vf_stage_begin() gives it an empty staging folder
 * (WS/.<stage>.partial); vf_stage_commit() swaps that folder in and records the stage in the
 * manifest; vf_stage_abort() throws the staging folder away. So a stage that fails or is
 * interrupted leaves every earlier output, its own previous output included, as it was.
 * A vf_workspace owns its manifest (a jansson object); vf_workspace_close() releases it. */
#ifndef VF_WORKSPACE_H
#define VF_WORKSPACE_H

#include <jansson.h>

#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/json.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_workspace {
    char root[VF_PATH_MAX];
    json_t *manifest;
} vf_workspace;

typedef struct vf_stage {
    vf_workspace *ws;
    char name[64];
    char dir[VF_PATH_MAX];   /* staging folder: write the stage's outputs here */
    double start_time;
} vf_stage;

/* Open a workspace; with create set, make the folder when missing. A folder that holds
 * files but no manifest is refused (it is not a workspace, and we do not write into it). */
vf_status vf_workspace_open(const char *root, int create, vf_workspace *ws);
void vf_workspace_close(vf_workspace *ws);

/* Whether `stage` has completed in this workspace. */
int vf_workspace_has_stage(const vf_workspace *ws, const char *stage);
/* The manifest record of a completed stage ({"params":..., "summary":...}), or NULL. Borrowed. */
json_t *vf_workspace_stage_record(const vf_workspace *ws, const char *stage);
/* WS/<stage>/<file> into out (file may be "" for the folder itself). */
vf_status vf_workspace_path(const vf_workspace *ws, const char *stage, const char *file, char *out,
                            size_t size);

/* The transforms file of the posed training views: a capture's undistorted frames
 * (WS/poses/transforms_undistorted.json, or transforms.json with the lens when they were not
 * undistorted; *real_capture = 1) or an imported posed set
 * (WS/ingest/transforms.json, *real_capture = 0; real_capture may be NULL). VF_EINPUT saying
 * what to run first when there is neither. */
vf_status vf_workspace_training_views(const vf_workspace *ws, char *path, size_t size,
                                      int *real_capture);
/* The transforms file of the posed frames as stored (with their lens, not undistorted): a
 * capture's WS/poses/transforms.json or an imported set's WS/ingest/transforms.json. For
 * pixels picked in the images the user sees (calib scale). VF_EINPUT saying what to run first
 * when there is neither. */
vf_status vf_workspace_posed_frames(const vf_workspace *ws, char *path, size_t size);

vf_status vf_stage_begin(vf_workspace *ws, const char *stage, vf_stage *s);
/* Like vf_stage_begin, but keep what an interrupted run left in the staging folder (a stage
 * that checkpoints there continues from it); the folder is created when missing. */
vf_status vf_stage_resume(vf_workspace *ws, const char *stage, vf_stage *s);
/* Swap the staging folder in and record params and summary (both stolen; either may be NULL).
 * On failure nothing is lost: the new output stays in the staging folder (for a retry or a
 * resume) and the stage's previous output and manifest record stay as they were. */
vf_status vf_stage_commit(vf_stage *s, json_t *params, json_t *summary);
void vf_stage_abort(vf_stage *s);

#ifdef __cplusplus
}
#endif
#endif
