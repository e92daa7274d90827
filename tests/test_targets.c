/* The physical loop's math: Wilson intervals, target descriptions in words, spreading samples,
 * guidance advice, pose smoothing and attack.json reading. */
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "check.h"
#include "vf/attack_file.h"
#include "vf/localize.h"
#include "vf/targets.h"
#include "vf/wilson.h"
#include "vf/workspace.h"

static void test_wilson(void)
{
    double lo, hi;
    vf_wilson_interval(0, 10, VF_Z95, &lo, &hi); /* textbook values (Newcombe 1998) */
    CHECK_NEAR(lo, 0.0, 1e-12);
    CHECK_NEAR(hi, 0.2775, 1e-4);
    vf_wilson_interval(5, 10, VF_Z95, &lo, &hi);
    CHECK_NEAR(lo, 0.2366, 1e-4);
    CHECK_NEAR(hi, 0.7634, 1e-4);
    vf_wilson_interval(10, 10, VF_Z95, &lo, &hi);
    CHECK_NEAR(lo, 0.7225, 1e-4);
    CHECK_NEAR(hi, 1.0, 1e-12);
    vf_wilson_interval(81, 263, VF_Z95, &lo, &hi); /* Wilson's own worked example size */
    CHECK(lo < 81.0 / 263 && hi > 81.0 / 263 && hi - lo < 0.12, "interval [%g, %g]", lo, hi);
    vf_wilson_interval(0, 0, VF_Z95, &lo, &hi);
    CHECK(lo == 0 && hi == 1, "no trials: [0, 1]");
}

static void c2w_of(double psi, double theta, double phi, double dx, double dy, double dz,
                   double c2w[16])
{
    vf_viewpoint v = {psi, theta, phi, dx, dy, dz};
    vf_viewpoint_to_c2w(&v, c2w);
}

/* The camera turned about its optical axis, clockwise as its user sees it. */
static void roll_camera(const double c2w[16], double deg, double out[16])
{
    double Rz[9], turn[16], zero[3] = {0, 0, 0};
    vf_rot_z(-deg * M_PI / 180, Rz);
    vf_mat4_from_rt(Rz, zero, turn);
    vf_mat4_mul(c2w, turn, out);
}

static void test_describe(void)
{
    double c2w[16], rolled[16];
    vf_target_words w;
    c2w_of(0, 0, 120, 0, 0, 0, c2w); /* upright, 180 - 120 = 60 deg up, on the -y side */
    vf_target_describe(c2w, &w);
    CHECK_NEAR(w.azimuth_deg, 0, 1e-9);
    CHECK_NEAR(w.elevation_deg, 60, 1e-9);
    CHECK_NEAR(w.distance, 4, 1e-9);
    CHECK_NEAR(w.height, 4 * sin(M_PI / 3), 1e-9);
    CHECK_NEAR(w.roll_deg, 0, 1e-9);
    CHECK_NEAR(w.aim_offset, 0, 1e-9);
    c2w_of(90, 0, 120, 0, 0.5, 0, c2w); /* a quarter turn counterclockwise: the +x side */
    vf_target_describe(c2w, &w);
    CHECK_NEAR(w.azimuth_deg, 90, 1e-9);
    CHECK_NEAR(w.distance, 4.5, 1e-9);
    roll_camera(c2w, 15, rolled);
    vf_target_describe(rolled, &w);
    CHECK_NEAR(w.roll_deg, 15, 1e-9);
    c2w_of(0, 0, 60, 0, 0, 0, c2w); /* phi < 90: the upside-down view (vf/pose.h) */
    vf_target_describe(c2w, &w);
    CHECK_NEAR(fabs(w.roll_deg), 180, 1e-9);
    CHECK_NEAR(w.azimuth_deg, 180, 1e-9);
    c2w_of(0, 0, 120, 0.3, 0, -0.2, c2w); /* offsets aim off centre, in the image plane */
    vf_target_describe(c2w, &w);
    CHECK_NEAR(w.aim_offset, sqrt(0.3 * 0.3 + 0.2 * 0.2), 1e-9);
}

