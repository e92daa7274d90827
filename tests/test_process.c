/* Child processes: exit codes and signals come back as they happened, and a child whose end
 * cannot be learned is never taken for a success. */
#include <signal.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "vf/log.h"
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

static void count_line(const char *line, void *ctx)
{
    (void)line;
    ++*(int *)ctx;
}

/* A child that goes silent is stopped after the idle limit; one that keeps talking is not. */
static void test_idle_timeout(void)
{
    vf_args args = {0};
    vf_args_add(&args, "-c");
    vf_args_add(&args, "echo start; exec sleep 30");
    int code, sig, timed_out, lines = 0;
    double start = vf_now();
    CHECK(vf_process_run_watched("/bin/sh", &args, NULL, count_line, &lines, 0.5, &code, &sig,
                                 &timed_out) == VF_OK,
          "run");
    double took = vf_now() - start;
    CHECK(timed_out && code == -1 && sig == SIGKILL && lines == 1,
          "silent child: timed out %d, code %d, signal %d, %d lines", timed_out, code, sig, lines);
    CHECK(took < 5, "stopped after %.1f s, not 30", took);
    vf_args_free(&args);

    vf_args_add(&args, "-c");
    vf_args_add(&args, "for i in 1 2 3 4; do echo $i; sleep 0.2; done; printf tail; exit 3");
    lines = 0;
    CHECK(vf_process_run_watched("/bin/sh", &args, NULL, count_line, &lines, 1.0, &code, &sig,
                                 &timed_out) == VF_OK,
          "run");
    CHECK(!timed_out && code == 3 && lines == 5,
          "talking child: timed out %d, code %d, %d lines (4 and a last one without newline)",
          timed_out, code, lines);
    vf_args_free(&args);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_exit_codes);
    CHECK_CASE(test_lost_status);
    CHECK_CASE(test_idle_timeout);
    return check_finish();
}
