#define _GNU_SOURCE
#include "vf/workspace.h"

#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "vf/json.h"
#include "vf/log.h"

#define MANIFEST "manifest.json"
#define MANIFEST_LOCK ".manifest.lock"
#define MAX_DEPTH 16 /* of built_on chains: ingest, poses, train, attack, export, reshoot, ... */

/* What each family of stages reads, when it is in the workspace ("attack" of a named stage
 * means the attack of the same name). A stage that reads one chosen at run time adds it with
 * vf_stage_uses (export: the attack it exports). */
static const struct {
    const char *family, *uses[4];
} stage_uses[] = {
    {"poses", {"ingest"}},
    {"calib", {"ingest", "poses"}},
    {"train", {"ingest", "poses"}},
    {"attack", {"train"}},
    {"real", {"ingest", "attack"}},
    {"transfer", {"attack"}},
    {"export", {"poses", "calib", "train"}},
    {"reshoot", {"export"}},
    {"score", {"export"}},
};

vf_status vf_stage_name_check(const char *stage)
{
    int part_start = 1, parts = 1;
    size_t n = strlen(stage ? stage : "");
    for (size_t i = 0; i < n; i++) {
        char c = stage[i];
        if (c == '/' && !part_start && parts == 1) {
            part_start = 1, parts++;
            continue;
        }
        int ok = islower((unsigned char)c) || isdigit((unsigned char)c) ||
                 (!part_start && (c == '_' || c == '-' || c == '.'));
        if (!ok)
            break;
        part_start = 0;
        if (i == n - 1)
            return n < sizeof(((vf_stage *)0)->name) ? VF_OK : vf_fail(VF_EINPUT, "stage name too long: %s", stage);
    }
    return vf_fail(VF_EINPUT, "'%s' is not a stage name (lower-case letters, digits, '_', '-' "
                              "and '.', a family and at most one name after a '/')",
                   stage ? stage : "");
}

/* "attack/x" -> family "attack", name "x"; "train" -> "train", "". */
static void split_stage(const char *stage, char *family, size_t size, const char **name)
{
    const char *slash = strchr(stage, '/');
    size_t len = slash ? (size_t)(slash - stage) : strlen(stage);
    snprintf(family, size, "%.*s", (int)len, stage);
    *name = slash ? slash + 1 : "";
}

/* WS/.<stage><suffix> for a family, WS/<family>/.<name><suffix> for a named stage. */
static vf_status hidden_path(const vf_workspace *ws, const char *stage, const char *suffix,
                             char *out, size_t size)
{
    char family[128];
    const char *name;
    split_stage(stage, family, sizeof family, &name);
    int n = name[0] ? snprintf(out, size, "%s/%s/.%s%s", ws->root, family, name, suffix)
                    : snprintf(out, size, "%s/.%s%s", ws->root, stage, suffix);
    return n >= 0 && (size_t)n < size ? VF_OK
                                      : vf_fail(VF_EINPUT, "workspace path too long: %s", ws->root);
}

/* An fcntl write lock on the whole of `path` (created when missing), waiting for it when
 * `wait` is set; *fd gets the open descriptor, which holds the lock until closed. VF_EINPUT
 * when the lock is held elsewhere and `wait` is not set. A stage's lock file is removed when
 * the stage ends (release_lock), so a lock taken on a file that was removed meanwhile is
 * taken again on the path's new file. */
static vf_status lock_file(const char *path, int wait, int *fd)
{
    int rc, err;
    for (;;) {
        *fd = open(path, O_RDWR | O_CREAT | O_CLOEXEC, 0644);
        if (*fd < 0)
            return vf_fail(VF_EINPUT, "cannot open the lock %s: %s", path, strerror(errno));
        struct flock lock = {.l_type = F_WRLCK, .l_whence = SEEK_SET};
        while ((rc = fcntl(*fd, wait ? F_SETLKW : F_SETLK, &lock)) != 0 && errno == EINTR)
            ;
        err = errno;
        struct stat held, named;
        if (rc != 0 || (fstat(*fd, &held) == 0 && stat(path, &named) == 0 &&
                        held.st_ino == named.st_ino && held.st_dev == named.st_dev))
            break;
        close(*fd); /* the file was removed or replaced after we opened it */
    }
    if (rc == 0)
        return VF_OK;
    close(*fd);
    *fd = -1;
    if (err == EACCES || err == EAGAIN)
        return vf_fail(VF_EINPUT, "busy");
    return vf_fail(VF_EINTERNAL, "cannot lock %s: %s", path, strerror(err));
}

static json_t *stages_of(const vf_workspace *ws)
{
    return json_object_get(ws->manifest, "stages");
}

static const char *record_id(const json_t *record)
{
    return json_string_value(json_object_get(record, "id"));
}

