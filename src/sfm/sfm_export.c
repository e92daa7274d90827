/* The poses stage's outputs from a COLMAP model: frames, points, and the normalization. */
#define _GNU_SOURCE
#include "vf/sfm_export.h"

#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/fsutil.h"
#include "vf/json.h"
#include "vf/workspace.h"

static int compare_image_names(const void *a, const void *b)
{
    return strcmp((*(const vf_colmap_image *const *)a)->name,
                  (*(const vf_colmap_image *const *)b)->name);
}

static vf_status fill_frame(const vf_colmap_model *model, const vf_colmap_image *img,
                            const vf_similarity *object_from_model, const char *image_dir,
                            vf_frame *frame)
{
    double c2w[16];
    vf_colmap_image_c2w(img, c2w);
    vf_similarity_apply_c2w(object_from_model, c2w, frame->c2w);
    vf_status status = vf_colmap_camera_to_vf(vf_colmap_model_camera(model, img->camera_id),
                                              &frame->camera);
    if (status == VF_OK)
        status = vf_path_join(frame->image_path, sizeof frame->image_path, image_dir, img->name);
    return status;
}

vf_status vf_sfm_dataset(const vf_colmap_model *model, const vf_similarity *object_from_model,
                         const char *image_dir, vf_dataset *out)
{
    memset(out, 0, sizeof *out);
    const vf_colmap_image **order = malloc((size_t)(model->image_count + 1) * sizeof *order);
    out->frames = calloc((size_t)(model->image_count + 1), sizeof *out->frames);
    if (!order || !out->frames) {
        free(order);
        vf_dataset_free(out);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
    for (int i = 0; i < model->image_count; i++)
        order[i] = &model->images[i];
    qsort(order, (size_t)model->image_count, sizeof *order, compare_image_names);
    vf_status status = VF_OK;
    for (int i = 0; status == VF_OK && i < model->image_count; i++)
        status = fill_frame(model, order[i], object_from_model, image_dir, &out->frames[i]);
    out->count = model->image_count;
    free(order);
    if (status != VF_OK)
        vf_dataset_free(out);
    return status;
}

static void write_point(FILE *f, const vf_colmap_point *pt, const vf_similarity *s)
{
    double p[3];
    vf_similarity_apply(s, pt->xyz, p);
    fprintf(f, "%lld %.9g %.9g %.9g %d %d %d %.6g", pt->id, p[0], p[1], p[2], pt->rgb[0],
            pt->rgb[1], pt->rgb[2], pt->error);
    for (int k = 0; k < pt->track_length; k++)
        fprintf(f, " %d %d", pt->track[2 * k], pt->track[2 * k + 1]);
    fputc('\n', f);
}

vf_status vf_sfm_save_points(const char *path, const vf_colmap_model *model,
                             const vf_similarity *object_from_model)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    if (!f)
        return vf_fail(VF_EINTERNAL, "out of memory writing %s", path);
    fprintf(f, "# Sparse points in the object frame (see normalization.json), COLMAP's layout:\n"
               "#   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n"
               "# IMAGE_ID and POINT2D_IDX as in sparse/images.txt and database.db.\n"
               "# Number of points: %d\n",
            model->point_count);
    for (int i = 0; i < model->point_count; i++)
        write_point(f, &model->points[i], object_from_model);
    fclose(f);
    vf_status status = vf_write_file_atomic(path, text, size);
    free(text);
    return status;
}

static json_t *similarity_json(const vf_similarity *s)
{
    double m[16];
    vf_similarity_to_mat4(s, m);
    json_t *rotation = json_array(), *matrix = json_array();
    for (int r = 0; r < 3; r++)
        json_array_append_new(rotation, vf_json_doubles(s->R + 3 * r, 3));
    for (int r = 0; r < 4; r++)
        json_array_append_new(
            matrix, json_pack("[o,o,o,o]", vf_json_number(m[4 * r]), vf_json_number(m[4 * r + 1]),
                              vf_json_number(m[4 * r + 2]), vf_json_number(m[4 * r + 3])));
    return json_pack("{s:o, s:o, s:o, s:o}", "scale", vf_json_number(s->scale), "rotation",
                     rotation, "translation", vf_json_doubles(s->t, 3), "matrix", matrix);
}

