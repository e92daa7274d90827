/* The paper's capture of a 3D model: views on the upper hemisphere rendered by Blender into a
 * posed set, and the workspace's record of the model (object.json). */
#define _GNU_SOURCE
#include <limits.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>

#include "object3d_internal.h"
#include "vf/dataset.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/pose.h"
#include "vf/rng.h"

#define OBJECT_FORMAT 1
#define EMPTY_ALPHA 0.5             /* a pixel shows the object above this opacity */

int vf_object3d_is_model(const char *path)
{
    static const char *const extensions[] = {".glb", ".gltf", ".obj", ".blend"};
    const char *dot = strrchr(path, '.');
    for (size_t i = 0; dot && i < sizeof extensions / sizeof extensions[0]; i++)
        if (!strcasecmp(dot, extensions[i]))
            return 1;
    return 0;
}

void vf_object3d_capture_defaults(vf_object3d_capture *c)
{
    *c = (vf_object3d_capture){.views = 100,
                               .test_views = 25,
                               .size = 256, /* see vf/object3d.h */
                               .samples = 32,
                               .distance = VF_CAMERA_DISTANCE,
                               .camera_angle_x = VF_NERF_CAMERA_ANGLE_X,
                               .min_elevation = 5,
                               .seed = 0,
                               .scene = "studio"};
}

void vf_object3d_capture_poses(const vf_object3d_capture *c, double *c2w)
{
    vf_rng rng;
    vf_rng_seed(&rng, c->seed);
    double z0 = sin(c->min_elevation * M_PI / 180);
    for (int i = 0; i < c->views + c->test_views; i++) {
        /* uniform over the sphere's area: the height is uniform */
        double z = z0 + (1 - z0) * vf_rng_uniform(&rng);
        /* phi = 180 - elevation: the same position with phi = elevation would roll the camera
         * 180 degrees (vf/pose.h), and upside-down photos are not the paper's capture. */
        vf_viewpoint v = {.psi = 360 * vf_rng_uniform(&rng) - 180,
                          .phi = 180 - asin(z) * 180 / M_PI,
                          .dy = c->distance - VF_CAMERA_DISTANCE};
        vf_viewpoint_to_c2w(&v, c2w + 16 * i);
    }
}

/* A posed set of `count` rendered views in dir/PREFIXNNN.png. */
static vf_status save_transforms(const char *path, const char *dir, const char *prefix,
                                 const vf_camera *cam, const double *c2w, int count)
{
    vf_dataset ds = {.count = count, .frames = calloc((size_t)count, sizeof(vf_frame))};
    if (!ds.frames)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_status status = VF_OK;
    for (int i = 0; status == VF_OK && i < count; i++) {
        char file[64];
        vf__blender_view_file(prefix, i, file, sizeof file);
        status = vf_path_join(ds.frames[i].image_path, VF_PATH_MAX, dir, file);
        ds.frames[i].camera = *cam;
        memcpy(ds.frames[i].c2w, c2w + 16 * i, sizeof ds.frames[i].c2w);
    }
    if (status == VF_OK)
        status = vf_dataset_save(path, &ds);
    free(ds.frames);
    return status;
}

/* How much of each view the object covers; VF_EINPUT when no view shows it at all. */
static vf_status check_coverage(const char *model, const char *dir, int count, double *mean)
{
    vf_status status = VF_OK;
    double total = 0;
    int seen = 0;
#pragma omp parallel for schedule(dynamic) reduction(+ : total, seen)
    for (int i = 0; i < count; i++) {
        char file[64], path[VF_PATH_MAX];
        vf_image img;
        vf__blender_view_file("r_", i, file, sizeof file);
        if (vf_path_join(path, sizeof path, dir, file) != VF_OK || vf_image_load(path, &img))
            continue; /* Blender checked that every file exists; a bad one fails training */
        size_t pixels = (size_t)img.width * img.height, covered = 0;
        for (size_t p = 0; img.channels == 4 && p < pixels; p++)
            covered += img.data[4 * p + 3] > EMPTY_ALPHA;
        total += (double)covered / (double)pixels;
        seen += covered > 0;
        vf_image_free(&img);
    }
    *mean = total / count;
    if (!seen)
        status = vf_fail(VF_EINPUT, "%s renders empty: none of its %d views shows any of it "
                                    "(check that its materials are not fully transparent)",
                         model, count);
    return status;
}

