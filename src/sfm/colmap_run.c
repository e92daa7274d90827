/* Running COLMAP as a child process (vf/process.h): the log, and progress and errors parsed
 * from what COLMAP prints. */
#define _GNU_SOURCE
#include "vf/colmap.h"

#include <errno.h>
#include <string.h>

#include "vf/log.h"

vf_status vf_colmap_open(vf_colmap *colmap, const char *log_path)
{
    memset(colmap, 0, sizeof *colmap);
    vf_status status = vf_find_program("VF_COLMAP", "colmap",
                                       "install it (apt-get install colmap) or set VF_COLMAP to "
                                       "the colmap program",
                                       colmap->program, sizeof colmap->program);
    if (status != VF_OK)
        return status;
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

/* What one run follows in COLMAP's output. */
typedef struct colmap_follow {
    vf_progress progress;
    char last_error[512];
} colmap_follow;

static void on_line(const char *line, void *ctx)
{
    colmap_follow *f = ctx;
    size_t done = 0, total = f->progress.total;
    if (f->progress.label && vf_colmap_parse_progress(line, &done, &total)) {
        f->progress.total = total;
        vf_progress_update(&f->progress, done, NULL);
    }
    if (is_error_line(line))
        snprintf(f->last_error, sizeof f->last_error, "%s", line);
}

vf_status vf_colmap_run(vf_colmap *colmap, const char *label, size_t total, const vf_args *args,
                        double *seconds)
{
    colmap->last_exit = -1;
    if (args->count == 0 || args->failed)
        return vf_fail(VF_EINTERNAL, "out of memory building the COLMAP command line");
    fprintf(colmap->log, "\n$ colmap");
    for (int i = 0; i < args->count; i++)
        fprintf(colmap->log, " %s", args->items[i]);
    fprintf(colmap->log, "\n");
    fflush(colmap->log);

    double start = vf_now();
    colmap_follow follow = {.last_error = ""};
    int exit_code, sig;
    vf_progress_begin(&follow.progress, label, total, "images");
    vf_status status =
        vf_process_run(colmap->program, args, colmap->log, on_line, &follow, &exit_code, &sig);
    if (label)
        vf_progress_end(&follow.progress);
    if (status != VF_OK)
        return status;
    double elapsed = vf_now() - start;
    fprintf(colmap->log, "# %s: %.1f s\n", args->items[0], elapsed);
    fflush(colmap->log);
    if (seconds)
        *seconds = elapsed;
    colmap->last_exit = exit_code;
    if (exit_code == 0)
        return VF_OK;
    char how[64];
    if (exit_code < 0)
        snprintf(how, sizeof how, "crashed (%s)", strsignal(sig));
    else
        snprintf(how, sizeof how, "failed (exit %d)", exit_code);
    return vf_fail(VF_EINTERNAL, "colmap %s %s%s%s", args->items[0], how,
                   follow.last_error[0] ? ": " : "", follow.last_error);
}