vf_status vf_sfm_save_normalization(const char *path, const vf_normalization *norm)
{
    vf_similarity inverse = vf_similarity_inverse(&norm->object_from_world);
    json_t *doc = json_pack(
        "{s:s, s:o, s:o, s:o, s:s, s:o, s:s, s:o, s:o}", "convention",
        "x_to = scale * rotation * x_from + translation (matrix: the same as a 4x4); the object "
        "frame has z up, the object at the origin and cameras at a mean distance of 4",
        "object_from_colmap", similarity_json(&norm->object_from_world), "colmap_from_object",
        similarity_json(&inverse), "up_colmap", vf_json_doubles(norm->up_world, 3), "up_method",
        norm->up_method, "center_colmap", vf_json_doubles(norm->center_world, 3), "center_method",
        norm->center_method, "colmap_mean_camera_distance", vf_json_number(norm->world_distance),
        "object_mean_camera_distance",
        vf_json_number(norm->world_distance * norm->object_from_world.scale));
    if (!doc)
        return vf_fail(VF_EINTERNAL, "cannot encode %s", path);
    vf_status status = vf_json_save(path, doc);
    json_decref(doc);
    return status;
}

/* Read one similarity of normalization.json, checking that it is one. */
static vf_status read_similarity(const json_t *obj, const char *path, const char *key,
                                 vf_similarity *s)
{
    const json_t *o = json_object_get(obj, key);
    const json_t *rot = json_object_get(o, "rotation"), *t = json_object_get(o, "translation");
    s->scale = json_number_value(json_object_get(o, "scale"));
    int ok = s->scale > 1e-9 && s->scale < 1e9 && json_array_size(rot) == 3 &&
             json_array_size(t) == 3;
    for (int r = 0; ok && r < 3; r++) {
        const json_t *row = json_array_get(rot, (size_t)r);
        s->t[r] = json_number_value(json_array_get(t, (size_t)r));
        ok = json_array_size(row) == 3 && json_is_number(json_array_get(t, (size_t)r)) &&
             fabs(s->t[r]) < 1e9;
        for (int c = 0; ok && c < 3; c++) {
            const json_t *x = json_array_get(row, (size_t)c);
            s->R[3 * r + c] = json_number_value(x);
            ok = json_is_number(x);
        }
    }
    /* a rotation: orthonormal rows (R R^T = I) and det +1 */
    for (int a = 0; ok && a < 3; a++)
        for (int b = 0; ok && b < 3; b++) {
            double dot = 0;
            for (int k = 0; k < 3; k++)
                dot += s->R[3 * a + k] * s->R[3 * b + k];
            ok = fabs(dot - (a == b)) < 1e-6;
        }
    if (ok)
        ok = vf_mat3_det(s->R) > 0;
    if (!ok)
        return vf_fail(VF_EINPUT, "%s: \"%s\" needs a scale (1e-9 to 1e9), a rotation (3x3, "
                       "orthonormal) and a translation (3 numbers)", path, key);
    return VF_OK;
}

vf_status vf_normalization_load(const char *path, vf_similarity *object_from_colmap,
                                vf_similarity *colmap_from_object)
{
    json_t *doc;
    vf_status status = vf_json_load(path, &doc);
    if (status != VF_OK)
        return status;
    vf_similarity fwd, back;
    status = read_similarity(doc, path, "object_from_colmap", &fwd);
    json_decref(doc);
    if (status != VF_OK)
        return status;
    back = vf_similarity_inverse(&fwd);
    if (object_from_colmap)
        *object_from_colmap = fwd;
    if (colmap_from_object)
        *colmap_from_object = back;
    return VF_OK;
}

vf_status vf_normalization_load_workspace(const vf_workspace *ws,
                                          vf_similarity *object_from_colmap,
                                          vf_similarity *colmap_from_object, int *found)
{
    char path[VF_PATH_MAX];
    vf_status status = vf_workspace_path(ws, "poses", VF_NORMALIZATION_FILE, path, sizeof path);
    if (found)
        *found = status == VF_OK && vf_is_file(path);
    if (status != VF_OK || (found && !*found))
        return status;
    if (!vf_is_file(path))
        return vf_fail(VF_EINPUT, "%s is missing: run 'vfcapture poses %s' again", path,
                       ws->root);
    return vf_normalization_load(path, object_from_colmap, colmap_from_object);
}
