/* The studio's two simulations: a phone capture around the model, and a re-shoot at an
 * exported target. */
#define _GNU_SOURCE
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "studio_internal.h"
#include "vf/attack_file.h"
#include "vf/export.h"
#include "vf/dataset.h"
#include "vf/fsutil.h"
#include "vf/ingest.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/object3d.h"
#include "vf/real.h"
#include "vf/score.h"
#include "vf/stats.h"
#include "vf/targets.h"

static void phone_defaults(vf_studio_phone *p)
{
    *p = (vf_studio_phone){.width = 360, .height = 640, .fov_y = 65, .fps = 30, .shutter = 0.5,
                           .samples = 8, .shake = 1, .noise = 1, .denoise = 6, .seed = 0};
}

void vf_studio_capture_defaults(vf_studio_capture_options *o)
{
    memset(o, 0, sizeof *o);
    phone_defaults(&o->phone);
    o->loops = 2;
    o->loop_seconds = 8;
    o->elevation_low = 12;
    o->elevation_high = 35;
    o->distance = 3.2;
}

void vf_studio_reshoot_defaults(vf_studio_reshoot_options *o)
{
    memset(o, 0, sizeof *o);
    phone_defaults(&o->phone);
    o->phone.width = o->phone.height = 0; /* the capture's */
    o->phone.fov_y = 0;
    o->phone.fps = 0;
    o->walk_seconds = 4;
    o->hold_seconds = 6;
    o->jitter = 0.03;
    o->starts = 3;
    o->give_up_seconds = 40;
    o->tolerance = 0.10;
}

static vf_status check_phone(const vf_studio_phone *p)
{
    if (p->width < 16 || p->height < 16 || p->width > 8192 || p->height > 8192)
        return vf_fail(VF_EINPUT, "frame size %dx%d is not one a phone films", p->width, p->height);
    if (!(p->fov_y > 5 && p->fov_y < 170) || !(p->fps >= 1 && p->fps <= 240) ||
        !(p->shutter >= 0 && p->shutter <= 1) || p->samples < 1 || !(p->shake >= 0) ||
        !(p->noise >= 0) || !(p->denoise >= 0 && p->denoise <= 50))
        return vf_fail(VF_EINPUT, "the phone's settings are out of range (field of view 5-170 "
                                  "deg, 1-240 fps, shutter 0-1, samples >= 1, denoise 0-50)");
    return VF_OK;
}

static vf_status model_record(const char *model, vf_object3d *obj)
{
    memset(obj, 0, sizeof *obj);
    if (!vf_is_file(model))
        return vf_fail(VF_EINPUT, "model %s does not exist", model);
    if (!vf_object3d_is_model(model))
        return vf_fail(VF_EINPUT, "%s is not a 3D model (give a .glb, .gltf, .obj or .blend file)",
                       model);
    if (!realpath(model, obj->model))
        snprintf(obj->model, sizeof obj->model, "%s", model);
    snprintf(obj->scene, sizeof obj->scene, "room");
    return VF_OK;
}

