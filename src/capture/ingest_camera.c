/* Ingest from a V4L2 webcam: capture for a while, writing every frame (already shrunk) into a
 * scratch folder beside images/ while showing how many usable frames there are, then keep the
 * chosen ones and drop the scratch folder. Frames go to disk, not memory, so the length of a
 * capture is bounded by the disk only. */
#include <stdio.h>
#include <stdlib.h>

#include "ingest_internal.h"
#include "vf/frames.h"
#include "vf/json.h"
#include "vf/log.h"

#define CAPTURE_DIR ".capture"

typedef struct capture_stats {
    double seconds;    /* capture time */
    long dropped;      /* frames the driver numbered but we never saw */
    int width, height; /* size written */
} capture_stats;

/* The capture loop: read, score, write into capture_dir, until time or frame limit. */
static vf_status capture(vf_frames *in, const vf_ingest_options *o, const char *capture_dir,
                         score_list *scores, capture_stats *stats)
{
    const vf_v4l2_info *info = vf_v4l2_get_info(in->camera);
    double fps = info->fps > 0 ? info->fps : 30;
    size_t expected = o->frame_limit > 0 ? (size_t)o->frame_limit : (size_t)(o->seconds * fps);
    vf_rgb8 frame = {0, 0, NULL};
    vf_frame_info frame_info;
    vf_live_counter live = {0};
    vf_progress progress;
    vf_status status = VF_OK;
    uint32_t previous = 0;
    double start = vf_now();
    vf_progress_begin(&progress, "capturing", expected, "frames");
    while (status == VF_OK && vf_now() - start < o->seconds &&
           (o->frame_limit <= 0 || scores->count < o->frame_limit)) {
        vf_frame_score score;
        char name[32], note[64];
        int got; /* a webcam always has a next frame */
        status = vf_frames_next(in, &frame, &frame_info, &got);
        if (status == VF_OK)
            status = vf_score_frame(&frame, &score);
        if (status == VF_OK) {
            snprintf(name, sizeof name, "frame_%06d.jpg", scores->count);
            status = vf__ingest_save_frame(capture_dir, name, &frame, o->max_size, &stats->width,
                                           &stats->height);
        }
        if (status == VF_OK)
            status = vf__score_list_push(scores, &score);
        if (status != VF_OK)
            break;
        uint32_t sequence = (uint32_t)frame_info.index; /* the driver's frame number */
        if (scores->count > 1 && sequence - previous > 1)
            stats->dropped += (long)(sequence - previous - 1);
        previous = sequence;
        vf_live_counter_add(&live, &score, &o->select);
        snprintf(note, sizeof note, "%d usable", live.usable);
        if (progress.total < (size_t)scores->count)
            progress.total = (size_t)scores->count;
        vf_progress_update(&progress, (size_t)scores->count, note);
    }
    vf_progress_end(&progress);
    stats->seconds = vf_now() - start;
    vf_rgb8_free(&frame);
    return status;
}

/* Open (through the frame source, vf/frames.h) and capture; the device is closed again before
 * returning. */
static vf_status record(const char *device, const vf_ingest_options *o, const char *capture_dir,
                        score_list *scores, capture_stats *stats, json_t *report)
{
    vf_v4l2_request request = {o->width, o->height, o->pixel_format, 0};
    vf_frames in;
    vf_status status = vf_frames_open_v4l2(device, o->ops, &request, &in);
    if (status != VF_OK)
        return status;
    const vf_v4l2_info *info = vf_v4l2_get_info(in.camera);
    char fourcc[5];
    vf_fourcc_text(info->pixel_format, fourcc);
    vf_info("%s (%s): %dx%d %s, capturing for %.3g s", device, info->card, info->width,
            info->height, fourcc, o->seconds);
    json_object_set_new(report, "card", json_string(info->card));
    json_object_set_new(report, "driver", json_string(info->driver));
    json_object_set_new(report, "pixel_format", json_string(fourcc));
    json_object_set_new(report, "width", json_integer(info->width));
    json_object_set_new(report, "height", json_integer(info->height));
    json_object_set_new(report, "nominal_fps", vf_json_number(info->fps));
    status = capture(&in, o, capture_dir, scores, stats);
    vf_frames_close(&in);
    return status;
}

/* Move the chosen frames from the scratch folder into images/. */
static vf_status keep_chosen(const char *capture_dir, const char *images_dir,
                             const vf_selection *sel, json_t *files)
{
    for (int k = 0; k < sel->chosen_count; k++) {
        char name[32], from[VF_PATH_MAX], to[VF_PATH_MAX];
        snprintf(name, sizeof name, "frame_%06d.jpg", sel->chosen[k]);
        vf_status status = vf_path_join(from, sizeof from, capture_dir, name);
        if (status == VF_OK)
            status = vf_path_join(to, sizeof to, images_dir, name);
        if (status == VF_OK && rename(from, to) != 0)
            status = vf_fail(VF_EINTERNAL, "cannot move %s into %s", from, images_dir);
        if (status != VF_OK)
            return status;
        json_array_append_new(files, json_string(name));
    }
    return vf_remove_tree(capture_dir);
}

vf_status vf_ingest_camera(const char *device, const vf_ingest_options *options,
                           const char *out_dir, json_t **report_out)
{
    score_list scores = {0};
    vf_selection sel = {0};
    capture_stats stats = {0};
    char capture_dir[VF_PATH_MAX], images_dir[VF_PATH_MAX];
    json_t *report = vf__ingest_report_new("camera", device), *files = json_array();

    vf_status status = vf__ingest_check_options(options);
    if (status == VF_OK && !(options->seconds > 0))
        status =
            vf_fail(VF_EINPUT, "the capture time must be positive, not %g s", options->seconds);
    if (status == VF_OK)
        status = vf_path_join(capture_dir, sizeof capture_dir, out_dir, CAPTURE_DIR);
    if (status == VF_OK)
        status = vf_mkdirs(capture_dir);
    if (status == VF_OK)
        status = record(device, options, capture_dir, &scores, &stats, report);
    if (status == VF_OK && scores.count == 0)
        status = vf_fail(VF_EINPUT, "camera %s gave no frames in %.3g s", device, stats.seconds);
    if (status == VF_OK) {
        json_object_set_new(report, "frame_count", json_integer(scores.count));
        json_object_set_new(report, "seconds", vf_json_number(stats.seconds));
        json_object_set_new(report, "fps", vf_json_number(scores.count / stats.seconds));
        json_object_set_new(report, "dropped", json_integer(stats.dropped));
        status = vf__ingest_select(&scores, &options->select, device, report, &sel);
    }
    if (status == VF_OK)
        status = vf__ingest_make_images_dir(out_dir, images_dir);
    if (status == VF_OK)
        status = keep_chosen(capture_dir, images_dir, &sel, files);
    if (status == VF_OK) {
        status = vf__ingest_finish(report, files, stats.width, stats.height, &scores, &sel,
                                   out_dir, report_out);
        report = files = NULL;
    }
    json_decref(report);
    json_decref(files);
    vf_selection_free(&sel);
    vf__score_list_free(&scores);
    return status;
}
