/* The studio's film: Blender renders the walk, the phone's sensor adds exposure drift and
 * noise, FFmpeg writes H.264 stored sideways with a rotation flag, the truth goes beside it. */
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "studio_internal.h"
#include "vf/fsutil.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/object3d.h"
#include "vf/process.h"
#include "vf/rgb8.h"

vf_status vf_studio_truth_path(const char *video, char *out, size_t size)
{
    const char *slash = strrchr(video, '/'), *dot = strrchr(video, '.');
    int stem = dot && (!slash || dot > slash) ? (int)(dot - video) : (int)strlen(video);
    if (snprintf(out, size, "%.*s.truth.json", stem, video) >= (int)size)
        return vf_fail(VF_EINPUT, "path too long: %s", video);
    return VF_OK;
}

static vf_status work_dir(const char *video, char *out, size_t size)
{
    if (snprintf(out, size, "%s.studio", video) >= (int)size)
        return vf_fail(VF_EINPUT, "path too long: %s", video);
    return VF_OK;
}

/* What the phone's sensor does to frame i: a drifting auto-exposure gain on linear light, then
 * shot noise (grows with the light) and read noise, then sRGB again; then its image processor
 * takes the grain out (Cycles' and the sensor's alike). */
vf_status vf__develop(vf_rgb8 *img, double gain, const vf_studio_phone *phone, vf_rng *rng)
{
    const double noise = phone->noise;
    static float linear[256];
    if (linear[255] == 0)
        for (int v = 0; v < 256; v++) {
            double s = v / 255.0;
            linear[v] = (float)(s <= 0.04045 ? s / 12.92 : pow((s + 0.055) / 1.055, 2.4));
        }
    const double read = 0.002 * noise, shot = 0.0005 * noise;
    size_t count = (size_t)img->width * img->height * 3;
    for (size_t i = 0; i < count; i++) {
        double l = gain * linear[img->data[i]];
        if (noise > 0)
            l += sqrt(read * read + shot * (l > 0 ? l : 0)) * vf_rng_normal(rng);
        l = l < 0 ? 0 : l > 1 ? 1 : l;
        double s = l <= 0.0031308 ? 12.92 * l : 1.055 * pow(l, 1 / 2.4) - 0.055;
        img->data[i] = (unsigned char)lrint(255 * s);
    }
    return vf_rgb8_denoise(img, phone->denoise);
}

static vf_status run_ffmpeg(const char *program, vf_args *args, FILE *log, const char *what)
{
    int exit_code = 0;
    vf_status status = vf_process_run(program, args, log, NULL, NULL, &exit_code, NULL);
    vf_args_free(args);
    if (status == VF_OK && exit_code != 0)
        status = vf_fail(VF_EINTERNAL, "FFmpeg failed (exit %d) %s", exit_code, what);
    return status;
}

/* The developed frames (upright PNGs in dir) as the phone stores them: turned counter-clockwise
 * to the sensor's landscape, with a display matrix saying "turn 90 degrees clockwise". */
vf_status vf__encode(const char *dir, double fps, const char *video, const char *work)
{
    char program[VF_PATH_MAX], pattern[VF_PATH_MAX], sideways[VF_PATH_MAX],
        partial[VF_PATH_MAX], log_path[VF_PATH_MAX];
    vf_status status = vf_find_program("VF_FFMPEG", "ffmpeg", "install it (apt-get install ffmpeg)",
                                       program, sizeof program);
    if (status == VF_OK)
        status = vf_path_join(pattern, sizeof pattern, dir, "f%05d.png");
    if (status == VF_OK)
        status = vf_path_join(sideways, sizeof sideways, work, "sideways.mp4");
    if (status == VF_OK)
        status = vf_path_join(log_path, sizeof log_path, work, "ffmpeg.log");
    if (status == VF_OK && snprintf(partial, sizeof partial, "%s.partial.mp4", video) >=
                               (int)sizeof partial)
        status = vf_fail(VF_EINPUT, "path too long: %s", video);
    if (status != VF_OK)
        return status;
    FILE *log = fopen(log_path, "w");
    if (!log)
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", log_path, strerror(errno));
    vf_args a = {0};
    vf_args_add(&a, "-y");
    vf_args_opt(&a, "-framerate", "%g", fps);
    vf_args_opt(&a, "-i", "%s", pattern);
    vf_args_opt(&a, "-vf", "%s", "transpose=cclock");
    vf_args_opt(&a, "-c:v", "%s", "libx264");
    vf_args_opt(&a, "-preset", "%s", "fast");
    vf_args_opt(&a, "-crf", "%d", 20);
    vf_args_opt(&a, "-pix_fmt", "%s", "yuv420p");
    vf_args_add(&a, sideways);
    status = run_ffmpeg(program, &a, log, "encoding the frames");
    if (status == VF_OK) {
        /* FFmpeg 5.1's rotate tag counts counter-clockwise: 270 is a clockwise turn of 90 */
        vf_args b = {0};
        vf_args_add(&b, "-y");
        vf_args_opt(&b, "-i", "%s", sideways);
        vf_args_opt(&b, "-c", "%s", "copy");
        vf_args_opt(&b, "-metadata:s:v:0", "%s", "rotate=270");
        vf_args_opt(&b, "-movflags", "%s", "+faststart");
        vf_args_add(&b, partial);
        status = run_ffmpeg(program, &b, log, "writing the rotation flag");
    }
    fclose(log);
    if (status == VF_OK && rename(partial, video) != 0)
        status = vf_fail(VF_EINTERNAL, "cannot write %s: %s", video, strerror(errno));
    if (status != VF_OK)
        remove(partial);
    return status;
}

