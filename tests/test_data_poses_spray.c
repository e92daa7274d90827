/* `vfcapture poses` on the spray can: 27 phone photos (750x1000 RGBA, background removed by
 * Photoroom, so few features and no usable reference poses). Every photo must register in one
 * model, and the cameras must form the ring they were taken on. Looking at the photos: the can
 * stands upright, the camera looks down on it from above the table, always at the can, and
 * moves along an arc in front of its label (the label sits left of centre in photos 1 and 12,
 * right of centre in 6 and 11). So in the object frame: cameras at about one distance from the
 * vertical axis through the object, at a moderate elevation, optical axes through the origin,
 * spread over tens of degrees of azimuth in the order the label says; the can's long axis
 * (the main axis of the sparse points) is vertical.
 * Give a workspace as argv[1] to check an earlier run instead of running COLMAP. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "poses_helpers.h"
#include "vf/image.h"
#include "vf/dataset.h"
#include "vf/pose.h"

#define SPRAY "data/real_captures/spray_can_photoroom/images"
#define DEG (180.0 / M_PI)

/* The photo number N of ".../Photoroom-20240806_225723_N.png". */
static int photo_number(const char *path)
{
    const char *u = strrchr(path, '_');
    return u ? atoi(u + 1) : -1;
}

static double mean(const double *v, int n)
{
    double s = 0;
    for (int i = 0; i < n; i++)
        s += v[i] / n;
    return s;
}

static double stddev(const double *v, int n)
{
    double m = mean(v, n), s = 0;
    for (int i = 0; i < n; i++)
        s += (v[i] - m) * (v[i] - m) / n;
    return sqrt(s);
}

/* Azimuth (degrees) of a camera, relative to `reference` degrees, wrapped to [-180, 180). */
static double azimuth_from(const double c2w[16], double reference)
{
    double a = atan2(c2w[7], c2w[3]) * DEG - reference;
    return a - 360 * floor((a + 180) / 360);
}

static void check_ring(const vf_dataset *ds)
{
    int n = ds->count;
    double *radius = malloc(sizeof(double) * n), *elevation = malloc(sizeof(double) * n);
    double *azimuth = malloc(sizeof(double) * n), worst_aim = 0, worst_level = 0;
    double reference = atan2(ds->frames[0].c2w[7], ds->frames[0].c2w[3]) * DEG;
    double left = 0, right = 0;
    for (int i = 0; i < n; i++) {
        const double *m = ds->frames[i].c2w;
        double p[3] = {m[3], m[7], m[11]}, back[3] = {m[2], m[6], m[10]};
        double dist = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
        radius[i] = hypot(p[0], p[1]);
        elevation[i] = atan2(p[2], radius[i]) * DEG;
        azimuth[i] = azimuth_from(m, reference);
        /* The camera looks along -z: the angle between that and the way to the origin. */
        double aim = acos(fmin(1, (back[0] * p[0] + back[1] * p[1] + back[2] * p[2]) / dist));
        worst_aim = fmax(worst_aim, aim * DEG);
        worst_level = fmax(worst_level, fabs(m[8])); /* image right's z part */
        int number = photo_number(ds->frames[i].image_path);
        left += (number == 1 || number == 12) ? azimuth[i] / 2 : 0;
        right += (number == 6 || number == 11) ? azimuth[i] / 2 : 0;
    }
    double spread = stddev(radius, n) / mean(radius, n);
    double lo = azimuth[0], hi = azimuth[0], el_lo = elevation[0], el_hi = elevation[0];
    for (int i = 1; i < n; i++) {
        lo = fmin(lo, azimuth[i]);
        hi = fmax(hi, azimuth[i]);
        el_lo = fmin(el_lo, elevation[i]);
        el_hi = fmax(el_hi, elevation[i]);
    }
    printf("ring: radius spread %.1f%%, elevation %.1f..%.1f deg, azimuth arc %.1f deg, "
           "label-left minus label-right photos %.1f deg, worst aim %.1f deg, worst |x.z| %.2f\n",
           100 * spread, el_lo, el_hi, hi - lo, left - right, worst_aim, worst_level);
    CHECK(spread < 0.2, "cameras at one distance from the vertical axis (spread %.3f)", spread);
    CHECK(el_lo > 0 && el_hi < 60, "cameras above the object, looking down (%.1f..%.1f deg)",
          el_lo, el_hi);
    CHECK(hi - lo > 30 && hi - lo < 180, "cameras spread along an arc (%.1f deg)", hi - lo);
    CHECK(left - right > 20, "azimuth order agrees with where the label sits (%.1f deg)",
          left - right);
    CHECK(worst_aim < 15, "every camera looks at the object (worst %.1f deg off)", worst_aim);
    CHECK(worst_level < 0.4, "cameras held upright (worst |x.z| %.2f)", worst_level);
    free(radius);
    free(elevation);
    free(azimuth);
}

