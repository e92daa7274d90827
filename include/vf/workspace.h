/* vf/workspace.h: the folder a capture lives in, one subfolder per stage.
 *
 *   WS/manifest.json   which stages ran, when, with which parameters and tool version
 *   WS/ingest/ ...     each stage writes only its own folder
 *   WS/FAMILY/NAME/    a stage with a name ("attack/nes-l0.01"): one of several of its family
 *   WS/<stage>/stage.json   that stage's manifest record, written with it (for workflow
 *                      engines such as Snakemake, which watch files: the manifest is the truth)
 *
 * A stage never writes its folder in place. vf_stage_begin() gives it an empty staging folder
 * (WS/.<stage>.partial, WS/FAMILY/.NAME.partial); vf_stage_commit() swaps that folder in and
 * records the stage in the manifest; vf_stage_abort() throws the staging folder away. So a
 * stage that fails or is interrupted leaves every earlier output, its own previous output
 * included, as it was.
 *
 * Several processes, on one machine or on nodes sharing the folder, may work in one workspace
 * at once (a study's jobs): a commit takes an exclusive POSIX record lock (fcntl) on
 * WS/.manifest.lock, reads the manifest from disk, changes its own stage's record and writes it
 * back, so no commit loses another's record. fcntl locks, not lock files or flock: the kernel
 * drops them when a process dies (SIGKILL, scancel, a lost node's lease), and NFS carries them
 * between nodes (flock on NFS is emulated with them anyway). A stage also holds a lock on
 * WS/.<stage>.lock from begin to commit or abort, so a second run of the same stage is refused
 * while the first is alive (a dead one's staging folder is taken over, or resumed).
 *
 * Every record carries an "id", new on each commit, and "built_on": the ids of the stages it
 * read when it began (vf_stage_begin fills it from the table in workspace.c; a stage that reads
 * one chosen at run time adds it with vf_stage_uses). When one of those is rerun or removed,
 * the stage is stale, and so is everything built on it: vf_workspace_need and vf_stage_begin
 * refuse with one line naming the stage to rerun.
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

#define VF_STAGE_FILE "stage.json" /* in each committed stage's folder: its record */

typedef struct vf_workspace {
    char root[VF_PATH_MAX];
    json_t *manifest;
} vf_workspace;

typedef struct vf_stage {
    vf_workspace *ws;
    char name[128];
    char dir[VF_PATH_MAX];   /* staging folder: write the stage's outputs here */
    double start_time;
    int uses;                /* the stages it read, and their ids when it began */
    char used[8][128], used_id[8][24];
    int lock_fd;             /* the stage's lock, held until commit or abort (-1: none) */
} vf_stage;

/* A stage name is a family ("train") or a family and a name ("attack/nes-l0.01"): lower
 * case letters, digits, '_', '-' and '.', each part starting with a letter or digit. */
vf_status vf_stage_name_check(const char *stage);

/* Open a workspace; with create set, make the folder when missing. A folder that holds
 * files but no manifest is refused (it is not a workspace, and we do not write into it). */
vf_status vf_workspace_open(const char *root, int create, vf_workspace *ws);
void vf_workspace_close(vf_workspace *ws);

/* Whether `stage` has completed in this workspace (stale or not). */
int vf_workspace_has_stage(const vf_workspace *ws, const char *stage);
/* VF_OK when `stage` completed and nothing it was built on has changed since. VF_EINPUT
 * otherwise, one line naming what to run: "WS has no train yet: run 'vfcapture train WS'
 * first" or "WS: train is stale (poses was rerun after it): run 'vfcapture train WS' again". */
vf_status vf_workspace_need(const vf_workspace *ws, const char *stage);
/* Whether `stage`'s record is stale; why (may be NULL) gets the reason ("poses was rerun after
 * it"). A stage not in the manifest is not stale. */
int vf_workspace_is_stale(const vf_workspace *ws, const char *stage, char *why, size_t size);
/* Read the manifest again from disk (what other processes committed since it was opened). */
vf_status vf_workspace_reload(vf_workspace *ws);
/* The names of the completed stages of a family ("attack" -> "attack/a", "attack/b"), in the
 * manifest's order, as borrowed strings into names (at most max); returns how many. */
int vf_workspace_stages_of(const vf_workspace *ws, const char *family, const char **names,
                           int max);
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

/* Start a stage: refuse when another process runs it now or when a stage it reads is stale,
 * then an empty staging folder. */
vf_status vf_stage_begin(vf_workspace *ws, const char *stage, vf_stage *s);
/* Like vf_stage_begin, but keep what an interrupted run left in the staging folder (a stage
 * that checkpoints there continues from it); the folder is created when missing. */
vf_status vf_stage_resume(vf_workspace *ws, const char *stage, vf_stage *s);
/* What an interrupted run left in a resumed staging folder (renders, say) is kept only when
 * it was made for the same request: DIR/request.json is compared with `request` (stolen), and
 * when it differs the subfolders `subdirs` (NULL-terminated) are removed; then request is
 * saved. */
vf_status vf_stage_keep_if_same(const char *dir, json_t *request, const char *const *subdirs);
/* Swap the staging folder in and record params and summary (both stolen; either may be NULL).
 * On failure nothing is lost: the new output stays in the staging folder (for a retry or a
 * resume) and the stage's previous output and manifest record stay as they were. */
vf_status vf_stage_commit(vf_stage *s, json_t *params, json_t *summary);
void vf_stage_abort(vf_stage *s);
/* Record that the stage reads `used` (one chosen at run time), so the
 * stage goes stale when `used` is rerun. `used` must be completed and current. */
vf_status vf_stage_uses(vf_stage *s, const char *used);

#ifdef __cplusplus
}
#endif
#endif
