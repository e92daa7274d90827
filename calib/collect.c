/* Finding the board in a folder of photos, a video or a webcam's stream (vf/calib.h). Videos
 * and webcams are read through the one frame source (vf/frames.h); a folder's photos are
 * listed the same way and searched in parallel. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/calib.h"
#include "vf/frames.h"
#include "vf/log.h"

/* Where the board is in one photo. */
typedef struct photo_board {
    int found, width, height;
    double quad[8];
} photo_board;

static vf_status search_photo(const char *folder, const char *name, const vf_calib_board *board,
                              double *uv, photo_board *r)
{
    char path[VF_PATH_MAX];
    vf_rgb8 img = {0};
    vf_status status = vf_path_join(path, sizeof path, folder, name);
    if (status == VF_OK)
        status = vf_rgb8_load(path, &img);
    if (status == VF_OK) {
        r->width = img.width, r->height = img.height;
        status = vf_calib_find_board(&img, board, uv, r->quad, &r->found);
    }
    vf_rgb8_free(&img);
    return status;
}

vf_status vf_calib_collect_folder(const char *folder, const vf_calib_board *board,
                                  vf_calib_views *out)
{
    char **names;
    int count;
    vf_status status = vf_list_images(folder, &names, &count);
    if (status == VF_OK && count == 0)
        status = vf_fail(VF_EINPUT, "folder %s has no .jpg or .png images of the board", folder);
    if (status != VF_OK)
        return status;
    int corners = vf_calib_board_corners(board);
    double *uv = malloc((size_t)count * corners * 2 * sizeof *uv);
    photo_board *photos = calloc((size_t)count, sizeof *photos);
    if (!uv || !photos)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    vf_first_error first = {0};
    vf_progress progress;
    int done = 0;
    vf_progress_begin(&progress, "searching for the board", (size_t)count, "photos");
#pragma omp parallel for schedule(dynamic)
    for (int i = 0; i < (status == VF_OK ? count : 0); i++) {
        vf_first_error_keep(&first, search_photo(folder, names[i], board,
                                                 uv + (size_t)i * corners * 2, &photos[i]));
#pragma omp critical
        vf_progress_update(&progress, (size_t)++done, NULL);
    }
    vf_progress_end(&progress);
    if (status == VF_OK)
        status = vf_first_error_raise(&first);
    for (int i = 0; status == VF_OK && i < count; i++) {
        out->frames_seen++;
        if (photos[i].found)
            status = vf_calib_views_add(out, photos[i].width, photos[i].height, names[i],
                                        uv + (size_t)i * corners * 2, photos[i].quad, corners);
    }
    vf_free_names(names, count);
    free(uv);
    free(photos);
    return status;
}

/* Search every frame `in` hands out for the board, until it ends or `seconds` have passed
 * (HUGE_VAL: no limit). Views are named "frame N" after the frame's number in its video or stream.
 * Progress: a webcam's in milliseconds (expected: all of them), a video's in frames (expected:
 * at most max_video_frames, fewer when the video is shorter). */
static vf_status collect_frames(vf_frames *in, const vf_calib_board *board, double seconds,
                                size_t expected, vf_calib_views *out)
{
    int corners = vf_calib_board_corners(board);
    double *uv = malloc((size_t)corners * 2 * sizeof *uv);
    vf_rgb8 frame = {0};
    vf_frame_info info;
    vf_progress progress;
    vf_status status = uv ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    double start = vf_now();
    vf_progress_begin(&progress, in->camera ? "capturing" : "searching for the board", expected,
                      in->camera ? "ms" : "frames");
    /* the search is slower than a webcam: the driver drops what arrives meanwhile */
    while (status == VF_OK && vf_now() - start < seconds) {
        int got, found;
        double quad[8];
        if ((status = vf_frames_next(in, &frame, &info, &got)) != VF_OK || !got)
            break;
        out->frames_seen++;
        status = vf_calib_find_board(&frame, board, uv, quad, &found);
        if (status == VF_OK && found) {
            char name[64];
            snprintf(name, sizeof name, "frame %ld", info.index);
            status = vf_calib_views_add(out, frame.width, frame.height, name, uv, quad, corners);
        }
        char note[48];
        snprintf(note, sizeof note, "%d boards", out->count);
        long length = in->video ? in->video_info.frame_count : 0; /* known once it is open */
        if (length > 0 && length < in->max_video_frames)
            progress.total = (size_t)length;
        vf_progress_update(&progress, in->camera ? (size_t)((vf_now() - start) * 1000)
                                                 : (size_t)out->frames_seen,
                           note);
    }
    vf_progress_end(&progress);
    vf_rgb8_free(&frame);
    free(uv);
    return status;
}

vf_status vf_calib_collect_video(const char *path, const vf_calib_board *board, int max_frames,
                                 vf_calib_views *out)
{
    vf_frames in;
    char *arg = (char *)path;
    vf_status status = vf_frames_open(&arg, 1, &in);
    if (status != VF_OK)
        return status;
    in.max_video_frames = max_frames;
    status = collect_frames(&in, board, HUGE_VAL, (size_t)max_frames, out);
    if (status == VF_OK && out->frames_seen == 0)
        status = vf_fail(VF_EINPUT, "%s has no frames", path);
    vf_frames_close(&in);
    return status;
}

vf_status vf_calib_collect_camera(const char *device, const vf_v4l2_ops *ops,
                                  const vf_calib_board *board, double seconds,
                                  vf_calib_views *out)
{
    vf_frames in;
    vf_status status = vf_frames_open_v4l2(device, ops, NULL, &in);
    if (status != VF_OK)
        return status;
    const vf_v4l2_info *info = vf_v4l2_get_info(in.camera);
    vf_info("%s (%s): %dx%d; move the board around the view for %.0f s", device, info->card,
            info->width, info->height, seconds);
    status = collect_frames(&in, board, seconds, (size_t)(seconds * 1000), out);
    vf_frames_close(&in);
    return status;
}