static void test_advice(void)
{
    double now[16], goal[16];
    vf_advice a;
    char text[256];
    c2w_of(0, 0, 120, 0, 0, 0, now);
    c2w_of(20, 0, 120, 0, 0.5, 0, goal);
    vf_advice_compute(now, goal, &a);
    CHECK_NEAR(a.orbit_deg, 20, 1e-9);
    CHECK_NEAR(a.back, 0.5, 1e-9);
    CHECK_NEAR(a.raise, 0.5 * sin(M_PI / 3), 1e-9);
    CHECK_NEAR(a.pan_deg, 0, 1e-9); /* orbiting keeps facing the object */
    CHECK_NEAR(a.tilt_deg, 0, 1e-9);
    vf_advice_text(&a, 0.1, 2, 0.02, text, sizeof text);
    CHECK(strstr(text, "orbit 20 deg right") && strstr(text, "step back 5 cm") &&
              strstr(text, "raise 4 cm"),
          "advice: %s", text);
    /* lower and closer, both cameras aimed at the object: no turn or tilt beyond keeping it
     * in view (the words once said "tilt 30 deg up" too, and the studio's person looked over
     * the object) */
    c2w_of(-30, 0, 160, 0, -1, 0, goal);
    vf_advice_compute(now, goal, &a);
    CHECK(a.raise < -0.5 && a.back < -0.5, "lower %.2f, closer %.2f", a.raise, a.back);
    CHECK_NEAR(a.pan_deg, 0, 1e-9);
    CHECK_NEAR(a.tilt_deg, 0, 1e-9);
    /* the same place, the camera turned 5 deg right and tilted 3 deg up */
    double Ry[9], Rx[9], R[9], turn[16], zero[3] = {0, 0, 0};
    vf_rot_y(-5 * M_PI / 180, Ry);
    vf_rot_x(3 * M_PI / 180, Rx);
    vf_mat3_mul(Ry, Rx, R);
    vf_mat4_from_rt(R, zero, turn);
    vf_mat4_mul(now, turn, goal);
    vf_advice_compute(now, goal, &a);
    CHECK(fabs(a.pan_deg - 5) < 0.1 && fabs(a.tilt_deg - 3) < 0.1, "turn %.2f, tilt %.2f",
          a.pan_deg, a.tilt_deg);
    CHECK(fabs(a.orbit_deg) < 1e-9 && fabs(a.raise) < 1e-9, "no step");
    roll_camera(now, -10, goal);
    vf_advice_compute(now, goal, &a);
    vf_advice_text(&a, 0, 2, 0.02, text, sizeof text);
    CHECK(!strcmp(text, "roll 10 deg counterclockwise"), "advice: %s", text);
    vf_advice_compute(now, now, &a);
    vf_advice_text(&a, 0, 2, 0.02, text, sizeof text);
    CHECK(!strcmp(text, "hold still: on target"), "advice: %s", text);
}

static void test_spread(void)
{
    /* Two clusters and an outlier: the medoid first, then the far points. */
    double range[6];
    vf_view_ranges_paper(range);
    double views[7 * 6] = {0};
    double psi[7] = {0, 1, 2, -1, 90, 91, 179};
    for (int i = 0; i < 7; i++) {
        views[6 * i] = psi[i];
        views[6 * i + 2] = 100;
    }
    int picked[3];
    CHECK(vf_targets_spread(views, 7, range, 3, picked) == VF_OK, "spread");
    CHECK(picked[0] <= 2, "medoid first: %d", picked[0]);
    CHECK(picked[1] == 6, "then the farthest (psi 179, wraps near -181): %d", picked[1]);
    CHECK(picked[2] == 4 || picked[2] == 5, "then the other cluster: %d", picked[2]);
}

static void test_smoother(void)
{
    vf_pose_smoother s;
    vf_pose_smoother_init(&s, 0.5);
    double a[16], b[16], out[16], Ra[9], Ro[9], far[16];
    c2w_of(0, 0, 120, 0, 0, 0, a);
    c2w_of(10, 0, 120, 0, 0, 0, b);
    vf_pose_smoother_add(&s, a, out);
    CHECK(!memcmp(out, a, sizeof out), "the first pose passes through");
    vf_pose_smoother_add(&s, b, out);
    vf_mat4_rotation(a, Ra);
    vf_mat4_rotation(out, Ro);
    CHECK_NEAR(vf_rot_angle_deg(Ra, Ro), 5, 1e-9);
    c2w_of(90, 0, 120, 0, 0, 0, far); /* a jump: start again from the new pose */
    vf_pose_smoother_add(&s, far, out);
    CHECK(!memcmp(out, far, sizeof out), "a jump resets");
}

