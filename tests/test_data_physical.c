/* The physical loop on the instant-ngp fox (50 real phone photos, 540x960, with instant-ngp's
 * own COLMAP poses as reference). One poses run serves every check:
 *   - `poses` on 40 photos; `localize` the 10 left out; after a similarity alignment of the
 *     reference onto our object frame (on the 40 shared cameras), median rotation error under
 *     1 degree and position error under 2% of the camera radius; a photo of something else is
 *     reported as not localized;
 *   - `score` on a "recapture" video of all 50 photos (ffmpeg) against an attack.json whose v*
 *     is the viewpoint of a known frame: the kept / out-of-tolerance split matches the frames'
 *     known poses, and the success rate matches the real classifier's outputs on the kept
 *     frames; `score --summary` tabulates it;
 *   - `export`: targets.json maps v* back to COLMAP's frame exactly (the pose COLMAP gave
 *     that frame), with CSV and shot card;
 *   - `reshoot --video` on the same video saves exactly the frames on target, and keeps them
 *     when the input breaks after them.
 * Give a workspace with poses as argv[1] to skip the COLMAP run. */
#include <jansson.h>
#include <stdlib.h>
#include <string.h>

#include "physical_helpers.h"
#include "check.h"
#include "poses_helpers.h"
#include "vf/classifier.h"
#include "vf/colmap_model.h"
#include "vf/dataset.h"
#include "vf/localize.h"
#include "vf/pose.h"
#include "vf/resources.h"
#include "vf/video.h"
#include "vf/wilson.h"
#include "vf/workspace.h"

#define FOX "data/real_captures/instant_ngp_fox"
#define HELD_OUT_EVERY 5   /* photos 4, 9, 14, ... (name order) are left out */
#define TOLERANCE 0.20     /* score's box: +-20% of each parameter's range */
#define V_STAR_FRAME "0012.jpg" /* a training frame: its viewpoint is v* */

static const char *tool(void)
{
    const char *t = getenv("VF_TOOL");
    return t ? t : "vfcapture";
}

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* The fox photos in name order (50 names, static storage). */
static int list_photos(char names[][64])
{
    DIR *dir = opendir(vf_test_shared(FOX "/images"));
    struct dirent *e;
    char *sorted[64];
    int n = 0;
    while (dir && (e = readdir(dir)) && n < 64)
        if (strstr(e->d_name, ".jpg"))
            sorted[n++] = strdup(e->d_name);
    if (dir)
        closedir(dir);
    qsort(sorted, (size_t)n, sizeof *sorted, compare_names);
    for (int i = 0; i < n; i++) {
        snprintf(names[i], 64, "%s", sorted[i]);
        free(sorted[i]);
    }
    return n;
}

static int held_out(int i)
{
    return i % HELD_OUT_EVERY == HELD_OUT_EVERY - 1;
}

/* A workspace whose ingest stage holds the 40 training photos. */
static int make_workspace(const char *ws, char names[][64], int n)
{
    char src[VF_PATH_MAX];
    snprintf(src, sizeof src, "%s/train_photos", vf_test_tmpdir());
    vf_mkdirs(src);
    for (int i = 0; i < n; i++)
        if (!held_out(i))
            vf_test_system("ln -s '%s/%s' '%s/%s'", vf_test_shared(FOX "/images"), names[i], src,
                           names[i]);
    return make_ingested_workspace(ws, src, 0);
}

/* The frame of `ds` whose image name ends with `name`, or NULL. */
static const vf_frame *find_frame(const vf_dataset *ds, const char *name)
{
    size_t len = strlen(name);
    for (int i = 0; i < ds->count; i++) {
        const char *p = ds->frames[i].image_path;
        size_t plen = strlen(p);
        if (plen >= len && !strcmp(p + plen - len, name))
            return &ds->frames[i];
    }
    return NULL;
}

/* Known poses of all 50 photos in our object frame: the reference (instant-ngp's COLMAP run)
 * moved by the similarity that best maps its training cameras' centres onto ours (`aligned`).
 * The two runs also disagree on the principal point (instant-ngp refined it, ours keeps the
 * image centre), which turns every camera by the same small rotation Q in its own frame; Q is
 * measured on the training cameras and `known` applies it: training frames get our own poses,
 * held-out frames the aligned reference turned by Q. */
