/* Running COLMAP as a child process: argument vectors, spawning with the output captured,
 * the log, and progress parsed from what COLMAP prints. */
#define _GNU_SOURCE
#include "vf/colmap.h"

#include <errno.h>
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

#include "vf/log.h"

extern char **environ;

void vf_args_add(vf_args *args, const char *item)
{
    if (args->count + 2 > args->capacity) {
        int capacity = args->capacity ? 2 * args->capacity : 32;
        char **items = realloc(args->items, (size_t)capacity * sizeof *items);
        if (!items)
            return; /* vf_colmap_run sees the missing terminator count and fails */
        args->items = items;
        args->capacity = capacity;
    }
    char *copy = strdup(item);
    if (!copy)
        return;
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

vf_status vf_colmap_open(vf_colmap *colmap, const char *log_path)
{
    memset(colmap, 0, sizeof *colmap);
    const char *override = getenv("VF_COLMAP");
    if (override && *override) {
        if (access(override, X_OK) != 0)
            return vf_fail(VF_EINTERNAL, "VF_COLMAP=%s is not an executable program", override);
        snprintf(colmap->program, sizeof colmap->program, "%s", override);
    } else if (!find_on_path("colmap", colmap->program, sizeof colmap->program)) {
        return vf_fail(VF_EINTERNAL, "COLMAP is not installed: install it (apt-get install colmap) "
                                     "or set VF_COLMAP to the colmap program");
    }
    snprintf(colmap->log_path, sizeof colmap->log_path, "%s", log_path);
    colmap->log = fopen(log_path, "w");
    if (!colmap->log)
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", log_path, strerror(errno));
    return VF_OK;
}

void vf_colmap_close(vf_colmap *colmap)
{
    if (colmap->log)
        fclose(colmap->log);
    colmap->log = NULL;
}

int vf_colmap_parse_progress(const char *line, size_t *done, size_t *total)
{
    static const char *const counted[] = {"Processed file [", "Matching image [",
                                          "Undistorting image ["};
    unsigned long a, b, c, d;
    for (size_t i = 0; i < sizeof counted / sizeof counted[0]; i++) {
        const char *p = strstr(line, counted[i]);
        if (p && sscanf(p + strlen(counted[i]), "%lu/%lu]", &a, &b) == 2) {
            *done = a;
            *total = b;
            return 1;
        }
    }
    const char *p = strstr(line, "Matching block [");
    if (p && sscanf(p, "Matching block [%lu/%lu, %lu/%lu]", &a, &b, &c, &d) == 4) {
        *done = (a - 1) * d + c;
        *total = b * d;
        return 1;
    }
    p = strstr(line, "Registering image #");
    if (p && sscanf(p, "Registering image #%lu (%lu)", &a, &b) == 2) {
        *done = b;
        return 1;
    }
    return 0;
}

/* Whether a line of COLMAP output reports a failure worth quoting to the user. */
static int is_error_line(const char *line)
{
    return strstr(line, "ERROR") || strstr(line, "Check failed") || strstr(line, "error:") ||
           strstr(line, "Error:") || strstr(line, "terminate called");
}

static vf_status spawn(const vf_colmap *colmap, const vf_args *args, int out_fd, pid_t *pid)
{
    char *argv[args->count + 2];
    argv[0] = (char *)colmap->program;
    for (int i = 0; i < args->count; i++)
        argv[i + 1] = args->items[i];
    argv[args->count + 1] = NULL;

    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_adddup2(&actions, out_fd, 1);
    posix_spawn_file_actions_adddup2(&actions, out_fd, 2);
    posix_spawn_file_actions_addclose(&actions, out_fd);
    int err = posix_spawn(pid, colmap->program, &actions, NULL, argv, environ);
    posix_spawn_file_actions_destroy(&actions);
    if (err)
        return vf_fail(VF_EINTERNAL, "cannot run %s: %s", colmap->program, strerror(err));
    return VF_OK;
}

/* Copy the child's output to the log line by line, updating the progress and keeping the last
 * error line. */
static void follow_output(vf_colmap *colmap, int fd, vf_progress *progress, char *last_error,
                          size_t error_size)
{
    FILE *in = fdopen(fd, "r");
    if (!in) {
        close(fd);
        return;
    }
    char *line = NULL;
    size_t cap = 0;
    ssize_t len;
    while ((len = getline(&line, &cap, in)) > 0) {
        fwrite(line, 1, (size_t)len, colmap->log);
        if (line[len - 1] == '\n')
            line[len - 1] = '\0';
        size_t done = 0, total = progress->total;
        if (progress->label && vf_colmap_parse_progress(line, &done, &total)) {
            progress->total = total;
            vf_progress_update(progress, done, NULL);
        }
        if (is_error_line(line))
            snprintf(last_error, error_size, "%s", line);
    }
    free(line);
    fclose(in);
    fflush(colmap->log);
}

vf_status vf_colmap_run(vf_colmap *colmap, const char *label, size_t total, const vf_args *args,
                        double *seconds)
{
    colmap->last_exit = -1;
    if (args->count == 0 || args->items[args->count] != NULL)
        return vf_fail(VF_EINTERNAL, "out of memory building the COLMAP command line");
    fprintf(colmap->log, "\n$ colmap");
    for (int i = 0; i < args->count; i++)
        fprintf(colmap->log, " %s", args->items[i]);
    fprintf(colmap->log, "\n");
    fflush(colmap->log);

    int fds[2];
    if (pipe2(fds, O_CLOEXEC) != 0)
        return vf_fail(VF_EINTERNAL, "cannot create a pipe: %s", strerror(errno));
    double start = vf_now();
    pid_t pid;
    vf_status status = spawn(colmap, args, fds[1], &pid);
    close(fds[1]);
    if (status != VF_OK) {
        close(fds[0]);
        return status;
    }
    vf_progress progress;
    char last_error[512] = "";
    vf_progress_begin(&progress, label, total, "images");
    follow_output(colmap, fds[0], &progress, last_error, sizeof last_error);
    if (label)
        vf_progress_end(&progress);

    int wstatus;
    while (waitpid(pid, &wstatus, 0) < 0 && errno == EINTR)
        ;
    double elapsed = vf_now() - start;
    fprintf(colmap->log, "# %s: %.1f s\n", args->items[0], elapsed);
    fflush(colmap->log);
    if (seconds)
        *seconds = elapsed;
    if (WIFEXITED(wstatus))
        colmap->last_exit = WEXITSTATUS(wstatus);
    if (colmap->last_exit == 0)
        return VF_OK;
    char how[64];
    if (WIFSIGNALED(wstatus))
        snprintf(how, sizeof how, "crashed (%s)", strsignal(WTERMSIG(wstatus)));
    else
        snprintf(how, sizeof how, "failed (exit %d)", WEXITSTATUS(wstatus));
    return vf_fail(VF_EINTERNAL, "colmap %s %s%s%s", args->items[0], how,
                   last_error[0] ? ": " : "", last_error);
}
