/* The physical loop in the simulated studio (vf/studio.h), short and small: the water bottle of
 * models_3d filmed handheld around it (270x480 at 15 fps, two loops of 2 s, so a shutter of a
 * tenth of the frame interval: the blur of a 1/60 s shutter at a walking pace), the video
 * through ingest and poses, a hand-made attack whose v* is the viewpoint of a registered
 * frame, export, the studio's re-shoot at target 0, then `reshoot --video` and `score` on that
 * video, and the closed loop (`simulate reshoot --follow`). Against the studio's true poses:
 *   - COLMAP's poses of the capture, after a similarity alignment: median rotation under 1
 *     degree and position under 2% of the camera distance (the targets). Poses run
 *     with one focal length (SIMPLE_RADIAL): 50 small frames do not pin down the default
 *     OPENCV model's eight parameters (measured at 216 px: fx and fy 3% apart, 1.37 deg
 *     median against 0.68 deg). 270x480, not 216x384: at 216 px COLMAP left frames out, the
 *     relaxed mapping took them all and was once 2.0 deg off (4 more runs: 0.54-0.67 deg,
 *     f 1.5% long); at 270 px 4 of 4 runs registered all 50 at once, 0.31-0.34 deg (loops
 *     of 3 s: 90 frames); loops of 2 s film 60 frames for the same 50, a third fewer renders
 *     (the whole test 382 s alone on 2 cores): all 50 registered, 0.20 deg, 0.45% (the
 *     re-shoot: 0.16 deg, 0.46%). Then 4 Cycles samples a pixel and the phone's denoising
 *     at 10, not 8 and 6: half the render time, the frames as smooth to the eye (the whole
 *     test 263 s alone): all 50 registered, 0.30 deg, 0.60% (the re-shoot 0.39 deg, 0.60%);
 *   - each re-shoot frame's localization (score's viewpoint) against its true pose in the
 *     workspace's frame: the same limits;
 *   - score keeps exactly the frames whose true pose lies in the tolerance box (frames within
 *     localization noise of the box's edge aside, and few: `simulate check` measures that
 *     noise in box units), and reshoot saves most of them (its smoothed pose must be in the
 *     box too); `simulate check` counts the same;
 *   - the closed loop: a person who moves by reshoot's advice alone reaches the target and
 *     holds it, most frames reshoot calls on target truly are, and the advice hardly ever
 *     points the wrong way.
 * Give a scratch folder as argv[1] to keep (and reuse) the video and the workspace. */
#include <jansson.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "physical_helpers.h"
#include "check.h"
#include "poses_helpers.h"
#include "vf/dataset.h"
#include "vf/pose.h"

#define MODEL "data/models_3d/water_bottle__WaterBottle.glb"
#define FPS 15
#define LOOP_SECONDS 2 /* two loops: 60 frames, of which ingest keeps 50 */
#define PHONE "--render-samples 4 --denoise 10" /* every render: see the poses above */
#define TOLERANCE 0.15 /* score's box: +-15% of each parameter's range; the person wanders
                          * 3% around v* and the hand shakes the position by 1% of the
                          * distance: most frames on target are well inside */

static const char *tool(void)
{
    const char *t = getenv("VF_TOOL");
    return t ? t : "vfcapture";
}

static int frame_index(const char *path)
{
    const char *name = strrchr(path, '/');
    int index;
    return sscanf(name ? name + 1 : path, "frame_%d", &index) == 1 ? index : -1;
}

static double c2w_of(const json_t *frame, const char *key, double out[16])
{
    return vf_json_read_doubles(json_object_get(frame, key), out, 16);
}

