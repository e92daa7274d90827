/* vf_stage_resume (vf/workspace.h): what an interrupted stage left in its staging folder is
 * kept for resuming, while vf_stage_begin still starts from an empty folder. */
#include <stdio.h>

#include "check.h"
#include "vf/fsutil.h"
#include "vf/workspace.h"

static void test_resume_rules(void)
{
    char root[VF_PATH_MAX], file[VF_PATH_MAX];
    snprintf(root, sizeof root, "%s/ws", vf_test_tmpdir());
    vf_workspace ws;
    vf_stage s;
    CHECK(vf_workspace_open(root, 1, &ws) == VF_OK, "%s", vf_error_message());

    /* A run that checkpoints and is interrupted (no commit, no abort). */
    CHECK(vf_stage_begin(&ws, "attack", &s) == VF_OK, "%s", vf_error_message());
    CHECK(vf_path_join(file, sizeof file, s.dir, "checkpoint.json") == VF_OK, "%s",
          vf_error_message());
    CHECK(vf_write_file_atomic(file, "{}", 2) == VF_OK, "%s", vf_error_message());

    /* Resuming keeps it; the stage is still not recorded. */
    CHECK(vf_stage_resume(&ws, "attack", &s) == VF_OK, "%s", vf_error_message());
    CHECK(vf_is_file(file), "the checkpoint survives vf_stage_resume");
    CHECK(!vf_workspace_has_stage(&ws, "attack"), "an unfinished stage is not recorded");

    /* Starting over throws it away. */
    CHECK(vf_stage_begin(&ws, "attack", &s) == VF_OK, "%s", vf_error_message());
    CHECK(!vf_is_file(file), "vf_stage_begin starts from an empty folder");

    /* Resuming with nothing left over gives an empty folder that commits normally. */
    vf_stage_abort(&s);
    CHECK(vf_stage_resume(&ws, "attack", &s) == VF_OK && vf_is_dir(s.dir), "%s",
          vf_error_message());
    CHECK(vf_stage_commit(&s, NULL, NULL) == VF_OK, "%s", vf_error_message());
    CHECK(vf_workspace_has_stage(&ws, "attack"), "the resumed stage is recorded on commit");
    vf_workspace_close(&ws);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_resume_rules);
    return check_finish();
}
