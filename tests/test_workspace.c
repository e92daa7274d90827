/* Workspace: stage outputs are swapped in atomically and recorded in the manifest; a stage
 * that is aborted leaves the earlier output exactly as it was. */
#include <stdio.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "vf/ingest.h"
#include "vf/rgb8.h"
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

/* Numbers survive vf_json_save and vf_json_load bit for bit (a checkpoint compares the saved
 * viewpoint box with the recomputed one: at 12 digits `attack --resume` refused every real
 * capture). */
static void test_json_round_trip(void)
{
    char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, vf_test_tmpdir(), "numbers.json");
    const double x[4] = {0.1 + 0.2, -17.123456789012345, 1.0 / 3.0, 6.02214076e23};
    json_t *doc = json_pack("[f, f, f, f]", x[0], x[1], x[2], x[3]), *back = NULL;
    CHECK(vf_json_save(path, doc) == VF_OK && vf_json_load(path, &back) == VF_OK, "save, load");
    for (int i = 0; back && i < 4; i++)
        CHECK(json_real_value(json_array_get(back, (size_t)i)) == x[i], "number %d exact", i);
    CHECK(back && json_equal(doc, back), "the document is unchanged");
    json_decref(doc);
    json_decref(back);
}

/* A message may build on the one before it (the commit's recovery messages do). */
static void test_error_chaining(void)
{
    vf_fail(VF_EINPUT, "cannot write X");
    vf_fail(VF_EINTERNAL, "%s; the previous output is in %s", vf_error_message(), "Y");
    CHECK(!strcmp(vf_error_message(), "cannot write X; the previous output is in Y"),
          "chained message: %s", vf_error_message());
}

/* An ingest whose commit fails (WS/ingest is a file, so the staged folder cannot move into
 * place) reports the failure with no summary: the old stage handed out a copy and leaked it. */
static void test_ingest_failed_commit(void)
{
    char root[VF_PATH_MAX], blocker[VF_PATH_MAX], photos[VF_PATH_MAX], path[VF_PATH_MAX];
    vf_path_join(root, sizeof root, vf_test_tmpdir(), "ws_blocked");
    vf_path_join(photos, sizeof photos, vf_test_tmpdir(), "posed");
    vf_workspace ws;
    CHECK(vf_workspace_open(root, 1, &ws) == VF_OK, "create");
    vf_workspace_close(&ws);
    vf_path_join(blocker, sizeof blocker, root, "ingest");
    write_text(root, "ingest", "a file where the stage folder goes");
    CHECK(vf_mkdirs(photos) == VF_OK, "photos folder");
    vf_rgb8 img = {0};
    CHECK(vf_rgb8_resize_buffer(&img, 32, 24) == VF_OK, "image");
    for (int i = 0; img.data && i < 32 * 24 * 3; i++)
        img.data[i] = (unsigned char)(i * 7);
    for (int i = 0; i < 2; i++) {
        char name[32];
        snprintf(name, sizeof name, "r_%d.png", i);
        vf_path_join(path, sizeof path, photos, name);
        CHECK(vf_rgb8_save(path, &img) == VF_OK, "save %s", name);
    }
    vf_rgb8_free(&img);
    write_text(photos, "transforms.json",
               "{\"camera_angle_x\": 0.69, \"frames\": ["
               "{\"file_path\": \"r_0\", \"transform_matrix\": [[1,0,0,0],[0,1,0,0],[0,0,1,4],[0,0,0,1]]},"
               "{\"file_path\": \"r_1\", \"transform_matrix\": [[0,-1,0,0],[1,0,0,0],[0,0,1,4],[0,0,0,1]]}]}");
    vf_ingest_request r;
    vf_ingest_request_defaults(&r);
    r.kind = VF_INGEST_TRANSFORMS;
    vf_path_join(path, sizeof path, photos, "transforms.json");
    r.input = path;
    json_t *summary = (json_t *)1;
    CHECK(vf_ingest_run(root, &r, &summary) != VF_OK, "the commit fails");
    CHECK(summary == NULL, "no summary of a stage that did not land");
    CHECK(file_says(blocker, "a file where the stage folder goes"), "the blocker is untouched");
    if (summary && summary != (json_t *)1)
        json_decref(summary);
}

/* Stage outputs swap in atomically; a failed or aborted run keeps the earlier output; foreign
 * folders and corrupt manifests are refused. */