static void known_poses(const vf_dataset *ours, const vf_dataset *ref, char names[][64], int n,
                        double (*aligned)[16], double (*known)[16])
{
    double *src = malloc(sizeof(double) * 3 * n), *dst = malloc(sizeof(double) * 3 * n);
    int m = 0;
    for (int i = 0; i < n; i++) {
        const vf_frame *a = find_frame(ours, names[i]), *b = find_frame(ref, names[i]);
        if (a && b) {
            vf_mat4_translation(b->c2w, src + 3 * m);
            vf_mat4_translation(a->c2w, dst + 3 * m);
            m++;
        }
    }
    vf_similarity align;
    CHECK(m == n - n / HELD_OUT_EVERY, "training cameras in both sets: %d", m);
    CHECK(vf_similarity_umeyama(src, dst, m, &align) == VF_OK, "alignment: %s",
          vf_error_message());
    double sum[9] = {0}, Q[9];
    for (int i = 0; i < n; i++) {
        const vf_frame *a = find_frame(ours, names[i]), *b = find_frame(ref, names[i]);
        CHECK(b != NULL, "reference has %s", names[i]);
        if (!b)
            continue;
        vf_similarity_apply_c2w(&align, b->c2w, aligned[i]);
        if (!a)
            continue;
        double Ra[9], Rb[9], Rbt[9], d[9];
        vf_mat4_rotation(a->c2w, Ra);
        vf_mat4_rotation(aligned[i], Rb);
        vf_mat3_transpose(Rb, Rbt);
        vf_mat3_mul(Rbt, Ra, d);
        for (int k = 0; k < 9; k++)
            sum[k] += d[k];
    }
    vf_rot_orthonormalize(sum, Q);
    double I[9];
    vf_mat3_identity(I);
    printf("our COLMAP run vs the reference: cameras turned by %.3f deg in their own frame "
           "(principal point), the same for all\n",
           vf_rot_angle_deg(Q, I));
    for (int i = 0; i < n; i++) {
        const vf_frame *a = find_frame(ours, names[i]);
        double R[9], RQ[9], t[3];
        if (a) {
            memcpy(known[i], a->c2w, sizeof known[i]);
            continue;
        }
        vf_mat4_rotation(aligned[i], R);
        vf_mat4_translation(aligned[i], t);
        vf_mat3_mul(R, Q, RQ);
        vf_mat4_from_rt(RQ, t, known[i]);
    }
    free(src);
    free(dst);
}

static void read_mat4(const json_t *rows, double m[16])
{
    for (int r = 0; r < 4; r++)
        for (int c = 0; c < 4; c++)
            m[4 * r + c] = json_number_value(json_array_get(json_array_get(rows, r), c));
}

static double position_error(const double a[16], const double b[16])
{
    double d = 0;
    for (int k = 0; k < 3; k++)
        d += (a[4 * k + 3] - b[4 * k + 3]) * (a[4 * k + 3] - b[4 * k + 3]);
    return sqrt(d);
}

