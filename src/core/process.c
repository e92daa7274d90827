/* Child processes: argument vectors, finding a program, spawning it with its output read line
 * by line into a log and a callback. */
#define _GNU_SOURCE
#include "vf/process.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include "vf/fsutil.h"

extern char **environ;

void vf_args_add(vf_args *args, const char *item)
{
    if (args->count + 2 > args->capacity) {
        int capacity = args->capacity ? 2 * args->capacity : 32;
        char **items = realloc(args->items, (size_t)capacity * sizeof *items);
        if (!items) {
            args->failed = 1;
            return;
        }
        args->items = items;
        args->capacity = capacity;
    }
    char *copy = strdup(item);
    if (!copy) {
        args->failed = 1;
        return;
    }
    args->items[args->count++] = copy;
    args->items[args->count] = NULL;
}

void vf_args_opt(vf_args *args, const char *name, const char *fmt, ...)
{
    char value[VF_PATH_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(value, sizeof value, fmt, ap);
    va_end(ap);
    vf_args_add(args, name);
    vf_args_add(args, value);
}

void vf_args_free(vf_args *args)
{
    for (int i = 0; i < args->count; i++)
        free(args->items[i]);
    free(args->items);
    memset(args, 0, sizeof *args);
}

/* The first executable named `name` on PATH. */
static int find_on_path(const char *name, char *out, size_t size)
{
    const char *path = getenv("PATH");
    if (!path || !*path)
        path = "/usr/local/bin:/usr/bin:/bin";
    while (*path) {
        size_t len = strcspn(path, ":");
        if (len > 0 && (size_t)snprintf(out, size, "%.*s/%s", (int)len, path, name) < size &&
            access(out, X_OK) == 0)
            return 1;
        path += len + (path[len] == ':');
    }
    return 0;
}

vf_status vf_find_program(const char *env_var, const char *name, const char *install_hint,
                          char *out, size_t size)
{
    const char *override = env_var ? getenv(env_var) : NULL;
    if (override && *override) {
        if (access(override, X_OK) != 0)
            return vf_fail(VF_EINTERNAL, "%s=%s is not an executable program", env_var, override);
        snprintf(out, size, "%s", override);
        return VF_OK;
    }
    if (!find_on_path(name, out, size))
        return vf_fail(VF_EINTERNAL, "%s is not installed: %s", name, install_hint);
    return VF_OK;
}

/* Start program with stdin /dev/null, stdout and stderr to out_fd and, when channel_fd >= 0,
 * that descriptor as the child's fd 3. */
static vf_status spawn(const char *program, const vf_args *args, int out_fd, int channel_fd,
                       pid_t *pid)
{
    if (args->failed)
        return vf_fail(VF_EINTERNAL, "out of memory building the command line of %s", program);
    char *argv[args->count + 2];
    argv[0] = (char *)program;
    for (int i = 0; i < args->count; i++)
        argv[i + 1] = args->items[i];
    argv[args->count + 1] = NULL;

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, out_fd, 1);
    posix_spawn_file_actions_adddup2(&actions, out_fd, 2);
    if (channel_fd >= 0)
        posix_spawn_file_actions_adddup2(&actions, channel_fd, 3);
    int err = posix_spawn(pid, program, &actions, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (err)
        return vf_fail(VF_EINTERNAL, "cannot run %s: %s", program, strerror(err));
    return VF_OK;
}

/* Hand one line of the child's output (newline included when it had one) to the log and the
 * callback. */
static void take_line(char *line, size_t len, FILE *log, vf_process_line_fn on_line, void *ctx)
{
    if (log)
        fwrite(line, 1, len, log);
    if (len && line[len - 1] == '\n')
        len--;
    line[len] = '\0';
    if (on_line)
        on_line(line, ctx);
}

/* Copy the child's output to the log and the callback, line by line, until it closes its end
 * (a line longer than the buffer is handed over in pieces). Returns 0 then, or 1 when it
 * printed nothing for idle_timeout_s seconds (0: no limit). */
static int follow_output(int fd, FILE *log, vf_process_line_fn on_line, void *ctx,
                         double idle_timeout_s)
{
    enum { CAP = 1 << 16 };
    char buf[CAP + 1];
    size_t len = 0;
    int timed_out = 0;
    for (;;) {
        struct pollfd pfd = {.fd = fd, .events = POLLIN};
        int ready = poll(&pfd, 1, idle_timeout_s > 0 ? (int)(1000 * idle_timeout_s) : -1);
        if (ready < 0 && errno == EINTR)
            continue;
        if (ready == 0)
            timed_out = 1;
        ssize_t n = ready > 0 ? read(fd, buf + len, CAP - len) : -1;
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            break;
        len += (size_t)n;
        size_t begin = 0;
        for (size_t i = len - (size_t)n; i < len; i++)
            if (buf[i] == '\n') {
                take_line(buf + begin, i + 1 - begin, log, on_line, ctx);
                begin = i + 1;
            }
        if (begin == 0 && len == CAP) { /* a full buffer without a newline */
            take_line(buf, len, log, on_line, ctx);
            begin = len;
        }
        memmove(buf, buf + begin, len - begin);
        len -= begin;
    }
    if (len) /* a last line without a newline */
        take_line(buf, len, log, on_line, ctx);
    close(fd);
    if (log)
        fflush(log);
    return timed_out;
}

vf_status vf_process_run(const char *program, const vf_args *args, FILE *log,
                         vf_process_line_fn on_line, void *ctx, int *exit_code, int *signal_out)
{
    return vf_process_run_watched(program, args, log, on_line, ctx, 0, exit_code, signal_out,
                                  NULL);
}

vf_status vf_process_run_watched(const char *program, const vf_args *args, FILE *log,
                                 vf_process_line_fn on_line, void *ctx, double idle_timeout_s,
                                 int *exit_code, int *signal_out, int *timed_out)
{
    *exit_code = -1;
    if (signal_out)
        *signal_out = 0;
    if (timed_out)
        *timed_out = 0;
    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0)
        return vf_fail(VF_EINTERNAL, "cannot create a pipe: %s", strerror(errno));
    pid_t pid;
    vf_status status = spawn(program, args, fds[1], -1, &pid);
    close(fds[1]);
    if (status != VF_OK) {
        close(fds[0]);
        return status;
    }
    if (follow_output(fds[0], log, on_line, ctx, idle_timeout_s)) {
        kill(pid, SIGKILL);
        if (timed_out)
            *timed_out = 1;
    }
    int wstatus = 0;
    pid_t done;
    while ((done = waitpid(pid, &wstatus, 0)) < 0 && errno == EINTR)
        ;
    if (done < 0) /* e.g. SIGCHLD ignored: the child's status is lost, so is its verdict */
        return vf_fail(VF_EINTERNAL, "cannot learn how %s ended: %s", program, strerror(errno));
    if (WIFEXITED(wstatus))
        *exit_code = WEXITSTATUS(wstatus);
    else if (WIFSIGNALED(wstatus) && signal_out)
        *signal_out = WTERMSIG(wstatus);
    return VF_OK;
}

