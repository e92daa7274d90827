/* Finding the board in a folder of photos, a video or a webcam's stream (vf/calib.h). */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/calib.h"
#include "vf/log.h"
#include "vf/video.h"

#define CAMERA_TIMEOUT_MS 5000 /* a camera that sends nothing for this long has stopped */

/* The image file names in a folder, sorted; the caller frees them with vf_free_names. */
static vf_status list_images(const char *folder, char ***names, int *count)
{
    vf_status status = vf_list_images(folder, names, count);
    if (status == VF_OK && *count == 0)
        status = vf_fail(VF_EINPUT, "folder %s has no .jpg or .png images of the board", folder);
    return status;
}

/* What searching one photo gave. */
typedef struct photo_result {
    vf_status status;
    int found, width, height;
    double quad[8];
    char message[256];
} photo_result;

static void search_photo(const char *folder, const char *name, const vf_calib_board *board,
                         double *uv, photo_result *r)
{
    char path[VF_PATH_MAX];
    vf_rgb8 img = {0};
    r->status = vf_path_join(path, sizeof path, folder, name);
    if (r->status == VF_OK)
        r->status = vf_rgb8_load(path, &img);
    if (r->status == VF_OK) {
        r->width = img.width, r->height = img.height;
        r->status = vf_calib_find_board(&img, board, uv, r->quad, &r->found);
    }
    if (r->status != VF_OK) /* the message is per thread: keep it for the caller */
        snprintf(r->message, sizeof r->message, "%s", vf_error_message());
    vf_rgb8_free(&img);
}

vf_status vf_calib_collect_folder(const char *folder, const vf_calib_board *board,
                                  vf_calib_views *out)
{
    char **names;
    int count;
    vf_status status = list_images(folder, &names, &count);
    if (status != VF_OK)
        return status;
    int corners = vf_calib_board_corners(board);
    double *uv = malloc((size_t)count * corners * 2 * sizeof *uv);
    photo_result *results = calloc((size_t)count, sizeof *results);
    if (!uv || !results)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    vf_progress progress;
    int done = 0;
    vf_progress_begin(&progress, "searching for the board", (size_t)count, "photos");
#pragma omp parallel for schedule(dynamic)
    for (int i = 0; i < (status == VF_OK ? count : 0); i++) {
        search_photo(folder, names[i], board, uv + (size_t)i * corners * 2, &results[i]);
#pragma omp critical
        vf_progress_update(&progress, (size_t)++done, NULL);
    }
    vf_progress_end(&progress);
    for (int i = 0; status == VF_OK && i < count; i++) {
        out->frames_seen++;
        if (results[i].status != VF_OK)
            status = vf_fail(results[i].status, "%s", results[i].message);
        else if (results[i].found)
            status = vf_calib_views_add(out, results[i].width, results[i].height, names[i],
                                        uv + (size_t)i * corners * 2, results[i].quad, corners);
    }
    vf_free_names(names, count);
    free(uv);
    free(results);
    return status;
}

vf_status vf_calib_collect_video(const char *path, const vf_calib_board *board, int max_frames,
                                 vf_calib_views *out)
{
    vf_video *video;
    vf_video_info info;
    vf_status status = vf_video_open(path, &video, &info);
    if (status != VF_OK)
        return status;
    int corners = vf_calib_board_corners(board);
    double *uv = malloc((size_t)corners * 2 * sizeof *uv);
    long step = info.frame_count > max_frames ? info.frame_count / max_frames : 1;
    vf_rgb8 frame = {0};
    vf_progress progress;
    vf_progress_begin(&progress, "searching for the board", (size_t)(info.frame_count / step),
                      "frames");
    if (!uv)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    for (long index = 0; status == VF_OK && out->frames_seen < max_frames; index++) {
        int got, found;
        double quad[8];
        if (index % step) {
            status = vf_video_skip(video, &got);
            if (!got)
                break;
            continue;
        }
        if ((status = vf_video_read(video, &frame, &got)) != VF_OK || !got)
            break;
        out->frames_seen++;
        status = vf_calib_find_board(&frame, board, uv, quad, &found);
        if (status == VF_OK && found) {
            char name[64];
            snprintf(name, sizeof name, "frame %ld", index);
            status = vf_calib_views_add(out, frame.width, frame.height, name, uv, quad, corners);
        }
        char note[48];
        snprintf(note, sizeof note, "%d boards", out->count);
        vf_progress_update(&progress, (size_t)out->frames_seen, note);
    }
    vf_progress_end(&progress);
    if (status == VF_OK && out->frames_seen == 0)
        status = vf_fail(VF_EINPUT, "%s has no frames", path);
    vf_rgb8_free(&frame);
    free(uv);
    vf_video_close(video);
    return status;
}

vf_status vf_calib_collect_camera(const char *device, const vf_v4l2_ops *ops,
                                  const vf_calib_board *board, double seconds,
                                  vf_calib_views *out)
{
    vf_v4l2_request request = {1280, 720, 0, 0};
    vf_v4l2 *cam;
    vf_status status = vf_v4l2_open(device, ops, &request, &cam);
    if (status != VF_OK)
        return status;
    const vf_v4l2_info *info = vf_v4l2_get_info(cam);
    vf_info("%s (%s): %dx%d; move the board around the view for %.0f s", device, info->card,
            info->width, info->height, seconds);
    int corners = vf_calib_board_corners(board);
    double *uv = malloc((size_t)corners * 2 * sizeof *uv);
    vf_rgb8 frame = {0};
    vf_progress progress;
    status = uv ? vf_v4l2_start(cam) : vf_fail(VF_EINTERNAL, "out of memory");
    double start = vf_now();
    vf_progress_begin(&progress, "capturing", (size_t)(seconds * 1000), "ms");
    /* the search is slower than the camera: the driver drops what arrives meanwhile */
    while (status == VF_OK && vf_now() - start < seconds) {
        uint32_t sequence;
        int found;
        double quad[8];
        status = vf_v4l2_read(cam, CAMERA_TIMEOUT_MS, &frame, &sequence);
        if (status == VF_OK)
            status = vf_calib_find_board(&frame, board, uv, quad, &found);
        out->frames_seen++;
        if (status == VF_OK && found) {
            char name[64];
            snprintf(name, sizeof name, "frame %u", (unsigned)sequence);
            status = vf_calib_views_add(out, frame.width, frame.height, name, uv, quad, corners);
        }
        char note[48];
        snprintf(note, sizeof note, "%d boards", out->count);
        vf_progress_update(&progress, (size_t)((vf_now() - start) * 1000), note);
    }
    vf_progress_end(&progress);
    vf_rgb8_free(&frame);
    free(uv);
    vf_v4l2_close(cam);
    return status;
}