/* `localize` the held-out photos; compare with the known poses. */
static void check_localize(const char *ws, char names[][64], int n, double (*aligned)[16],
                           double (*known)[16])
{
    char cmd[8192], out[VF_PATH_MAX], err[VF_PATH_MAX];
    snprintf(out, sizeof out, "%s/localize.json", vf_test_tmpdir());
    snprintf(err, sizeof err, "%s/localize.err", vf_test_tmpdir());
    int used = snprintf(cmd, sizeof cmd, "'%s' localize '%s' --json", tool(), ws);
    for (int i = 0; i < n; i++)
        if (held_out(i))
            used += snprintf(cmd + used, sizeof cmd - (size_t)used, " '%s/%s'",
                             vf_test_shared(FOX "/images"), names[i]);
    double start = vf_now();
    int rc = vf_test_system("%s >'%s' 2>'%s'", cmd, out, err);
    CHECK(rc == 0, "localize exit %d (stderr in %s)", rc, err);
    json_t *doc = load_json(out);
    json_t *frames = json_object_get(doc, "frames");
    int count = (int)json_array_size(frames), localized = 0, k = 0;
    CHECK(count == n / HELD_OUT_EVERY, "localize reports %d frames", count);
    double rot[16], pos[16], rot_q[16];
    for (int i = 0; i < n && k < count; i++) {
        if (!held_out(i))
            continue;
        json_t *f = json_array_get(frames, (size_t)k++);
        if (!json_is_true(json_object_get(f, "localized"))) {
            printf("%s: %s\n", names[i], json_string_value(json_object_get(f, "reason")));
            continue;
        }
        double c2w[16], Ra[9], Rb[9], Rq[9];
        read_mat4(json_object_get(f, "c2w_object"), c2w);
        vf_mat4_rotation(c2w, Ra);
        vf_mat4_rotation(aligned[i], Rb);
        vf_mat4_rotation(known[i], Rq);
        rot[localized] = vf_rot_angle_deg(Ra, Rb);
        rot_q[localized] = vf_rot_angle_deg(Ra, Rq);
        pos[localized] = position_error(c2w, aligned[i]) / VF_CAMERA_DISTANCE;
        printf("%s: %lld inliers, rotation error %.3f deg (%.3f deg after Q), position error "
               "%.2f%% of the radius\n",
               names[i], json_integer_value(json_object_get(f, "inliers")), rot[localized],
               rot_q[localized], 100 * pos[localized]);
        localized++;
    }
    double fps = json_number_value(json_object_get(doc, "frames_per_second"));
    printf("localized %d of %d held-out photos in %.1f s (%.1f frames/s of localization)\n",
           localized, count, vf_now() - start, fps);
    CHECK(localized == count, "every held-out photo localized (%d of %d)", localized, count);
    if (localized > 0) {
        double rot_med = quantile(rot, localized, 0.5), pos_med = quantile(pos, localized, 0.5);
        double rot_max = quantile(rot, localized, 1.0), pos_max = quantile(pos, localized, 1.0);
        double rot_q_med = quantile(rot_q, localized, 0.5);
        printf("median rotation error %.3f deg (max %.3f; %.3f deg once the principal-point "
               "turn Q is taken out), median position error %.2f%% (max %.2f%%)\n",
               rot_med, rot_max, rot_q_med, 100 * pos_med, 100 * pos_max);
        CHECK(rot_q_med < 0.5, "median rotation error after Q %.3f deg", rot_q_med);
        CHECK(rot_med < 1.0, "median rotation error %.3f deg", rot_med);
        CHECK(pos_med < 0.02, "median position error %.4f of the radius", pos_med);
        CHECK(rot_max < 2.0 && pos_max < 0.04, "worst frame %.3f deg, %.4f", rot_max, pos_max);
    }
    json_decref(doc);
}

/* A photo of another object, at the capture's size, is not localized. */
static void check_not_localized(const char *ws)
{
    char img[VF_PATH_MAX], out[VF_PATH_MAX];
    snprintf(img, sizeof img, "%s/other.jpg", vf_test_tmpdir());
    snprintf(out, sizeof out, "%s/other.json", vf_test_tmpdir());
    int rc = vf_test_system("ffmpeg -loglevel error -y -i '%s' -vf scale=540:960 '%s'",
                            vf_test_shared("data/imagenet_samples/000_n01440764.jpg"), img);
    CHECK(rc == 0, "made an unrelated 540x960 photo");
    rc = vf_test_system("'%s' localize '%s' '%s' --json >'%s' 2>/dev/null", tool(), ws, img, out);
    CHECK(rc == 0, "localize on an unrelated photo exits 0 (%d)", rc);
    json_t *doc = load_json(out);
    json_t *f = json_array_get(json_object_get(doc, "frames"), 0);
    const char *reason = json_string_value(json_object_get(f, "reason"));
    CHECK(!json_is_true(json_object_get(f, "localized")) && reason &&
              strstr(reason, "not localized"),
          "unrelated photo: %s", reason ? reason : "(localized!)");
    if (reason)
        printf("unrelated photo: %s\n", reason);
    json_decref(doc);
}

/* attack.json: v* = the viewpoint of V_STAR_FRAME, fox labels, samples = the training
 * frames' viewpoints. */
