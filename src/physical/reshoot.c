/* The reshoot stage (vf/reshoot.h): guided capture at an exported target. */
#include "vf/reshoot.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/attack_file.h"
#include "vf/export.h"
#include "vf/calib.h"
#include "vf/frames.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/overlay.h"
#include "vf/targets.h"

typedef struct reshoot_run {
    const vf_reshoot_options *opt;
    const char *root;
    vf_reshoot_frame_fn on_frame;
    void *ctx;
    vf_attack_file attack;
    vf_viewpoint target_v;
    double target_c2w[16];
    double metres;
    vf_localizer *loc;
    vf_pose_smoother smoother;
    char frames_dir[VF_PATH_MAX];
    json_t *result; /* poses.json and the counts */
    json_t *saved;  /* [{file, frame, viewpoint, c2w_object, ...}] */
    int seen, localized;
    vf_overlay *window; /* the live window, or NULL */
    int quit;           /* the person closed it with q or Esc */
} reshoot_run;

/* Save a frame on target with its pose. */
static vf_status save_frame(reshoot_run *run, const vf_rgb8 *frame, const vf_frame_info *info,
                            const vf_localize_result *r, double box)
{
    char name[48], path[VF_PATH_MAX];
    /* PNG: lossless, so `score` on these files sees the pixels the camera gave. */
    snprintf(name, sizeof name, "frame_%05zu.png", json_array_size(run->saved));
    vf_status status = vf_path_join(path, sizeof path, run->frames_dir, name);
    if (status == VF_OK)
        status = vf_rgb8_save(path, frame);
    if (status == VF_OK)
        json_array_append_new(
            run->saved,
            json_pack("{s:s, s:s, s:o, s:o, s:i, s:o, s:o}", "file", name, "source", info->name,
                      "viewpoint", vf_viewpoint_json(&r->viewpoint), "c2w_object",
                      vf_json_mat4(r->c2w_object), "inliers", r->inliers, "reprojection_px",
                      vf_json_number(r->reprojection_px), "box_distance", vf_json_number(box)));
    return status;
}

/* One frame: localize, smooth, advise, save when on target. */
static vf_status handle_frame(reshoot_run *run, const vf_rgb8 *frame, const vf_frame_info *info)
{
    vf_localize_result r;
    vf_status status = vf_localize_frame(run->loc, frame, &r);
    if (status != VF_OK)
        return status;
    run->seen++;
    char line[512];
    json_t *entry = json_pack("{s:s, s:b}", "frame", info->name, "localized", r.localized);
    if (!r.localized) {
        snprintf(line, sizeof line, "%s (keep the object in view, move slowly)", r.reason);
    } else {
        run->localized++;
        double smooth[16], box_raw, box_smooth;
        vf_pose_smoother_add(&run->smoother, r.c2w_object, smooth);
        vf_viewpoint sv;
        vf_c2w_to_viewpoint(smooth, &sv);
        int raw_in = vf_viewpoint_within(&r.viewpoint, &run->target_v, run->attack.range,
                                         run->opt->tolerance, &box_raw);
        int smooth_in = vf_viewpoint_within(&sv, &run->target_v, run->attack.range,
                                            run->opt->tolerance, &box_smooth);
        vf_advice a;
        vf_advice_compute(smooth, run->target_c2w, &a);
        /* Steps below 2 deg or 2% of the distance are left out (too small to act on), but
         * only inside the box: outside it the small steps are what is left to do, and "hold
         * still" there would leave the person short of the target (the studio's closed loop:
         * stopped at 0.15-0.25 of the range from a +-10% box with the coarse words alone). */
        double fine = smooth_in ? 1 : 0.25;
        char text[384];
        vf_advice_text(&a, run->metres, 2.0 * fine, 0.02 * fine * VF_CAMERA_DISTANCE, text,
                       sizeof text);
        int keep = raw_in && smooth_in;
        if (keep && (status = save_frame(run, frame, info, &r, box_raw)) != VF_OK) {
            json_decref(entry);
            return status;
        }
        snprintf(line, sizeof line, "%s%s", keep ? "ON TARGET, saved; " : "", text);
        json_object_set_new(entry, "advice", json_string(text));
        json_object_set_new(entry, "on_target", json_boolean(keep));
        json_object_set_new(entry, "box_distance", vf_json_number(box_smooth));
        json_object_set_new(entry, "viewpoint", vf_viewpoint_json(&r.viewpoint));
    }
    if (run->on_frame)
        run->on_frame(entry, line, run->ctx);
    json_decref(entry);
    if (run->window) {
        char head[96], counts[96];
        snprintf(head, sizeof head, "target %d - %.60s", run->opt->target, info->name);
        snprintf(counts, sizeof counts, "%d of %d frames localized, %d saved", run->localized,
                 run->seen, (int)json_array_size(run->saved));
        const char *lines[3] = {head, line, counts};
        status = vf_overlay_show(run->window, frame, lines, 3, strncmp(line, "ON TARGET", 9) == 0,
                                 &run->quit);
    }
    return status;
}

