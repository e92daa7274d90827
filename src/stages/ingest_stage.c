/* The ingest stage (vf/ingest.h): a capture, a posed set or a 3D model into WS/ingest/. */
#define _GNU_SOURCE
#include "vf/ingest.h"

#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/dataset.h"
#include "vf/image.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/workspace.h"

static const char *const kind_names[] = {"video", "photos", "camera", "transforms", "model"};

const char *vf_ingest_kind_name(vf_ingest_kind kind)
{
    return (unsigned)kind < 5 ? kind_names[kind] : "?";
}

vf_status vf_ingest_input_kind(const char *path, vf_ingest_kind *kind)
{
    size_t n = strlen(path);
    if (vf_is_dir(path))
        *kind = VF_INGEST_PHOTOS;
    else if (!vf_is_file(path))
        return vf_fail(VF_EINPUT,
                       "cannot read %s: no such file; give a video file, a folder "
                       "of photos or a 3D model (.glb, .gltf, .obj, .blend)",
                       path);
    else if (n > 5 && !strcmp(path + n - 5, ".json"))
        *kind = VF_INGEST_TRANSFORMS;
    else if (vf_object3d_is_model(path))
        *kind = VF_INGEST_MODEL;
    else
        *kind = VF_INGEST_VIDEO;
    return VF_OK;
}

void vf_ingest_request_defaults(vf_ingest_request *r)
{
    memset(r, 0, sizeof *r);
    vf_ingest_defaults(&r->capture);
    vf_object3d_capture_defaults(&r->model);
}

/* Decode every image (in parallel) to catch corrupt files before anything is written, and
 * note whether any has an alpha channel (an object on a transparent background). Progress
 * shows only for sets big enough to take a while, so that a small import that fails says so
 * in one line. */
static vf_status check_images(const vf_dataset *ds, int *has_alpha)
{
    vf_first_error error = {0};
    int alpha = 0, done = 0;
    int show = ds->count >= 64;
    vf_progress progress;
    vf_progress_begin(&progress, "checking images", (size_t)ds->count, "images");
#pragma omp parallel for schedule(dynamic) reduction(| : alpha)
    for (int i = 0; i < ds->count; i++) {
        vf_image img;
        vf_status s = vf_image_load(ds->frames[i].image_path, &img);
        if (s == VF_OK) {
            if (img.width != ds->frames[i].camera.width ||
                img.height != ds->frames[i].camera.height)
                s = vf_fail(VF_EINPUT, "%s changed size while reading", ds->frames[i].image_path);
            alpha |= img.channels == 4;
            vf_image_free(&img);
        }
        vf_first_error_keep(&error, s);
#pragma omp critical
        if (show)
            vf_progress_update(&progress, (size_t)++done, NULL);
    }
    if (show)
        vf_progress_end(&progress);
    *has_alpha = alpha;
    return vf_first_error_raise(&error);
}

/* Copy the images into the staging folder; `copy` gets the new paths. */
static vf_status copy_images(const vf_dataset *ds, const char *stage_dir, vf_dataset *copy)
{
    char images_dir[VF_PATH_MAX];
    vf_status status = vf_path_join(images_dir, sizeof images_dir, stage_dir, "images");
    if (status == VF_OK)
        status = vf_mkdirs(images_dir);
    for (int i = 0; status == VF_OK && i < ds->count; i++) {
        char name[NAME_MAX + 1], file[NAME_MAX + 16];
        vf_path_basename(name, sizeof name, ds->frames[i].image_path, 0);
        snprintf(file, sizeof file, "%04d_%s", i, name); /* unique even if names repeat */
        copy->frames[i] = ds->frames[i];
        status = vf_path_join(copy->frames[i].image_path, VF_PATH_MAX, images_dir, file);
        if (status == VF_OK)
            status = vf_copy_file(ds->frames[i].image_path, copy->frames[i].image_path);
    }
    return status;
}