static void write_attack(const char *ws, const vf_dataset *ours, vf_viewpoint *v_star)
{
    const vf_frame *f = find_frame(ours, V_STAR_FRAME);
    CHECK(f != NULL, "our poses have %s", V_STAR_FRAME);
    if (!f)
        return;
    vf_c2w_to_viewpoint(f->c2w, v_star);
    vf_viewpoint *samples = malloc(sizeof *samples * (size_t)ours->count);
    for (int i = 0; i < ours->count; i++)
        vf_c2w_to_viewpoint(ours->frames[i].c2w, &samples[i]);
    test_label_set fox = {4, {277, 278, 279, 280}, {"red fox", "kit fox", "Arctic fox", "grey fox"}};
    write_test_attack(ws, &fox, v_star, samples, ours->count);
    free(samples);
}

/* Box distance of a known pose from v* (as score measures it). */
static double box_distance(const double c2w[16], const vf_viewpoint *v_star)
{
    static const double range[6] = {360, 60, 140, 1, 2, 1};
    vf_viewpoint v;
    vf_c2w_to_viewpoint(c2w, &v);
    double a[6], c[6], worst = 0;
    vf_viewpoint_to_array(&v, a);
    vf_viewpoint_to_array(v_star, c);
    for (int i = 0; i < 6; i++) {
        double d = i == 0 ? remainder(a[i] - c[i], 360.0) : a[i] - c[i];
        worst = fmax(worst, fabs(d) / range[i]);
    }
    return worst;
}

/* The classifier's verdict on each frame of the video, independently of score. */
static int classify_video(const char *video, int *top, int max)
{
    char model[VF_PATH_MAX];
    vf_classifier *cls = NULL;
    vf_video *vid = NULL;
    vf_video_info info;
    if (vf_find_model(VF_DEFAULT_MODEL, NULL, model, sizeof model) != VF_OK ||
        vf_classifier_open(model, &cls) != VF_OK || vf_video_open(video, &vid, &info) != VF_OK)
        return -1;
    vf_rgb8 frame = {0};
    int got, n = 0;
    float *probs = malloc(sizeof(float) * VF_NUM_CLASSES);
    while (n < max && vf_video_read(vid, &frame, &got) == VF_OK && got) {
        vf_image img;
        vf_image_alloc(&img, frame.width, frame.height, 3);
        for (size_t i = 0; i < (size_t)frame.width * frame.height * 3; i++)
            img.data[i] = frame.data[i] / 255.0f;
        vf_classifier_classify_images(cls, &img, 1, probs);
        vf_topk(probs, 1, &top[n++], NULL);
        vf_image_free(&img);
    }
    free(probs);
    vf_rgb8_free(&frame);
    vf_video_close(vid);
    vf_classifier_close(cls);
    return n;
}

static int is_fox(int c)
{
    return c >= 277 && c <= 280;
}