vf_status vf_studio_capture(const char *model, const vf_studio_capture_options *o,
                            const char *video, json_t **report)
{
    vf_object3d obj;
    vf_status status = model_record(model, &obj);
    if (status == VF_OK)
        status = check_phone(&o->phone);
    if (status == VF_OK && (o->loops < 1 || o->loops > 10 || !(o->loop_seconds > 0.5) ||
                            !(o->distance > 1.2) || !(o->elevation_low > -10) ||
                            !(o->elevation_high < 80)))
        status = vf_fail(VF_EINPUT, "the walk's settings are out of range (1-10 loops, a loop "
                                    "over 0.5 s, distance over 1.2 object radii, elevations "
                                    "-10 to 80 deg)");
    if (status != VF_OK)
        return status;
    obj.samples = o->phone.samples;
    double *c2w = NULL;
    int n = vf__capture_walk(o, &c2w);
    if (n < 0)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_info("filming %s: %d loops of %.0f s, %d frames %dx%d at %.0f fps", model, o->loops,
            o->loop_seconds, n, o->phone.width, o->phone.height, o->phone.fps);
    json_t *truth =
        json_pack("{s:s, s:s, s:s, s:{s:i, s:o, s:o, s:o, s:o, s:i, s:o, s:o, s:o, s:o, s:I}}",
                  "kind", "vfcapture studio truth", "simulation", "capture", "model", obj.model,
                  "walk", "loops", o->loops, "loop_seconds", vf_json_number(o->loop_seconds),
                  "elevation_low", vf_json_number(o->elevation_low), "elevation_high",
                  vf_json_number(o->elevation_high), "distance", vf_json_number(o->distance),
                  "samples", o->phone.samples, "shutter", vf_json_number(o->phone.shutter), "shake",
                  vf_json_number(o->phone.shake), "noise", vf_json_number(o->phone.noise),
                  "denoise", vf_json_number(o->phone.denoise), "seed", (json_int_t)o->phone.seed);
    status = vf__film(&obj, &o->phone, c2w, n, NULL, video, truth, report);
    free(c2w);
    return status;
}

/* ---- the re-shoot ---- */

void vf__truth_free(capture_truth *t)
{
    json_decref(t->doc);
    free(t->c2w);
    memset(t, 0, sizeof *t);
}

vf_status vf__truth_load(const char *path, capture_truth *t)
{
    memset(t, 0, sizeof *t);
    vf_status status = vf_json_load(path, &t->doc);
    if (status != VF_OK)
        return status;
    const json_t *cam = json_object_get(t->doc, "camera");
    const json_t *frames = json_object_get(t->doc, "frames");
    const json_t *tr = json_object_get(t->doc, "transform");
    const char *model = json_string_value(json_object_get(t->doc, "model"));
    if (vf_camera_from_json(cam, path, &t->camera) != VF_OK)
        t->camera = (vf_camera){0}; /* refused below, in one line */
    t->fps = json_number_value(json_object_get(t->doc, "fps"));
    t->count = (int)json_array_size(frames);
    double center[3];
    int ok = model && t->camera.width > 0 && t->camera.fy > 0 && t->fps > 0 && t->count > 0 &&
             vf_json_read_doubles(json_object_get(tr, "center"), center, 3) &&
             json_number_value(json_object_get(tr, "scale")) > 0;
    if (!ok)
        return vf_fail(VF_EINPUT, "%s is not a studio truth file (camera, fps, model, transform "
                                  "and frames expected)", path);
    snprintf(t->obj.model, sizeof t->obj.model, "%s", model);
    memcpy(t->obj.transform.center, center, sizeof center);
    t->obj.transform.scale = json_number_value(json_object_get(tr, "scale"));
    snprintf(t->obj.scene, sizeof t->obj.scene, "room");
    t->c2w = malloc(sizeof(double) * 16 * (size_t)t->count);
    if (!t->c2w)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; i < t->count; i++)
        if (!vf_json_read_doubles(json_object_get(json_array_get(frames, (size_t)i), "c2w"),
                                 t->c2w + 16 * i, 16))
            return vf_fail(VF_EINPUT, "%s: frame %d has no c2w", path, i);
    return VF_OK;
}