static json_t *summarize(const vf_dataset *ds, int has_alpha)
{
    double distance = 0;
    for (int i = 0; i < ds->count; i++) {
        const double *m = ds->frames[i].c2w;
        distance += sqrt(m[3] * m[3] + m[7] * m[7] + m[11] * m[11]) / ds->count;
    }
    const vf_camera *cam = &ds->frames[0].camera;
    return json_pack(
        "{s:i, s:i, s:i, s:o, s:o, s:b, s:s, s:o}", "frames", ds->count, "width", cam->width,
        "height", cam->height, "focal_x", vf_json_number(cam->fx), "focal_y",
        vf_json_number(cam->fy), "distortion", vf_camera_has_distortion(cam), "background",
        has_alpha ? "transparent" : "opaque", "mean_camera_distance", vf_json_number(distance));
}

/* Import a posed dataset into the staging folder. */
static vf_status import_transforms(const vf_ingest_request *opt, const char *stage_dir,
                                   json_t **params, json_t **summary)
{
    vf_dataset ds, copy = {0};
    char source[PATH_MAX], transforms_out[VF_PATH_MAX];
    int has_alpha = 0;

    vf_status status = vf_dataset_load(opt->input, &ds);
    if (status != VF_OK)
        return status;
    if ((status = check_images(&ds, &has_alpha)) == VF_OK)
        vf_info("%s: %d posed frames", opt->input, ds.count);
    copy.count = ds.count;
    copy.frames = calloc((size_t)ds.count, sizeof *copy.frames);
    if (status == VF_OK && !copy.frames)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    if (status == VF_OK)
        status = copy_images(&ds, stage_dir, &copy);
    if (status == VF_OK)
        status = vf_path_join(transforms_out, sizeof transforms_out, stage_dir, "transforms.json");
    if (status == VF_OK)
        status = vf_dataset_save(transforms_out, &copy);
    if (status == VF_OK) {
        if (!realpath(opt->input, source))
            snprintf(source, sizeof source, "%s", opt->input);
        *summary = summarize(&ds, has_alpha);
        *params = json_pack("{s:s, s:s}", "source", "transforms", "transforms", source);
    }
    free(copy.frames);
    vf_dataset_free(&ds);
    return status;
}

/* The manifest's summary of a capture ingest, from its report. */
static json_t *summarize_capture(const json_t *report)
{
    json_t *source = json_object_get(report, "source");
    json_t *summary = json_pack(
        "{s:O, s:O, s:O, s:O, s:O, s:O, s:O, s:O, s:s}", "source", json_object_get(source, "kind"),
        "input", json_object_get(source, "path"), "frames", json_object_get(report, "kept"),
        "frames_read", json_object_get(report, "frame_count"), "blurry",
        json_object_get(report, "blurry"), "duplicates", json_object_get(report, "duplicates"),
        "width", json_object_get(report, "output_width"), "height",
        json_object_get(report, "output_height"), "report", "ingest/report.json");
    json_t *rotation = json_object_get(json_object_get(report, "rotation"), "clockwise_degrees");
    if (rotation)
        json_object_set(summary, "rotation", rotation);
    json_t *orientation = json_object_get(report, "orientation");
    if (orientation)
        json_object_set(summary, "mixed_orientation", json_object_get(orientation, "mixed"));
    return summary;
}

/* The options as the manifest records them. */
static json_t *capture_params(const vf_ingest_request *opt, const char *kind, const json_t *report)
{
    const vf_ingest_options *cap = &opt->capture;
    json_t *params = json_pack("{s:s, s:O, s:i, s:i, s:o, s:o}", "source", kind, "input",
                               json_object_get(json_object_get(report, "source"), "path"), "frames",
                               cap->select.max_frames, "max_size", cap->max_size, "blur_ratio",
                               vf_json_number(cap->select.blur_ratio), "duplicate_threshold",
                               vf_json_number(cap->select.duplicate_threshold));
    if (opt->kind == VF_INGEST_CAMERA) {
        json_object_set_new(params, "seconds", vf_json_number(cap->seconds));
        json_object_set_new(params, "size", json_pack("[i, i]", cap->width, cap->height));
    }
    return params;
}

