/* A phone video through `vfcapture ingest` and `vfcapture poses`, then a video COLMAP cannot
 * register.
 *   1. Every second fox photo (25) becomes an H.264 MP4 stored sideways with a "turn 90
 *      clockwise" flag, as phones write portrait video. ingest --frames 12 --max-size 640 must
 *      read the flag (portrait 360x640 frames) and keep the sharpest frame of each of 12
 *      equal stretches.
 *   2. poses (self-calibrating, exhaustive matching) registers all 12 frames; after a
 *      similarity alignment they agree with instant-ngp's poses of the same photos, which
 *      also proves the frames came out upright. A short training on them is supervised by
 *      the sparse points each frame sees (and not with --depth 0).
 *   3. A noise video ingested into the same workspace: poses fails with one line saying why,
 *      exit 1, and the workspace (the good poses included) stays byte for byte as it was. */
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "check.h"
#include "poses_helpers.h"
#include "vf/dataset.h"

#define FOX "data/real_captures/instant_ngp_fox"
#define SOURCE_EVERY 2 /* video frame i is fox photo SOURCE_EVERY * i */
#define KEEP 12

static char tmp[VF_PATH_MAX - 256], ws[VF_PATH_MAX];

static int run_tool(const char *args)
{
    const char *tool = getenv("VF_TOOL");
    return vf_test_system("'%s' %s >'%s/out.txt' 2>'%s/err.txt'", tool ? tool : "vfcapture",
                          args, tmp, tmp);
}

/* 1. The video and its ingest; returns the report (chosen video frame indices, file names). */
static json_t *ingest_video(void)
{
    int rc = vf_test_system(
        "mkdir -p %s/frames && i=0 && for f in $(ls %s/images/*.jpg | awk 'NR %% %d == 1'); do "
        "ln -s $f %s/frames/$(printf %%03d $i).jpg; i=$((i+1)); done && "
        "ffmpeg -loglevel error -y -framerate 10 -i %s/frames/%%03d.jpg -vf transpose=cclock "
        "-c:v libx264 -preset ultrafast -crf 16 -pix_fmt yuv420p %s/sideways.mp4 && "
        "ffmpeg -loglevel error -y -i %s/sideways.mp4 -c copy -metadata:s:v:0 rotate=270 "
        "%s/phone.mp4",
        tmp, vf_test_shared(FOX), SOURCE_EVERY, tmp, tmp, tmp, tmp, tmp);
    CHECK(rc == 0, "ffmpeg made the phone video");
    char args[3 * VF_PATH_MAX];
    snprintf(args, sizeof args, "ingest '%s/phone.mp4' -o '%s' --frames %d --max-size 640 --quiet",
             tmp, ws, KEEP);
    double start = vf_now();
    rc = run_tool(args);
    printf("ingest of 25 frames 960x540 (rotated): %.2f s\n", vf_now() - start);
    CHECK(rc == 0, "ingest exit %d", rc);
    char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, ws, "ingest/report.json");
    json_t *report = load_json(path);
    CHECK(report != NULL, "ingest report");
    if (!report)
        return NULL;
    json_t *rotation = json_object_get(report, "rotation");
    CHECK(json_integer_value(json_object_get(rotation, "clockwise_degrees")) == 90,
          "rotation flag read");
    CHECK(json_integer_value(json_object_get(report, "output_width")) == 360 &&
              json_integer_value(json_object_get(report, "output_height")) == 640,
          "portrait frames shrunk to 360x640");

    /* Each kept frame is the sharpest of its stretch (no frame here is blurry or repeated). */
    json_t *chosen = json_object_get(report, "chosen");
    json_t *sharp = json_object_get(report, "sharpness");
    int n = (int)json_array_size(chosen), total = (int)json_array_size(sharp), wrong = 0;
    CHECK(n == KEEP && total == 25, "%d of %d frames kept", n, total);
    for (int k = 0; k < n && total == 25; k++) {
        int lo = k * total / KEEP, hi = (k + 1) * total / KEEP, best = lo;
        for (int i = lo; i < hi; i++)
            if (json_real_value(json_array_get(sharp, i)) >
                json_real_value(json_array_get(sharp, best)))
                best = i;
        wrong += json_integer_value(json_array_get(chosen, k)) != best;
    }
    CHECK(wrong == 0, "%d kept frames are not the sharpest of their stretch", wrong);
    return report;
}