vf_status vf__align_workspace(const vf_workspace *ws, const capture_truth *t,
                                 vf_similarity *s, json_t **report)
{
    char path[VF_PATH_MAX];
    vf_dataset ds = {0};
    vf_status status = vf_workspace_posed_frames(ws, path, sizeof path);
    if (status == VF_OK)
        status = vf_dataset_load(path, &ds);
    if (status != VF_OK)
        return status;
    double *src = malloc(sizeof(double) * 3 * (size_t)(ds.count + 1));
    double *dst = malloc(sizeof(double) * 3 * (size_t)(ds.count + 1));
    const double **ours = malloc(sizeof *ours * (size_t)(ds.count + 1));
    const double **ref = malloc(sizeof *ref * (size_t)(ds.count + 1));
    int n = 0;
    for (int i = 0; src && dst && ours && ref && i < ds.count; i++) {
        const char *name = strrchr(ds.frames[i].image_path, '/');
        int index;
        if (sscanf(name ? name + 1 : ds.frames[i].image_path, "frame_%d", &index) != 1 ||
            index < 0 || index >= t->count)
            continue;
        ours[n] = ds.frames[i].c2w;
        ref[n] = t->c2w + 16 * index;
        for (int k = 0; k < 3; k++) {
            src[3 * n + k] = ref[n][4 * k + 3];
            dst[3 * n + k] = ours[n][4 * k + 3];
        }
        n++;
    }
    if (!src || !dst || !ours || !ref)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    else if (n < 3)
        status = vf_fail(VF_EINPUT, "%s holds %d frames of the capture in the truth file (3 "
                                    "needed): was the workspace ingested from that video?",
                         path, n);
    vf_pose_agreement agree = {0};
    if (status == VF_OK)
        status = vf_similarity_umeyama(src, dst, n, s);
    if (status == VF_OK)
        status = vf_pose_compare(ours, ref, n, 0, &agree);
    if (status == VF_OK)
        *report = json_pack("{s:i, s:o, s:o, s:o}", "frames", n, "scale", vf_json_number(s->scale),
                            "rotation_median_deg", vf_json_number(agree.rot_median),
                            "position_median", vf_json_number(agree.pos_median));
    free(src);
    free(dst);
    free(ours);
    free(ref);
    vf_dataset_free(&ds);
    return status;
}

/* The truth file beside the video the workspace was ingested from; 0 when it was not a video. */
static int truth_beside_video(const vf_workspace *ws, char *out, size_t size)
{
    char kind[32], source[VF_PATH_MAX];
    vf_ingest_source_kind(ws->root, kind, sizeof kind);
    vf_ingest_source_path(ws->root, source, sizeof source);
    return !strcmp(kind, "video") && source[0] && vf_studio_truth_path(source, out, size) == VF_OK;
}

vf_status vf__truth_of_workspace(const vf_workspace *ws, const char *given, char *out,
                                    size_t size)
{
    if (given)
        snprintf(out, size, "%s", given);
    else if (!truth_beside_video(ws, out, size))
        return vf_fail(VF_EINPUT, "%s was not ingested from a video; give the capture's truth "
                                  "file (--truth)", ws->root);
    if (!vf_is_file(out))
        return vf_fail(VF_EINPUT, "no truth file %s: the studio re-shoots only what it filmed "
                                  "(vfcapture simulate capture)", out);
    return VF_OK;
}

vf_status vf_studio_object(const vf_workspace *ws, vf_object3d *obj, vf_similarity *to_object,
                           int *filmed)
{
    char truth_path[VF_PATH_MAX];
    *filmed = 0;
    if (!truth_beside_video(ws, truth_path, sizeof truth_path) || !vf_is_file(truth_path))
        return VF_OK; /* not the studio's video */
    capture_truth t = {0};
    vf_similarity to_ws;
    json_t *alignment = NULL;
    vf_status status = vf__truth_load(truth_path, &t);
    if (status == VF_OK)
        status = vf__align_workspace(ws, &t, &to_ws, &alignment);
    if (status == VF_OK) {
        *obj = t.obj;
        obj->samples = VF_STUDIO_REAL_SAMPLES;
        /* a field of the object alone is attacked, and score classifies the re-shoot's frames,
         * on white: the object itself then too (the studio scene: white all around) */
        const json_t *params = json_object_get(vf_workspace_stage_record(ws, "train"), "params");
        if (json_is_true(json_object_get(params, "object_only")))
            snprintf(obj->scene, sizeof obj->scene, "studio");
        *to_object = vf_similarity_inverse(&to_ws);
        *filmed = 1;
        vf_info("the object of %s: %s, filmed by the studio (%s; aligned on %lld frames, "
                "%.2f deg median), rendered %s",
                ws->root, t.obj.model, truth_path,
                json_integer_value(json_object_get(alignment, "frames")),
                json_number_value(json_object_get(alignment, "rotation_median_deg")),
                strcmp(obj->scene, "studio") ? "in the room" : "on white (object mode)");
    }
    json_decref(alignment);
    vf__truth_free(&t);
    return status;
}