/* What the renders in out_dir are made of; when a staging folder left by an interrupted run
 * was made for something else, its renders are thrown away. */
static vf_status prepare_folder(const char *model, const vf_object3d_capture *c,
                                const char *out_dir)
{
    struct stat st;
    if (stat(model, &st) != 0)
        return vf_fail(VF_EINPUT, "cannot read %s: no such file", model);
    json_t *request =
        json_pack("{s:s, s:I, s:I, s:i, s:i, s:i, s:i, s:o, s:o, s:o, s:I, s:s}", "model", model,
                  "bytes", (json_int_t)st.st_size, "mtime", (json_int_t)st.st_mtime, "views",
                  c->views, "test_views", c->test_views, "size", c->size, "samples", c->samples,
                  "distance", vf_json_number(c->distance), "camera_angle_x",
                  vf_json_number(c->camera_angle_x), "min_elevation",
                  vf_json_number(c->min_elevation), "seed", (json_int_t)c->seed, "scene", c->scene);
    static const char *const renders[] = {"images", "test", NULL};
    return vf_stage_keep_if_same(out_dir, request, renders);
}

static json_t *object_json(const char *model, const json_t *fit, const vf_object3d_capture *c,
                           double coverage)
{
    struct stat st;
    json_int_t bytes = stat(model, &st) == 0 ? (json_int_t)st.st_size : -1;
    return json_pack("{s:i, s:s, s:I, s:{s:O, s:O}, s:O, s:O, s:O, s:{s:i, s:i, s:i, s:i, s:o, "
                     "s:o, s:o, s:s}, s:o}",
                     "format", OBJECT_FORMAT, "model", model, "bytes", bytes, "transform", "center",
                     json_object_get(fit, "center"), "scale", json_object_get(fit, "scale"),
                     "vertices", json_object_get(fit, "vertices"), "meshes",
                     json_object_get(fit, "meshes"), "radius", json_object_get(fit, "radius"),
                     "render", "views", c->views, "test_views", c->test_views, "size", c->size,
                     "samples", c->samples, "distance", vf_json_number(c->distance),
                     "camera_angle_x", vf_json_number(c->camera_angle_x), "min_elevation",
                     vf_json_number(c->min_elevation), "scene", c->scene, "mean_coverage",
                     coverage >= 0 ? vf_json_number(coverage) : json_null());
}

static vf_status transform_from_json(const json_t *doc, const char *path,
                                     vf_object3d_transform *t)
{
    const json_t *center = json_object_get(doc, "center");
    t->scale = json_number_value(json_object_get(doc, "scale"));
    for (int k = 0; k < 3; k++)
        t->center[k] = json_number_value(json_array_get(center, (size_t)k));
    int ok = json_array_size(center) == 3 && isfinite(t->scale) && t->scale > 0 && t->scale < 1e12;
    for (int k = 0; k < 3; k++)
        ok &= json_is_number(json_array_get(center, (size_t)k)) && fabs(t->center[k]) < 1e12;
    return ok ? VF_OK
              : vf_fail(VF_EINPUT, "%s: the model's transform (center, scale) is damaged", path);
}

