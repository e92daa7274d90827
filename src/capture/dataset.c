#include "vf/dataset.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/image.h"
#include "vf/json.h"
#include "vf/workspace.h"

/* Intrinsics as a transforms file states them: any field may be missing (NAN / 0). */
typedef struct stated_intrinsics {
    double angle_x, fl_x, fl_y, cx, cy, k1, k2, p1, p2;
    int w, h;
} stated_intrinsics;

static double number_or(const json_t *obj, const char *key, double fallback)
{
    const json_t *v = json_object_get(obj, key);
    return json_is_number(v) ? json_number_value(v) : fallback;
}

/* An image size: a whole number from 1 to VF_CAMERA_MAX_SIDE, else -1 (refused later);
 * fallback when absent. Never a cast of an arbitrary double to int. */
static int size_or(const json_t *obj, const char *key, int fallback)
{
    const json_t *v = json_object_get(obj, key);
    if (!v)
        return fallback;
    double x = json_is_number(v) ? json_number_value(v) : NAN;
    return x >= 1 && x <= VF_CAMERA_MAX_SIDE && x == floor(x) ? (int)x : -1;
}

/* Fields in `obj` override those already in `in` (top level first, then per frame). */
static void read_intrinsics(const json_t *obj, stated_intrinsics *in)
{
    in->angle_x = number_or(obj, "camera_angle_x", in->angle_x);
    in->fl_x = number_or(obj, "fl_x", in->fl_x);
    in->fl_y = number_or(obj, "fl_y", in->fl_y);
    in->cx = number_or(obj, "cx", in->cx);
    in->cy = number_or(obj, "cy", in->cy);
    in->k1 = number_or(obj, "k1", in->k1);
    in->k2 = number_or(obj, "k2", in->k2);
    in->p1 = number_or(obj, "p1", in->p1);
    in->p2 = number_or(obj, "p2", in->p2);
    in->w = size_or(obj, "w", in->w);
    in->h = size_or(obj, "h", in->h);
}

/* Turn what the file states into a camera for an image of the real size. A file whose w/h
 * differ from the image by a uniform scale (images resized after posing) is scaled. */
static vf_status resolve_camera(const stated_intrinsics *in, int img_w, int img_h, vf_camera *cam)
{
    if (in->w < 0 || in->h < 0)
        return vf_fail(VF_EINPUT, "w and h must be whole numbers of pixels from 1 to %d",
                       VF_CAMERA_MAX_SIDE);
    int w = in->w > 0 ? in->w : img_w, h = in->h > 0 ? in->h : img_h;
    memset(cam, 0, sizeof *cam);
    cam->width = w;
    cam->height = h;
    if (in->fl_x > 0) {
        cam->fx = in->fl_x;
        cam->fy = in->fl_y > 0 ? in->fl_y : in->fl_x;
    } else if (in->angle_x > 0 && in->angle_x < M_PI) {
        cam->fx = cam->fy = 0.5 * w / tan(0.5 * in->angle_x);
    } else {
        return vf_fail(VF_EINPUT, "no focal length (need camera_angle_x or fl_x)");
    }
    cam->cx = isnan(in->cx) ? 0.5 * w : in->cx;
    cam->cy = isnan(in->cy) ? 0.5 * h : in->cy;
    cam->k1 = in->k1;
    cam->k2 = in->k2;
    cam->p1 = in->p1;
    cam->p2 = in->p2;
    vf_status status = vf_camera_check(cam);
    if (status != VF_OK)
        return status;
    if (w != img_w || h != img_h) {
        double sx = (double)img_w / w, sy = (double)img_h / h;
        if (fabs(sx - sy) > 0.01 * sx)
            return vf_fail(VF_EINPUT, "image is %dx%d but the file says %dx%d", img_w, img_h, w, h);
        *cam = vf_camera_scaled(cam, img_w, img_h);
    }
    return VF_OK;
}

static vf_status read_matrix(const json_t *rows, double m[16])
{
    if (!json_is_array(rows) || json_array_size(rows) < 3)
        return vf_fail(VF_EINPUT, "transform_matrix is not a 4x4 (or 3x4) array");
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++) {
            if (r == 3 && json_array_size(rows) == 3) {
                m[12 + c] = c == 3 ? 1.0 : 0.0;
                continue;
            }
            const json_t *v = json_array_get(json_array_get(rows, (size_t)r), (size_t)c);
            if (!json_is_number(v) || !(fabs(json_number_value(v)) <= 1e6))
                return vf_fail(VF_EINPUT, "transform_matrix[%d][%d] is not a number from -1e6 "
                               "to 1e6", r, c);
            m[4 * r + c] = json_number_value(v);
        }
    return VF_OK;
}