static vf_status capture(reshoot_run *run)
{
    vf_frames in;
    char *video = (char *)run->opt->video;
    vf_status status = VF_OK;
    if (run->opt->camera)
        vf_frames_open_source(run->opt->camera, &in);
    else
        status = run->opt->device ? vf_frames_open_v4l2(run->opt->device, NULL, NULL, &in)
                                  : vf_frames_open(&video, 1, &in);
    if (status != VF_OK)
        return status;
    if (run->opt->device)
        vf_info("reading %s for %.0f s", run->opt->device, run->opt->seconds);
    if (run->opt->window && vf_overlay_available() &&
        vf_overlay_open("vfcapture reshoot", &run->window) == VF_OK)
        vf_info("showing the advice in a window (q or Esc stops)");
    vf_rgb8 frame = {0};
    vf_frame_info info;
    int got;
    double start = vf_now();
    while ((status = vf_frames_next(&in, &frame, &info, &got)) == VF_OK && got) {
        if ((status = handle_frame(run, &frame, &info)) != VF_OK) {
            vf_error_prefix("%s", info.name);
            break;
        }
        if (run->quit || (run->opt->device && vf_now() - start > run->opt->seconds))
            break;
    }
    vf_overlay_close(run->window);
    run->window = NULL;
    vf_rgb8_free(&frame);
    vf_frames_close(&in);
    return status;
}

static vf_status reshoot(const vf_reshoot_options *o, vf_workspace *ws, reshoot_run *run)
{
    char path[VF_PATH_MAX], stage_name[32];
    vf_status status = vf_attack_file_load_workspace(ws, vf_export_attack(ws), &run->attack);
    if (status == VF_OK)
        status = vf_targets_workspace_target(ws->root, o->target, &run->target_v, run->target_c2w);
    if (status == VF_OK)
        status = vf_localizer_open(ws, &o->loc, &run->loc);
    if (status != VF_OK)
        return status;
    if (!vf_workspace_metres_per_unit(ws, &run->metres))
        run->metres = 0;
    vf_pose_smoother_init(&run->smoother, o->smoothing);
    vf_stage stage;
    snprintf(stage_name, sizeof stage_name, "reshoot_t%02d", o->target);
    if ((status = vf_stage_begin(ws, stage_name, &stage)) != VF_OK)
        return status;
    status = vf_path_join(run->frames_dir, sizeof run->frames_dir, stage.dir, "frames");
    if (status == VF_OK)
        status = vf_mkdirs(run->frames_dir);
    /* A capture that stops early (a webcam unplugged, a frame of another size) keeps the
     * frames already on target: they are committed, and the error is returned after. */
    vf_status stopped = VF_OK;
    char stop_message[1024] = "";
    if (status == VF_OK && (stopped = capture(run)) != VF_OK && json_array_size(run->saved) == 0)
        status = stopped;
    else if (stopped != VF_OK)
        snprintf(stop_message, sizeof stop_message, "%s", vf_error_message());
    json_t *doc = json_pack("{s:i, s:o, s:o, s:O}", "target", o->target, "target_viewpoint",
                            vf_viewpoint_json(&run->target_v), "tolerance_percent",
                            vf_json_number(100 * o->tolerance), "frames", run->saved);
    if (stop_message[0])
        json_object_set_new(doc, "stopped_early", json_string(stop_message));
    if (status == VF_OK &&
        (status = vf_path_join(path, sizeof path, stage.dir, "poses.json")) == VF_OK)
        status = vf_json_save(path, doc);
    if (status == VF_OK)
        json_object_update_new(doc, json_pack("{s:i, s:i, s:i}", "seen", run->seen, "localized",
                                              run->localized, "saved",
                                              (int)json_array_size(run->saved)));
    run->result = doc;
    if (status == VF_OK)
        status =
            vf_stage_commit(&stage,
                            json_pack("{s:i, s:o}", "target", o->target, "tolerance_percent",
                                      vf_json_number(100 * o->tolerance)),
                            json_pack("{s:i, s:i, s:i}", "frames", run->seen, "localized",
                                      run->localized, "saved", (int)json_array_size(run->saved)));
    else
        vf_stage_abort(&stage);
    if (status == VF_OK && stop_message[0])
        status = vf_fail(stopped, "%s (the %zu frames on target before it are kept in %s/%s)",
                         stop_message, json_array_size(run->saved), ws->root, stage_name);
    return status;
}

void vf_reshoot_defaults(vf_reshoot_options *o)
{
    *o = (vf_reshoot_options){
        .target = -1, .tolerance = 0.05, .smoothing = 0.4, .seconds = 60, .window = 1};
    vf_localize_defaults(&o->loc);
}

vf_status vf_reshoot_run(vf_workspace *ws, const vf_reshoot_options *o, vf_reshoot_frame_fn fn,
                         void *ctx, json_t **result)
{
    reshoot_run run = {
        .opt = o, .root = ws->root, .on_frame = fn, .ctx = ctx, .saved = json_array()};
    *result = NULL;
    vf_status status = VF_OK;
    if (o->target < 0)
        status = vf_fail(VF_EINPUT, "say which target to shoot: --target N (0 is v*; see "
                                    "WS/export/targets.json)");
    else if (!!o->device + !!o->video + !!o->camera != 1)
        status = vf_fail(VF_EINPUT, "give one source: --v4l2 /dev/videoN or --video FILE");
    else if (!(o->tolerance > 0 && o->tolerance <= 1) || !(o->smoothing > 0 && o->smoothing <= 1))
        status = vf_fail(VF_EINPUT, "tolerance and smoothing must be shares in (0, 1]");
    if (status == VF_OK)
        status = reshoot(o, ws, &run);
    if (status == VF_OK)
        *result = json_incref(run.result);
    json_decref(run.result);
    vf_localizer_close(run.loc);
    vf_attack_file_free(&run.attack);
    json_decref(run.saved);
    return status;
}
