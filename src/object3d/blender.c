/* Running Blender on the project's own script (blender_render.py): the job file, the program's
 * progress and its one-line errors. */
#define _GNU_SOURCE
#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "object3d_internal.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/process.h"
#include "vf/rgb8.h"

/* Exit codes of the script (its fail()): a problem of the input, of the installation. */
#define SCRIPT_INPUT_ERROR 2
#define SCRIPT_UNCAUGHT 3 /* --python-exit-code: an exception the script did not expect */
#define SCRIPT_SETUP_ERROR 4

/* How long Blender may print nothing (import a large model, render one view) before it is
 * taken for hung and stopped: $VF_BLENDER_TIMEOUT seconds, default 10 minutes. */
static int blender_silent_s(void)
{
    const char *env = getenv("VF_BLENDER_TIMEOUT");
    long s = env ? strtol(env, NULL, 10) : 0;
    return s > 0 && s < 86400 ? (int)s : 600;
}

void vf__blender_view_file(const char *prefix, int i, char *out, size_t size)
{
    snprintf(out, size, "%s%03d.png", prefix, i);
}

static json_t *job_json(const vf__blender_job *job, const char *info_path)
{
    json_t *views = json_array();
    for (int i = 0; i < job->count; i++) {
        char file[64];
        vf__blender_view_file(job->prefix, i, file, sizeof file);
        json_t *m = json_array();
        for (int k = 0; k < 16; k++)
            json_array_append_new(m, vf_json_number(job->c2w[16 * i + k]));
        json_array_append_new(views, json_pack("{s:s, s:o}", "file", file, "c2w", m));
    }
    json_t *normalize = json_null();
    if (job->transform) {
        const vf_object3d_transform *t = job->transform;
        normalize = json_pack("{s:[o,o,o], s:o}", "center", vf_json_number(t->center[0]),
                              vf_json_number(t->center[1]), vf_json_number(t->center[2]), "scale",
                              vf_json_number(t->scale));
    }
    const vf_camera *c = &job->camera;
    return json_pack("{s:s, s:o, s:i, s:i, s:o, s:o, s:o, s:o, s:i, s:s, s:o, s:o, s:s, s:s, "
                     "s:b}",
                     "model", job->model, "normalize", normalize, "width", c->width, "height",
                     c->height, "fx", vf_json_number(c->fx), "fy", vf_json_number(c->fy), "cx",
                     vf_json_number(c->cx), "cy", vf_json_number(c->cy), "samples", job->samples,
                     "scene", job->scene ? job->scene : "studio", "shutter",
                     vf_json_number(job->shutter), "views", views, "output_dir", job->out_dir,
                     "info", info_path, "serve", job->serve);
}

/* What one run follows in Blender's output. */
typedef struct follow {
    vf_progress progress;
    int shown;
    char error[512];     /* the script's own "vf-error:" line */
    char exception[512]; /* the last line that looks like a Python or Blender error */
} follow;

static void on_line(const char *line, void *ctx)
{
    follow *f = ctx;
    unsigned long done, total;
    if (sscanf(line, "vf-view %lu %lu", &done, &total) == 2) {
        if (f->shown)
            vf_progress_update(&f->progress, done, NULL);
    } else if (!strncmp(line, "vf-error: ", 10)) {
        snprintf(f->error, sizeof f->error, "%s", line + 10);
    } else if (strstr(line, "Error") || strstr(line, "error:")) {
        snprintf(f->exception, sizeof f->exception, "%s", line);
    }
}

static vf_status write_text(const char *path, const char *text)
{
    FILE *fp = fopen(path, "w");
    if (!fp)
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(errno));
    size_t n = strlen(text);
    int ok = fwrite(text, 1, n, fp) == n;
    ok &= fclose(fp) == 0;
    return ok ? VF_OK : vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(errno));
}

