/* The simulated studio without Blender: the capture's walk (where the person goes, how the
 * phone is held) and the errors that come before any rendering. test_data_studio films. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "../src/studio/studio_internal.h"
#include "check.h"
#include "vf/fsutil.h"
#include "vf/targets.h"

/* Distance of point p from the optical axis of c2w (OpenGL: looking along -z), and whether p
 * is in front. */
static double off_axis(const double c2w[16], const double p[3], int *in_front)
{
    double d[3] = {p[0] - c2w[3], p[1] - c2w[7], p[2] - c2w[11]};
    double fwd[3] = {-c2w[2], -c2w[6], -c2w[10]};
    double along = d[0] * fwd[0] + d[1] * fwd[1] + d[2] * fwd[2];
    *in_front = along > 0;
    double perp2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2] - along * along;
    return sqrt(perp2 > 0 ? perp2 : 0);
}

static void test_walk(void)
{
    vf_studio_capture_options o;
    vf_studio_capture_defaults(&o);
    double *c2w = NULL;
    int n = vf__capture_walk(&o, &c2w);
    CHECK(n == 480, "2 loops of 8 s at 30 fps: %d frames", n);
    static const double origin[3] = {0, 0, 0};
    double worst_axis = 0, worst_step = 0, low = 0, high = 0, turned = 0;
    double dmin = 1e9, dmax = 0;
    int behind = 0;
    for (int i = 0; i < n; i++) {
        const double *m = c2w + 16 * i;
        int front;
        worst_axis = fmax(worst_axis, off_axis(m, origin, &front));
        behind += !front;
        double d = sqrt(m[3] * m[3] + m[7] * m[7] + m[11] * m[11]);
        dmin = fmin(dmin, d), dmax = fmax(dmax, d);
        double elevation = asin(m[11] / d) * 180 / M_PI;
        if (i < n / 5)
            low += elevation / (n / 5);
        if (i >= n - n / 5)
            high += elevation / (n / 5);
        if (i > 0) {
            const double *p = m - 16;
            double r1[9], r2[9];
            vf_mat4_rotation(m, r1);
            vf_mat4_rotation(p, r2);
            worst_step = fmax(worst_step, vf_rot_angle_deg(r1, r2));
            turned += remainder(atan2(m[7], m[3]) - atan2(p[7], p[3]), 2 * M_PI);
        }
    }
    printf("walk: optical axis within %.3f of the centre, distance %.2f-%.2f, elevation %.1f "
           "then %.1f deg, %.0f deg around, largest turn between frames %.2f deg\n",
           worst_axis, dmin, dmax, low, high, fabs(turned) * 180 / M_PI, worst_step);
    CHECK(behind == 0, "the object is in front of every camera (%d behind)", behind);
    CHECK(worst_axis < 0.4, "the object stays roughly centred: %.3f", worst_axis);
    CHECK(dmin > 0.85 * o.distance && dmax < 1.15 * o.distance, "distance %.2f-%.2f", dmin, dmax);
    CHECK(fabs(low - o.elevation_low) < 4 && fabs(high - o.elevation_high) < 4,
          "one loop a height: %.1f and %.1f deg", low, high);
    CHECK(fabs(fabs(turned) * 180 / M_PI - 720) < 45, "two loops: %.0f deg", turned * 180 / M_PI);
    CHECK(worst_step > 0.3 && worst_step < 4, "a hand, not a jump: %.2f deg", worst_step);
    free(c2w);

    /* a tripod on the same path: aimed exactly at the centre, level */
    o.phone.shake = 0;
    n = vf__capture_walk(&o, &c2w);
    double level = 0;
    worst_axis = 0;
    for (int i = 0; i < n; i++) {
        int front;
        worst_axis = fmax(worst_axis, off_axis(c2w + 16 * i, origin, &front));
        level = fmax(level, fabs(c2w[16 * i + 8])); /* the camera's x axis, z component */
    }
    CHECK(worst_axis < 1e-6 && level < 1e-9, "no shake: centred (%g) and level (%g)", worst_axis,
          level);
    free(c2w);
}

static void test_truth_path(void)
{
    char out[VF_PATH_MAX];
    CHECK(vf_studio_truth_path("a/b.mp4", out, sizeof out) == VF_OK &&
              !strcmp(out, "a/b.truth.json"), "%s", out);
    CHECK(vf_studio_truth_path("a.d/clip", out, sizeof out) == VF_OK &&
              !strcmp(out, "a.d/clip.truth.json"), "%s", out);
}

