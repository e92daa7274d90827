/* What the ingest sources share: score lists, frame writing, the common report. */
#define _GNU_SOURCE
#include "ingest_internal.h"

#include <errno.h>
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "vf/json.h"
#include "vf/workspace.h"

void vf_ingest_defaults(vf_ingest_options *options)
{
    memset(options, 0, sizeof *options);
    vf_select_defaults(&options->select);
    options->max_size = 1024;
    options->photo_blur_ratio = 0.2;
    options->seconds = 10;
    options->width = 1280;
    options->height = 720;
}

vf_status vf__ingest_check_options(const vf_ingest_options *options)
{
    if (options->max_size < 16)
        return vf_fail(VF_EINPUT, "the maximum frame size must be at least 16 pixels, not %d",
                       options->max_size);
    return VF_OK;
}

vf_status vf__score_list_push(score_list *list, const vf_frame_score *score)
{
    if (list->count == list->capacity) {
        int capacity = list->capacity ? 2 * list->capacity : 256;
        vf_frame_score *items = realloc(list->items, sizeof *items * (size_t)capacity);
        if (!items)
            return vf_fail(VF_EINTERNAL, "out of memory after %d frames", list->count);
        list->items = items;
        list->capacity = capacity;
    }
    list->items[list->count++] = *score;
    return VF_OK;
}

void vf__score_list_free(score_list *list)
{
    free(list->items);
    memset(list, 0, sizeof *list);
}

/* One field of the report's "source". */
static void source_field(const char *ws_root, const char *key, char *out, size_t size)
{
    char path[VF_PATH_MAX];
    json_t *doc = NULL;
    snprintf(out, size, "%s", "");
    if (vf_path_join(path, sizeof path, ws_root, "ingest/" INGEST_REPORT) != VF_OK ||
        !vf_is_file(path) || vf_json_load(path, &doc) != VF_OK)
        return;
    const char *v = json_string_value(json_object_get(json_object_get(doc, "source"), key));
    snprintf(out, size, "%s", v ? v : "");
    json_decref(doc);
}

void vf_ingest_source_kind(const char *ws_root, char *kind, size_t size)
{
    source_field(ws_root, "kind", kind, size);
}

void vf_ingest_source_path(const char *ws_root, char *path, size_t size)
{
    source_field(ws_root, "path", path, size);
}

json_t *vf__ingest_report_new(const char *kind, const char *path)
{
    char absolute[PATH_MAX];
    if (!realpath(path, absolute))
        snprintf(absolute, sizeof absolute, "%s", path);
    return json_pack("{s:{s:s, s:s}}", "source", "kind", kind, "path", absolute);
}

vf_status vf__ingest_make_images_dir(const char *out_dir, char *images_dir)
{
    vf_status status = vf_path_join(images_dir, VF_PATH_MAX, out_dir, INGEST_IMAGES);
    return status == VF_OK ? vf_mkdirs(images_dir) : status;
}

/* A plain write, without the fsync and rename of vf_write_file_atomic: frames are written
 * inside a staging folder that is swapped in whole only after the stage succeeded, and one
 * syncfs in vf__ingest_finish replaces a sync per frame (which costs ~20 ms each, more than a
 * webcam's frame interval). */
static vf_status write_bytes(const char *path, const unsigned char *bytes, size_t size)
{
    FILE *f = fopen(path, "wb");
    if (!f)
        return vf_fail(VF_EINPUT, "cannot write %s: %s", path, strerror(errno));
    size_t written = fwrite(bytes, 1, size, f);
    int err = written == size ? 0 : errno ? errno : ENOSPC;
    if (fclose(f) != 0 && !err)
        err = errno;
    if (err)
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(err));
    return VF_OK;
}

