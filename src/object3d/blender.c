/* Running Blender on the project's own script (blender_render.py): the job file, the program's
 * progress and its one-line errors. */
#define _GNU_SOURCE
#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "object3d_internal.h"
#include "vf/log.h"
#include "vf/process.h"

/* Exit codes of the script (its fail()): a problem of the input, of the installation. */
#define SCRIPT_INPUT_ERROR 2
#define SCRIPT_UNCAUGHT 3 /* --python-exit-code: an exception the script did not expect */
#define SCRIPT_SETUP_ERROR 4

void vf__blender_view_file(const char *prefix, int i, char *out, size_t size)
{
    snprintf(out, size, "%s%03d.png", prefix, i);
}

vf_status vf__keep_renders_for(const char *dir, json_t *request, const char *const *subdirs)
{
    char path[VF_PATH_MAX], sub[VF_PATH_MAX];
    json_t *before = NULL;
    vf_status status = request ? vf_path_join(path, sizeof path, dir, "request.json")
                               : vf_fail(VF_EINTERNAL, "out of memory");
    if (status == VF_OK && vf_is_file(path) && vf_json_load(path, &before) == VF_OK &&
        json_equal(before, request))
        vf_info("continuing the renders of an interrupted run");
    else
        for (int i = 0; status == VF_OK && subdirs[i]; i++)
            if ((status = vf_path_join(sub, sizeof sub, dir, subdirs[i])) == VF_OK)
                status = vf_remove_tree(sub);
    json_decref(before);
    if (status == VF_OK)
        status = vf_json_save(path, request);
    json_decref(request);
    return status;
}

static json_t *job_json(const vf__blender_job *job, const char *info_path)
{
    json_t *views = json_array();
    for (int i = 0; i < job->count; i++) {
        char file[64];
        vf__blender_view_file(job->prefix, i, file, sizeof file);
        json_t *m = json_array();
        for (int k = 0; k < 16; k++)
            json_array_append_new(m, json_real(job->c2w[16 * i + k]));
        json_array_append_new(views, json_pack("{s:s, s:o}", "file", file, "c2w", m));
    }
    json_t *normalize = json_null();
    if (job->transform) {
        const vf_object3d_transform *t = job->transform;
        normalize = json_pack("{s:[f,f,f], s:f}", "center", t->center[0], t->center[1],
                              t->center[2], "scale", t->scale);
    }
    const vf_camera *c = &job->camera;
    return json_pack("{s:s, s:o, s:i, s:i, s:f, s:f, s:f, s:f, s:i, s:s, s:f, s:o, s:s, s:s}", "model",
                     job->model, "normalize", normalize, "width", c->width, "height", c->height,
                     "fx", c->fx, "fy", c->fy, "cx", c->cx, "cy", c->cy, "samples", job->samples,
                     "scene", job->scene ? job->scene : "studio", "shutter", job->shutter,
                     "views", views, "output_dir",
                     job->out_dir, "info", info_path);
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

vf_status vf__blender_render(const vf__blender_job *job, json_t **fit)
{
    char program[VF_PATH_MAX], script[VF_PATH_MAX], job_path[VF_PATH_MAX];
    char info_path[VF_PATH_MAX], log_path[VF_PATH_MAX];
    vf_status status = vf_find_program("VF_BLENDER", "blender",
                                       "install it (apt-get install blender python3-numpy) or set "
                                       "VF_BLENDER to the blender program",
                                       program, sizeof program);
    if (status == VF_OK)
        status = vf_mkdirs(job->out_dir);
    if (status == VF_OK)
        status = vf_path_join(script, sizeof script, job->work_dir, "blender_render.py");
    if (status == VF_OK)
        status = vf_path_join(job_path, sizeof job_path, job->work_dir, "blender_job.json");
    if (status == VF_OK)
        status = vf_path_join(info_path, sizeof info_path, job->work_dir, "blender_fit.json");
    if (status == VF_OK)
        status = vf_path_join(log_path, sizeof log_path, job->work_dir, "blender.log");
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
    vf_args args = {0};
    vf_args_add(&args, "-b");
    vf_args_add(&args, "--factory-startup");
    vf_args_opt(&args, "-t", "%ld", cores > 0 ? cores : 1);
    vf_args_opt(&args, "--python-exit-code", "%d", SCRIPT_UNCAUGHT);
    vf_args_opt(&args, "--python", "%s", script);
    vf_args_add(&args, "--");
    vf_args_add(&args, job_path);
    fprintf(log, "\n$ %s", program);
    for (int i = 0; i < args.count; i++)
        fprintf(log, " %s", args.items[i]);
    fprintf(log, "\n");

    follow f = {.shown = job->label != NULL};
    vf_progress_begin(&f.progress, job->label, (size_t)job->count, "views");
    int exit_code, sig;
    double start = vf_now();
    status = vf_process_run(program, &args, log, on_line, &f, &exit_code, &sig);
    if (f.shown)
        vf_progress_end(&f.progress);
    fprintf(log, "# blender: exit %d, %.1f s\n", exit_code, vf_now() - start);
    fclose(log);
    vf_args_free(&args);
    if (status != VF_OK)
        return status;

    if (exit_code == SCRIPT_INPUT_ERROR)
        return vf_fail(VF_EINPUT, "%s", f.error);
    if (exit_code == SCRIPT_SETUP_ERROR)
        return vf_fail(VF_EINTERNAL, "%s", f.error);
    if (exit_code != 0) {
        const char *why = f.error[0] ? f.error : f.exception;
        if (exit_code < 0)
            return vf_fail(VF_EINTERNAL, "Blender crashed (%s) rendering %s; see %s",
                           strsignal(sig), job->model, log_path);
        return vf_fail(VF_EINTERNAL, "Blender failed (exit %d) rendering %s%s%s; see %s",
                       exit_code, job->model, why[0] ? ": " : "", why, log_path);
    }
    int missing = count_missing(job);
    if (missing)
        return vf_fail(VF_EINTERNAL, "Blender finished but %d of %d views of %s are missing; see %s",
                       missing, job->count, job->model, log_path);
    if (fit && (status = vf_json_load(info_path, fit)) != VF_OK)
        return status;
    return VF_OK;
}
