/* The poses stage's outputs from a COLMAP model: frames, points, and the normalization. */
#define _GNU_SOURCE
#include "vf/sfm_export.h"

#include <jansson.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
        json_array_append_new(matrix, json_pack("[f,f,f,f]", m[4 * r], m[4 * r + 1],
                                                m[4 * r + 2], m[4 * r + 3]));
    return json_pack("{s:f, s:o, s:o, s:o}", "scale", s->scale, "rotation", rotation,
                     "translation", vf_json_doubles(s->t, 3), "matrix", matrix);
}

vf_status vf_sfm_save_normalization(const char *path, const vf_normalization *norm)
{
    vf_similarity inverse = vf_similarity_inverse(&norm->object_from_world);
    json_t *doc = json_pack(
        "{s:s, s:o, s:o, s:o, s:s, s:o, s:s, s:f, s:f}", "convention",
        "x_to = scale * rotation * x_from + translation (matrix: the same as a 4x4); the object "
        "frame has z up, the object at the origin and cameras at a mean distance of 4",
        "object_from_colmap", similarity_json(&norm->object_from_world), "colmap_from_object",
        similarity_json(&inverse), "up_colmap", vf_json_doubles(norm->up_world, 3), "up_method",
        norm->up_method, "center_colmap", vf_json_doubles(norm->center_world, 3), "center_method",
        norm->center_method, "colmap_mean_camera_distance", norm->world_distance,
        "object_mean_camera_distance", norm->world_distance * norm->object_from_world.scale);
    if (!doc)
        return vf_fail(VF_EINTERNAL, "cannot encode %s", path);
    vf_status status = vf_json_save(path, doc);
    json_decref(doc);
    return status;
}