/* file_path relative to the JSON's folder; NeRF-synthetic paths have no extension. */
static vf_status resolve_image_path(const char *base_dir, const char *file_path, char *out,
                                    size_t size)
{
    if (file_path[0] == '/')
        snprintf(out, size, "%s", file_path);
    else if (vf_path_join(out, size, base_dir, file_path) != VF_OK)
        return VF_EINPUT;
    if (vf_is_file(out))
        return VF_OK;
    size_t len = strlen(out);
    if (len + 5 < size) {
        strcat(out, ".png");
        if (vf_is_file(out))
            return VF_OK;
        out[len] = '\0';
    }
    return vf_fail(VF_EINPUT, "image %s does not exist", out);
}

static vf_status load_frame(const json_t *frame, const stated_intrinsics *top, const char *base_dir,
                            vf_frame *out)
{
    const json_t *path = json_object_get(frame, "file_path");
    if (!json_is_string(path))
        return vf_fail(VF_EINPUT, "missing file_path");
    vf_status status = resolve_image_path(base_dir, json_string_value(path), out->image_path,
                                          sizeof out->image_path);
    if (status == VF_OK)
        status = read_matrix(json_object_get(frame, "transform_matrix"), out->c2w);
    if (status != VF_OK)
        return status;
    int img_w, img_h, channels;
    if ((status = vf_image_info(out->image_path, &img_w, &img_h, &channels)) != VF_OK)
        return status;
    stated_intrinsics in = *top;
    read_intrinsics(frame, &in);
    return resolve_camera(&in, img_w, img_h, &out->camera);
}

vf_status vf_dataset_load(const char *transforms_path, vf_dataset *out)
{
    memset(out, 0, sizeof *out);
    snprintf(out->source, sizeof out->source, "%s", transforms_path);
    json_t *doc;
    vf_status status = vf_json_load(transforms_path, &doc);
    if (status != VF_OK)
        return status;
    const json_t *frames = json_object_get(doc, "frames");
    if (!json_is_array(frames) || json_array_size(frames) == 0) {
        json_decref(doc);
        return vf_fail(VF_EINPUT, "%s: no \"frames\" list (is this a NeRF transforms file?)",
                       transforms_path);
    }
    stated_intrinsics top = {.cx = NAN, .cy = NAN};
    read_intrinsics(doc, &top);
    char base_dir[VF_PATH_MAX];
    vf_path_dirname(base_dir, sizeof base_dir, transforms_path);

    out->count = (int)json_array_size(frames);
    out->frames = calloc((size_t)out->count, sizeof *out->frames);
    if (!out->frames)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < out->count; i++) {
        status = load_frame(json_array_get(frames, (size_t)i), &top, base_dir, &out->frames[i]);
        if (status != VF_OK)
            vf_error_prefix("%s: frame %d", transforms_path, i);
    }
    json_decref(doc);
    if (status != VF_OK)
        vf_dataset_free(out);
    return status;
}

static void write_intrinsics(json_t *obj, const vf_camera *c)
{
    json_object_set_new(obj, "camera_angle_x", vf_json_number(2.0 * atan(0.5 * c->width / c->fx)));
    json_object_update_new(obj, vf_camera_json(c));
}

vf_status vf_dataset_save(const char *transforms_path, const vf_dataset *ds)
{
    char base_dir[VF_PATH_MAX];
    vf_path_dirname(base_dir, sizeof base_dir, transforms_path);
    size_t base_len = strlen(base_dir);
    int shared = 1; /* one camera for all frames: write it once at the top, as most tools expect */
    for (int i = 1; i < ds->count; i++)
        shared &= !memcmp(&ds->frames[i].camera, &ds->frames[0].camera, sizeof(vf_camera));

    json_t *doc = json_object();
    if (shared && ds->count > 0)
        write_intrinsics(doc, &ds->frames[0].camera);
    json_t *frames = json_array();
    for (int i = 0; i < ds->count; i++) {
        const vf_frame *f = &ds->frames[i];
        const char *path = f->image_path;
        if (!strncmp(path, base_dir, base_len) && path[base_len] == '/')
            path += base_len + 1;
        json_t *frame =
            json_pack("{s:s, s:o}", "file_path", path, "transform_matrix", vf_json_mat4(f->c2w));
        if (!shared)
            write_intrinsics(frame, &f->camera);
        json_array_append_new(frames, frame);
    }
    json_object_set_new(doc, "frames", frames);
    vf_status status = vf_json_save(transforms_path, doc);
    json_decref(doc);
    return status;
}

void vf_dataset_free(vf_dataset *ds)
{
    free(ds->frames);
    ds->frames = NULL;
    ds->count = 0;
}

vf_status vf_dataset_load_training(const vf_workspace *ws, vf_dataset *out, int *real_capture)
{
    char path[VF_PATH_MAX];
    memset(out, 0, sizeof *out);
    vf_status s = vf_workspace_training_views(ws, path, sizeof path, real_capture);
    return s == VF_OK ? vf_dataset_load(path, out) : s;
}

double *vf_dataset_poses(const vf_dataset *ds)
{
    double *c2w = malloc((size_t)(ds->count ? ds->count : 1) * 16 * sizeof *c2w);
    for (int i = 0; c2w && i < ds->count; i++)
        memcpy(c2w + 16 * i, ds->frames[i].c2w, 16 * sizeof *c2w);
    return c2w;
}
