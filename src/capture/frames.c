/* The frames the physical loop reads: image files, videos, folders, or a webcam (vf/frames.h). */
#define _GNU_SOURCE
#include "vf/frames.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#define WEBCAM_TIMEOUT_MS 2000

static int has_extension(const char *path, const char *const *exts)
{
    const char *dot = strrchr(path, '.');
    if (!dot || strchr(dot, '/'))
        return 0;
    for (; *exts; exts++)
        if (!strcasecmp(dot + 1, *exts))
            return 1;
    return 0;
}

int vf_is_video_name(const char *path)
{
    static const char *const exts[] = {"mp4", "mov", "m4v", "mkv", "avi", "webm", "mpg", NULL};
    return has_extension(path, exts);
}

static int is_image_name(const char *path)
{
    static const char *const exts[] = {"jpg", "jpeg", "png", NULL};
    return has_extension(path, exts);
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

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* A folder's images and videos, in name order. */
static vf_status add_folder(vf_frames *in, const char *folder)
{
    DIR *dir = opendir(folder);
    if (!dir)
        return vf_fail(VF_EINPUT, "cannot open folder %s", folder);
    int first = in->count;
    struct dirent *e;
    vf_status status = VF_OK;
    while (status == VF_OK && (e = readdir(dir))) {
        if (e->d_name[0] == '.' || !(is_image_name(e->d_name) || vf_is_video_name(e->d_name)))
            continue;
        char path[VF_PATH_MAX];
        status = vf_path_join(path, sizeof path, folder, e->d_name);
        if (status == VF_OK)
            status = add_file(in, path);
    }
    closedir(dir);
    if (status == VF_OK && in->count == first)
        status = vf_fail(VF_EINPUT, "folder %s holds no images or videos", folder);
    if (status == VF_OK)
        qsort(in->files + first, (size_t)(in->count - first), sizeof *in->files, compare_names);
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
        else if (is_image_name(args[i]) || vf_is_video_name(args[i]))
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

vf_status vf_frames_open_v4l2(const char *device, vf_frames *in)
{
    memset(in, 0, sizeof *in);
    vf_v4l2_request request = {1280, 720, 0, 0};
    snprintf(in->device, sizeof in->device, "%s", device);
    vf_status status = vf_v4l2_open(device, NULL, &request, &in->camera);
    if (status == VF_OK)
        status = vf_v4l2_start(in->camera);
    if (status != VF_OK)
        vf_frames_close(in);
    return status;
}

vf_status vf_frames_next(vf_frames *in, vf_rgb8 *frame, vf_frame_info *info, int *got)
{
    *got = 0;
    if (in->camera) {
        uint32_t sequence = 0;
        vf_status status = vf_v4l2_read(in->camera, WEBCAM_TIMEOUT_MS, frame, &sequence);
        if (status != VF_OK)
            return status;
        snprintf(info->source, sizeof info->source, "%s", in->device);
        snprintf(info->name, sizeof info->name, "%s#%u", in->device, sequence);
        info->index = sequence;
        *got = 1;
        return VF_OK;
    }
    for (;;) {
        if (in->video) {
            vf_status status = vf_video_read(in->video, frame, got);
            if (status != VF_OK)
                return status;
            if (*got) {
                in->video_frame++;
                snprintf(info->source, sizeof info->source, "%s", in->video_path);
                snprintf(info->name, sizeof info->name, "%s#%ld", in->video_path, in->video_frame);
                info->index = in->video_frame;
                return VF_OK;
            }
            vf_video_close(in->video);
            in->video = NULL;
        }
        if (in->next >= in->count)
            return VF_OK;
        const char *path = in->files[in->next++];
        if (vf_is_video_name(path)) {
            vf_video_info vi;
            vf_status status = vf_video_open(path, &in->video, &vi);
            if (status != VF_OK)
                return status;
            snprintf(in->video_path, sizeof in->video_path, "%s", path);
            in->video_frame = -1;
            continue;
        }
        vf_status status = vf_rgb8_load(path, frame);
        if (status != VF_OK)
            return status;
        snprintf(info->source, sizeof info->source, "%s", path);
        snprintf(info->name, sizeof info->name, "%s", path);
        info->index = -1;
        *got = 1;
        return VF_OK;
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
