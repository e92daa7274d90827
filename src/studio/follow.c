/* The closed-loop re-shoot: a simulated person films with a phone that `vfcapture reshoot`
 * reads as a camera (vf_frame_source), reads the advice it gives frame by frame and moves by
 * it, so the guidance itself is tested. Blender stays open and renders each frame as the
 * person moves (vf_object3d_live); reshoot sees only the frames.
 *
 * The person, in the model's frame: stands at `eye`, aims the phone at the object's centre
 * turned by `pan`, `tilt` and `roll` (degrees), and holds it with the studio's hand. Each
 * frame they act on the advice they read REACTION_S ago (a person needs that long to read
 * and start moving): every part of it is carried out at a rate of its remaining amount over
 * APPROACH_S, no faster than a person walks around an object or turns a phone (SPEED_*). No
 * advice (the frame was not localized): they hold still. "orbit 12 deg right" turns the eye
 * about the vertical through the centre, "raise 5 cm" lifts it, "step back" moves it away from
 * the centre, "turn", "tilt", "roll" turn the phone. Distances are read in the workspace's
 * units (or cm when it has a metric scale) and turned into the person's own through the
 * alignment, as a person knows how far a step is.
 *
 * A walk ends when reshoot has said ON TARGET for hold_seconds, or after give_up_seconds. */
#define _GNU_SOURCE
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "studio_internal.h"
#include "vf/attack_file.h"
#include "vf/export.h"
#include "vf/calib.h"
#include "vf/fsutil.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/reshoot.h"
#include "vf/targets.h"

#define REACTION_S 0.3     /* from reading the advice to moving */
#define APPROACH_S 1.0     /* a step of the advice is carried out over about this long */
#define SPEED_ORBIT 30.0   /* deg/s around the object */
#define SPEED_MOVE 0.25    /* share of the camera distance a second (raise, step) */
#define SPEED_TURN 30.0    /* deg/s turning the phone */
#define WRONG_MIN_DEG 2.0  /* below these the advice says nothing (vf_advice_text) */
#define WRONG_MIN_UNITS (0.02 * VF_CAMERA_DISTANCE)

read_advice vf__read_advice(const char *text, double metres_per_unit)
{
    read_advice a = {0};
    if (!text)
        return a;
    a.given = 1;
    char buf[512];
    snprintf(buf, sizeof buf, "%s", text);
    for (char *save = NULL, *part = strtok_r(buf, ",", &save); part;
         part = strtok_r(NULL, ",", &save)) {
        while (*part == ' ')
            part++;
        double x;
        char word[32] = "", unit[32] = "";
        double *to = NULL;
        int sign = 1;
        if (sscanf(part, "orbit %lf deg %31s", &x, word) == 2)
            to = &a.orbit, sign = strcmp(word, "left") ? 1 : -1;
        else if (sscanf(part, "turn %lf deg %31s", &x, word) == 2)
            to = &a.pan, sign = strcmp(word, "left") ? 1 : -1;
        else if (sscanf(part, "tilt %lf deg %31s", &x, word) == 2)
            to = &a.tilt, sign = strcmp(word, "down") ? 1 : -1;
        else if (sscanf(part, "roll %lf deg %31s", &x, word) == 2)
            to = &a.roll, sign = strcmp(word, "counterclockwise") ? 1 : -1;
        else if (sscanf(part, "raise %lf %31s", &x, unit) == 2)
            to = &a.raise;
        else if (sscanf(part, "lower %lf %31s", &x, unit) == 2)
            to = &a.raise, sign = -1;
        else if (sscanf(part, "step back %lf %31s", &x, unit) == 2)
            to = &a.back;
        else if (sscanf(part, "step closer %lf %31s", &x, unit) == 2)
            to = &a.back, sign = -1;
        if (!to)
            continue; /* "hold still: on target" */
        if (!strcmp(unit, "cm") && metres_per_unit > 0)
            x = x / 100 / metres_per_unit;
        *to = sign * x;
    }
    return a;
}

/* The person and the phone, model frame. */
typedef struct person {
    double eye[3];
    double pan, tilt, roll; /* degrees, the phone turned from aiming at the centre */
} person;