/* Ingest a video, photo folder or webcam into the staging folder. */
static vf_status import_capture(const vf_ingest_request *opt, const char *stage_dir,
                                json_t **params, json_t **summary)
{
    json_t *report = NULL;
    const char *kind = vf_ingest_kind_name(opt->kind);
    vf_status status;
    if (opt->kind == VF_INGEST_CAMERA)
        status = vf_ingest_camera(opt->input, &opt->capture, stage_dir, &report);
    else if (opt->kind == VF_INGEST_PHOTOS)
        status = vf_ingest_photos(opt->input, &opt->capture, stage_dir, &report);
    else
        status = vf_ingest_video(opt->input, &opt->capture, stage_dir, &report);
    if (status == VF_OK) {
        *summary = summarize_capture(report);
        *params = capture_params(opt, kind, report);
    }
    json_decref(report);
    return status;
}

/* Render a 3D model's capture into the staging folder. */
static vf_status import_model(const vf_ingest_request *opt, const char *stage_dir, json_t **params,
                              json_t **summary)
{
    const vf_object3d_capture *m = &opt->model;
    vf_info("%s: rendering %d + %d views of %dx%d with Blender (%d samples)", opt->input, m->views,
            m->test_views, m->size, m->size, m->samples);
    vf_status status = vf_object3d_ingest(opt->input, m, stage_dir, summary);
    if (status == VF_OK)
        *params = json_pack("{s:s, s:O, s:i, s:i, s:i, s:i, s:I}", "source", "model", "input",
                            json_object_get(*summary, "input"), "views", m->views, "test_views",
                            m->test_views, "size", m->size, "samples", m->samples, "seed",
                            (json_int_t)m->seed);
    return status;
}

typedef vf_status (*import_fn)(const vf_ingest_request *opt, const char *stage_dir,
                               json_t **params, json_t **summary);

/* Run an import in the workspace's staging folder and swap it in when it succeeds. A
 * workspace this run created is removed again when it fails, so bad input leaves nothing
 * behind, and an existing one keeps its earlier outputs. A model's renders are slow: when
 * they stop half-way (interrupted, not refused) the staging folder is kept for the next run. */
static vf_status run_in_stage(const char *root, const vf_ingest_request *opt, import_fn import,
                              json_t **summary_out)
{
    vf_workspace ws;
    vf_stage stage;
    json_t *params = NULL, *summary = NULL;
    int fresh = !vf_is_dir(root);
    vf_status status = vf_workspace_open(root, 1, &ws);
    if (status != VF_OK)
        return status;
    int resumable = import == import_model;
    status =
        resumable ? vf_stage_resume(&ws, "ingest", &stage) : vf_stage_begin(&ws, "ingest", &stage);
    json_t *identity = NULL; /* read before the import: it is what the import read */
    if (status == VF_OK && opt->kind != VF_INGEST_CAMERA)
        status = vf_ingest_input_identity(opt->input, &identity);
    if (status == VF_OK)
        status = import(opt, stage.dir, &params, &summary);
    if (status == VF_OK && identity)
        json_object_set(params, "input_identity", identity);
    json_decref(identity);
    char first[VF_PATH_MAX]; /* renders made so far stay for a retry */
    int keep = resumable && status == VF_EINTERNAL &&
               vf_path_join(first, sizeof first, stage.dir, "images/r_000.png") == VF_OK &&
               vf_is_file(first);
    if (status == VF_OK) {
        json_t *copy = json_deep_copy(summary); /* the commit takes summary */
        status = vf_stage_commit(&stage, params, summary);
        if (status == VF_OK)
            *summary_out = copy;
        else
            json_decref(copy);
    } else {
        json_decref(params);
        json_decref(summary);
        if (!keep)
            vf_stage_abort(&stage);
    }
    vf_workspace_close(&ws);
    if (status != VF_OK && fresh && !keep)
        vf_remove_tree(root);
    return status;
}

vf_status vf_ingest_run(const char *ws_root, const vf_ingest_request *r, json_t **summary)
{
    static const import_fn imports[] = {import_capture, import_capture, import_capture,
                                        import_transforms, import_model};
    *summary = NULL;
    if ((unsigned)r->kind > VF_INGEST_MODEL || !r->input)
        return vf_fail(VF_EINPUT, "ingest: give an input and its kind");
    return run_in_stage(ws_root, r, imports[r->kind], summary);
}