static int count_missing(const vf__blender_job *job)
{
    int missing = 0;
    for (int i = 0; i < job->count; i++) {
        char file[64], path[VF_PATH_MAX];
        vf__blender_view_file(job->prefix, i, file, sizeof file);
        missing += vf_path_join(path, sizeof path, job->out_dir, file) != VF_OK ||
                   !vf_is_file(path);
    }
    return missing;
}

/* The script and the job file written into job->work_dir, Blender found, and its arguments
 * (args, to free) and log path; a line saying how it was run appended to the log. */
static vf_status prepare(const vf__blender_job *job, char program[VF_PATH_MAX],
                         char info_path[VF_PATH_MAX], char log_path[VF_PATH_MAX], vf_args *args)
{
    char script[VF_PATH_MAX], job_path[VF_PATH_MAX];
    vf_status status = vf_find_program("VF_BLENDER", "blender",
                                       "install it (apt-get install blender python3-numpy) or set "
                                       "VF_BLENDER to the blender program",
                                       program, VF_PATH_MAX);
    if (status == VF_OK)
        status = vf_mkdirs(job->out_dir);
    if (status == VF_OK)
        status = vf_path_join(script, sizeof script, job->work_dir, "blender_render.py");
    if (status == VF_OK)
        status = vf_path_join(job_path, sizeof job_path, job->work_dir, "blender_job.json");
    if (status == VF_OK)
        status = vf_path_join(info_path, VF_PATH_MAX, job->work_dir, "blender_fit.json");
    if (status == VF_OK)
        status = vf_path_join(log_path, VF_PATH_MAX, job->work_dir, "blender.log");
    if (status == VF_OK)
        status = write_text(script, vf__blender_script);
    json_t *doc = status == VF_OK ? job_json(job, info_path) : NULL;
    if (status == VF_OK)
        status = doc ? vf_json_save(job_path, doc) : vf_fail(VF_EINTERNAL, "out of memory");
    json_decref(doc);
    if (status != VF_OK)
        return status;

    FILE *log = fopen(log_path, "a"); /* a resumed run keeps the earlier run's log */
    if (!log)
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", log_path, strerror(errno));
    long cores = sysconf(_SC_NPROCESSORS_ONLN);
    vf_args_add(args, "-b");
    vf_args_add(args, "--factory-startup");
    vf_args_opt(args, "-t", "%ld", cores > 0 ? cores : 1);
    vf_args_opt(args, "--python-exit-code", "%d", SCRIPT_UNCAUGHT);
    vf_args_opt(args, "--python", "%s", script);
    vf_args_add(args, "--");
    vf_args_add(args, job_path);
    fprintf(log, "\n$ %s", program);
    for (int i = 0; i < args->count; i++)
        fprintf(log, " %s", args->items[i]);
    fprintf(log, "\n");
    if (fclose(log) != 0)
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", log_path, strerror(errno));
    return VF_OK;
}