static void rot_axis(int axis, double deg, double r[9])
{
    double c = cos(deg * M_PI / 180), s = sin(deg * M_PI / 180);
    double m[3][9] = {{1, 0, 0, 0, c, -s, 0, s, c},
                      {c, 0, s, 0, 1, 0, -s, 0, c},
                      {c, -s, 0, s, c, 0, 0, 0, 1}};
    memcpy(r, m[axis], sizeof m[axis]);
}

/* The phone's steady pose: aimed at the centre, then turned right by pan (about its up),
 * up by tilt (about its right) and clockwise by roll (its up towards its right). */
static void person_camera(const person *p, double c2w[16])
{
    static const double center[3] = {0, 0, 0};
    double look[16], r[9], t[9], u[9], m1[9], m2[9], m3[9], base[9];
    studio_hand still = {0};
    vf__hand_camera(&still, 0, p->eye, center, look);
    vf_mat4_rotation(look, base);
    rot_axis(1, -p->pan, r);
    rot_axis(0, p->tilt, t);
    rot_axis(2, -p->roll, u);
    vf_mat3_mul(base, r, m1);
    vf_mat3_mul(m1, t, m2);
    vf_mat3_mul(m2, u, m3);
    vf_mat4_from_rt(m3, p->eye, c2w);
}

static double clamp(double x, double limit)
{
    return x > limit ? limit : x < -limit ? -limit : x;
}

/* One frame's movement by advice a (model units through `scale`, the workspace's units per
 * model unit). */
static void person_move(person *p, const read_advice *a, double dt, double scale,
                        double distance)
{
    if (!a->given)
        return;
    double k = dt / APPROACH_S, move = SPEED_MOVE * distance * dt;
    double orbit = clamp(k * a->orbit, SPEED_ORBIT * dt) * M_PI / 180;
    double x = p->eye[0], y = p->eye[1];
    p->eye[0] = cos(orbit) * x - sin(orbit) * y; /* + right: azimuth grows anticlockwise */
    p->eye[1] = sin(orbit) * x + cos(orbit) * y;
    p->eye[2] += clamp(k * a->raise / scale, move);
    double d = sqrt(p->eye[0] * p->eye[0] + p->eye[1] * p->eye[1] + p->eye[2] * p->eye[2]);
    double step = clamp(k * a->back / scale, move);
    for (int i = 0; i < 3 && d > 1e-9; i++)
        p->eye[i] *= (d + step) / d;
    p->pan += clamp(k * a->pan, SPEED_TURN * dt);
    p->tilt += clamp(k * a->tilt, SPEED_TURN * dt);
    p->roll += clamp(k * a->roll, SPEED_TURN * dt);
}

/* Whether the advice points away from the target on some step the truth says is needed. */
static int wrong_way(const read_advice *a, const vf_advice *truth)
{
    if (!a->given)
        return 0;
    int orbit = fabs(truth->orbit_deg) >= WRONG_MIN_DEG && a->orbit * truth->orbit_deg < 0;
    int raise = fabs(truth->raise) >= WRONG_MIN_UNITS && a->raise * truth->raise < 0;
    int back = fabs(truth->back) >= WRONG_MIN_UNITS && a->back * truth->back < 0;
    return orbit || raise || back;
}

typedef struct follow_run {
    /* the studio */
    const vf_studio_phone *phone;
    const vf_studio_reshoot_options *opt;
    vf_object3d_live *live;
    vf_similarity to_ws;
    double scale, distance, metres;
    vf_viewpoint target;
    double target_c2w[16], range[VF_VIEW_DIM];
    studio_hand hand;
    studio_wave exposure;
    char film_dir[VF_PATH_MAX];
    int filmed;        /* frames written, all walks */
    json_t *frames;    /* the truth's frames */
    /* the walk under way */
    int walk, step, max_steps, hold_steps, on_target_steps;
    person who;
    read_advice *heard; /* the advice of each frame of the walk, read as it came */
    double c2w[16];     /* the frame being localized, model frame */
    /* the walk's figures */
    int localized, wrong, wrong_run, wrong_longest, first_on, first_in, on_and_in;
    double box;
    vf_status status; /* the camera's own failure, reported after reshoot's */
} follow_run;