/* COLMAP's poses of the capture against the truth; returns the registered share. */
static double check_capture_poses(const char *ws, const json_t *truth)
{
    char path[3 * VF_PATH_MAX];
    snprintf(path, sizeof path, "%s/poses/transforms.json", ws);
    vf_dataset ds;
    int loaded = vf_dataset_load(path, &ds) == VF_OK;
    CHECK(loaded, "poses: %s", vf_error_message());
    if (!loaded)
        return 0;
    const json_t *frames = json_object_get(truth, "frames");
    const double **ours = malloc(sizeof *ours * (size_t)ds.count);
    const double **ref = malloc(sizeof *ref * (size_t)ds.count);
    double(*truth_c2w)[16] = malloc(sizeof *truth_c2w * (size_t)ds.count);
    int n = 0;
    for (int i = 0; i < ds.count; i++) {
        int index = frame_index(ds.frames[i].image_path);
        if (index < 0 || !c2w_of(json_array_get(frames, (size_t)index), "c2w", truth_c2w[n]))
            continue;
        ours[n] = ds.frames[i].c2w;
        ref[n] = truth_c2w[n];
        n++;
    }
    snprintf(path, sizeof path, "%s/ingest/images", ws);
    int ingested = 0;
    for (int i = 0; i < 1000; i++) {
        char image[4 * VF_PATH_MAX];
        snprintf(image, sizeof image, "%s/frame_%06d.jpg", path, i);
        ingested += vf_is_file(image);
    }
    printf("capture: %d of %d ingested frames registered\n", n, ingested);
    CHECK(n == ds.count, "every registered frame is a frame of the video (%d of %d)", n,
          ds.count);
    CHECK(n >= 0.7 * ingested, "most frames registered: %d of %d", n, ingested);
    check_poses(ours, ref, n, (pose_limits){1.0, 3.0, 0.02, 0.05});
    free(ours);
    free(ref);
    free(truth_c2w);
    vf_dataset_free(&ds);
    return ingested ? (double)n / ingested : 0;
}

/* v* = the viewpoint of the registered frame nearest a third of the way round the first loop
 * (video frame 10 of 30): the re-shoot walks there from the capture's start, out of the
 * box and into it, whichever frames COLMAP registered (the middle registered frame was near
 * the start when the second loop's frames registered, and the split vanished). */
static void write_attack(const char *ws, vf_viewpoint *v_star)
{
    char path[3 * VF_PATH_MAX];
    snprintf(path, sizeof path, "%s/poses/transforms.json", ws);
    vf_dataset ds;
    int loaded = vf_dataset_load(path, &ds) == VF_OK;
    CHECK(loaded && ds.count > 2, "poses");
    if (!loaded)
        return;
    vf_viewpoint *samples = malloc(sizeof *samples * (size_t)ds.count);
    for (int i = 0; i < ds.count; i++)
        vf_c2w_to_viewpoint(ds.frames[i].c2w, &samples[i]);
    int nearest = 0, third = FPS * LOOP_SECONDS / 3;
    for (int i = 1; i < ds.count; i++)
        if (abs(frame_index(ds.frames[i].image_path) - third) <
            abs(frame_index(ds.frames[nearest].image_path) - third))
            nearest = i;
    *v_star = samples[nearest];
    test_label_set bottle = {1, {898}, {"water bottle"}};
    write_test_attack(ws, &bottle, v_star, samples, ds.count);
    free(samples);
    vf_dataset_free(&ds);
}

/* Localization and the kept split of `score` on the re-shoot, against its truth. Returns the
 * number of frames score kept. */
