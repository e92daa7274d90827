/* Ingest from a folder of photos: score them all (in parallel), choose, write the chosen ones.
 * Photos with an alpha channel (background removed) keep it: they are written as PNG, so that
 * training later knows where the object ends; the others are written as JPEG. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "ingest_internal.h"
#include "vf/image.h"
#include "vf/log.h"

typedef struct photo_list {
    char **names;          /* file names in the folder, sorted */
    unsigned char *alpha;  /* per photo: 1 when it has an alpha channel */
    int count;
} photo_list;

static void photo_list_free(photo_list *list)
{
    vf_free_names(list->names, list->count);
    free(list->alpha);
    memset(list, 0, sizeof *list);
}

static vf_status list_photos(const char *folder, photo_list *list)
{
    vf_status status = vf_list_images(folder, &list->names, &list->count);
    if (status == VF_OK && list->count > 0 && !(list->alpha = calloc((size_t)list->count, 1)))
        status = vf_fail(VF_EINTERNAL, "out of memory listing %s", folder);
    if (status == VF_OK && list->count == 0)
        status = vf_fail(VF_EINPUT,
                         "folder %s has no JPEG or PNG photos; give a folder of photos or a "
                         "video file",
                         folder);
    return status;
}

/* Load and score every photo, in parallel; sizes gets width, height of each, list->alpha
 * whether it has an alpha channel. */
static vf_status score_photos(const char *folder, photo_list *list, score_list *scores,
                              int *sizes)
{
    vf_first_error error = {0};
    int done = 0;
    vf_progress progress;
    vf_progress_begin(&progress, "scoring photos", (size_t)list->count, "photos");
#pragma omp parallel for schedule(dynamic)
    for (int i = 0; i < list->count; i++) {
        char path[VF_PATH_MAX];
        vf_rgb8 photo = {0, 0, NULL};
        int width, height, channels;
        vf_status s = vf_path_join(path, sizeof path, folder, list->names[i]);
        if (s == VF_OK)
            s = vf_image_info(path, &width, &height, &channels);
        if (s == VF_OK)
            list->alpha[i] = channels == 2 || channels == 4;
        if (s == VF_OK)
            s = vf_rgb8_load(path, &photo);
        if (s == VF_OK) {
            s = vf_score_frame(&photo, &scores->items[i]);
            sizes[2 * i] = photo.width;
            sizes[2 * i + 1] = photo.height;
        }
        vf_rgb8_free(&photo);
        vf_first_error_keep(&error, s);
#pragma omp critical
        vf_progress_update(&progress, (size_t)++done, NULL);
    }
    vf_progress_end(&progress);
    return vf_first_error_raise(&error);
}

/* The name a photo is written under: its index (unique even if names repeat) and stem. */
static void output_name(const photo_list *list, int index, char *out, size_t size)
{
    char stem[VF_PATH_MAX];
    vf_path_basename(stem, sizeof stem, list->names[index], 1);
    snprintf(out, size, "%04d_%.200s.%s", index, stem, list->alpha[index] ? "png" : "jpg");
}

/* Write a photo with its alpha channel as PNG, shrunk as vf__ingest_save_frame shrinks. */
static vf_status save_with_alpha(const char *path, const char *images_dir, const char *name,
                                 int max_size, int *width, int *height)
{
    vf_image photo = {0}, small = {0};
    char out[VF_PATH_MAX];
    vf_status status = vf_image_load(path, &photo);
    if (status == VF_OK)
        status = vf_path_join(out, sizeof out, images_dir, name);
    if (status == VF_OK) {
        int longer = photo.width > photo.height ? photo.width : photo.height;
        double scale = longer > max_size ? (double)max_size / longer : 1.0;
        int w = (int)lround(photo.width * scale), h = (int)lround(photo.height * scale);
        status = vf_image_resize(&photo, w > 0 ? w : 1, h > 0 ? h : 1, &small);
    }
    if (status == VF_OK)
        status = vf_image_save(out, &small);
    if (status == VF_OK && width)
        *width = small.width, *height = small.height;
    vf_image_free(&photo);
    vf_image_free(&small);
    return status;
}