/* The camera: the person moves by what they read, the phone takes the frame. */
static vf_status next_frame(void *ctx, vf_rgb8 *frame, int *got)
{
    follow_run *f = ctx;
    *got = 0;
    if (f->step >= f->max_steps || f->on_target_steps >= f->hold_steps)
        return VF_OK; /* the person is done */
    double dt = 1 / f->phone->fps, t = f->step * dt;
    int delay = (int)lround(REACTION_S * f->phone->fps);
    if (f->step > delay)
        person_move(&f->who, &f->heard[f->step - 1 - delay], dt, f->scale, f->distance);
    double steady[16];
    person_camera(&f->who, steady);
    vf__hand_move(&f->hand, t + 100.0 * f->walk, steady, f->c2w);
    vf_status status = vf_object3d_live_render(f->live, f->c2w, frame);
    if (status == VF_OK) {
        vf_rng rng;
        vf_rng_seed(&rng, f->phone->seed * 1000003ULL + (uint64_t)f->filmed + 7777);
        status = vf__develop(frame, exp(vf__wave_at(&f->exposure, f->filmed * dt)), f->phone,
                             &rng);
        char name[32], path[VF_PATH_MAX];
        snprintf(name, sizeof name, "f%05d.png", f->filmed + 1);
        if (status == VF_OK)
            status = vf_path_join(path, sizeof path, f->film_dir, name);
        if (status == VF_OK)
            status = vf_rgb8_save(path, frame);
    }
    if (status != VF_OK) {
        f->status = status;
        return status;
    }
    *got = 1;
    return VF_OK;
}

/* What reshoot said about the frame: the person reads it; the truth is written down. */
static void on_advice(const json_t *entry, const char *line, void *ctx)
{
    (void)line;
    follow_run *f = ctx;
    read_advice a = vf__read_advice(json_string_value(json_object_get(entry, "advice")), f->metres);
    f->heard[f->step] = a;
    double ws_c2w[16];
    vf_similarity_apply_c2w(&f->to_ws, f->c2w, ws_c2w);
    vf_viewpoint truly;
    vf_c2w_to_viewpoint(ws_c2w, &truly);
    vf_viewpoint_within(&truly, &f->target, f->range, 1, &f->box);
    vf_advice needed;
    vf_advice_compute(ws_c2w, f->target_c2w, &needed);
    int wrong = wrong_way(&a, &needed), on = json_is_true(json_object_get(entry, "on_target"));
    f->localized += a.given;
    f->wrong += wrong;
    f->wrong_run = wrong ? f->wrong_run + 1 : 0;
    if (f->wrong_run > f->wrong_longest)
        f->wrong_longest = f->wrong_run;
    if (on && f->first_on < 0)
        f->first_on = f->step;
    if (f->box <= f->opt->tolerance && f->first_in < 0)
        f->first_in = f->step;
    f->on_target_steps += on;
    f->on_and_in += on && f->box <= f->opt->tolerance;
    json_array_append_new(
        f->frames,
        json_pack("{s:i, s:o, s:o, s:o, s:o, s:o, s:i, s:s?, s:b, s:b}", "index", f->filmed, "time",
                  vf_json_number(f->filmed / f->phone->fps), "c2w", vf_json_doubles(f->c2w, 16),
                  "c2w_workspace", vf_json_doubles(ws_c2w, 16), "viewpoint",
                  vf_viewpoint_json(&truly), "box_distance", vf_json_number(f->box), "walk",
                  f->walk, "advice", json_string_value(json_object_get(entry, "advice")),
                  "on_target", on, "wrong_way", wrong));
    f->filmed++;
    f->step++;
}