/* `score` the recapture video; returns the number of frames kept. */
static int check_score(const char *ws, const char *video, double (*known)[16], int n,
                       const vf_viewpoint *v_star)
{
    char out[VF_PATH_MAX], err[VF_PATH_MAX];
    snprintf(out, sizeof out, "%s/score.json", vf_test_tmpdir());
    snprintf(err, sizeof err, "%s/score.err", vf_test_tmpdir());
    double start = vf_now();
    int rc = vf_test_system("'%s' score '%s' '%s' --tolerance %g --json >'%s' 2>'%s'", tool(), ws,
                            video, 100 * TOLERANCE, out, err);
    CHECK(rc == 0, "score exit %d (stderr in %s)", rc, err);
    printf("score took %.1f s\n", vf_now() - start);
    char path[2 * VF_PATH_MAX];
    snprintf(path, sizeof path, "%s/score/score.json", ws);
    json_t *doc = load_json(path);
    json_t *frames = json_object_get(doc, "frames_detail");
    CHECK((int)json_array_size(frames) == n, "score saw %zu frames of %d",
          json_array_size(frames), n);
    int top[64];
    int classified = classify_video(video, top, 64);
    CHECK(classified == n, "classified %d video frames", classified);
    int kept = 0, fooled = 0, agree = 0, ambiguous = 0, localized = 0;
    for (int i = 0; i < n && i < (int)json_array_size(frames); i++) {
        json_t *f = json_array_get(frames, (size_t)i);
        const char *status = json_string_value(json_object_get(f, "status"));
        int is_kept = !strcmp(status, "kept");
        localized += is_kept || !strcmp(status, "out of tolerance");
        double d = box_distance(known[i], v_star);
        int expect = d <= TOLERANCE;
        if (fabs(d - TOLERANCE) < 0.15 * TOLERANCE)
            ambiguous++; /* within localization noise of the box's edge */
        else {
            agree += expect == is_kept;
            CHECK(expect == is_kept, "frame %d: known box distance %.3f, score says %s", i, d,
                  status);
        }
        if (is_kept) {
            kept++;
            fooled += !is_fox(top[i]);
            CHECK(json_integer_value(json_object_get(f, "class")) == top[i],
                  "frame %d: score's class %lld, the classifier's %d", i,
                  json_integer_value(json_object_get(f, "class")), top[i]);
        }
    }
    json_t *k = json_object_get(doc, "kept");
    long long asr_k = json_integer_value(json_object_get(k, "misclassified"));
    long long asr_n = json_integer_value(json_object_get(k, "frames"));
    double lo, hi;
    vf_wilson_interval(fooled, kept, VF_Z95, &lo, &hi);
    printf("score: %d of %d frames localized; kept %lld, %lld misclassified (ASR %.1f%%, 95%% "
           "interval %.1f%% to %.1f%%); %d frames agree with their known poses, %d at the box "
           "edge\n",
           localized, n, asr_n, asr_k, 100 * json_number_value(json_object_get(k, "asr")),
           100 * json_number_value(json_array_get(json_object_get(k, "interval95"), 0)),
           100 * json_number_value(json_array_get(json_object_get(k, "interval95"), 1)), agree,
           ambiguous);
    CHECK(localized == n, "every recaptured frame localized (%d of %d)", localized, n);
    CHECK(kept >= 5 && n - kept >= 20, "a real split: %d kept of %d", kept, n);
    CHECK(ambiguous <= 6, "%d frames at the box edge", ambiguous);
    CHECK(asr_n == kept && asr_k == fooled, "ASR %lld/%lld, the classifier says %d/%d", asr_k,
          asr_n, fooled, kept);
    CHECK_NEAR(json_number_value(json_array_get(json_object_get(k, "interval95"), 0)), lo, 1e-9);
    CHECK_NEAR(json_number_value(json_array_get(json_object_get(k, "interval95"), 1)), hi, 1e-9);
    json_decref(doc);

    /* --summary: one row for this workspace, with the same counts. */
    snprintf(out, sizeof out, "%s/summary.csv", vf_test_tmpdir());
    rc = vf_test_system("'%s' score --summary '%s' --csv '%s' >'%s.md' 2>'%s'", tool(), ws, out,
                        out, err);
    CHECK(rc == 0, "score --summary exit %d", rc);
    char *csv = NULL;
    size_t size;
    char expect[64];
    snprintf(expect, sizeof expect, ",%d,%d\n", fooled, kept);
    CHECK(vf_read_file(out, &csv, &size) == VF_OK && strstr(csv, expect),
          "summary CSV ends its row with %s", expect);
    free(csv);
    return kept;
}

/* `score` where no frame falls in the box (3 photos, a box of 0.01% of each range): no rate
 * (the old code reported "0.0% ... 0/0"), one line saying so, exit 1, and the finished score
 * of the whole video is kept. */
static void check_score_no_frames(const char *ws, char names[][64], int n)
{
    char dir[VF_PATH_MAX], err[VF_PATH_MAX], path[2 * VF_PATH_MAX];
    snprintf(dir, sizeof dir, "%s/three_photos", vf_test_tmpdir());
    snprintf(err, sizeof err, "%s/score_none.err", vf_test_tmpdir());
    int rc = vf_test_system("mkdir -p '%s' && cp '%s/%s' '%s/%s' '%s/%s' '%s/'", dir,
                            vf_test_shared(FOX "/images"), names[0], vf_test_shared(FOX "/images"),
                            names[n / 2], vf_test_shared(FOX "/images"), names[n - 1], dir);
    CHECK(rc == 0, "made the three-photo folder");
    rc = vf_test_system("'%s' score -q '%s' '%s' --tolerance 0.01 >/dev/null 2>'%s'", tool(), ws,
                        dir, err);
    char *text = NULL;
    CHECK(rc == 1, "no frame in the box exits 1 (%d)", rc);
    int lines = 0;
    if (vf_read_file(err, &text, NULL) == VF_OK && text)
        for (const char *c = text; *c; c++)
            lines += *c == '\n';
    CHECK(text && lines == 1 && strstr(text, "no measurement") && !strstr(text, "0.0%"),
          "one line, no rate: %s", text ? text : "?");
    free(text);
    snprintf(path, sizeof path, "%s/score/score.json", ws);
    json_t *doc = load_json(path);
    CHECK((int)json_array_size(json_object_get(doc, "frames_detail")) == n,
          "the score of the whole video is kept (%zu frames)",
          json_array_size(json_object_get(doc, "frames_detail")));
    json_decref(doc);
}

