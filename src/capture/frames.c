/* The one frame source: image files, videos, folders, or a webcam (vf/frames.h). */
#define _GNU_SOURCE
#include "vf/frames.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int vf_is_video_name(const char *path)
{
    static const char *const exts[] = {"mp4", "mov", "m4v", "mkv", "avi", "webm",
                                       "mpg", "mpeg", "3gp", "mts", "m2ts", NULL};
    return vf_path_has_extension(path, exts);
}

static int is_frames_name(const char *name)
{
    return vf_is_image_name(name) || vf_is_video_name(name);
}

static vf_status add_file(vf_frames *in, const char *path)
{
    char **files = realloc(in->files, sizeof *files * (size_t)(in->count + 1));
    if (!files)
        return vf_fail(VF_EINTERNAL, "out of memory");
    in->files = files;
    if (!(in->files[in->count] = strdup(path)))
        return vf_fail(VF_EINTERNAL, "out of memory");
    in->count++;
    return VF_OK;
}

/* A folder's images and videos, in name order. */
static vf_status add_folder(vf_frames *in, const char *folder)
{
    char **names;
    int count;
    vf_status status = vf_list_folder(folder, is_frames_name, &names, &count);
    if (status == VF_OK && count == 0)
        status = vf_fail(VF_EINPUT, "folder %s holds no images or videos", folder);
    for (int i = 0; status == VF_OK && i < count; i++) {
        char path[VF_PATH_MAX];
        status = vf_path_join(path, sizeof path, folder, names[i]);
        if (status == VF_OK)
            status = add_file(in, path);
    }
    vf_free_names(names, count);
    return status;
}

vf_status vf_frames_open(char *const *args, int count, vf_frames *in)
{
    memset(in, 0, sizeof *in);
    vf_status status = count > 0 ? VF_OK : vf_fail(VF_EINPUT, "give images, videos or folders");
    for (int i = 0; status == VF_OK && i < count; i++) {
        if (vf_is_dir(args[i]))
            status = add_folder(in, args[i]);
        else if (!vf_is_file(args[i]))
            status = vf_fail(VF_EINPUT, "%s does not exist", args[i]);
        else if (is_frames_name(args[i]))
            status = add_file(in, args[i]);
        else
            status = vf_fail(VF_EINPUT, "%s is neither an image (.jpg, .png) nor a video (.mp4, "
                                        ".mov, .mkv, ...)",
                             args[i]);
    }
    if (status != VF_OK)
        vf_frames_close(in);
    return status;
}

vf_status vf_frames_open_v4l2(const char *device, const vf_v4l2_ops *ops,
                              const vf_v4l2_request *request, vf_frames *in)
{
    static const vf_v4l2_request hd = {1280, 720, 0, 0};
    memset(in, 0, sizeof *in);
    snprintf(in->device, sizeof in->device, "%s", device);
    vf_status status = vf_v4l2_open(device, ops, request ? request : &hd, &in->camera);
    if (status == VF_OK)
        status = vf_v4l2_start(in->camera);
    if (status != VF_OK)
        vf_frames_close(in);
    return status;
}

void vf_frames_open_source(const vf_frame_source *source, vf_frames *in)
{
    memset(in, 0, sizeof *in);
    snprintf(in->device, sizeof in->device, "%s", source->name ? source->name : "camera");
    in->source = source;
}

/* The next frame of the video being read that is handed out (*got = 0 at its end or after
 * max_video_frames of it): the frames before it are skipped without decoding. */
static vf_status read_video(vf_frames *in, vf_rgb8 *frame, int *got)
{
    *got = 0;
    if (in->max_video_frames > 0 && in->video_given >= in->max_video_frames)
        return VF_OK;
    int more = 1;
    vf_status status = VF_OK;
    while (status == VF_OK && more && in->video_frame + 1 < in->video_given * in->video_stride) {
        status = vf_video_skip(in->video, &more);
        in->video_frame++;
    }
    if (status != VF_OK || !more)
        return status;
    status = vf_video_read(in->video, frame, got);
    if (status == VF_OK && *got)
        in->video_frame++, in->video_given++;
    return status;
}

static vf_status open_video(vf_frames *in, const char *path)
{
    vf_status status = vf_video_open(path, &in->video, &in->video_info);
    if (status != VF_OK)
        return status;
    snprintf(in->video_path, sizeof in->video_path, "%s", path);
    long count = in->video_info.frame_count, most = in->max_video_frames;
    in->video_stride = most > 0 && count > most ? count / most : 1;
    in->video_frame = -1;
    in->video_given = 0;
    return VF_OK;
}

/* The name of a frame: "WHERE#N", or "WHERE" for a photo (index -1). */
static void describe(vf_frame_info *info, const char *where, long index)
{
    snprintf(info->source, sizeof info->source, "%s", where);
    if (index >= 0)
        snprintf(info->name, sizeof info->name, "%s#%ld", where, index);
    else
        snprintf(info->name, sizeof info->name, "%s", where);
    info->index = index;
}

vf_status vf_frames_next(vf_frames *in, vf_rgb8 *frame, vf_frame_info *info, int *got)
{
    *got = 0;
    if (in->source) {
        vf_status status = in->source->next(in->source->ctx, frame, got);
        if (status == VF_OK && *got)
            describe(info, in->device, in->source_given++);
        return status;
    }
    if (in->camera) {
        uint32_t sequence = 0;
        vf_status status = vf_v4l2_read(in->camera, VF_CAMERA_TIMEOUT_MS, frame, &sequence);
        if (status != VF_OK)
            return status;
        describe(info, in->device, (long)sequence);
        *got = 1;
        return VF_OK;
    }
    for (;;) {
        if (in->video) {
            vf_status status = read_video(in, frame, got);
            if (status != VF_OK)
                return status;
            if (*got) {
                describe(info, in->video_path, in->video_frame);
                return VF_OK;
            }
            vf_video_close(in->video);
            in->video = NULL;
        }
        if (in->next >= in->count)
            return VF_OK;
        const char *path = in->files[in->next++];
        vf_status status =
            vf_is_video_name(path) ? open_video(in, path) : vf_rgb8_load(path, frame);
        if (status != VF_OK)
            return status;
        if (!in->video) {
            describe(info, path, -1);
            *got = 1;
            return VF_OK;
        }
    }
}

void vf_frames_close(vf_frames *in)
{
    for (int i = 0; i < in->count; i++)
        free(in->files[i]);
    free(in->files);
    vf_video_close(in->video);
    vf_v4l2_close(in->camera);
    memset(in, 0, sizeof *in);
}