vf_status vf__ingest_save_frame(const char *images_dir, const char *name, const vf_rgb8 *frame,
                                int max_size, int *width, int *height)
{
    char path[VF_PATH_MAX];
    vf_rgb8 small = {0, 0, NULL};
    unsigned char *jpeg = NULL;
    size_t size = 0;
    vf_status status = vf_path_join(path, sizeof path, images_dir, name);
    if (status == VF_OK)
        status = vf_rgb8_fit(frame, max_size, &small);
    if (status == VF_OK)
        status = vf_rgb8_encode_jpeg(&small, 95, &jpeg, &size);
    if (status == VF_OK)
        status = write_bytes(path, jpeg, size);
    free(jpeg);
    if (status == VF_OK && width)
        *width = small.width;
    if (status == VF_OK && height)
        *height = small.height;
    vf_rgb8_free(&small);
    return status;
}

/* The rejected frames, each with its reason and the numbers behind it. */
static json_t *rejections(const score_list *scores, const vf_selection *sel)
{
    json_t *list = json_array();
    for (int i = 0; i < sel->count; i++) {
        if (sel->verdict[i] == VF_FRAME_BLURRY)
            json_array_append_new(list,
                                  json_pack("{s:i, s:s, s:o, s:o}", "index", i, "reason", "blurry",
                                            "sharpness", vf_json_number(scores->items[i].sharpness),
                                            "local_median", vf_json_number(sel->local_median[i])));
        else if (sel->verdict[i] == VF_FRAME_DUPLICATE)
            json_array_append_new(list,
                                  json_pack("{s:i, s:s, s:i, s:o}", "index", i, "reason",
                                            "duplicate", "of", sel->duplicate_of[i], "difference",
                                            vf_json_number(sel->difference[i])));
    }
    return list;
}

vf_status vf__ingest_select(const score_list *scores, const vf_select_params *params,
                            const char *source, json_t *report, vf_selection *selection)
{
    vf_status status = vf_select_frames(scores->items, scores->count, params, selection);
    if (status != VF_OK)
        return status;
    int blurry = 0, duplicates = 0;
    json_t *chosen = json_array();
    for (int i = 0; i < selection->count; i++) {
        blurry += selection->verdict[i] == VF_FRAME_BLURRY;
        duplicates += selection->verdict[i] == VF_FRAME_DUPLICATE;
    }
    for (int k = 0; k < selection->chosen_count; k++)
        json_array_append_new(chosen, json_integer(selection->chosen[k]));
    json_object_set_new(report, "selection",
                        json_pack("{s:i, s:o, s:i, s:o}", "max_frames", params->max_frames,
                                  "blur_ratio", vf_json_number(params->blur_ratio), "blur_window",
                                  params->blur_window, "duplicate_threshold",
                                  vf_json_number(params->duplicate_threshold)));
    json_object_set_new(report, "kept", json_integer(selection->chosen_count));
    json_object_set_new(report, "blurry", json_integer(blurry));
    json_object_set_new(report, "duplicates", json_integer(duplicates));
    json_object_set_new(report, "chosen", chosen);
    if (selection->chosen_count == 0) {
        vf_selection_free(selection);
        return vf_fail(VF_EINPUT,
                       "no usable frame in %s: all %d were blurry or repeated; capture again, "
                       "moving slowly around the object",
                       source, scores->count);
    }
    return VF_OK;
}

vf_status vf__ingest_finish(json_t *report, json_t *files, int out_width, int out_height,
                            const score_list *scores, const vf_selection *selection,
                            const char *out_dir, json_t **out)
{
    char path[VF_PATH_MAX];
    json_t *sharpness = json_array();
    for (int i = 0; i < scores->count; i++)
        json_array_append_new(sharpness, vf_json_number(scores->items[i].sharpness));
    json_object_set_new(report, "files", files);
    json_object_set_new(report, "output_width", json_integer(out_width));
    json_object_set_new(report, "output_height", json_integer(out_height));
    json_object_set_new(report, "rejected", rejections(scores, selection));
    json_object_set_new(report, "sharpness", sharpness);
    vf_status status = vf_path_join(path, sizeof path, out_dir, INGEST_REPORT);
    int dir = open(out_dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (dir >= 0) { /* the frames written without a sync of their own reach the disk */
        syncfs(dir);
        close(dir);
    }
    if (status == VF_OK)
        status = vf_json_save(path, report);
    if (status == VF_OK && out)
        *out = report;
    else
        json_decref(report);
    return status;
}