/* The main axis of the sparse points (power iteration on their covariance) is the can's. */
static void check_can_axis(const char *points_path)
{
    FILE *f = fopen(points_path, "r");
    CHECK(f != NULL, "%s exists", points_path);
    if (!f)
        return;
    double sum[3] = {0}, outer[9] = {0}, p[3];
    int n = 0;
    char line[4096];
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#' || sscanf(line, "%*d %lf %lf %lf", &p[0], &p[1], &p[2]) != 3)
            continue;
        for (int r = 0; r < 3; r++) {
            sum[r] += p[r];
            for (int c = 0; c < 3; c++)
                outer[3 * r + c] += p[r] * p[c];
        }
        n++;
    }
    fclose(f);
    CHECK(n > 100, "%d sparse points", n);
    if (n == 0)
        return;
    double cov[9], axis[3] = {0.3, 0.3, 0.9};
    for (int r = 0; r < 9; r++)
        cov[r] = outer[r] / n - sum[r / 3] * sum[r % 3] / ((double)n * n);
    for (int it = 0; it < 200; it++) {
        double next[3];
        vf_mat3_apply(cov, axis, next);
        double norm = sqrt(next[0] * next[0] + next[1] * next[1] + next[2] * next[2]);
        for (int k = 0; k < 3; k++)
            axis[k] = next[k] / norm;
    }
    double tilt = acos(fabs(axis[2])) * DEG;
    printf("the can's axis (sparse points): %.1f deg from vertical\n", tilt);
    CHECK(tilt < 15, "the can stands upright in the object frame (%.1f deg off)", tilt);
}

/* The photos' backgrounds were removed to opaque white: the undistorted training frames must
 * carry the object's mask again (transparent background, opaque can, nothing else). */
static void check_masks(const char *transforms)
{
    vf_dataset ds;
    CHECK(vf_dataset_load(transforms, &ds) == VF_OK, "undistorted poses: %s", vf_error_message());
    double least = 1, most = 0;
    for (int i = 0; i < ds.count; i++) {
        vf_image img;
        CHECK(vf_image_load(ds.frames[i].image_path, &img) == VF_OK, "%s", vf_error_message());
        CHECK(img.channels == 4, "%s has alpha", ds.frames[i].image_path);
        size_t n = (size_t)img.width * img.height, opaque = 0;
        for (size_t k = 0; img.channels == 4 && k < n; k++)
            opaque += img.data[4 * k + 3] > 0.5f;
        double share = (double)opaque / (double)n;
        least = share < least ? share : least;
        most = share > most ? share : most;
        CHECK(img.channels != 4 || img.data[3] == 0.0f, "the corner is transparent");
        vf_image_free(&img);
    }
    printf("object masks: %d frames, the can covers %.1f%% to %.1f%% of each\n", ds.count,
           100 * least, 100 * most);
    CHECK(ds.count == 27 && least > 0.03 && most < 0.25, "masks cover the can only (%.3f..%.3f)",
          least, most);
    vf_dataset_free(&ds);
}

int main(int argc, char **argv)
{
    char ws[VF_PATH_MAX], path[VF_PATH_MAX], out[VF_PATH_MAX], err[VF_PATH_MAX];
    vf_path_join(out, sizeof out, vf_test_tmpdir(), "out.json");
    vf_path_join(err, sizeof err, vf_test_tmpdir(), "err.txt");
    if (argc > 1) {
        snprintf(ws, sizeof ws, "%s", argv[1]);
    } else {
        vf_path_join(ws, sizeof ws, vf_test_tmpdir(), "spray");
        CHECK(make_ingested_workspace(ws, vf_test_shared(SPRAY), 0) == 27,
              "workspace with the 27 spray can photos (RGBA)");
        double seconds;
        int rc = run_poses(ws, "--json", out, err, &seconds);
        CHECK(rc == 0, "vfcapture poses exit %d (stderr in %s)", rc, err);
        json_t *summary = load_json(out);
        char *steps = json_dumps(json_object_get(summary, "seconds"), JSON_COMPACT);
        printf("vfcapture poses took %.1f s: registered %lld of %lld in %lld model(s), "
               "reprojection error %.3f px, camera model %s, steps %s\n",
               seconds, json_integer_value(json_object_get(summary, "registered")),
               json_integer_value(json_object_get(summary, "total")),
               json_integer_value(json_object_get(summary, "models")),
               json_number_value(json_object_get(summary, "reprojection_error_px")),
               json_string_value(json_object_get(summary, "camera_model")),
               steps ? steps : "?");
        free(steps);
        CHECK(json_integer_value(json_object_get(summary, "registered")) == 27, "all registered");
        CHECK(json_integer_value(json_object_get(summary, "models")) == 1, "one model");
        CHECK(json_number_value(json_object_get(summary, "reprojection_error_px")) < 1.0,
              "reprojection error under 1 px");
        const char *model = json_string_value(json_object_get(summary, "camera_model"));
        CHECK(model && !strcmp(model, "SIMPLE_RADIAL"),
              "removed background chose the simpler lens (%s)", model ? model : "?");
        json_decref(summary);
    }
    vf_dataset ds;
    vf_path_join(path, sizeof path, ws, "poses/transforms.json");
    CHECK(vf_dataset_load(path, &ds) == VF_OK, "our poses: %s", vf_error_message());
    if (ds.count == 27)
        check_ring(&ds);
    vf_dataset_free(&ds);
    vf_path_join(path, sizeof path, ws, "poses/points3D.txt");
    check_can_axis(path);
    vf_path_join(path, sizeof path, ws, "poses/transforms_undistorted.json");
    check_masks(path);
    return check_finish();
}