vf_status vf__blender_render(const vf__blender_job *job, json_t **fit)
{
    char program[VF_PATH_MAX], info_path[VF_PATH_MAX], log_path[VF_PATH_MAX];
    vf_args args = {0};
    vf_status status = prepare(job, program, info_path, log_path, &args);
    FILE *log = status == VF_OK ? fopen(log_path, "a") : NULL;
    if (status == VF_OK && !log)
        status = vf_fail(VF_EINTERNAL, "cannot write %s: %s", log_path, strerror(errno));
    if (status != VF_OK) {
        vf_args_free(&args);
        return status;
    }
    follow f = {.shown = job->label != NULL};
    vf_progress_begin(&f.progress, job->label, (size_t)job->count, "views");
    int exit_code, sig, timed_out, silent_s = blender_silent_s();
    double start = vf_now();
    status = vf_process_run_watched(program, &args, log, on_line, &f, silent_s, &exit_code, &sig,
                                    &timed_out);
    if (f.shown)
        vf_progress_end(&f.progress);
    fprintf(log, "# blender: exit %d, %.1f s\n", exit_code, vf_now() - start);
    fclose(log);
    vf_args_free(&args);
    if (status != VF_OK)
        return status;

    if (timed_out) /* a model that hangs the importer or the renderer must not hang us */
        status = vf_fail(VF_EINPUT,
                         "Blender printed nothing for %d s rendering %s and was stopped "
                         "(VF_BLENDER_TIMEOUT sets the limit)",
                         silent_s, job->model);
    else if (exit_code == SCRIPT_INPUT_ERROR) /* the script's own line says it all */
        return vf_fail(VF_EINPUT, "%s", f.error);
    else if (exit_code == SCRIPT_SETUP_ERROR)
        status = vf_fail(VF_EINTERNAL, "%s", f.error);
    else if (exit_code < 0)
        status = vf_fail(VF_EINTERNAL, "Blender crashed (%s) rendering %s", strsignal(sig),
                         job->model);
    else if (exit_code != 0) {
        const char *why = f.error[0] ? f.error : f.exception;
        status = vf_fail(VF_EINTERNAL, "Blender failed (exit %d) rendering %s%s%s", exit_code,
                         job->model, why[0] ? ": " : "", why);
    } else {
        int missing = count_missing(job);
        if (missing)
            status = vf_fail(VF_EINTERNAL, "Blender finished but %d of %d views of %s are missing",
                             missing, job->count, job->model);
    }
    if (status != VF_OK) /* the log would go with a removed staging folder */
        return vf_keep_failure_log(log_path, "Blender", status);
    if (fit && (status = vf_json_load(info_path, fit)) != VF_OK)
        return status;
    return VF_OK;
}

/* ---- a live camera: one Blender kept open, one view a request ---- */


struct vf_object3d_live {
    int pid, channel;
    char dir[VF_PATH_MAX], log_path[VF_PATH_MAX], model[VF_PATH_MAX];
    long views;
};

/* The script's last "vf-error:" line in the log, or "". */
static void last_error(const char *log_path, char *out, size_t size)
{
    FILE *fp = fopen(log_path, "r");
    char line[1024];
    out[0] = '\0';
    while (fp && fgets(line, sizeof line, fp))
        if (!strncmp(line, "vf-error: ", 10)) {
            line[strcspn(line, "\n")] = '\0';
            snprintf(out, size, "%.500s", line + 10);
        }
    if (fp)
        fclose(fp);
}

static vf_status live_gone(vf_object3d_live *live, const char *doing)
{
    char why[512];
    int code = vf_process_finish(live->pid, 2.0);
    live->pid = -1;
    last_error(live->log_path, why, sizeof why);
    if (code == SCRIPT_INPUT_ERROR)
        return vf_fail(VF_EINPUT, "%s", why);
    return vf_keep_failure_log(live->log_path, "Blender",
                               vf_fail(VF_EINTERNAL, "Blender stopped while %s %s (exit %d)%s%s",
                                       doing, live->model, code, why[0] ? ": " : "", why));
}

/* One line from Blender (without its newline), waiting at most timeout_s. */
static vf_status live_read_line(vf_object3d_live *live, char *out, size_t size, int timeout_s,
                                const char *doing)
{
    size_t used = 0;
    for (;;) {
        struct pollfd pfd = {.fd = live->channel, .events = POLLIN};
        int ready = poll(&pfd, 1, timeout_s * 1000);
        if (ready < 0 && errno == EINTR)
            continue;
        if (ready == 0)
            return vf_keep_failure_log(
                live->log_path, "Blender",
                vf_fail(VF_EINTERNAL, "Blender did not answer in %d s while %s %s", timeout_s,
                        doing, live->model));
        char c;
        ssize_t n = recv(live->channel, &c, 1, 0);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0)
            return live_gone(live, doing);
        if (c == '\n')
            break;
        if (used + 1 < size)
            out[used++] = c;
    }
    out[used] = '\0';
    return VF_OK;
}

