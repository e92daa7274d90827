/* vf/process.h: running another program (COLMAP, Blender) as a child process.
 *
 * vfcapture never runs a shell: a program is found on PATH (or through an environment
 * variable naming it), started with posix_spawn, its stdin tied to /dev/null and its stdout and
 * stderr read line by line. Every line is appended to a log file and handed to a callback that
 * turns the program's own words into progress and remembers its last error line.
 *
 * A long-lived helper (the ONNX Runtime worker) is started instead with vf_process_start: it
 * gets one end of a Unix socket as its file descriptor 3 to exchange messages on, and its
 * stdout and stderr go to a file descriptor of the caller's (read back when it fails).
 *
 * Memory: a vf_args owns its strings (vf_args_free). */
#ifndef VF_PROCESS_H
#define VF_PROCESS_H

#include <stdio.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* A growing, NULL-terminated argument vector. */
typedef struct vf_args {
    char **items;
    int count, capacity;
    int failed; /* an argument was lost to out-of-memory: the command line is refused */
} vf_args;

/* Append one argument (copied). Out-of-memory is remembered and reported by vf_process_run and
 * vf_process_start. An empty vf_args ({0}) runs the program without arguments. */
void vf_args_add(vf_args *args, const char *item);
/* Append "--name" and its formatted value,
 * e.g. vf_args_opt(a, "--Mapper.ba_refine_focal_length", "%d", 0). */
void vf_args_opt(vf_args *args, const char *name, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 3, 4)))
#endif
    ;
void vf_args_free(vf_args *args);

/* The program named by the environment variable env_var when it is set (it must be
 * executable), else the first executable `name` on PATH. VF_EINTERNAL when there is none:
 * "NAME is not installed: INSTALL_HINT" (or naming the bad variable). */
vf_status vf_find_program(const char *env_var, const char *name, const char *install_hint,
                          char *out, size_t size);

/* Called with each line the child prints (newline removed). */
typedef void (*vf_process_line_fn)(const char *line, void *ctx);

/* Run `program args...` (args->items[0] is argv[1]) and wait for it. Its output goes to log
 * (may be NULL) and, line by line, to on_line (may be NULL). *exit_code gets the exit status,
 * or -1 when it was killed by a signal (then *signal_out, when not NULL, gets the signal).
 * Fails (VF_EINTERNAL) when the program cannot be started or its end cannot be learned (waitpid
 * fails, e.g. with SIGCHLD ignored); a non-zero exit is for the caller to judge. */
vf_status vf_process_run(const char *program, const vf_args *args, FILE *log,
                         vf_process_line_fn on_line, void *ctx, int *exit_code, int *signal_out);

/* vf_process_run for a program that may hang on untrusted input (Blender on a model): when
 * the child prints nothing for idle_timeout_s seconds (0: no limit) it is killed (SIGKILL),
 * and *timed_out (may be NULL) is set; *exit_code is then -1 and *signal_out SIGKILL. */
vf_status vf_process_run_watched(const char *program, const vf_args *args, FILE *log,
                                 vf_process_line_fn on_line, void *ctx, double idle_timeout_s,
                                 int *exit_code, int *signal_out, int *timed_out);

/* Start `program args...` without waiting: *channel gets the caller's end of a socket whose
 * other end is the child's fd 3, the child's stdin is /dev/null and its stdout and stderr go to
 * output_fd. Both of the caller's descriptors are close-on-exec, so later children do not keep
 * the socket open. Writes on *channel should use send(..., MSG_NOSIGNAL) so that a worker which
 * died is an error, not a SIGPIPE. */
vf_status vf_process_start(const char *program, const vf_args *args, int output_fd, int *channel,
                           int *pid);

/* Wait up to timeout_s seconds for a started child to exit, then kill it (SIGKILL) and reap it.
 * Returns its exit status, or -1 when it was killed by a signal or its status cannot be read. */
int vf_process_finish(int pid, double timeout_s);

#ifdef __cplusplus
}
#endif
#endif
