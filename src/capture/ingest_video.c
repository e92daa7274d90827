/* Ingest from a video file: decode once to score every frame, choose, then decode again and
 * write only the chosen frames. Two passes keep memory flat for long videos (frames are never
 * held), at the cost of decoding twice (H.264 1080p decodes at about 100 frames a second). */
#include <stdio.h>

#include "ingest_internal.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/video.h"

/* Score `frame` and every frame after it. */
static vf_status score_frames(vf_video *video, vf_rgb8 *frame, const vf_select_params *params,
                              long expected, score_list *scores)
{
    vf_progress progress;
    vf_live_counter live = {0};
    vf_status status = VF_OK;
    int got = 1;
    vf_progress_begin(&progress, "scoring frames", (size_t)expected, "frames");
    while (status == VF_OK && got) {
        vf_frame_score score;
        status = vf_score_frame(frame, &score);
        if (status == VF_OK)
            status = vf__score_list_push(scores, &score);
        if (status != VF_OK)
            break;
        char note[64];
        vf_live_counter_add(&live, &score, params);
        snprintf(note, sizeof note, "%d usable", live.usable);
        if (progress.total < (size_t)scores->count) /* the container's count was short */
            progress.total = (size_t)scores->count;
        vf_progress_update(&progress, (size_t)scores->count, note);
        status = vf_video_read(video, frame, &got);
    }
    vf_progress_end(&progress);
    return status;
}

/* Pass 1: open the video, describe it and score its frames. */
static vf_status score_video(const char *path, const vf_select_params *params,
                             vf_video_info *info, score_list *scores)
{
    vf_video *video;
    vf_status status = vf_video_open(path, &video, info);
    if (status != VF_OK)
        return status;
    vf_rgb8 frame = {0, 0, NULL};
    int got = 0;
    status = vf_video_read(video, &frame, &got);
    if (status == VF_OK && !got)
        status = vf_fail(VF_EINPUT, "%s has no video frames; record again or give another file",
                         path);
    if (status == VF_OK) {
        vf_info("%s: %s %dx%d, %.4g fps, about %ld frames%s", path, info->codec, info->width,
                info->height, info->fps, info->frame_count,
                info->rotation ? ", stored sideways: turned upright" : "");
        status = score_frames(video, &frame, params, info->frame_count, scores);
    }
    vf_rgb8_free(&frame);
    vf_video_close(video);
    return status;
}

/* Pass 2: decode again, writing the chosen frames as images/frame_NNNNNN.jpg. */
static vf_status write_chosen(const char *path, const vf_selection *sel, int max_size,
                              const char *images_dir, json_t *files, int *width, int *height)
{
    vf_video *video;
    vf_video_info info;
    vf_status status = vf_video_open(path, &video, &info);
    if (status != VF_OK)
        return status;
    vf_rgb8 frame = {0, 0, NULL};
    vf_progress progress;
    vf_progress_begin(&progress, "writing frames", (size_t)sel->chosen_count, "frames");
    int next = 0; /* the next chosen frame to write */
    for (int i = 0; status == VF_OK && next < sel->chosen_count; i++) {
        int got = 0, chosen = i == sel->chosen[next];
        status = chosen ? vf_video_read(video, &frame, &got) : vf_video_skip(video, &got);
        if (status == VF_OK && !got)
            status = vf_fail(VF_EINTERNAL, "%s ended after %d frames when read again (%d before)",
                             path, i, sel->count);
        if (status != VF_OK || !chosen)
            continue;
        char name[32];
        snprintf(name, sizeof name, "frame_%06d.jpg", i);
        status = vf__ingest_save_frame(images_dir, name, &frame, max_size, next ? NULL : width,
                                       next ? NULL : height);
        json_array_append_new(files, json_string(name));
        vf_progress_update(&progress, (size_t)++next, NULL);
    }
    vf_progress_end(&progress);
    vf_rgb8_free(&frame);
    vf_video_close(video);
    return status;
}

static void describe_video(json_t *report, const vf_video_info *info, int frames)
{
    json_object_set_new(report, "codec", json_string(info->codec));
    json_object_set_new(report, "fps", vf_json_number(info->fps));
    json_object_set_new(report, "frame_count", json_integer(frames));
    json_object_set_new(report, "container_frame_count", json_integer(info->frame_count));
    json_object_set_new(report, "duration_s",
                        vf_json_number(info->fps > 0 ? frames / info->fps : 0));
    json_object_set_new(report, "width", json_integer(info->width));
    json_object_set_new(report, "height", json_integer(info->height));
    json_object_set_new(report, "rotation",
                        json_pack("{s:i, s:i, s:i, s:b}", "clockwise_degrees", info->rotation,
                                  "coded_width", info->coded_width, "coded_height",
                                  info->coded_height, "applied", info->rotation != 0));
}

vf_status vf_ingest_video(const char *path, const vf_ingest_options *options, const char *out_dir,
                          json_t **report_out)
{
    score_list scores = {0};
    vf_selection sel = {0};
    vf_video_info info;
    char images_dir[VF_PATH_MAX];
    int width = 0, height = 0;
    json_t *report = NULL, *files = json_array();

    vf_status status = vf__ingest_check_options(options);
    if (status == VF_OK)
        status = score_video(path, &options->select, &info, &scores);
    if (status == VF_OK) {
        report = vf__ingest_report_new("video", path);
        describe_video(report, &info, scores.count);
        status = vf__ingest_select(&scores, &options->select, path, report, &sel);
    }
    if (status == VF_OK)
        status = vf__ingest_make_images_dir(out_dir, images_dir);
    if (status == VF_OK)
        status = write_chosen(path, &sel, options->max_size, images_dir, files, &width, &height);
    if (status == VF_OK) {
        status =
            vf__ingest_finish(report, files, width, height, &scores, &sel, out_dir, report_out);
        report = files = NULL;
    }
    json_decref(report);
    json_decref(files);
    vf_selection_free(&sel);
    vf__score_list_free(&scores);
    return status;
}