/* Errors before Blender runs: one line, the input named, nothing written. */
static void test_refusals(void)
{
    char video[VF_PATH_MAX], ws_dir[VF_PATH_MAX];
    snprintf(video, sizeof video, "%s/out.mp4", vf_test_tmpdir());
    vf_studio_capture_options o;
    vf_studio_capture_defaults(&o);
    vf_status s = vf_studio_capture("/nonexistent/model.glb", &o, video, NULL);
    CHECK(s == VF_EINPUT && strstr(vf_error_message(), "/nonexistent/model.glb"), "%s",
          vf_error_message());
    s = vf_studio_capture(video, &o, video, NULL); /* not a model: it does not exist either */
    CHECK(s == VF_EINPUT, "%s", vf_error_message());
    o.loops = 0;
    s = vf_studio_capture(vf_test_shared("data/models_3d/water_bottle__WaterBottle.glb"), &o,
                          video, NULL);
    CHECK(s == VF_EINPUT && strstr(vf_error_message(), "loops"), "%s", vf_error_message());
    CHECK(!vf_is_file(video), "nothing written");

    /* a re-shoot of a workspace that was not filmed by the studio */
    snprintf(ws_dir, sizeof ws_dir, "%s/ws", vf_test_tmpdir());
    vf_workspace ws;
    CHECK(vf_workspace_open(ws_dir, 1, &ws) == VF_OK, "workspace");
    vf_studio_reshoot_options r;
    vf_studio_reshoot_defaults(&r);
    s = vf_studio_reshoot(&ws, NULL, &r, video, NULL);
    CHECK(s == VF_EINPUT && strstr(vf_error_message(), "--truth"), "%s", vf_error_message());
    /* nor is it the studio's object (`real` then reads WS/ingest/object.json) */
    vf_object3d obj;
    vf_similarity to_object;
    int filmed = -1;
    s = vf_studio_object(&ws, &obj, &to_object, &filmed);
    CHECK(s == VF_OK && filmed == 0, "not filmed by the studio: %d (%s)", filmed,
          vf_error_message());
    vf_workspace_close(&ws);
    CHECK(!vf_is_file(video), "nothing written");
}

/* The closed loop's person reads reshoot's words back into the advice they came from. */
static void test_read_advice(void)
{
    const vf_advice asked[3] = {{12, 0.5, -0.3, 4, -3, -7}, {-103, -0.2, 0.25, -5, 30, 9},
                                {0.5, 0.01, 0.0, 1, 0, 0}};
    for (int i = 0; i < 3; i++)
        for (int cm = 0; cm < 2; cm++) {
            double metres = cm ? 0.05 : 0; /* 5 cm a unit: distances in cm */
            char text[384];
            vf_advice_text(&asked[i], metres, 2.0, 0.08, text, sizeof text);
            read_advice r = vf__read_advice(text, metres);
            const vf_advice *a = &asked[i];
            int big = fabs(a->orbit_deg) >= 2; /* the words leave out what is under 2 deg */
            CHECK(r.given, "%s", text);
            CHECK(fabs(r.orbit - (big ? a->orbit_deg : 0)) < 0.51, "orbit of '%s'", text);
            CHECK(fabs(r.roll - (fabs(a->roll_deg) >= 2 ? a->roll_deg : 0)) < 0.51,
                  "roll of '%s'", text);
            CHECK(fabs(r.tilt - (fabs(a->tilt_deg) >= 2 ? a->tilt_deg : 0)) < 0.51,
                  "tilt of '%s'", text);
            CHECK(fabs(r.pan - (fabs(a->pan_deg) >= 2 ? a->pan_deg : 0)) < 0.51, "turn of '%s'",
                  text);
            double unit = cm ? 0.01 / metres : 0.006; /* what the words round to */
            CHECK(fabs(r.raise - (fabs(a->raise) >= 0.08 ? a->raise : 0)) < unit,
                  "raise of '%s'", text);
            CHECK(fabs(r.back - (fabs(a->back) >= 0.08 ? a->back : 0)) < unit,
                  "step of '%s'", text);
        }
    CHECK(!vf__read_advice(NULL, 0).given, "no advice");
    read_advice still = vf__read_advice("hold still: on target", 0);
    CHECK(still.given && still.orbit == 0 && still.raise == 0, "hold still");
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_walk);
    CHECK_CASE(test_truth_path);
    CHECK_CASE(test_refusals);
    CHECK_CASE(test_read_advice);
    return check_finish();
}