static int check_score(const char *ws, const char *video, const json_t *truth)
{
    char out[VF_PATH_MAX], err[VF_PATH_MAX], path[3 * VF_PATH_MAX];
    snprintf(out, sizeof out, "%s/score.out", vf_test_tmpdir());
    snprintf(err, sizeof err, "%s/score.err", vf_test_tmpdir());
    int rc = vf_test_system("'%s' score '%s' '%s' --tolerance %g --json >'%s' 2>'%s'", tool(),
                            ws, video, 100 * TOLERANCE, out, err);
    CHECK(rc == 0, "score exit %d (stderr in %s)", rc, err);
    /* `simulate check`, the studio's own report: its edge band (localization noise in box
     * units) decides which frames are too near the box's edge to hold score to */
    rc = vf_test_system("'%s' simulate check '%s' '%s' --json >'%s' 2>'%s'", tool(), ws, video,
                        out, err);
    json_t *check = load_json(out);
    CHECK(rc == 0 && check, "simulate check exit %d", rc);
    double band = json_number_value(json_object_get(check, "edge_band"));
    CHECK(band > 0 && band < 0.5 * TOLERANCE, "edge band %.3f", band);
    snprintf(path, sizeof path, "%s/score/score.json", ws);
    json_t *doc = load_json(path);
    const json_t *rows = json_object_get(doc, "frames_detail");
    const json_t *frames = json_object_get(truth, "frames");
    int n = (int)json_array_size(frames);
    CHECK((int)json_array_size(rows) == n, "score saw %zu frames of %d", json_array_size(rows), n);
    double *rot = malloc(sizeof(double) * (size_t)n), *pos = malloc(sizeof(double) * (size_t)n);
    int localized = 0, kept = 0, truly_in = 0, agree = 0, edge = 0;
    for (int i = 0; i < n && i < (int)json_array_size(rows); i++) {
        const json_t *row = json_array_get(rows, (size_t)i), *f = json_array_get(frames, (size_t)i);
        const char *status = json_string_value(json_object_get(row, "status"));
        double box = json_number_value(json_object_get(f, "box_distance")), a[VF_VIEW_DIM];
        int is_kept = status && !strcmp(status, "kept"), expect = box <= TOLERANCE;
        truly_in += expect;
        kept += is_kept;
        int located = vf_json_read_doubles(json_object_get(row, "viewpoint"), a, VF_VIEW_DIM);
        if (located) {
            double ours[16], known[16], r1[9], r2[9];
            vf_viewpoint v = vf_viewpoint_from_array(a);
            vf_viewpoint_to_c2w(&v, ours);
            c2w_of(f, "c2w_workspace", known);
            vf_mat4_rotation(ours, r1);
            vf_mat4_rotation(known, r2);
            rot[localized] = vf_rot_angle_deg(r1, r2);
            pos[localized] = sqrt(pow(ours[3] - known[3], 2) + pow(ours[7] - known[7], 2) +
                                  pow(ours[11] - known[11], 2)) / VF_CAMERA_DISTANCE;
            localized++;
        }
        if (!located) {
            continue; /* counted by the localized share below */
        } else if (fabs(box - TOLERANCE) < band) {
            edge++; /* within localization noise of the box's edge */
        } else {
            agree += expect == is_kept;
            CHECK(expect == is_kept, "frame %d: true box distance %.3f, score says %s", i, box,
                  status ? status : "?");
        }
    }
    double rot_median = quantile(rot, localized, 0.5), pos_median = quantile(pos, localized, 0.5);
    printf("re-shoot: %d of %d frames localized, rotation median %.2f deg, position median "
           "%.2f%% of the distance; %d truly in the box, score kept %d, %d agree, %d within "
           "%.3f of the box's edge\n",
           localized, n, rot_median, 100 * pos_median, truly_in, kept, agree, edge, band);
    CHECK(localized >= 0.8 * n, "most re-shoot frames localized (%d of %d)", localized, n);
    CHECK(rot_median < 1.0, "localization rotation median %.2f deg", rot_median);
    CHECK(pos_median < 0.02, "localization position median %.4f", pos_median);
    CHECK(truly_in >= 8 && n - truly_in >= 8, "a real split: %d of %d frames in the box",
          truly_in, n);
    CHECK(edge <= n / 4, "%d frames at the box's edge", edge);
    free(rot);
    free(pos);
    json_decref(doc);
    CHECK(json_integer_value(json_object_get(check, "localized")) == localized &&
              json_integer_value(json_object_get(check, "kept")) == kept &&
              json_integer_value(json_object_get(check, "truly_in_box")) == truly_in &&
              json_integer_value(json_object_get(check, "at_box_edge")) == edge,
          "simulate check: localized %lld, kept %lld, in the box %lld, at the edge %lld",
          json_integer_value(json_object_get(check, "localized")),
          json_integer_value(json_object_get(check, "kept")),
          json_integer_value(json_object_get(check, "truly_in_box")),
          json_integer_value(json_object_get(check, "at_box_edge")));
    json_decref(check);
    return kept;
}

static void check_reshoot(const char *ws, const char *video, int kept)
{
    long long saved = reshoot_video(tool(), ws, video, TOLERANCE, NULL);
    printf("reshoot --video: %lld frames saved\n", saved);
    /* reshoot saves a frame when its smoothed pose is in the box too (a steadier cue for the
     * person): a subset of score's, most of it (the full loop at +-10%: 46 of 52) */
    CHECK(saved <= kept && saved >= 0.75 * kept, "reshoot saved %lld frames, score kept %d",
          saved, kept);
}

/* One closed-loop walk from the capture's first viewpoint (a quarter turn and a climb from
 * v*), 5 frames a second (the person reacts within 0.3 s, so 2 frames). */