/* `export`: v* maps back to the COLMAP pose of its frame; CSV and shot card written. */
static void check_export(const char *ws)
{
    char out[VF_PATH_MAX], path[2 * VF_PATH_MAX];
    snprintf(out, sizeof out, "%s/export.json", vf_test_tmpdir());
    int rc = vf_test_system("'%s' export '%s' --count 4 --json >'%s' 2>/dev/null", tool(), ws,
                            out);
    CHECK(rc == 0, "export exit %d", rc);
    json_t *doc = load_json(out);
    json_t *targets = json_object_get(doc, "targets");
    CHECK(json_array_size(targets) == 5, "v* and 4 samples: %zu targets",
          json_array_size(targets));
    double c2w[16];
    read_mat4(json_object_get(json_array_get(targets, 0), "c2w_colmap"), c2w);
    vf_colmap_model model;
    snprintf(path, sizeof path, "%s/poses/sparse", ws);
    CHECK(vf_colmap_model_load(path, &model) == VF_OK, "sparse model");
    double worst = -1;
    for (int i = 0; i < model.image_count; i++)
        if (strstr(model.images[i].name, V_STAR_FRAME)) {
            double colmap[16];
            vf_colmap_image_c2w(&model.images[i], colmap);
            worst = 0;
            for (int k = 0; k < 16; k++)
                worst = fmax(worst, fabs(colmap[k] - c2w[k]));
        }
    vf_colmap_model_free(&model);
    CHECK(worst >= 0 && worst < 1e-6, "v* in COLMAP's frame is the frame's COLMAP pose (off by %g)",
          worst);
    /* v* is that frame's pose: no gap to the photos, the frame its nearest photo */
    const json_t *trust = json_object_get(json_array_get(targets, 0), "trust");
    const char *nearest = json_string_value(json_object_get(trust, "nearest_photo"));
    CHECK(json_number_value(json_object_get(trust, "gap_deg")) < 1e-3 &&
              json_is_true(json_object_get(trust, "trusted")) && nearest &&
              strstr(nearest, V_STAR_FRAME),
          "v*'s trust: %.3g deg from %s", json_number_value(json_object_get(trust, "gap_deg")),
          nearest ? nearest : "?");
    json_t *words = json_object_get(json_array_get(targets, 0), "words");
    printf("v* in words: azimuth %.1f deg, elevation %.1f deg, distance %.2f, roll %.1f deg\n",
           json_number_value(json_object_get(words, "azimuth_deg")),
           json_number_value(json_object_get(words, "elevation_deg")),
           json_number_value(json_object_get(words, "distance")),
           json_number_value(json_object_get(words, "roll_deg")));
    json_decref(doc);
    const char *files[] = {"targets.json", "targets.csv", "shot_card.png"};
    for (int i = 0; i < 3; i++) {
        snprintf(path, sizeof path, "%s/export/%s", ws, files[i]);
        CHECK(vf_is_file(path), "%s exists", path);
    }
}

/* `reshoot --video`: without smoothing, the frames saved are exactly score's kept frames. */
static void check_reshoot(const char *ws, const char *video, int kept)
{
    const char *advice;
    long long saved = reshoot_video(tool(), ws, video, TOLERANCE, &advice);
    printf("reshoot: %lld frames saved; first advice: %s\n", saved, advice);
    CHECK(saved == kept, "reshoot saved %lld frames, score kept %d", saved, kept);
    CHECK(strlen(advice) > 5, "advice given");
    char path[2 * VF_PATH_MAX];
    snprintf(path, sizeof path, "%s/reshoot_t00/frames/frame_00000.png", ws);
    CHECK(kept == 0 || vf_is_file(path), "%s saved", path);
}

/* A capture that fails part-way (here a broken image after the video) keeps the frames already
 * on target: exit 1 with one line saying so, and the stage is committed with stopped_early. */