/* One walk from natural viewpoint `from` (model frame): reshoot runs on the person's phone. */
static vf_status walk(vf_workspace *ws, follow_run *f, const double from[16], json_t *walks)
{
    f->step = f->on_target_steps = f->localized = f->wrong = f->wrong_run = f->on_and_in = 0;
    f->wrong_longest = 0;
    f->first_on = f->first_in = -1;
    memset(&f->who, 0, sizeof f->who);
    for (int k = 0; k < 3; k++)
        f->who.eye[k] = from[4 * k + 3];
    double start_ws[16];
    vf_similarity_apply_c2w(&f->to_ws, from, start_ws);
    vf_viewpoint start;
    vf_c2w_to_viewpoint(start_ws, &start);
    double box0;
    vf_viewpoint_within(&start, &f->target, f->range, 1, &box0);

    char name[64];
    snprintf(name, sizeof name, "studio-phone-walk%d", f->walk + 1);
    vf_frame_source camera = {.next = next_frame, .ctx = f, .name = name};
    vf_reshoot_options ro;
    vf_reshoot_defaults(&ro);
    ro.target = f->opt->target;
    ro.camera = &camera;
    ro.tolerance = f->opt->tolerance;
    ro.window = 0;
    json_t *result = NULL;
    vf_status status = vf_reshoot_run(ws, &ro, on_advice, f, &result);
    json_decref(result);
    if (f->status != VF_OK)
        status = f->status;
    if (status != VF_OK)
        return status;
    double dt = 1 / f->phone->fps;
    /* reached: reshoot said ON TARGET for the hold, and most of those frames truly were */
    int reached = f->on_target_steps >= f->hold_steps && 2 * f->on_and_in > f->on_target_steps;
    vf_info("walk %d of %d: %s after %.1f s", f->walk + 1, f->opt->starts,
            f->first_on >= 0 ? "reshoot said on target" : "gave up",
            (f->first_on >= 0 ? f->first_on : f->step) * dt);
    json_array_append_new(
        walks,
        json_pack("{s:i, s:o, s:o, s:i, s:i, s:b, s:o, s:o, s:i, s:i, s:o, s:i, s:o}", "walk",
                  f->walk, "from", vf_viewpoint_json(&start), "from_box_distance",
                  vf_json_number(box0), "frames", f->step, "localized", f->localized, "reached",
                  reached, "seconds_to_on_target",
                  f->first_on >= 0 ? vf_json_number(f->first_on * dt) : json_null(),
                  "seconds_to_truly_in_box",
                  f->first_in >= 0 ? vf_json_number(f->first_in * dt) : json_null(),
                  "on_target_frames", f->on_target_steps, "on_target_truly_in_box", f->on_and_in,
                  "final_box_distance", vf_json_number(f->box), "wrong_way_frames", f->wrong,
                  "wrong_way_longest_seconds", vf_json_number(f->wrong_longest * dt)));
    return VF_OK;
}

