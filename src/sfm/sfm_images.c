/* Laying out the frames for COLMAP: list, group by size, composite alpha, link the rest. */
#define _GNU_SOURCE
#include "vf/sfm_images.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "vf/image.h"
#include "vf/log.h"

/* Fill out->frames with the images of src_dir (source paths only), sorted. */
static vf_status list_images(const char *src_dir, vf_sfm_images *out)
{
    char **names;
    int count;
    vf_status status = vf_list_images(src_dir, &names, &count);
    if (status == VF_OK && count == 0)
        status = vf_fail(VF_EINPUT, "%s holds no JPEG or PNG images", src_dir);
    if (status == VF_OK && !(out->frames = calloc((size_t)count, sizeof *out->frames)))
        status = vf_fail(VF_EINTERNAL, "out of memory listing %s", src_dir);
    for (int i = 0; i < count && status == VF_OK; i++) {
        status = vf_path_join(out->frames[i].source, sizeof out->frames[i].source, src_dir,
                              names[i]);
        out->count += status == VF_OK;
    }
    vf_free_names(names, count);
    return status;
}

/* Read every header; count distinct sizes. */
static vf_status read_sizes(vf_sfm_images *images)
{
    images->size_groups = 0;
    for (int i = 0; i < images->count; i++) {
        vf_sfm_frame *f = &images->frames[i];
        int channels;
        vf_status status = vf_image_info(f->source, &f->width, &f->height, &channels);
        if (status != VF_OK)
            return status;
        int seen = 0;
        for (int j = 0; j < i && !seen; j++)
            seen = images->frames[j].width == f->width && images->frames[j].height == f->height;
        images->size_groups += !seen;
    }
    return VF_OK;
}

/* The share of pixels that are transparent or near-white. */
static double background_share(const vf_image *img)
{
    size_t plain = 0, n = (size_t)img->width * (size_t)img->height;
    int c = img->channels, alpha = c == 2 || c == 4;
    for (size_t i = 0; i < n; i++) {
        const float *p = img->data + i * (size_t)c;
        int transparent = alpha && p[c - 1] < 0.05f;
        int white = p[0] >= 0.97f && (c < 3 || (p[1] >= 0.97f && p[2] >= 0.97f));
        plain += transparent || white;
    }
    return n ? (double)plain / (double)n : 0;
}

/* Write one frame into dst_dir: composite and save, or link. */
static vf_status place_frame(vf_sfm_frame *f, const vf_image *img, const char *dst_dir,
                             const float background[3])
{
    char dst[VF_PATH_MAX], folder[VF_PATH_MAX];
    vf_status status = vf_path_join(dst, sizeof dst, dst_dir, f->name);
    vf_path_dirname(folder, sizeof folder, dst);
    if (status == VF_OK)
        status = vf_mkdirs(folder);
    if (status != VF_OK)
        return status;
    if (f->had_alpha) {
        vf_image rgb;
        status = vf_image_to_rgb(img, background, &rgb);
        if (status == VF_OK)
            status = vf_image_save(dst, &rgb);
        vf_image_free(&rgb);
        return status;
    }
    if (link(f->source, dst) == 0)
        return VF_OK;
    return vf_copy_file(f->source, dst);
}

/* The frame's name for COLMAP: "[WxH/]file", with .png when it gets composited. */
static void name_frame(vf_sfm_frame *f, int grouped)
{
    char base[256], group[32] = "";
    vf_path_basename(base, sizeof base, f->source, f->had_alpha);
    if (grouped)
        snprintf(group, sizeof group, "%dx%d/", f->width, f->height);
    snprintf(f->name, sizeof f->name, "%s%s%s", group, base, f->had_alpha ? ".png" : "");
}

/* Decode, measure and place every frame, in parallel. */
static vf_status place_frames(vf_sfm_images *images, const char *dst_dir,
                              const float background[3])
{
    vf_first_error error = {0};
    double share_sum = 0;
    int alpha = 0, done = 0;
    vf_progress progress;
    vf_progress_begin(&progress, "preparing frames", (size_t)images->count, "images");
#pragma omp parallel for schedule(dynamic) reduction(+ : share_sum, alpha)
    for (int i = 0; i < images->count; i++) {
        vf_sfm_frame *f = &images->frames[i];
        vf_image img;
        vf_status s = vf_image_load(f->source, &img);
        if (s == VF_OK) {
            f->had_alpha = img.channels == 2 || img.channels == 4;
            name_frame(f, images->size_groups > 1);
            share_sum += background_share(&img);
            alpha += f->had_alpha;
            s = place_frame(f, &img, dst_dir, background);
            vf_image_free(&img);
        }
        vf_first_error_keep(&error, s);
#pragma omp critical
        vf_progress_update(&progress, (size_t)++done, NULL);
    }
    vf_progress_end(&progress);
    images->with_alpha = alpha;
    images->background_fraction = share_sum / images->count;
    return vf_first_error_raise(&error);
}

vf_status vf_sfm_images_prepare(const char *src_dir, const char *dst_dir,
                                const float background[3], vf_sfm_images *out)
{
    memset(out, 0, sizeof *out);
    if (!vf_is_dir(src_dir))
        return vf_fail(VF_EINPUT, "%s does not exist", src_dir);
    vf_status status = list_images(src_dir, out);
    if (status == VF_OK)
        status = read_sizes(out);
    if (status == VF_OK)
        status = vf_mkdirs(dst_dir);
    if (status == VF_OK)
        status = place_frames(out, dst_dir, background);
    if (status != VF_OK)
        vf_sfm_images_free(out);
    return status;
}

void vf_sfm_images_free(vf_sfm_images *images)
{
    free(images->frames);
    memset(images, 0, sizeof *images);
}