vf_status vf_object3d_live_open(const vf_object3d *obj, const vf_camera *cam, const char *dir,
                                vf_object3d_live **out)
{
    *out = NULL;
    if (!(obj->transform.scale > 0))
        return vf_fail(VF_EINTERNAL, "a live camera needs the model's recorded transform");
    vf_object3d_live *live = calloc(1, sizeof *live);
    if (!live)
        return vf_fail(VF_EINTERNAL, "out of memory");
    live->pid = live->channel = -1;
    snprintf(live->dir, sizeof live->dir, "%s", dir);
    snprintf(live->model, sizeof live->model, "%s", obj->model);
    vf__blender_job job = {.model = obj->model,
                           .transform = &obj->transform,
                           .camera = *cam,
                           .samples = obj->samples,
                           .scene = obj->scene,
                           .out_dir = dir,
                           .prefix = "live",
                           .work_dir = dir,
                           .serve = 1};
    char program[VF_PATH_MAX], info_path[VF_PATH_MAX], line[512];
    vf_args args = {0};
    vf_status status = prepare(&job, program, info_path, live->log_path, &args);
    int log_fd = status == VF_OK ? open(live->log_path, O_WRONLY | O_APPEND | O_CLOEXEC) : -1;
    if (status == VF_OK && log_fd < 0)
        status = vf_fail(VF_EINTERNAL, "cannot write %s: %s", live->log_path, strerror(errno));
    if (status == VF_OK)
        status = vf_process_start(program, &args, log_fd, &live->channel, &live->pid);
    if (log_fd >= 0)
        close(log_fd);
    vf_args_free(&args);
    if (status == VF_OK)
        status = live_read_line(live, line, sizeof line, blender_silent_s(), "loading");
    if (status == VF_OK && strcmp(line, "ready") != 0)
        status = vf_fail(VF_EINTERNAL, "Blender said '%s' instead of 'ready' loading %s", line,
                         obj->model);
    if (status != VF_OK) {
        vf_object3d_live_close(live);
        return status;
    }
    *out = live;
    return VF_OK;
}

vf_status vf_object3d_live_render(vf_object3d_live *live, const double c2w[16], vf_rgb8 *frame)
{
    char file[64], path[VF_PATH_MAX], line[512];
    if (live->pid < 0)
        return vf_fail(VF_EINTERNAL, "the live camera on %s has stopped", live->model);
    vf__blender_view_file("live", (int)(live->views++ % 1000), file, sizeof file);
    json_t *request = json_pack("{s:o, s:s}", "c2w", vf_json_doubles(c2w, 16), "file", file);
    char *text = request ? json_dumps(request, JSON_COMPACT) : NULL;
    json_decref(request);
    if (!text)
        return vf_fail(VF_EINTERNAL, "out of memory");
    size_t len = strlen(text);
    text[len] = '\n'; /* json_dumps' terminator becomes the line's end */
    vf_status status = VF_OK;
    for (size_t sent = 0; status == VF_OK && sent < len + 1;) {
        ssize_t n = send(live->channel, text + sent, len + 1 - sent, MSG_NOSIGNAL);
        if (n < 0 && errno == EINTR)
            continue;
        if (n < 0)
            status = live_gone(live, "rendering");
        else
            sent += (size_t)n;
    }
    free(text);
    if (status == VF_OK)
        status = live_read_line(live, line, sizeof line, blender_silent_s(), "rendering");
    if (status == VF_OK && strncmp(line, "done ", 5) != 0)
        status = vf_fail(VF_EINTERNAL, "Blender could not render %s: %s", live->model,
                         strncmp(line, "vf-error: ", 10) ? line : line + 10);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, live->dir, file);
    if (status == VF_OK)
        status = vf_rgb8_load(path, frame);
    return status;
}

void vf_object3d_live_close(vf_object3d_live *live)
{
    if (!live)
        return;
    if (live->channel >= 0)
        close(live->channel); /* the script's loop ends with its socket */
    if (live->pid >= 0)
        vf_process_finish(live->pid, 10.0);
    free(live);
}