static double smoothstep(double x)
{
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x * x * (3 - 2 * x);
}

vf_status vf_studio_reshoot(vf_workspace *ws, const char *model,
                            const vf_studio_reshoot_options *o, const char *video,
                            json_t **report)
{
    char truth_path[VF_PATH_MAX];
    capture_truth t = {0};
    vf_attack_file attack = {0};
    vf_viewpoint target, start;
    vf_similarity to_ws;
    json_t *alignment = NULL;
    vf_status status = vf__truth_of_workspace(ws, o->truth, truth_path, sizeof truth_path);
    if (status == VF_OK)
        status = vf__truth_load(truth_path, &t);
    if (status == VF_OK && model) {
        vf_object3d given;
        status = model_record(model, &given);
        if (status == VF_OK)
            snprintf(t.obj.model, sizeof t.obj.model, "%s", given.model);
    }
    if (status == VF_OK)
        status = vf_targets_workspace_target(ws->root, o->target, &target, NULL);
    if (status == VF_OK)
        status = vf_attack_file_load_workspace(ws, vf_export_attack(ws), &attack);
    if (status == VF_OK)
        status = vf__align_workspace(ws, &t, &to_ws, &alignment);
    vf_studio_phone phone = o->phone;
    if (status == VF_OK) {
        if (!phone.width || !phone.height) {
            phone.width = t.camera.width;
            phone.height = t.camera.height;
        }
        if (!(phone.fov_y > 0))
            phone.fov_y = 2 * atan(0.5 * t.camera.height / t.camera.fy) * 180 / M_PI;
        if (!(phone.fps > 0))
            phone.fps = o->follow ? VF_STUDIO_FOLLOW_FPS : t.fps;
        status = check_phone(&phone);
    }
    if (status == VF_OK && (!(o->walk_seconds >= 0) || !(o->hold_seconds > 0) ||
                            !(o->jitter >= 0 && o->jitter < 0.5)))
        status = vf_fail(VF_EINPUT, "the walk's settings are out of range (walk >= 0 s, hold "
                                    "> 0 s, jitter a share under 0.5)");
    if (status == VF_OK && o->follow) {
        if (o->starts < 1 || !(o->give_up_seconds > o->hold_seconds) ||
            !(o->tolerance > 0 && o->tolerance <= 1))
            status = vf_fail(VF_EINPUT, "the closed loop's settings are out of range (at least "
                                        "one start, giving up later than the hold, tolerance "
                                        "a share in (0, 1])");
        else
            status = vf__follow(ws, &t, &to_ws, &phone, o, video, truth_path, alignment,
                                report);
        json_decref(alignment);
        vf_attack_file_free(&attack);
        vf__truth_free(&t);
        return status;
    }
    int n = (int)lround((o->walk_seconds + o->hold_seconds) * phone.fps);
    double *c2w = status == VF_OK ? malloc(sizeof(double) * 16 * (size_t)n) : NULL;
    json_t *extra = json_array();
    if (status == VF_OK && !c2w)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    if (status == VF_OK) {
        /* the walk starts where the capture started, in the workspace's terms */
        double first[16];
        vf_similarity_apply_c2w(&to_ws, t.c2w, first);
        vf_c2w_to_viewpoint(first, &start);
        vf_similarity to_model = vf_similarity_inverse(&to_ws);
        double distance = 0; /* the hand's scale: the capture's camera distance */
        for (int i = 0; i < t.count; i++)
            distance += sqrt(t.c2w[16 * i + 3] * t.c2w[16 * i + 3] +
                             t.c2w[16 * i + 7] * t.c2w[16 * i + 7] +
                             t.c2w[16 * i + 11] * t.c2w[16 * i + 11]) / t.count;
        vf_rng rng;
        vf_rng_seed(&rng, phone.seed + 1000);
        studio_hand hand;
        vf__hand_init(&hand, &rng, phone.shake, distance);
        studio_wave wander[VF_VIEW_DIM];
        for (int k = 0; k < VF_VIEW_DIM; k++)
            vf__wave_init(&wander[k], &rng, 0.1, 0.6, o->jitter * attack.range[k]);
        double a0[VF_VIEW_DIM], a1[VF_VIEW_DIM];
        vf_viewpoint_to_array(&start, a0);
        vf_viewpoint_to_array(&target, a1);
        a1[0] = a0[0] + remainder(a1[0] - a0[0], 360.0); /* the short way round */
        for (int i = 0; i < n; i++) {
            double time = i / phone.fps, a[VF_VIEW_DIM];
            double s = o->walk_seconds > 0 ? smoothstep(time / o->walk_seconds) : 1;
            for (int k = 0; k < VF_VIEW_DIM; k++)
                a[k] = a0[k] + s * (a1[k] - a0[k]) + s * vf__wave_at(&wander[k], time);
            vf_viewpoint v = vf_viewpoint_from_array(a);
            double steady_ws[16], steady[16], held[16], held_ws[16];
            vf_viewpoint_to_c2w(&v, steady_ws);
            vf_similarity_apply_c2w(&to_model, steady_ws, steady);
            vf__hand_move(&hand, time, steady, c2w + 16 * i);
            memcpy(held, c2w + 16 * i, sizeof held);
            vf_similarity_apply_c2w(&to_ws, held, held_ws);
            vf_viewpoint truly;
            vf_c2w_to_viewpoint(held_ws, &truly);
            double box;
            vf_viewpoint_within(&truly, &target, attack.range, 1, &box);
            json_array_append_new(extra, json_pack("{s:o, s:o, s:o}", "c2w_workspace",
                                                   vf_json_doubles(held_ws, 16), "viewpoint",
                                                   vf_viewpoint_json(&truly), "box_distance",
                                                   vf_json_number(box)));
        }
    }
    if (status == VF_OK) {
        vf_info("re-shooting target %d of %s: %.0f s walk from the capture's first viewpoint, "
                "%.0f s around the target, %d frames",
                o->target, ws->root, o->walk_seconds, o->hold_seconds, n);
        double m[16];
        vf_similarity_to_mat4(&to_ws, m);
        json_object_set_new(alignment, "model_to_workspace", vf_json_doubles(m, 16));
        json_t *truth = json_pack(
            "{s:s, s:s, s:s, s:s, s:s, s:i, s:o, s:O, s:{s:o, s:o, s:o, s:o, s:o, s:o, s:o, "
            "s:I}}",
            "kind", "vfcapture studio truth", "simulation", "reshoot", "model", t.obj.model,
            "capture_truth", truth_path, "workspace", ws->root, "target", o->target,
            "target_viewpoint", vf_viewpoint_json(&target), "alignment", alignment, "walk",
            "walk_seconds", vf_json_number(o->walk_seconds), "hold_seconds",
            vf_json_number(o->hold_seconds), "jitter", vf_json_number(o->jitter), "shutter",
            vf_json_number(phone.shutter), "shake", vf_json_number(phone.shake), "noise",
            vf_json_number(phone.noise), "denoise", vf_json_number(phone.denoise), "seed",
            (json_int_t)phone.seed);
        t.obj.samples = phone.samples;
        status = vf__film(&t.obj, &phone, c2w, n, extra, video, truth, report);
        if (status == VF_OK && report && *report)
            json_object_set(*report, "alignment", alignment);
    }
    json_decref(alignment);
    json_decref(extra);
    free(c2w);
    vf_attack_file_free(&attack);
    vf__truth_free(&t);
    return status;
}