/* Load, shrink and write the chosen photos, in parallel. */
static vf_status write_photos(const char *folder, const photo_list *list, const vf_selection *sel,
                              int max_size, const char *images_dir, int *width, int *height)
{
    vf_first_error error = {0};
#pragma omp parallel for schedule(dynamic)
    for (int k = 0; k < sel->chosen_count; k++) {
        int i = sel->chosen[k];
        char path[VF_PATH_MAX], name[256];
        vf_rgb8 photo = {0, 0, NULL};
        output_name(list, i, name, sizeof name);
        vf_status s = vf_path_join(path, sizeof path, folder, list->names[i]);
        if (s == VF_OK && list->alpha[i])
            s = save_with_alpha(path, images_dir, name, max_size, k ? NULL : width,
                                k ? NULL : height);
        else if (s == VF_OK && (s = vf_rgb8_load(path, &photo)) == VF_OK)
            s = vf__ingest_save_frame(images_dir, name, &photo, max_size, k ? NULL : width,
                                      k ? NULL : height);
        vf_rgb8_free(&photo);
        vf_first_error_keep(&error, s);
    }
    return vf_first_error_raise(&error);
}

/* Photo names and sizes, and how many are portrait or landscape (warning when mixed: later
 * stages cope, but a phone turned halfway through a capture is worth knowing about). */
static void describe_photos(json_t *report, const char *folder, const photo_list *list,
                            const int *sizes)
{
    int portrait = 0, landscape = 0;
    json_t *names = json_array();
    for (int i = 0; i < list->count; i++) {
        portrait += sizes[2 * i + 1] > sizes[2 * i];
        landscape += sizes[2 * i] > sizes[2 * i + 1];
        json_array_append_new(names, json_string(list->names[i]));
    }
    int mixed = portrait > 0 && landscape > 0;
    if (mixed)
        vf_warn("%s mixes %d portrait and %d landscape photos; they are kept as they are",
                folder, portrait, landscape);
    json_object_set_new(report, "frame_count", json_integer(list->count));
    json_object_set_new(report, "width", json_integer(sizes[0]));
    json_object_set_new(report, "height", json_integer(sizes[1]));
    json_object_set_new(report, "orientation",
                        json_pack("{s:i, s:i, s:i, s:b}", "portrait", portrait, "landscape",
                                  landscape, "square", list->count - portrait - landscape,
                                  "mixed", mixed));
    json_object_set_new(report, "photos", names);
}

vf_status vf_ingest_photos(const char *folder, const vf_ingest_options *options,
                           const char *out_dir, json_t **report_out)
{
    photo_list list;
    score_list scores = {0};
    vf_selection sel = {0};
    char images_dir[VF_PATH_MAX];
    int width = 0, height = 0, *sizes = NULL;
    json_t *report = NULL, *files = NULL;

    vf_status status = vf__ingest_check_options(options);
    if (status == VF_OK)
        status = list_photos(folder, &list);
    if (status != VF_OK)
        return status;
    scores.items = calloc((size_t)list.count, sizeof *scores.items);
    scores.count = scores.capacity = list.count;
    sizes = calloc((size_t)list.count * 2, sizeof *sizes);
    if (!scores.items || !sizes)
        status = vf_fail(VF_EINTERNAL, "out of memory for %d photos", list.count);
    if (status == VF_OK)
        status = score_photos(folder, &list, &scores, sizes);
    if (status == VF_OK) {
        vf_info("%s: %d photos", folder, list.count);
        report = vf__ingest_report_new("photos", folder);
        describe_photos(report, folder, &list, sizes);
        vf_select_params select = options->select;
        select.unordered = 1;
        select.blur_ratio = options->photo_blur_ratio;
        status = vf__ingest_select(&scores, &select, folder, report, &sel);
    }
    if (status == VF_OK)
        status = vf__ingest_make_images_dir(out_dir, images_dir);
    if (status == VF_OK)
        status = write_photos(folder, &list, &sel, options->max_size, images_dir, &width, &height);
    if (status == VF_OK) {
        files = json_array();
        for (int k = 0; k < sel.chosen_count; k++) {
            char name[256];
            output_name(&list, sel.chosen[k], name, sizeof name);
            json_array_append_new(files, json_string(name));
        }
        status =
            vf__ingest_finish(report, files, width, height, &scores, &sel, out_dir, report_out);
        report = NULL;
    }
    json_decref(report);
    vf_selection_free(&sel);
    vf__score_list_free(&scores);
    free(sizes);
    photo_list_free(&list);
    return status;
}