static void test_attack_file(void)
{
    char path[4200];
    snprintf(path, sizeof path, "%s/attack.json", vf_test_tmpdir());
    json_t *doc = json_pack("{s:{s:[i,i], s:[s,s]}, s:{s:[f,f,f,f,f,f], s:[f,f,f,f,f,f]}, "
                            "s:[f,f,f,f,f,f], s:[[f,f,f,f,f,f]], s:[{s:i, s:s, s:f, s:b}], "
                            "s:f, s:{s:f, s:f, s:f, s:f, s:i, s:i}}",
                            "label", "indices", 559, 765, "names", "folding chair",
                            "rocking chair", "bounds", "lo", -180.0, -30.0, 20.0, -0.5, -1.0,
                            -0.5, "hi", 180.0, 30.0, 160.0, 0.5, 1.0, 0.5, "v_star", 10.0, 5.0,
                            100.0, 0.1, 0.2, 0.3, "samples", 1.0, 2.0, 3.0, 0.0, 0.0, 0.0,
                            "sample_predictions", "class", 417, "name", "balloon", "confidence",
                            0.75, "fooled", 1, "asr_v_star", 1.0, "camera", "fl_x", 300.0, "fl_y",
                            300.0, "cx", 112.0, "cy", 112.0, "w", 224, "h", 224);
    CHECK(vf_json_save(path, doc) == VF_OK, "saved");
    json_decref(doc);
    vf_attack_file a;
    CHECK(vf_attack_file_load(path, &a) == VF_OK, "load: %s", vf_error_message());
    CHECK(a.label_count == 2 && vf_attack_is_label(&a, 765) && !vf_attack_is_label(&a, 417),
          "labels");
    CHECK(!strcmp(a.label_text, "folding chair, rocking chair"), "label text %s", a.label_text);
    CHECK_NEAR(a.v_star.phi, 100, 0);
    CHECK(a.sample_count == 1 && a.predictions && a.predictions[0].cls == 417 &&
              a.predictions[0].fooled,
          "samples and predictions");
    CHECK(a.has_camera && a.camera.width == 224, "camera");
    CHECK(isnan(a.natural_accuracy) && a.asr_v_star == 1.0, "rates");
    vf_attack_file_free(&a);
    /* The camera is read like a camera file (vf_camera_from_json, one set of bounds): one out
     * of them is refused naming it (the old reader dropped it silently and kept going). */
    doc = NULL;
    CHECK(vf_json_load(path, &doc) == VF_OK, "reload");
    json_object_set_new(json_object_get(doc, "camera"), "w", json_integer(200000));
    vf_json_save(path, doc);
    json_decref(doc);
    CHECK(vf_attack_file_load(path, &a) == VF_EINPUT && strstr(vf_error_message(), "camera") &&
              strstr(vf_error_message(), "100000"),
          "a camera out of bounds is refused: %s", vf_error_message());
    doc = json_pack("{s:[f,f]}", "v_star", 1.0, 2.0);
    vf_json_save(path, doc);
    json_decref(doc);
    CHECK(vf_attack_file_load(path, &a) == VF_EINPUT && strstr(vf_error_message(), "v_star"),
          "a short v_star is refused: %s", vf_error_message());
}

/* Out of memory while spreading is an error, never a list of repeated picks. A child process
 * caps its address space so that the buffer for 2^31 - 1 viewpoints cannot be had (skipped
 * under AddressSanitizer, whose allocator aborts instead of failing). */
static void test_spread_out_of_memory(void)
{
#if defined(__SANITIZE_ADDRESS__)
    printf("skipped under AddressSanitizer\n");
#else
    pid_t pid = fork();
    if (pid == 0) {
        struct rlimit cap = {(rlim_t)2 << 30, (rlim_t)2 << 30};
        setrlimit(RLIMIT_AS, &cap);
        const double views[6] = {0}, range[6] = {360, 60, 140, 1, 2, 1};
        int picked[2] = {-1, -1};
        /* views is never read when the buffer cannot be had */
        vf_status s = vf_targets_spread(views, 0x7fffffff, range, 2, picked);
        _exit(s == VF_EINTERNAL && strstr(vf_error_message(), "out of memory") ? 0 : 1);
    }
    int status = 0;
    CHECK(pid > 0 && waitpid(pid, &status, 0) == pid && WIFEXITED(status) &&
              WEXITSTATUS(status) == 0,
          "spreading without memory fails cleanly (child status %d)", status);
#endif
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_wilson);
    CHECK_CASE(test_describe);
    CHECK_CASE(test_advice);
    CHECK_CASE(test_spread);
    CHECK_CASE(test_spread_out_of_memory);
    CHECK_CASE(test_smoother);
    CHECK_CASE(test_attack_file);
    return check_finish();
}