vf_status vf__follow(vf_workspace *ws, capture_truth *t, const vf_similarity *to_ws,
                     const vf_studio_phone *phone, const vf_studio_reshoot_options *o,
                     const char *video, const char *truth_path, json_t *alignment,
                     json_t **report)
{
    follow_run f = {.phone = phone, .opt = o, .to_ws = *to_ws, .scale = to_ws->scale,
                    .frames = json_array()};
    double started = vf_now();
    f.max_steps = (int)lround(o->give_up_seconds * phone->fps);
    f.hold_steps = (int)ceil(o->hold_seconds * phone->fps);
    f.heard = calloc((size_t)f.max_steps + 1, sizeof *f.heard);
    if (!vf_workspace_metres_per_unit(ws, &f.metres))
        f.metres = 0;
    vf_attack_file attack = {0};
    char work[VF_PATH_MAX], live_dir[VF_PATH_MAX];
    vf_status status = f.heard ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    if (status == VF_OK)
        status = vf_targets_workspace_target(ws->root, o->target, &f.target, f.target_c2w);
    if (status == VF_OK)
        status = vf_attack_file_load_workspace(ws, vf_export_attack(ws), &attack);
    if (status == VF_OK) {
        memcpy(f.range, attack.range, sizeof f.range);
        if (snprintf(work, sizeof work, "%s.studio", video) >= (int)sizeof work)
            status = vf_fail(VF_EINPUT, "path too long: %s", video);
    }
    if (status == VF_OK)
        status = vf_remove_tree(work); /* a closed loop cannot resume: it starts over */
    if (status == VF_OK)
        status = vf_path_join(f.film_dir, sizeof f.film_dir, work, "film");
    if (status == VF_OK)
        status = vf_path_join(live_dir, sizeof live_dir, work, "live");
    if (status == VF_OK)
        status = vf_mkdirs(f.film_dir);
    for (int i = 0; i < t->count; i++)
        f.distance += sqrt(t->c2w[16 * i + 3] * t->c2w[16 * i + 3] +
                           t->c2w[16 * i + 7] * t->c2w[16 * i + 7] +
                           t->c2w[16 * i + 11] * t->c2w[16 * i + 11]) / t->count;
    vf_rng rng;
    vf_rng_seed(&rng, phone->seed + 2000);
    vf__hand_init(&f.hand, &rng, phone->shake, f.distance);
    vf__wave_init(&f.exposure, &rng, 0.03, 0.15, phone->noise * 0.08);
    vf_camera cam = vf__phone_camera(phone);
    t->obj.samples = phone->samples;
    if (status == VF_OK) {
        vf_info("re-shooting target %d of %s closed-loop: %d walks from the capture's "
                "viewpoints, the person moving by reshoot's advice (%.0f fps, tolerance "
                "+-%.0f%%, giving up after %.0f s)",
                o->target, ws->root, o->starts, phone->fps, 100 * o->tolerance,
                o->give_up_seconds);
        status = vf_object3d_live_open(&t->obj, &cam, live_dir, &f.live);
    }
    json_t *walks = json_array();
    for (int w = 0; status == VF_OK && w < o->starts; w++) {
        f.walk = w;
        /* the walks start where the capture was at evenly spread moments */
        int from = (int)((long)t->count * w / o->starts);
        status = walk(ws, &f, t->c2w + 16 * from, walks);
    }
    vf_object3d_live_close(f.live);
    if (status == VF_OK)
        status = vf__encode(f.film_dir, phone->fps, video, work);

    if (status == VF_OK) {
        int reached = 0;
        for (size_t i = 0; i < json_array_size(walks); i++)
            reached += json_is_true(json_object_get(json_array_get(walks, i), "reached"));
        double m[16];
        vf_similarity_to_mat4(to_ws, m);
        json_object_set_new(alignment, "model_to_workspace", vf_json_doubles(m, 16));
        vf_camera c = cam;
        json_t *truth = json_pack(
            "{s:s, s:s, s:s, s:s, s:s, s:i, s:o, s:O, s:{s:b, s:i, s:o, s:o, s:o, s:o, s:o, "
            "s:o, s:I}, s:O, s:o, s:o, s:O, s:{s:[o,o,o], s:o}}",
            "kind", "vfcapture studio truth", "simulation", "reshoot", "model", t->obj.model,
            "capture_truth", truth_path, "workspace", ws->root, "target", o->target,
            "target_viewpoint", vf_viewpoint_json(&f.target), "alignment", alignment, "walk",
            "follow", 1, "starts", o->starts, "hold_seconds", vf_json_number(o->hold_seconds),
            "give_up_seconds", vf_json_number(o->give_up_seconds), "tolerance",
            vf_json_number(o->tolerance), "shake", vf_json_number(phone->shake), "noise",
            vf_json_number(phone->noise), "denoise", vf_json_number(phone->denoise), "seed",
            (json_int_t)phone->seed, "walks", walks, "camera", vf_camera_json(&c), "fps", vf_json_number(phone->fps), "frames", f.frames,
            "transform", "center", vf_json_number(t->obj.transform.center[0]),
            vf_json_number(t->obj.transform.center[1]), vf_json_number(t->obj.transform.center[2]),
            "scale", vf_json_number(t->obj.transform.scale));
        char path[VF_PATH_MAX];
        status = vf_studio_truth_path(video, path, sizeof path);
        if (status == VF_OK)
            status = truth ? vf_json_save(path, truth) : vf_fail(VF_EINTERNAL, "out of memory");
        json_decref(truth);
        if (status == VF_OK && report)
            *report = json_pack(
                "{s:s, s:s, s:i, s:o, s:o, s:i, s:i, s:O, s:i, s:O}", "video", video, "truth", path,
                "frames", f.filmed, "seconds", vf_json_number(f.filmed / phone->fps),
                "render_seconds", vf_json_number(vf_now() - started), "width", c.width, "height",
                c.height, "walks", walks, "reached", reached, "alignment", alignment);
        if (status == VF_OK)
            status = vf_remove_tree(work);
    }
    json_decref(walks);
    json_decref(f.frames);
    free(f.heard);
    vf_attack_file_free(&attack);
    return status;
}