vf_status vf_object3d_ingest(const char *model_path, const vf_object3d_capture *c,
                             const char *out_dir, json_t **report)
{
    char model[PATH_MAX], images[VF_PATH_MAX], test[VF_PATH_MAX], path[VF_PATH_MAX];
    if (!realpath(model_path, model))
        return vf_fail(VF_EINPUT, "cannot read %s: no such file", model_path);
    int total = c->views + c->test_views;
    double *c2w = malloc((size_t)total * 16 * sizeof *c2w);
    if (!c2w)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_object3d_capture_poses(c, c2w);
    vf_camera cam = vf_camera_from_fov(c->size, c->size, c->camera_angle_x);
    double start = vf_now(), coverage = 0;
    json_t *fit = NULL, *object = NULL;
    vf_object3d_transform transform;

    vf_status status = prepare_folder(model, c, out_dir);
    if (status == VF_OK)
        status = vf_path_join(images, sizeof images, out_dir, "images");
    if (status == VF_OK)
        status = vf_path_join(test, sizeof test, out_dir, "test");
    vf__blender_job job = {.model = model,
                           .camera = cam,
                           .samples = c->samples,
                           .scene = c->scene,
                           .c2w = c2w,
                           .count = c->views,
                           .out_dir = images,
                           .prefix = "r_",
                           .work_dir = out_dir,
                           .label = "rendering training views"};
    if (status == VF_OK)
        status = vf__blender_render(&job, &fit);
    if (status == VF_OK)
        status = transform_from_json(fit, model, &transform);
    int studio = !strcmp(c->scene, "studio");
    if (status == VF_OK && studio)
        status = check_coverage(model, images, c->views, &coverage);
    if (!studio)
        coverage = -1; /* the room hides it */
    if (status == VF_OK && c->test_views > 0) {
        job = (vf__blender_job){.model = model,
                                .transform = &transform,
                                .camera = cam,
                                .samples = c->samples,
                                .scene = c->scene,
                                .c2w = c2w + 16 * c->views,
                                .count = c->test_views,
                                .out_dir = test,
                                .prefix = "r_",
                                .work_dir = out_dir,
                                .label = "rendering test views"};
        status = vf__blender_render(&job, NULL);
    }
    if (status == VF_OK && (status = vf_path_join(path, sizeof path, out_dir, "transforms.json")) ==
                               VF_OK)
        status = save_transforms(path, images, "r_", &cam, c2w, c->views);
    if (status == VF_OK && c->test_views > 0 &&
        (status = vf_path_join(path, sizeof path, out_dir, "transforms_test.json")) == VF_OK)
        status = save_transforms(path, test, "r_", &cam, c2w + 16 * c->views, c->test_views);
    if (status == VF_OK) {
        object = object_json(model, fit, c, coverage);
        status = vf_path_join(path, sizeof path, out_dir, VF_OBJECT3D_FILE);
    }
    if (status == VF_OK)
        status = vf_json_save(path, object);
    if (status == VF_OK && report)
        *report = json_pack(
            "{s:s, s:s, s:i, s:i, s:i, s:i, s:s, s:s, s:o, s:o, s:O, s:O}", "source", "model",
            "input", model, "frames", c->views, "test_frames", c->test_views, "width", c->size,
            "height", c->size, "scene", c->scene, "background", studio ? "transparent" : "room",
            "mean_camera_distance", vf_json_number(c->distance), "seconds",
            vf_json_number(vf_now() - start), "transform", json_object_get(object, "transform"),
            "mean_coverage", json_object_get(object, "mean_coverage"));
    json_decref(object);
    json_decref(fit);
    free(c2w);
    return status;
}