static void check_follow(const char *ws, const char *dir)
{
    char video[2 * VF_PATH_MAX], path[3 * VF_PATH_MAX];
    snprintf(video, sizeof video, "%s/follow.mp4", dir);
    double start = vf_now();
    int rc = vf_test_system("'%s' simulate reshoot '%s' --target 0 --follow --starts 1 --fps 5 "
                            "--give-up 20 --hold-seconds 1 --tolerance 10 " PHONE " -o '%s' -q",
                            tool(), ws, video);
    CHECK(rc == 0, "simulate reshoot --follow exit %d", rc);
    snprintf(path, sizeof path, "%s/follow.truth.json", dir);
    json_t *truth = rc == 0 ? load_json(path) : NULL;
    const json_t *w = json_array_get(json_object_get(truth, "walks"), 0);
    CHECK(w != NULL, "the closed loop's walk");
    if (!w) {
        json_decref(truth);
        return;
    }
    long long on = json_integer_value(json_object_get(w, "on_target_frames"));
    long long in = json_integer_value(json_object_get(w, "on_target_truly_in_box"));
    long long wrong = json_integer_value(json_object_get(w, "wrong_way_frames"));
    long long localized = json_integer_value(json_object_get(w, "localized"));
    double seconds = json_number_value(json_object_get(w, "seconds_to_on_target"));
    printf("follow: on target after %.1f s, %lld of %lld frames called on target truly in the "
           "box, advice the wrong way on %lld of %lld localized frames (%.0f s)\n",
           seconds, in, on, wrong, localized, vf_now() - start);
    /* measured (10 fps, 20 s): on target after 6.7 s, 10 of 10 truly in, 0 of 78 wrong */
    CHECK(json_is_true(json_object_get(w, "reached")), "the person reached the target");
    CHECK(seconds > 0 && seconds < 15, "on target after %.1f s", seconds);
    CHECK(4 * in >= 3 * on, "%lld of %lld frames called on target truly in the box", in, on);
    CHECK(10 * wrong <= localized, "advice the wrong way on %lld of %lld frames", wrong,
          localized);
    json_decref(truth);
}

int main(int argc, char **argv)
{
    char dir[VF_PATH_MAX], ws[2 * VF_PATH_MAX], capture[2 * VF_PATH_MAX], reshoot[2 * VF_PATH_MAX],
        path[3 * VF_PATH_MAX];
    snprintf(dir, sizeof dir, "%s", argc > 1 ? argv[1] : vf_test_tmpdir());
    snprintf(ws, sizeof ws, "%s/ws", dir);
    snprintf(capture, sizeof capture, "%s/capture.mp4", dir);
    snprintf(reshoot, sizeof reshoot, "%s/reshoot.mp4", dir);

    double start = vf_now();
    int rc = vf_is_file(capture)
                 ? 0
                 : vf_test_system("'%s' simulate capture '%s' -o '%s' --size 270x480 --fps %d "
                                  "--shutter 0.1 --loop-seconds %d " PHONE " -q",
                                  tool(), vf_test_shared(MODEL), capture, FPS, LOOP_SECONDS);
    CHECK(rc == 0, "simulate capture exit %d", rc);
    printf("simulate capture: %.0f s\n", vf_now() - start);
    start = vf_now();
    if (rc == 0 && !vf_is_dir(ws))
        rc = vf_test_system("'%s' ingest '%s' -o '%s' --frames 50 -q && '%s' poses '%s' "
                            "--matcher exhaustive --camera-model SIMPLE_RADIAL -q",
                            tool(), capture, ws, tool(), ws);
    CHECK(rc == 0, "ingest and poses exit %d", rc);
    printf("ingest and poses: %.0f s\n", vf_now() - start);
    snprintf(path, sizeof path, "%s/capture.truth.json", dir);
    json_t *truth = load_json(path);
    CHECK(truth && json_array_size(json_object_get(truth, "frames")) == 2 * FPS * LOOP_SECONDS,
          "the truth has a pose for each of the %d frames", 2 * FPS * LOOP_SECONDS);
    if (!truth)
        return check_finish();
    check_capture_poses(ws, truth);
    json_decref(truth);

    vf_viewpoint v_star;
    write_attack(ws, &v_star);
    rc = vf_test_system("'%s' export '%s' --count 2 -q >/dev/null", tool(), ws);
    CHECK(rc == 0, "export exit %d", rc);
    start = vf_now();
    /* 1.5 s of walking and 1 s of filming at v*: 38 frames, 25 of them in the box (a hold of
     * 1.5 s: 45 frames, 32 in the box, and 27 s more of Blender alone on 2 cores) */
    rc = vf_test_system("'%s' simulate reshoot '%s' --target 0 -o '%s' --walk-seconds 1.5 "
                        "--hold-seconds 1 --jitter 3 " PHONE " -q",
                        tool(), ws, reshoot);
    CHECK(rc == 0, "simulate reshoot exit %d", rc);
    printf("simulate reshoot: %.0f s\n", vf_now() - start);
    snprintf(path, sizeof path, "%s/reshoot.truth.json", dir);
    truth = load_json(path);
    CHECK(truth != NULL, "the re-shoot's truth");
    if (!truth)
        return check_finish();
    int kept = check_score(ws, reshoot, truth);
    check_reshoot(ws, reshoot, kept);
    json_decref(truth);
    check_follow(ws, dir);
    return check_finish();
}
