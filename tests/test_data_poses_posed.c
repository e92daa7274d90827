/* `vfcapture poses` on a posed set: 17 of the instant-ngp fox's photos (every third, 540x960,
 * with instant-ngp's poses and lens) imported with `ingest --transforms`. The stage keeps the
 * set's poses and camera and only triangulates points at them: every frame is in the model,
 * the poses agree with the set's to numerical precision (after the similarity of the object
 * frame), COLMAP's lens is the set's, the points reproject within a pixel and every photo
 * sees 100 or more of them, all in front of it (what training's depth loss reads); the set's
 * own frames moved as eval moves a set's test set land on the stage's. A set that
 * brings its camera refuses another one (--intrinsics), and poses in OpenCV's axes are found
 * not to fit the photos, each in one line. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "poses_helpers.h"
#include "vf/colmap_model.h"
#include "vf/dataset.h"
#include "vf/pose.h"
#include "vf/poses.h"

#define FOX "data/real_captures/instant_ngp_fox"
#define FRAMES 17 /* of 50 */

/* The fox's transforms.json with every `every`-th frame, image paths made absolute; `flip`
 * turns the poses into OpenCV's camera axes (a common mistake: y down, looking along +z). */
static void write_subset(const char *path, int every, int flip)
{
    json_t *doc = load_json(vf_test_shared(FOX "/transforms.json"));
    CHECK(doc != NULL, "the fox's transforms.json loads");
    json_t *frames = json_object_get(doc, "frames"), *kept = json_array();
    for (size_t i = 0; i < json_array_size(frames); i += (size_t)every) {
        json_t *f = json_deep_copy(json_array_get(frames, i));
        char file[VF_PATH_MAX];
        snprintf(file, sizeof file, "%s/%s", vf_test_shared(FOX),
                 json_string_value(json_object_get(f, "file_path")));
        json_object_set_new(f, "file_path", json_string(file));
        json_t *m = json_object_get(f, "transform_matrix");
        for (size_t r = 0; flip && r < 3; r++)
            for (size_t c = 1; c < 3; c++) {
                json_t *row = json_array_get(m, r);
                json_array_set_new(row, c, json_real(-json_number_value(json_array_get(row, c))));
            }
        json_array_append_new(kept, f);
    }
    json_object_set_new(doc, "frames", kept);
    CHECK(json_dump_file(doc, path, JSON_INDENT(1)) == 0, "wrote %s", path);
    json_decref(doc);
}

/* The file holds one line, and it says `what`. */
static int one_line_saying(const char *path, const char *what)
{
    char text[4096] = "";
    FILE *f = fopen(path, "r");
    size_t n = f ? fread(text, 1, sizeof text - 1, f) : 0;
    if (f)
        fclose(f);
    text[n] = '\0';
    char *newline = strchr(text, '\n');
    printf("error: %s", text);
    return strstr(text, what) && newline && !newline[1];
}