/* Renders left by an interrupted run are reused only for the same walk and camera. */
static vf_status keep_renders_for(const char *work, const char *render_dir, const json_t *request)
{
    char path[VF_PATH_MAX];
    json_t *before = NULL;
    vf_status status = vf_path_join(path, sizeof path, work, "request.json");
    if (status == VF_OK && vf_is_file(path) && vf_json_load(path, &before) == VF_OK &&
        json_equal(before, request))
        vf_info("continuing the renders of an interrupted run (%s)", work);
    else if (status == VF_OK)
        status = vf_remove_tree(render_dir);
    json_decref(before);
    if (status == VF_OK)
        status = vf_mkdirs(work);
    return status == VF_OK ? vf_json_save(path, request) : status;
}

vf_status vf__film(const vf_object3d *obj, const vf_studio_phone *phone, const double *c2w,
                   int n, const json_t *extra, const char *video, json_t *truth,
                   json_t **report)
{
    char work[VF_PATH_MAX], render_dir[VF_PATH_MAX], film_dir[VF_PATH_MAX],
        truth_path[VF_PATH_MAX];
    vf_camera cam = vf__phone_camera(phone);
    vf_status status = work_dir(video, work, sizeof work);
    if (status == VF_OK)
        status = vf_path_join(render_dir, sizeof render_dir, work, "render");
    if (status == VF_OK)
        status = vf_path_join(film_dir, sizeof film_dir, work, "film");
    if (status == VF_OK)
        status = vf_studio_truth_path(video, truth_path, sizeof truth_path);
    json_t *frames = json_array();
    for (int i = 0; i < n; i++) {
        json_t *f = json_pack("{s:i, s:o, s:o}", "index", i, "time", vf_json_number(i / phone->fps),
                              "c2w", vf_json_doubles(c2w + 16 * i, 16));
        if (extra)
            json_object_update(f, json_array_get(extra, (size_t)i));
        json_array_append_new(frames, f);
    }
    json_object_set_new(truth, "camera", vf_camera_json(&cam));
    json_object_set_new(truth, "fps", vf_json_number(phone->fps));
    json_object_set_new(truth, "frames", frames);
    if (status == VF_OK)
        status = keep_renders_for(work, render_dir, truth);

    double start = vf_now();
    vf_object3d_transform fit = obj->transform;
    if (status == VF_OK)
        status = vf_object3d_render_video(obj, &cam, c2w, n, phone->shutter, render_dir, "r",
                                          "rendering the film", &fit);
    double render_seconds = vf_now() - start;
    if (status == VF_OK)
        status = vf_mkdirs(film_dir);

    /* the sensor: exposure drifts slowly; the noise of frame i has its own seed */
    vf_rng rng;
    vf_rng_seed(&rng, phone->seed ^ 0x5eed5eedULL);
    studio_wave exposure;
    vf__wave_init(&exposure, &rng, 0.03, 0.15, phone->noise * 0.08);
    vf_rgb8 img = {0};
    for (int i = 0; status == VF_OK && i < n; i++) {
        char in[VF_PATH_MAX], out[VF_PATH_MAX], name[32];
        snprintf(name, sizeof name, "r%03d.png", i);
        status = vf_path_join(in, sizeof in, render_dir, name);
        snprintf(name, sizeof name, "f%05d.png", i + 1);
        if (status == VF_OK)
            status = vf_path_join(out, sizeof out, film_dir, name);
        if (status == VF_OK)
            status = vf_rgb8_load(in, &img);
        if (status == VF_OK) {
            vf_rng_seed(&rng, phone->seed * 1000003ULL + (uint64_t)i);
            status = vf__develop(&img, exp(vf__wave_at(&exposure, i / phone->fps)), phone, &rng);
            if (status == VF_OK)
                status = vf_rgb8_save(out, &img);
        }
    }
    vf_rgb8_free(&img);
    if (status == VF_OK)
        status = vf__encode(film_dir, phone->fps, video, work);

    json_object_set_new(truth, "transform",
                        json_pack("{s:[o,o,o], s:o}", "center", vf_json_number(fit.center[0]),
                                  vf_json_number(fit.center[1]), vf_json_number(fit.center[2]),
                                  "scale", vf_json_number(fit.scale)));
    if (status == VF_OK)
        status = vf_json_save(truth_path, truth);
    if (status == VF_OK && report)
        *report =
            json_pack("{s:s, s:s, s:i, s:o, s:o, s:i, s:i}", "video", video, "truth", truth_path,
                      "frames", n, "seconds", vf_json_number(n / phone->fps), "render_seconds",
                      vf_json_number(render_seconds), "width", cam.width, "height", cam.height);
    if (status == VF_OK)
        status = vf_remove_tree(work);
    json_decref(truth);
    return status;
}