/* 2. poses, and the comparison with instant-ngp's poses of the same photos. */
static void poses_of_video(const json_t *report)
{
    char out[VF_PATH_MAX], err[VF_PATH_MAX];
    vf_path_join(out, sizeof out, tmp, "poses.json");
    vf_path_join(err, sizeof err, tmp, "poses.err");
    double seconds;
    int rc = run_poses(ws, "--json", out, err, &seconds);
    CHECK(rc == 0, "poses exit %d (stderr in %s)", rc, err);
    json_t *summary = load_json(out);
    printf("poses of %d frames: %.1f s, registered %lld, %lld model(s), reprojection %.3f px\n",
           KEEP, seconds, json_integer_value(json_object_get(summary, "registered")),
           json_integer_value(json_object_get(summary, "models")),
           json_number_value(json_object_get(summary, "reprojection_error_px")));
    CHECK(json_integer_value(json_object_get(summary, "registered")) == KEEP, "all registered");
    CHECK(json_integer_value(json_object_get(summary, "models")) == 1, "one model");
    CHECK(json_number_value(json_object_get(summary, "reprojection_error_px")) < 1.0,
          "reprojection error under 1 px");
    json_decref(summary);

    vf_dataset ours, ref;
    char path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, ws, "poses/transforms.json");
    CHECK(vf_dataset_load(path, &ours) == VF_OK, "our poses: %s", vf_error_message());
    CHECK(vf_dataset_load(vf_test_shared(FOX "/transforms.json"), &ref) == VF_OK, "reference");
    const double *mine[KEEP], *theirs[KEEP];
    int matched = 0;
    json_t *files = json_object_get(report, "files"), *chosen = json_object_get(report, "chosen");
    for (int i = 0; i < ours.count && ours.count == KEEP; i++)
        for (int k = 0; k < KEEP; k++) {
            const char *file = json_string_value(json_array_get(files, k));
            if (!file || !strstr(ours.frames[i].image_path, file))
                continue;
            /* Video frame j is the photo tmp/frames/<j>.jpg links to. */
            char link[VF_PATH_MAX], photo[VF_PATH_MAX] = "", name[256], other[256];
            snprintf(link, sizeof link, "%s/frames/%03d.jpg", tmp,
                     (int)json_integer_value(json_array_get(chosen, k)));
            ssize_t len = readlink(link, photo, sizeof photo - 1);
            photo[len > 0 ? len : 0] = '\0';
            vf_path_basename(name, sizeof name, photo, 0);
            for (int r = 0; r < ref.count; r++) {
                vf_path_basename(other, sizeof other, ref.frames[r].image_path, 0);
                if (!strcmp(name, other)) {
                    mine[matched] = ours.frames[i].c2w;
                    theirs[matched++] = ref.frames[r].c2w;
                }
            }
        }
    CHECK(matched == KEEP, "every frame matched to its photo (%d)", matched);
    if (matched == KEEP) {
        vf_pose_agreement e = compare_poses(mine, theirs, matched);
        printf("against the reference: rotation median %.3f deg, p90 %.3f deg; position median "
               "%.3f%%, p90 %.3f%%\n",
               e.rot_median, e.rot_p90, 100 * e.pos_median, 100 * e.pos_p90);
        CHECK(e.rot_median < 1.5 && e.rot_p90 < 2.5, "rotations agree (%.3f, %.3f deg)",
              e.rot_median, e.rot_p90);
        CHECK(e.pos_median < 0.02 && e.pos_p90 < 0.04, "positions agree (%.4f, %.4f)",
              e.pos_median, e.pos_p90);
    }
    vf_dataset_free(&ours);
    vf_dataset_free(&ref);
}