/* The stages `stage` reads by the table, for its family and name, that are in the manifest. */
static int table_uses(const vf_workspace *ws, const char *stage, char used[][128], int max)
{
    char family[128];
    const char *name;
    split_stage(stage, family, sizeof family, &name);
    if (!strncmp(family, "reshoot", 7)) /* reshoot_t00, reshoot_t01, ...: one per target */
        snprintf(family, sizeof family, "reshoot");
    int n = 0;
    for (size_t t = 0; t < sizeof stage_uses / sizeof stage_uses[0]; t++) {
        if (strcmp(stage_uses[t].family, family))
            continue;
        for (int u = 0; u < 4 && stage_uses[t].uses[u] && n < max; u++) {
            const char *dep = stage_uses[t].uses[u];
            if (!strcmp(dep, "attack") && name[0])
                snprintf(used[n], sizeof used[n], "attack/%s", name);
            else
                snprintf(used[n], sizeof used[n], "%s", dep);
            if (json_object_get(stages_of(ws), used[n]))
                n++;
        }
    }
    return n;
}

static int stale_at(const vf_workspace *ws, const char *stage, char *why, size_t size, int depth)
{
    const json_t *built_on = json_object_get(json_object_get(stages_of(ws), stage), "built_on");
    const char *used;
    json_t *id;
    if (depth > MAX_DEPTH)
        return 0;
    json_object_foreach((json_t *)built_on, used, id) {
        const json_t *record = json_object_get(stages_of(ws), used);
        const char *now = record_id(record);
        if (!record || !now || strcmp(now, json_string_value(id) ?: "")) {
            if (why)
                snprintf(why, size, "%s was %s after it", used, record ? "rerun" : "removed");
            return 1;
        }
        if (stale_at(ws, used, why, size, depth + 1)) {
            if (why) {
                char inner[256];
                snprintf(inner, sizeof inner, "%s", why);
                snprintf(why, size, "it was built on %s, which is stale: %s", used, inner);
            }
            return 1;
        }
    }
    return 0;
}

int vf_workspace_is_stale(const vf_workspace *ws, const char *stage, char *why, size_t size)
{
    if (why && size)
        why[0] = '\0';
    return stale_at(ws, stage, why, size, 0);
}

/* 'vfcapture attack WS --attack x' for stage attack/x. */
static void command_for(const vf_workspace *ws, const char *stage, char *out, size_t size)
{
    char family[128];
    const char *name;
    split_stage(stage, family, sizeof family, &name);
    if (!strncmp(family, "reshoot", 7))
        snprintf(family, sizeof family, "reshoot");
    if (name[0])
        snprintf(out, size, "vfcapture %s %s --attack %s", family, ws->root, name);
    else
        snprintf(out, size, "vfcapture %s %s", family, ws->root);
}

vf_status vf_workspace_need(const vf_workspace *ws, const char *stage)
{
    char command[VF_PATH_MAX + 256], why[256];
    command_for(ws, stage, command, sizeof command);
    if (!vf_workspace_has_stage(ws, stage))
        return vf_fail(VF_EINPUT, "%s has no %s yet: run '%s' first", ws->root, stage, command);
    if (vf_workspace_is_stale(ws, stage, why, sizeof why))
        return vf_fail(VF_EINPUT, "%s: %s is stale (%s): run '%s' again", ws->root, stage, why,
                       command);
    return VF_OK;
}

/* Whether a folder holds no file, in it or in its sub-folders (a workflow engine makes the
 * folders of a stage's outputs before the stage runs: such a folder may become a workspace). */
static int folder_is_empty(const char *path)
{
    DIR *dir = opendir(path);
    if (!dir)
        return 0;
    struct dirent *entry;
    int empty = 1;
    while (empty && (entry = readdir(dir))) {
        if (!strcmp(entry->d_name, ".") || !strcmp(entry->d_name, ".."))
            continue;
        char sub[VF_PATH_MAX];
        empty = vf_path_join(sub, sizeof sub, path, entry->d_name) == VF_OK && vf_is_dir(sub) &&
                folder_is_empty(sub);
    }
    closedir(dir);
    return empty;
}

static vf_status load_manifest(const char *path, json_t **out)
{
    vf_status status = vf_json_load(path, out);
    if (status == VF_OK && !json_is_object(json_object_get(*out, "stages"))) {
        json_decref(*out);
        *out = NULL;
        status = vf_fail(VF_EINPUT, "%s is not a vfcapture manifest", path);
    }
    return status;
}

