/* Workspace: stage outputs are swapped in atomically and recorded in the manifest; a stage
 * that is aborted leaves the earlier output exactly as it was. */
#include <stdio.h>
#include <string.h>

#include "check.h"
#include "vf/workspace.h"

static void write_text(const char *dir, const char *name, const char *text)
{
    char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, dir, name);
    CHECK(vf_write_file_atomic(path, text, strlen(text)) == VF_OK, "write %s", path);
}

static int file_says(const char *path, const char *text)
{
    char *data;
    if (vf_read_file(path, &data, NULL) != VF_OK)
        return 0;
    int same = !strcmp(data, text);
    free(data);
    return same;
}

int main(void)
{
    char root[VF_PATH_MAX], path[VF_PATH_MAX];
    vf_path_join(root, sizeof root, vf_test_tmpdir(), "ws");
    vf_workspace ws;
    vf_stage stage;

    CHECK(vf_workspace_open(root, 0, &ws) == VF_EINPUT, "opening a missing workspace fails");
    CHECK(strstr(vf_error_message(), "does not exist") != NULL, "message: %s", vf_error_message());
    CHECK(vf_workspace_open(root, 1, &ws) == VF_OK, "create: %s", vf_error_message());
    CHECK(!vf_workspace_has_stage(&ws, "ingest"), "new workspace has no stages");

    /* First run of a stage. */
    CHECK(vf_stage_begin(&ws, "ingest", &stage) == VF_OK, "begin");
    write_text(stage.dir, "a.txt", "first");
    CHECK(vf_stage_commit(&stage, json_pack("{s:i}", "n", 1), NULL) == VF_OK, "commit");
    CHECK(vf_workspace_has_stage(&ws, "ingest"), "stage recorded");
    vf_workspace_path(&ws, "ingest", "a.txt", path, sizeof path);
    CHECK(file_says(path, "first"), "output in place");
    CHECK(!vf_is_dir(stage.dir), "staging folder gone after commit");

    /* A second run that fails: the first output stays. */
    CHECK(vf_stage_begin(&ws, "ingest", &stage) == VF_OK, "begin again");
    write_text(stage.dir, "a.txt", "second, never committed");
    vf_stage_abort(&stage);
    CHECK(file_says(path, "first"), "aborted stage leaves the earlier output");
    CHECK(!vf_is_dir(stage.dir), "staging folder removed on abort");

    /* A second run that succeeds replaces the output and the record. */
    CHECK(vf_stage_begin(&ws, "ingest", &stage) == VF_OK, "begin third");
    write_text(stage.dir, "a.txt", "third");
    CHECK(vf_stage_commit(&stage, json_pack("{s:i}", "n", 3), NULL) == VF_OK, "commit third");
    CHECK(file_says(path, "third"), "replaced output");
    vf_workspace_close(&ws);

    /* The manifest on disk survives a reopen. */
    CHECK(vf_workspace_open(root, 0, &ws) == VF_OK, "reopen: %s", vf_error_message());
    json_t *record = vf_workspace_stage_record(&ws, "ingest");
    CHECK(json_integer_value(json_object_get(json_object_get(record, "params"), "n")) == 3,
          "manifest records the latest parameters");
    CHECK(json_is_string(json_object_get(record, "version")), "manifest records the version");
    vf_workspace_close(&ws);

    /* A folder with other files in it is not taken over. */
    char foreign[VF_PATH_MAX];
    vf_path_join(foreign, sizeof foreign, vf_test_tmpdir(), "photos");
    vf_mkdirs(foreign);
    write_text(foreign, "holiday.jpg", "not ours");
    CHECK(vf_workspace_open(foreign, 1, &ws) == VF_EINPUT, "non-workspace folder refused");
    CHECK(strstr(vf_error_message(), "not a vfcapture workspace") != NULL, "message: %s",
          vf_error_message());

    /* A corrupt manifest is reported, not overwritten. */
    vf_path_join(path, sizeof path, root, "manifest.json");
    vf_write_file_atomic(path, "{broken", 7);
    CHECK(vf_workspace_open(root, 1, &ws) == VF_EINPUT, "corrupt manifest refused");
    CHECK(file_says(path, "{broken"), "corrupt manifest left for the user to inspect");
    return check_finish();
}
