/* Child processes: exit codes and signals come back as they happened, and a child whose end
 * cannot be learned is never taken for a success. */
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "vf/process.h"

static int run(const char *program, const char *arg, int *exit_code, int *sig)
{
    vf_args args = {0};
    if (arg) {
        vf_args_add(&args, "-c");
        vf_args_add(&args, arg);
    }
    vf_status s = vf_process_run(program, &args, NULL, NULL, NULL, exit_code, sig);
    vf_args_free(&args);
    return s == VF_OK;
}

static void test_exit_codes(void)
{
    int code, sig;
    CHECK(run("/bin/true", NULL, &code, &sig) && code == 0 && sig == 0, "true: %d %d", code, sig);
    CHECK(run("/bin/false", NULL, &code, &sig) && code == 1, "false: %d", code);
    CHECK(run("/bin/sh", "kill -TERM $$", &code, &sig) && code == -1 && sig == SIGTERM,
          "killed: code %d signal %d", code, sig);
    CHECK(!run("/no/such/program", NULL, &code, &sig), "a missing program is an error");
}

/* With SIGCHLD ignored the kernel reaps children itself and waitpid fails (ECHILD): the
 * status word was read uninitialised and a failed COLMAP could pass as exit 0. */
static void test_lost_status(void)
{
    struct sigaction old, ignore = {.sa_handler = SIG_IGN};
    sigaction(SIGCHLD, &ignore, &old);
    int code = 0, sig = 0;
    CHECK(!run("/bin/false", NULL, &code, &sig), "a lost status is an error, not exit %d", code);
    CHECK(strstr(vf_error_message(), "cannot learn how"), "message: %s", vf_error_message());

    vf_args args = {0};
    int channel, pid;
    CHECK(vf_process_start("/bin/false", &args, 2, &channel, &pid) == VF_OK, "start");
    CHECK(vf_process_finish(pid, 5) == -1, "finish reports no success it did not see");
    close(channel);
    vf_args_free(&args);
    sigaction(SIGCHLD, &old, NULL);

    CHECK(vf_process_start("/bin/false", &args, 2, &channel, &pid) == VF_OK, "start");
    CHECK(vf_process_finish(pid, 5) == 1, "finish: false exits 1");
    close(channel);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_exit_codes);
    CHECK_CASE(test_lost_status);
    return check_finish();
}