vf_status vf_process_start(const char *program, const vf_args *args, int output_fd, int *channel,
                           int *pid)
{
    int fds[2];
    if (socketpair(AF_UNIX, SOCK_STREAM | SOCK_CLOEXEC, 0, fds) != 0)
        return vf_fail(VF_EINTERNAL, "cannot create a socket pair: %s", strerror(errno));
    pid_t child;
    vf_status status = spawn(program, args, output_fd, fds[1], &child);
    close(fds[1]);
    if (status != VF_OK) {
        close(fds[0]);
        return status;
    }
    *channel = fds[0];
    *pid = (int)child;
    return VF_OK;
}

int vf_process_finish(int pid, double timeout_s)
{
    int wstatus = 0;
    pid_t done;
    for (int waited_ms = 0;; waited_ms += 10) {
        done = waitpid((pid_t)pid, &wstatus, WNOHANG);
        if (done == (pid_t)pid || (done < 0 && errno != EINTR))
            break;
        if (waited_ms >= 1000 * timeout_s) {
            kill((pid_t)pid, SIGKILL);
            while ((done = waitpid((pid_t)pid, &wstatus, 0)) < 0 && errno == EINTR)
                ;
            break;
        }
        usleep(10000);
    }
    if (done < 0) /* no status to read: never report a success we did not see */
        return -1;
    return WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : -1;
}