static void test_stage_swap(void)
{
    char root[VF_PATH_MAX], path[VF_PATH_MAX];
    vf_path_join(root, sizeof root, vf_test_tmpdir(), "ws");
    vf_workspace ws;
    vf_stage stage;
    json_t *record;

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
    json_t *mirror = NULL;
    vf_workspace_path(&ws, "ingest", VF_STAGE_FILE, path, sizeof path);
    CHECK(vf_json_load(path, &mirror) == VF_OK &&
              json_equal(mirror, vf_workspace_stage_record(&ws, "ingest")),
          "the stage folder holds its manifest record");
    json_decref(mirror);
    vf_workspace_path(&ws, "ingest", "a.txt", path, sizeof path);

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

    /* A commit whose manifest cannot be written (here: a folder in its place) loses nothing:
     * the new output stays staged for a retry, the old output and record stay in place. */
    char manifest[VF_PATH_MAX], moved[VF_PATH_MAX], staged[VF_PATH_MAX];
    vf_path_join(manifest, sizeof manifest, root, "manifest.json");
    vf_path_join(moved, sizeof moved, root, "manifest.saved");
    CHECK(vf_stage_begin(&ws, "ingest", &stage) == VF_OK, "begin fourth");
    write_text(stage.dir, "a.txt", "fourth, finished");
    CHECK(rename(manifest, moved) == 0 && vf_mkdirs(manifest) == VF_OK, "manifest blocked");
    CHECK(vf_stage_commit(&stage, json_pack("{s:i}", "n", 4), NULL) != VF_OK, "commit fails");
    vf_path_join(staged, sizeof staged, stage.dir, "a.txt");
    CHECK(file_says(staged, "fourth, finished"), "the finished output is still staged");
    CHECK(file_says(path, "third"), "the previous output is back in place");
    record = vf_workspace_stage_record(&ws, "ingest");
    CHECK(json_integer_value(json_object_get(json_object_get(record, "params"), "n")) == 3,
          "the manifest record is the previous one");
    CHECK(vf_remove_tree(manifest) == VF_OK && rename(moved, manifest) == 0, "unblocked");
    CHECK(vf_stage_resume(&ws, "ingest", &stage) == VF_OK &&
              vf_stage_commit(&stage, json_pack("{s:i}", "n", 4), NULL) == VF_OK,
          "the retry commits what was staged: %s", vf_error_message());
    CHECK(file_says(path, "fourth, finished"), "retried output in place");
    vf_workspace_close(&ws);

    /* The manifest on disk survives a reopen. */
    CHECK(vf_workspace_open(root, 0, &ws) == VF_OK, "reopen: %s", vf_error_message());
    record = vf_workspace_stage_record(&ws, "ingest");
    CHECK(json_integer_value(json_object_get(json_object_get(record, "params"), "n")) == 4,
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
}

/* Several processes commit different stages of one workspace at once, each through the handle
 * it opened at the start (as a study's parallel jobs do): every record must survive. Without a
 * lock around the manifest's read-modify-write, each commit wrote back the manifest its process
 * had read, and the others' records were lost. */
static void test_concurrent_commits(void)
{
    enum { PROCESSES = 4, ROUNDS = 25 };
    char root[VF_PATH_MAX];
    vf_path_join(root, sizeof root, vf_test_tmpdir(), "ws_concurrent");
    vf_workspace ws;
    CHECK(vf_workspace_open(root, 1, &ws) == VF_OK, "create: %s", vf_error_message());
    vf_workspace_close(&ws);
    pid_t pids[PROCESSES];
    for (int p = 0; p < PROCESSES; p++) {
        pids[p] = fork();
        if (pids[p] == 0) {
            vf_workspace mine;
            int failed = vf_workspace_open(root, 0, &mine) != VF_OK;
            for (int r = 0; r < ROUNDS && !failed; r++) {
                char name[32];
                vf_stage s;
                snprintf(name, sizeof name, "p%d_r%d", p, r);
                failed = vf_stage_begin(&mine, name, &s) != VF_OK ||
                         vf_stage_commit(&s, json_pack("{s:i}", "round", r), NULL) != VF_OK;
            }
            vf_workspace_close(&mine);
            _exit(failed);
        }
    }
    int children_ok = 1;
    for (int p = 0; p < PROCESSES; p++) {
        int status = 0;
        children_ok &= pids[p] > 0 && waitpid(pids[p], &status, 0) == pids[p] &&
                       WIFEXITED(status) && WEXITSTATUS(status) == 0;
    }
    CHECK(children_ok, "every process committed its stages");
    CHECK(vf_workspace_open(root, 0, &ws) == VF_OK, "reopen: %s", vf_error_message());
    int kept = 0;
    for (int p = 0; p < PROCESSES; p++)
        for (int r = 0; r < ROUNDS; r++) {
            char name[32];
            snprintf(name, sizeof name, "p%d_r%d", p, r);
            kept += vf_workspace_has_stage(&ws, name);
        }
    CHECK(kept == PROCESSES * ROUNDS, "the manifest keeps %d of the %d records committed", kept,
          PROCESSES * ROUNDS);
    vf_workspace_close(&ws);
}

/* Rerunning a stage makes what was built on it stale, all the way down: later stages refuse
 * with one line naming what to rerun, and rerunning them in order makes them current again.
 * A second run of a stage is refused while the first still holds it. */
static void test_staleness(void)
{
    char root[VF_PATH_MAX];
    vf_path_join(root, sizeof root, vf_test_tmpdir(), "ws_stale");
    vf_workspace ws;
    vf_stage s, second;
    CHECK(vf_workspace_open(root, 1, &ws) == VF_OK, "create: %s", vf_error_message());
    const char *chain[] = {"ingest", "poses", "train"};
    for (int i = 0; i < 3; i++)
        CHECK(vf_stage_begin(&ws, chain[i], &s) == VF_OK && vf_stage_commit(&s, NULL, NULL) == VF_OK,
              "%s: %s", chain[i], vf_error_message());
    CHECK(vf_workspace_need(&ws, "train") == VF_OK, "a fresh chain is current");
    CHECK(vf_workspace_need(&ws, "attack") == VF_EINPUT &&
              strstr(vf_error_message(), "vfcapture attack") != NULL,
          "a missing stage names its command: %s", vf_error_message());

    /* Another ingest: poses and train are stale, and nothing reads them silently. */
    CHECK(vf_stage_begin(&ws, "ingest", &s) == VF_OK && vf_stage_commit(&s, NULL, NULL) == VF_OK,
          "re-ingest");
    char why[256];
    CHECK(vf_workspace_is_stale(&ws, "poses", why, sizeof why) && strstr(why, "ingest"),
          "poses stale: %s", why);
    CHECK(vf_workspace_is_stale(&ws, "train", why, sizeof why), "train stale through poses");
    CHECK(vf_workspace_need(&ws, "train") == VF_EINPUT && strstr(vf_error_message(), "stale"),
          "need(train): %s", vf_error_message());
    CHECK(vf_stage_begin(&ws, "attack", &s) == VF_EINPUT && strstr(vf_error_message(), "train"),
          "attack on a stale field refused: %s", vf_error_message());
    CHECK(vf_stage_begin(&ws, "train", &s) == VF_EINPUT && strstr(vf_error_message(), "poses"),
          "train on stale poses refused: %s", vf_error_message());

    /* The same stage twice at once: the second is refused until the first ends. */
    CHECK(vf_stage_begin(&ws, "poses", &s) == VF_OK, "rerun poses");
    vf_workspace other;
    CHECK(vf_workspace_open(root, 0, &other) == VF_OK, "second handle");
    pid_t child = fork();
    if (child == 0) /* fcntl locks are per process: try from another one */
        _exit(vf_stage_begin(&other, "poses", &second) == VF_OK ? 1 : 0);
    int status = 0;
    CHECK(waitpid(child, &status, 0) == child && WIFEXITED(status) && WEXITSTATUS(status) == 0,
          "a second poses while the first runs is refused");
    vf_workspace_close(&other);
    CHECK(vf_stage_commit(&s, NULL, NULL) == VF_OK, "poses committed");
    CHECK(!vf_workspace_is_stale(&ws, "poses", NULL, 0), "rerun poses is current");
    CHECK(vf_stage_begin(&ws, "train", &s) == VF_OK && vf_stage_commit(&s, NULL, NULL) == VF_OK,
          "rerun train: %s", vf_error_message());
    CHECK(vf_workspace_need(&ws, "train") == VF_OK, "the chain is current again");
    vf_workspace_close(&ws);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_json_round_trip);
    CHECK_CASE(test_error_chaining);
    CHECK_CASE(test_stage_swap);
    CHECK_CASE(test_ingest_failed_commit);
    CHECK_CASE(test_concurrent_commits);
    CHECK_CASE(test_staleness);
    return check_finish();
}