/* ---- the re-shoot's score against its truth ---- */

static int same_file(const char *a, const char *b)
{
    char ra[PATH_MAX], rb[PATH_MAX];
    return realpath(a, ra) && realpath(b, rb) && !strcmp(ra, rb);
}

vf_status vf_studio_check(vf_workspace *ws, const char *video, json_t **report)
{
    char truth_path[VF_PATH_MAX];
    json_t *truth = NULL, *score = NULL;
    vf_attack_file attack = {0};
    vf_status status = vf_studio_truth_path(video, truth_path, sizeof truth_path);
    if (status == VF_OK && !vf_is_file(truth_path))
        status = vf_fail(VF_EINPUT, "no truth file %s: check a video of `vfcapture simulate "
                                    "reshoot`", truth_path);
    if (status == VF_OK && !vf_workspace_has_stage(ws, "score"))
        status = vf_fail(VF_EINPUT, "%s has no score yet: run 'vfcapture score %s %s' first",
                         ws->root, ws->root, video);
    if (status == VF_OK)
        status = vf_json_load(truth_path, &truth);
    if (status == VF_OK)
        status = vf_score_load(ws, &score);
    if (status == VF_OK)
        status = vf_attack_file_load_workspace(ws, vf_export_attack(ws), &attack);
    const json_t *frames = json_object_get(truth, "frames");
    const json_t *rows = json_object_get(score, "frames_detail");
    double center[VF_VIEW_DIM];
    double tolerance = json_number_value(json_object_get(score, "tolerance_percent")) / 100;
    if (status == VF_OK &&
        (!vf_json_read_doubles(json_object_get(score, "center_viewpoint"), center, VF_VIEW_DIM) ||
         !json_is_array(frames)))
        status = vf_fail(VF_EINPUT, "%s is not what the studio writes", truth_path);
    size_t n = json_array_size(rows);
    /* per frame: localization errors, the true box distance, score's verdict, and how far
     * localization moved the box distance (the noise that decides frames near the edge) */
    double *rot = NULL, *pos = NULL, *box = NULL, *noise = NULL;
    int *kept_flag = NULL, *located_flag = NULL;
    if (status == VF_OK) {
        rot = malloc(sizeof(double) * (n + 1)), pos = malloc(sizeof(double) * (n + 1));
        box = malloc(sizeof(double) * (n + 1)), noise = malloc(sizeof(double) * (n + 1));
        kept_flag = malloc(sizeof(int) * (n + 1)), located_flag = malloc(sizeof(int) * (n + 1));
        if (!rot || !pos || !box || !noise || !kept_flag || !located_flag)
            status = vf_fail(VF_EINTERNAL, "out of memory");
    }
    int seen = 0, localized = 0, kept = 0, truly_in = 0, agree = 0, edge = 0;
    vf_viewpoint c = vf_viewpoint_from_array(center);
    for (size_t i = 0; status == VF_OK && i < n; i++) {
        const json_t *row = json_array_get(rows, i);
        const char *name = json_string_value(json_object_get(row, "frame"));
        const char *hash = name ? strrchr(name, '#') : NULL;
        double known[16], a[VF_VIEW_DIM];
        char scored[VF_PATH_MAX];
        snprintf(scored, sizeof scored, "%.*s", hash ? (int)(hash - name) : 0, hash ? name : "");
        if (!same_file(scored, video))
            continue; /* a frame of another video */
        const json_t *f = json_array_get(frames, (size_t)atol(hash + 1));
        if (!f || !vf_json_read_doubles(json_object_get(f, "c2w_workspace"), known, 16))
            continue; /* not a frame of this video */
        vf_viewpoint truly;
        vf_c2w_to_viewpoint(known, &truly);
        truly_in += vf_viewpoint_within(&truly, &c, attack.range, tolerance, &box[seen]);
        const char *st = json_string_value(json_object_get(row, "status"));
        kept_flag[seen] = st && !strcmp(st, "kept");
        kept += kept_flag[seen];
        located_flag[seen] =
            vf_json_read_doubles(json_object_get(row, "viewpoint"), a, VF_VIEW_DIM);
        if (located_flag[seen++]) {
            double ours[16], r1[9], r2[9], located;
            vf_viewpoint v = vf_viewpoint_from_array(a);
            vf_viewpoint_within(&v, &c, attack.range, tolerance, &located);
            noise[localized] = fabs(located - box[seen - 1]);
            vf_viewpoint_to_c2w(&v, ours);
            vf_mat4_rotation(ours, r1);
            vf_mat4_rotation(known, r2);
            rot[localized] = vf_rot_angle_deg(r1, r2);
            pos[localized] = sqrt(pow(ours[3] - known[3], 2) + pow(ours[7] - known[7], 2) +
                                  pow(ours[11] - known[11], 2)) / VF_CAMERA_DISTANCE;
            localized++;
        }
    }
    /* the edge band: the 90th percentile of that noise (at least a tenth of the tolerance) */
    double band = 0.1 * tolerance;
    if (localized > 0) {
        vf_sort_doubles(noise, localized);
        band = fmax(band, vf_sorted_quantile(noise, localized, 0.9));
    }
    for (int i = 0; i < seen; i++) { /* score's verdicts on the frames it localized */
        if (!located_flag[i])
            continue;
        if (fabs(box[i] - tolerance) < band)
            edge++;
        else
            agree += (box[i] <= tolerance) == kept_flag[i];
    }
    if (status == VF_OK && seen == 0)
        status = vf_fail(VF_EINPUT, "%s scored no frame of %s: run 'vfcapture score %s %s'",
                         ws->root, video, ws->root, video);
    vf_real_rates real; /* the object's own side, when `vfcapture real` ran */
    int real_found = 0;
    if (status == VF_OK)
        status = vf_real_load_rates(ws, attack.stage, &real, &real_found);
    if (status == VF_OK && report) {
        const json_t *k = json_object_get(score, "kept");
        *report = json_pack(
            "{s:s, s:s, s:i, s:i, s:o, s:o, s:o, s:i, s:i, s:i, s:i, s:o, s:o, "
            "s:{s:O, s:O, s:O, s:O}, s:O}",
            "video", video, "truth", truth_path, "frames", seen, "localized", localized,
            "rotation_median_deg", vf_json_number(vf_median(rot, localized)), "position_median",
            vf_json_number(vf_median(pos, localized)), "tolerance", vf_json_number(tolerance),
            "truly_in_box", truly_in, "kept", kept, "agree", agree, "at_box_edge", edge,
            "edge_band", vf_json_number(band), "agreement",
            vf_json_number(localized - edge > 0 ? (double)agree / (localized - edge) : NAN),
            "physical", "frames", json_object_get(k, "frames"), "misclassified",
            json_object_get(k, "misclassified"), "asr", json_object_get(k, "asr"), "interval95",
            json_object_get(k, "interval95"), "natural", json_object_get(score, "natural"));
        json_object_set_new(*report, "real",
                            real_found ? json_pack("{s:o, s:o, s:o}", "natural_accuracy",
                                                   vf_json_number(real.natural_accuracy),
                                                   "asr_v_star", vf_json_number(real.asr_v_star),
                                                   "asr_samples", vf_json_number(real.asr_samples))
                                       : json_null());
    }
    free(rot);
    free(pos);
    free(box);
    free(noise);
    free(kept_flag);
    free(located_flag);
    vf_attack_file_free(&attack);
    json_decref(truth);
    json_decref(score);
    return status;
}