static void check_reshoot_stops(const char *ws, const char *video, int kept)
{
    char dir[VF_PATH_MAX], path[2 * VF_PATH_MAX], err[VF_PATH_MAX];
    snprintf(dir, sizeof dir, "%s/interrupted", vf_test_tmpdir());
    snprintf(err, sizeof err, "%s/reshoot_stops.err", vf_test_tmpdir());
    int rc = vf_test_system("mkdir -p '%s' && ln -sf '%s' '%s/a.mp4' && echo broken >'%s/zz.png'",
                            dir, video, dir, dir);
    CHECK(rc == 0, "made the failing input");
    rc = vf_test_system("'%s' reshoot '%s' --target 0 --video '%s' --tolerance %g --smoothing 1 "
                        ">/dev/null 2>'%s'",
                        tool(), ws, dir, 100 * TOLERANCE, err);
    CHECK(rc == 1, "a capture that fails part-way exits 1 (%d)", rc);
    char *text = NULL;
    CHECK(vf_read_file(err, &text, NULL) == VF_OK && text && strstr(text, "zz.png") &&
              strstr(text, "are kept in"),
          "one line naming the bad frame and the frames kept: %s", text ? text : "?");
    free(text);
    snprintf(path, sizeof path, "%s/reshoot_t00/poses.json", ws);
    json_t *doc = load_json(path);
    CHECK(json_is_string(json_object_get(doc, "stopped_early")), "poses.json says it stopped");
    CHECK((int)json_array_size(json_object_get(doc, "frames")) == kept,
          "the %d frames on target are kept (%zu)", kept,
          json_array_size(json_object_get(doc, "frames")));
    json_decref(doc);
}

int main(int argc, char **argv)
{
    char names[64][64], ws[VF_PATH_MAX], path[2 * VF_PATH_MAX], video[VF_PATH_MAX];
    int n = list_photos(names);
    CHECK(n == 50, "50 fox photos (%d)", n);
    if (argc > 1) {
        snprintf(ws, sizeof ws, "%s", argv[1]);
    } else {
        snprintf(ws, sizeof ws, "%s/fox40", vf_test_tmpdir());
        CHECK(make_workspace(ws, names, n) == n - n / HELD_OUT_EVERY, "workspace of 40 photos");
        double seconds;
        snprintf(path, sizeof path, "%s/poses", vf_test_tmpdir());
        int rc = run_poses(ws, "--no-undistort --max-features 1024 --matcher sequential "
                               "--overlap 8 --json",
                           "/dev/null", path, &seconds);
        CHECK(rc == 0, "poses exit %d (stderr in %s)", rc, path);
        printf("poses on 40 photos took %.1f s\n", seconds);
    }
    vf_dataset ours, ref;
    snprintf(path, sizeof path, "%s/poses/transforms.json", ws);
    CHECK(vf_dataset_load(path, &ours) == VF_OK, "our poses: %s", vf_error_message());
    CHECK(vf_dataset_load(vf_test_shared(FOX "/transforms.json"), &ref) == VF_OK, "reference");
    if (check_failed)
        return check_finish();
    CHECK(ours.count == n - n / HELD_OUT_EVERY, "all 40 registered (%d)", ours.count);

    double(*aligned)[16] = malloc(sizeof *aligned * (size_t)n);
    double(*known)[16] = malloc(sizeof *known * (size_t)n);
    known_poses(&ours, &ref, names, n, aligned, known);
    check_localize(ws, names, n, aligned, known);
    check_not_localized(ws);

    vf_viewpoint v_star;
    write_attack(ws, &ours, &v_star);
    snprintf(video, sizeof video, "%s/recapture.mp4", vf_test_tmpdir());
    int rc = vf_test_system("ffmpeg -loglevel error -y -framerate 5 -pattern_type glob -i "
                            "'%s/*.jpg' -c:v libx264 -crf 18 -pix_fmt yuv420p '%s'",
                            vf_test_shared(FOX "/images"), video);
    CHECK(rc == 0, "made the recapture video");
    int kept = check_score(ws, video, known, n, &v_star);
    check_score_no_frames(ws, names, n);
    check_export(ws);
    check_reshoot(ws, video, kept);
    check_reshoot_stops(ws, video, kept);

    free(aligned);
    free(known);
    vf_dataset_free(&ours);
    vf_dataset_free(&ref);
    return check_finish();
}