int main(void)
{
    char dir[VF_PATH_MAX], set_path[VF_PATH_MAX], ws[VF_PATH_MAX], out[VF_PATH_MAX],
        err[VF_PATH_MAX], path[VF_PATH_MAX];
    snprintf(dir, sizeof dir, "%s", vf_test_tmpdir());
    vf_path_join(set_path, sizeof set_path, dir, "set.json");
    vf_path_join(ws, sizeof ws, dir, "fox");
    vf_path_join(out, sizeof out, dir, "out.json");
    vf_path_join(err, sizeof err, dir, "err.txt");
    write_subset(set_path, 3, 0);
    const char *tool = getenv("VF_TOOL") ? getenv("VF_TOOL") : "vfcapture";
    int rc = vf_test_system("'%s' ingest --transforms '%s' -o '%s' >/dev/null 2>'%s'", tool,
                            set_path, ws, err);
    CHECK(rc == 0, "ingest --transforms exit %d (stderr in %s)", rc, err);

    /* a posed set brings its camera: another one is refused before COLMAP runs */
    rc = run_poses(ws, "--intrinsics 700,700,270,480", out, err, NULL);
    CHECK(rc != 0 && one_line_saying(err, "brings its own camera"),
          "--intrinsics on a posed set: one error line (exit %d)", rc);

    /* poses in OpenCV's axes do not fit the photos: one line saying so (measured: the points
     * take in 0% of the matches, right poses 19-29%) */
    char flipped[VF_PATH_MAX], flipped_ws[VF_PATH_MAX];
    vf_path_join(flipped, sizeof flipped, dir, "flipped.json");
    vf_path_join(flipped_ws, sizeof flipped_ws, dir, "flipped");
    write_subset(flipped, 6, 1);
    rc = vf_test_system("'%s' ingest --transforms '%s' -o '%s' >/dev/null 2>'%s'", tool, flipped,
                        flipped_ws, err);
    CHECK(rc == 0, "ingest --transforms of the flipped set exit %d", rc);
    rc = run_poses(flipped_ws, "-q", out, err, NULL);
    CHECK(rc != 0 && one_line_saying(err, "poses do not fit its photos"),
          "poses in the wrong axes: one error line (exit %d)", rc);

    double seconds;
    rc = run_poses(ws, "--json", out, err, &seconds);
    CHECK(rc == 0, "vfcapture poses exit %d (stderr in %s)", rc, err);
    printf("vfcapture poses took %.1f s\n", seconds);
    json_t *summary = load_json(out);
    int points = (int)json_integer_value(json_object_get(summary, "points"));
    double error = json_number_value(json_object_get(summary, "reprojection_error_px"));
    printf("registered %lld of %lld, %d points, reprojection error %.3f px, matcher %s\n",
           json_integer_value(json_object_get(summary, "registered")),
           json_integer_value(json_object_get(summary, "total")), points, error,
           json_string_value(json_object_get(summary, "matcher")));
    CHECK(json_integer_value(json_object_get(summary, "registered")) == FRAMES,
          "all %d in the model", FRAMES);
    CHECK(!strcmp(json_string_value(json_object_get(summary, "mapping")) ?: "", "known poses"),
          "the summary says the poses were the set's");
    /* measured: 2,455 points at 0.61 px (all 50 photos: 9,670 at 0.70 px) */
    CHECK(points > 1000, "%d points triangulated", points);
    CHECK(error < 1.0, "reprojection error %.3f px", error);
    double explained = json_number_value(json_object_get(summary, "matches_explained"));
    printf("the points take in %.0f%% of the matched features\n", 100 * explained);
    CHECK(explained > 0.15, "the set's poses explain %.2f of the matches", explained);
    const json_t *cam = json_array_get(json_object_get(summary, "cameras"), 0);
    CHECK(!strcmp(json_string_value(json_object_get(cam, "model")) ?: "", "OPENCV") &&
              fabs(json_number_value(json_array_get(json_object_get(cam, "params"), 0)) -
                   687.76) < 1e-6,
          "COLMAP's camera is the set's (OPENCV, fx 687.76)");
    json_decref(summary);

    /* the set's poses, moved into the object frame by one similarity */
    vf_dataset ours, set;
    vf_path_join(path, sizeof path, ws, "poses/transforms.json");
    CHECK(vf_dataset_load(path, &ours) == VF_OK, "our poses: %s", vf_error_message());
    CHECK(vf_dataset_load(set_path, &set) == VF_OK, "the set: %s", vf_error_message());
    const double **mine = malloc(sizeof *mine * FRAMES),
                  **theirs = malloc(sizeof *theirs * FRAMES);
    int matched = 0;
    for (int i = 0; i < ours.count && matched < FRAMES; i++) {
        const vf_frame *f = find_by_file_name(&set, ours.frames[i].image_path);
        if (f) {
            mine[matched] = ours.frames[i].c2w;
            theirs[matched++] = f->c2w;
        }
    }
    CHECK(matched == FRAMES, "every frame is one of the set's (%d)", matched);
    vf_pose_agreement e = check_poses(mine, theirs, matched, (pose_limits){1e-3, 1e-3, 1e-6, 1e-6});
    CHECK(e.rot_max < 1e-3, "largest rotation difference %.2g deg", e.rot_max);

    /* a test set of the posed set (here the set itself) moved into the object frame, as eval
     * does, lands on the poses stage's frames */
    vf_workspace w;
    int moved = 0;
    CHECK(vf_workspace_open(ws, 0, &w) == VF_OK, "workspace opens");
    CHECK(vf_poses_move_set_frames(&w, &set, &moved) == VF_OK && moved, "the set is moved");
    vf_workspace_close(&w);
    double worst = 0;
    for (int i = 0; i < ours.count; i++) {
        const vf_frame *f = find_by_file_name(&set, ours.frames[i].image_path);
        for (int k = 0; f && k < 16; k++)
            worst = fmax(worst, fabs(f->c2w[k] - ours.frames[i].c2w[k]));
    }
    /* measured 2.5e-6: the files' decimal digits (cameras 4 units out) */
    CHECK(worst < 1e-4, "moved frames match the object frame's (off by %.2g)", worst);
    free(mine);
    free(theirs);
    vf_dataset_free(&ours);
    vf_dataset_free(&set);

    /* the points the field's depth loss reads: every training photo sees some, in front */
    vf_dataset views;
    vf_colmap_view_points seen;
    vf_path_join(path, sizeof path, ws, "poses/transforms_undistorted.json");
    CHECK(vf_dataset_load(path, &views) == VF_OK, "undistorted set: %s", vf_error_message());
    const char **names = malloc(sizeof *names * (size_t)(views.count + 1));
    for (int i = 0; i < views.count; i++)
        names[i] = views.frames[i].image_path;
    vf_path_join(path, sizeof path, ws, "poses");
    CHECK(vf_colmap_view_points_load(path, names, views.count, &seen) == VF_OK,
          "the points each photo sees: %s", vf_error_message());
    int fewest = 1 << 30, behind = 0;
    for (int i = 0; i < seen.views; i++) {
        double w2c[16];
        vf_mat4_rigid_inverse(views.frames[i].c2w, w2c);
        fewest = seen.count[i] < fewest ? seen.count[i] : fewest;
        for (int k = 0; k < seen.count[i]; k++) {
            double in_camera[3];
            vf_mat4_transform_point(w2c, seen.xyz[i] + 3 * k, in_camera);
            behind += in_camera[2] >= 0; /* OpenGL axes: a camera looks along -z */
        }
    }
    printf("points a photo sees: at least %d; behind their camera: %d\n", fewest, behind);
    CHECK(seen.views == 17 && fewest >= 100, "every photo sees 100 points or more (%d)", fewest);
    CHECK(behind == 0, "%d sightings behind the camera", behind);
    vf_colmap_view_points_free(&seen);
    free(names);
    vf_dataset_free(&views);
    return check_finish();
}