vf_status vf_workspace_reload(vf_workspace *ws)
{
    char path[VF_PATH_MAX];
    json_t *fresh = NULL;
    vf_status status = vf_path_join(path, sizeof path, ws->root, MANIFEST);
    if (status == VF_OK && (status = load_manifest(path, &fresh)) == VF_OK) {
        json_decref(ws->manifest);
        ws->manifest = fresh;
    }
    return status;
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

    if (vf_is_file(manifest_path))
        return load_manifest(manifest_path, &ws->manifest);
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

int vf_workspace_stages_of(const vf_workspace *ws, const char *family, const char **names,
                           int max)
{
    const char *key;
    json_t *record;
    size_t len = strlen(family);
    int n = 0;
    json_object_foreach(stages_of(ws), key, record) {
        if (n < max && !strncmp(key, family, len) && key[len] == '/' &&
            vf_workspace_has_stage(ws, key))
            names[n++] = key;
    }
    return n;
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
    if (status == VF_OK && capture && vf_workspace_is_stale(ws, "poses", NULL, 0))
        return vf_workspace_need(ws, "poses"); /* ingest rerun since */
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

/* Add `used` to what the stage read; VF_EINPUT when it is stale itself. */
static vf_status add_use(vf_stage *s, const char *used)
{
    const char *id = record_id(vf_workspace_stage_record(s->ws, used));
    char why[256], command[VF_PATH_MAX + 256];
    if (vf_workspace_is_stale(s->ws, used, why, sizeof why)) {
        command_for(s->ws, used, command, sizeof command);
        return vf_fail(VF_EINPUT, "%s: cannot run %s on %s, which is stale (%s): run '%s' first",
                       s->ws->root, s->name, used, why, command);
    }
    for (int i = 0; i < s->uses; i++)
        if (!strcmp(s->used[i], used))
            return VF_OK;
    if (!id) /* a record from before ids: nothing to compare with later */
        return VF_OK;
    if (s->uses == (int)(sizeof s->used / sizeof s->used[0]))
        return vf_fail(VF_EINTERNAL, "%s reads too many stages", s->name);
    snprintf(s->used[s->uses], sizeof s->used[0], "%s", used);
    snprintf(s->used_id[s->uses], sizeof s->used_id[0], "%s", id);
    s->uses++;
    return VF_OK;
}

vf_status vf_stage_uses(vf_stage *s, const char *used)
{
    vf_status status = vf_workspace_need(s->ws, used);
    return status == VF_OK ? add_use(s, used) : status;
}

/* Remove the stage's lock file while holding it (so a finished stage leaves no file), then
 * let go. */
static void release_lock(vf_stage *s)
{
    char lock[VF_PATH_MAX];
    if (s->lock_fd >= 0 && hidden_path(s->ws, s->name, ".lock", lock, sizeof lock) == VF_OK)
        unlink(lock);
    if (s->lock_fd >= 0)
        close(s->lock_fd);
    s->lock_fd = -1;
}

static vf_status stage_start(vf_workspace *ws, const char *stage, int keep, vf_stage *s)
{
    memset(s, 0, sizeof *s);
    s->ws = ws;
    s->lock_fd = -1;
    s->start_time = vf_now();
    vf_status status = vf_stage_name_check(stage);
    if (status != VF_OK)
        return status;
    snprintf(s->name, sizeof s->name, "%s", stage);
    char lock[VF_PATH_MAX], parent[VF_PATH_MAX], used[8][128];
    if ((status = hidden_path(ws, stage, ".partial", s->dir, sizeof s->dir)) != VF_OK ||
        (status = hidden_path(ws, stage, ".lock", lock, sizeof lock)) != VF_OK)
        return status;
    vf_path_dirname(parent, sizeof parent, lock);
    if ((status = vf_mkdirs(parent)) != VF_OK)
        return status;
    if ((status = lock_file(lock, 0, &s->lock_fd)) != VF_OK)
        return status == VF_EINPUT
                   ? vf_fail(VF_EINPUT, "another process is running %s in %s now (it holds %s): "
                                        "wait for it to finish or stop it",
                             stage, ws->root, lock)
                   : status;
    int n = table_uses(ws, stage, used, 8);
    for (int i = 0; i < n && status == VF_OK; i++)
        status = add_use(s, used[i]);
    /* What an interrupted run left: thrown away unless resuming, and said so. */
    if (status == VF_OK && !keep && vf_is_dir(s->dir) && !folder_is_empty(s->dir))
        vf_info("%s: discarding what an interrupted run left in %s", stage, s->dir);
    if (status == VF_OK && !keep)
        status = vf_remove_tree(s->dir);
    if (status == VF_OK)
        status = vf_mkdirs(s->dir);
    if (status != VF_OK)
        release_lock(s);
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

/* A new record id: 16 hex digits from the kernel's random source. */
static void new_id(char *out, size_t size)
{
    unsigned char bytes[8] = {0};
    if (getrandom(bytes, sizeof bytes, 0) != (ssize_t)sizeof bytes) { /* never in practice */
        unsigned long long t = (unsigned long long)(vf_now() * 1e6) ^ (unsigned long long)getpid();
        memcpy(bytes, &t, sizeof bytes);
    }
    snprintf(out, size, "%02x%02x%02x%02x%02x%02x%02x%02x", bytes[0], bytes[1], bytes[2],
             bytes[3], bytes[4], bytes[5], bytes[6], bytes[7]);
}

/* Under the manifest's lock: read it from disk, set the stage's record, write it back. The
 * in-memory manifest gets the record too (and keeps what it had read of the others). */
static vf_status record_stage(vf_workspace *ws, const char *stage, json_t *record)
{
    char manifest_path[VF_PATH_MAX], lock[VF_PATH_MAX];
    json_t *disk = NULL;
    int fd = -1;
    vf_status status = vf_path_join(manifest_path, sizeof manifest_path, ws->root, MANIFEST);
    if (status == VF_OK)
        status = vf_path_join(lock, sizeof lock, ws->root, MANIFEST_LOCK);
    if (status == VF_OK)
        status = lock_file(lock, 1, &fd);
    if (status == VF_OK)
        status = load_manifest(manifest_path, &disk);
    if (status == VF_OK) {
        json_object_set(json_object_get(disk, "stages"), stage, record);
        status = vf_json_save(manifest_path, disk);
    }
    if (fd >= 0)
        close(fd);
    if (status == VF_OK)
        json_object_set(stages_of(ws), stage, record);
    json_decref(disk);
    json_decref(record);
    return status;
}

vf_status vf_stage_commit(vf_stage *s, json_t *params, json_t *summary)
{
    char final_dir[VF_PATH_MAX], old_dir[VF_PATH_MAX], stage_file[VF_PATH_MAX], when[32], id[24];
    vf_workspace *ws = s->ws;
    utc_timestamp(when, sizeof when);
    new_id(id, sizeof id);
    json_t *built_on = json_object();
    for (int i = 0; i < s->uses; i++)
        json_object_set_new(built_on, s->used[i], json_string(s->used_id[i]));
    json_t *record = json_pack(
        "{s:s, s:s, s:s, s:o, s:o, s:o, s:o}", "completed", when, "id", id, "version", VF_VERSION,
        "seconds", vf_json_number(vf_now() - s->start_time), "built_on", built_on, "params",
        params ? params : json_object(), "summary", summary ? summary : json_object());
    vf_status status =
        record ? VF_OK : vf_fail(VF_EINTERNAL, "cannot record %s in the manifest", s->name);
    if (status == VF_OK)
        status = hidden_path(ws, s->name, ".old", old_dir, sizeof old_dir);
    if (status == VF_OK)
        status = vf_workspace_path(ws, s->name, "", final_dir, sizeof final_dir);
    if (status == VF_OK)
        status = vf_remove_tree(old_dir);
    /* The folder describes itself: WS/<stage>/stage.json is its record (what a workflow
     * engine watches; the manifest stays the reference). */
    if (status == VF_OK && (status = vf_path_join(stage_file, sizeof stage_file, s->dir,
                                                  VF_STAGE_FILE)) == VF_OK)
        status = vf_json_save(stage_file, record);
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

    status = record_stage(ws, s->name, record);
    if (status != VF_OK) {
        /* The manifest must describe what is on disk: the new output back to staging, the old
         * folder back in place. */
        if (rename(final_dir, s->dir) != 0)
            status = vf_fail(VF_EINTERNAL, "%s; the new output stays in %s", vf_error_message(),
                             final_dir);
        else if (had_final && rename(old_dir, final_dir) != 0)
            status = vf_fail(VF_EINTERNAL, "%s; the previous output is in %s", vf_error_message(),
                             old_dir);
    } else {
        vf_remove_tree(old_dir);
        release_lock(s);
    }
    return status;

fail:
    json_decref(record);
    return status;
}

void vf_stage_abort(vf_stage *s)
{
    vf_remove_tree(s->dir);
    release_lock(s);
}

vf_status vf_stage_keep_if_same(const char *dir, json_t *request, const char *const *subdirs)
{
    char path[VF_PATH_MAX], sub[VF_PATH_MAX];
    json_t *before = NULL;
    vf_status status = request ? vf_path_join(path, sizeof path, dir, "request.json")
                               : vf_fail(VF_EINTERNAL, "out of memory");
    if (status == VF_OK && vf_is_file(path) && vf_json_load(path, &before) == VF_OK &&
        json_equal(before, request))
        vf_info("continuing the renders of an interrupted run");
    else
        for (int i = 0; status == VF_OK && subdirs[i]; i++)
            if ((status = vf_path_join(sub, sizeof sub, dir, subdirs[i])) == VF_OK)
                status = vf_remove_tree(sub);
    json_decref(before);
    if (status == VF_OK)
        status = vf_json_save(path, request);
    json_decref(request);
    return status;
}