/* 2b. A short training on those poses: the sparse points each frame sees supervise the
 * field's depth (report.json counts their sightings), and --depth 0 turns that off; the
 * opaque frames get the distortion loss. */
static void train_on_points(void)
{
    char args[2 * VF_PATH_MAX], path[VF_PATH_MAX];
    vf_path_join(path, sizeof path, ws, "train/report.json");
    const double weights[2] = {-1, 0}; /* the default, then off */
    for (int k = 0; k < 2; k++) {
        snprintf(args, sizeof args, "train '%s' --train-steps 30 --holdout 0 --restart --quiet%s", ws,
                 k ? " --depth 0" : "");
        CHECK(run_tool(args) == 0, "train (%s) exit 0 (stderr in %s/err.txt)",
              k ? "--depth 0" : "default", tmp);
        json_t *report = load_json(path);
        const long long points = json_integer_value(json_object_get(report, "depth_points"));
        printf("train, depth weight %s: %lld sightings of sparse points\n",
               weights[k] < 0 ? "default" : "0", points);
        if (k == 0) {
            CHECK(points >= 30 * KEEP, "each frame's sparse points supervise its depth (%lld)",
                  points);
            const double distortion = json_real_value(json_object_get(report, "distortion"));
            CHECK(fabs(distortion - 0.01) < 1e-6, /* stored as a float */
                  "opaque frames get the distortion loss (weight %g)", distortion);
        } else
            CHECK(points == 0 && report, "--depth 0: no depth supervision (%lld)", points);
        json_decref(report);
    }
}

/* A listing of every file under ws with its checksum. */
static void snapshot(const char *name)
{
    vf_test_system("cd '%s' && find . -type f | sort | xargs md5sum >'%s/%s'", ws, tmp, name);
}

/* 3. Noise COLMAP cannot register. */
static void noise_video(void)
{
    int rc = vf_test_system("ffmpeg -loglevel error -y -f lavfi "
                            "-i color=c=gray:s=320x240:r=10:d=1.2 -vf noise=alls=100:allf=t+u "
                            "-c:v libx264 -preset ultrafast -pix_fmt yuv420p %s/noise.mp4",
                            tmp);
    CHECK(rc == 0, "ffmpeg made the noise video");
    char args[3 * VF_PATH_MAX];
    snprintf(args, sizeof args, "ingest '%s/noise.mp4' -o '%s' --quiet", tmp, ws);
    CHECK(run_tool(args) == 0, "noise ingested");
    snapshot("before.md5");
    snprintf(args, sizeof args, "poses '%s' --quiet", ws);
    setenv("TMPDIR", tmp, 1); /* the failed run keeps COLMAP's log there */
    double start = vf_now();
    rc = run_tool(args);
    printf("poses on noise failed in %.1f s\n", vf_now() - start);
    CHECK(rc == 1, "poses on noise: exit %d, wanted 1", rc);
    CHECK(vf_test_system("test $(grep -c . '%s/err.txt') -eq 1 && "
                         "grep -q 'registered only 0 of 12 frames' '%s/err.txt'",
                         tmp, tmp) == 0,
          "one line saying none of the 12 frames registered (see %s/err.txt)", tmp);
    snapshot("after.md5");
    CHECK(vf_test_system("cmp -s '%s/before.md5' '%s/after.md5' && grep -q "
                         "'poses/transforms.json' '%s/after.md5'",
                         tmp, tmp, tmp) == 0,
          "the workspace, earlier poses included, is as it was");
}

int main(void)
{
    snprintf(tmp, sizeof tmp, "%s", vf_test_tmpdir());
    vf_path_join(ws, sizeof ws, tmp, "ws");
    json_t *report = ingest_video();
    if (report) {
        poses_of_video(report);
        train_on_points();
    }
    json_decref(report);
    noise_video();
    return check_finish();
}