vf_status vf_object3d_load(const vf_workspace *ws, vf_object3d *out)
{
    char path[VF_PATH_MAX];
    json_t *doc = NULL;
    vf_status status = vf_workspace_path(ws, "ingest", VF_OBJECT3D_FILE, path, sizeof path);
    if (status != VF_OK)
        return status;
    if (!vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s was not made from a 3D model (no ingest/%s): this check "
                                  "needs the object itself; ingest a .glb model",
                       ws->root, VF_OBJECT3D_FILE);
    if ((status = vf_json_load(path, &doc)) != VF_OK)
        return status;
    memset(out, 0, sizeof *out);
    const char *model = json_string_value(json_object_get(doc, "model"));
    if (json_integer_value(json_object_get(doc, "format")) != OBJECT_FORMAT || !model)
        status = vf_fail(VF_EINPUT, "%s is not a model record this version reads", path);
    else if (snprintf(out->model, sizeof out->model, "%s", model) >= (int)sizeof out->model)
        status = vf_fail(VF_EINPUT, "%s: the model path is too long", path);
    if (status == VF_OK)
        status = transform_from_json(json_object_get(doc, "transform"), path, &out->transform);
    long long samples = json_integer_value(json_object_get(json_object_get(doc, "render"),
                                                           "samples"));
    out->samples = samples >= 1 && samples <= 65536 ? (int)samples : 64;
    const char *scene =
        json_string_value(json_object_get(json_object_get(doc, "render"), "scene"));
    snprintf(out->scene, sizeof out->scene, "%s",
             scene && !strcmp(scene, "room") ? "room" : "studio");
    if (status == VF_OK && !vf_is_file(out->model))
        status = vf_fail(VF_EINPUT, "the model %s this workspace was made from is gone; "
                                    "put it back to check viewpoints against it",
                         out->model);
    json_decref(doc);
    return status;
}

/* Blender's job for views of a recorded model, written beside the renders. */
static vf__blender_job model_job(const vf_object3d *obj, const vf_camera *cam, const double *c2w,
                                 int n, const char *dir, const char *prefix, const char *label)
{
    return (vf__blender_job){.model = obj->model,
                             .transform = &obj->transform,
                             .camera = *cam,
                             .samples = obj->samples,
                             .scene = obj->scene,
                             .c2w = c2w,
                             .count = n,
                             .out_dir = dir,
                             .prefix = prefix,
                             .work_dir = dir,
                             .label = label};
}

vf_status vf_object3d_render_images(const vf_object3d *obj, const vf_camera *cam,
                                    const double *c2w, int n, const char *dir,
                                    const char *prefix, const char *progress_label,
                                    vf_image *images)
{
    static const float white[3] = {1, 1, 1};
    vf__blender_job job = model_job(obj, cam, c2w, n, dir, prefix, progress_label);
    vf_status status = vf__blender_render(&job, NULL);
    int loaded = 0;
    for (int i = 0; status == VF_OK && i < n; i++) {
        char file[64], path[VF_PATH_MAX];
        vf__blender_view_file(prefix, i, file, sizeof file);
        status = vf_path_join(path, sizeof path, dir, file);
        if (status == VF_OK)
            status = vf_image_load_rgb(path, white, &images[i]);
        if (status != VF_OK)
            break;
        loaded++;
        if (images[i].width != cam->width || images[i].height != cam->height)
            status = vf_fail(VF_EINTERNAL, "%s is %dx%d, not the %dx%d asked for", path,
                             images[i].width, images[i].height, cam->width, cam->height);
    }
    if (status != VF_OK)
        for (int i = 0; i < loaded; i++)
            vf_image_free(&images[i]);
    return status;
}

vf_status vf_object3d_render_video(const vf_object3d *obj, const vf_camera *cam,
                                   const double *c2w, int n, double shutter, const char *dir,
                                   const char *prefix, const char *progress_label,
                                   vf_object3d_transform *fit)
{
    vf__blender_job job = model_job(obj, cam, c2w, n, dir, prefix, progress_label);
    job.shutter = shutter;
    if (!(obj->transform.scale > 0))
        job.transform = NULL; /* fit it */
    json_t *measured = NULL;
    vf_status status = vf__blender_render(&job, &measured);
    if (status == VF_OK && fit) {
        json_t *center = json_object_get(measured, "center");
        for (int k = 0; k < 3; k++)
            fit->center[k] = json_number_value(json_array_get(center, (size_t)k));
        fit->scale = json_number_value(json_object_get(measured, "scale"));
        if (!(fit->scale > 0) || json_array_size(center) != 3)
            status = vf_fail(VF_EINTERNAL, "Blender's fit of %s has no transform", obj->model);
    }
    json_decref(measured);
    return status;
}
