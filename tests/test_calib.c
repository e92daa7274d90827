/* Calibration and metric scale on synthetic views: a checkerboard and an ArUco marker rendered
 * through a known lens (calib/calib_cv.cpp) must give that lens and that scale back. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/calib.h"
#include "vf/dataset.h"
#include "vf/log.h"
#include "vf/pose.h"

static const vf_camera lens = {.width = 640, .height = 480, .fx = 520, .fy = 516, .cx = 322.3,
                               .cy = 238.7, .k1 = -0.12, .k2 = 0.05, .p1 = 0.001, .p2 = -0.0008};

/* Camera-from-plane rotation: tilt about x and y, roll about the optical axis (radians). */
static void tilt(double ax, double ay, double roll, double rot[9])
{
    double rx[9], ry[9], rz[9], tmp[9];
    vf_rot_x(ax, rx);
    vf_rot_y(ay, ry);
    vf_rot_z(roll, rz);
    vf_mat3_mul(ry, rx, tmp);
    vf_mat3_mul(rz, tmp, rot);
}

/* Render the board at view k: tilted every way, at several distances and offsets (the board's
 * centre moves up to `shift` metres off the optical axis, at about `distance` metres). */
static vf_status board_view(const vf_rgb8 *texture, double texel, int k, double shift,
                            double distance, vf_rgb8 *out)
{
    double a = 2 * M_PI * k / 7.0, rot[9], t[3], centre[3] = {0.5 * texture->width * texel,
                                                           0.5 * texture->height * texel, 0};
    tilt(0.6 * sin(a), 0.6 * cos(a), 0.3 * sin(3.0 * k), rot);
    double in_camera[3] = {shift * cos(1.7 * k), 0.7 * shift * sin(2.3 * k),
                           distance + 0.1 * sin(0.9 * k)};
    double rc[3];
    vf_mat3_apply(rot, centre, rc);
    for (int i = 0; i < 3; i++)
        t[i] = in_camera[i] - rc[i];
    return vf_calib_render_plane(&lens, rot, t, texture, texel, 200, 2, out);
}

static void test_intrinsics(void)
{
    vf_calib_board board = {9, 6, 0.03, 0, 0};
    vf_rgb8 texture = {0}, img = {0};
    const int square_px = 24, views = 14;
    CHECK(vf_calib_board_image(&board, square_px, &texture) == VF_OK, "%s", vf_error_message());
    double texel = board.square / square_px, *uv = malloc(54 * 2 * sizeof *uv);
    vf_calib_views set = {0}, few = {0};
    double start = vf_now();
    for (int k = 0; k < views; k++) {
        int found = 0;
        double quad[8];
        CHECK(board_view(&texture, texel, k, 0.07, 0.55, &img) == VF_OK, "%s",
              vf_error_message());
        CHECK(vf_calib_find_board(&img, &board, uv, quad, &found) == VF_OK, "%s",
              vf_error_message());
        CHECK(found, "board found in view %d", k);
        set.frames_seen++, few.frames_seen++;
        if (found) {
            CHECK(vf_calib_views_add(&set, img.width, img.height, "view", uv, quad, 54) == VF_OK,
                  "add");
            if (few.count < 3)
                vf_calib_views_add(&few, img.width, img.height, "view", uv, quad, 54);
        }
    }
    printf("render + search: %.1f ms per view\n", 1000 * (vf_now() - start) / views);
    /* a frame without the board: nothing found */
    vf_rgb8 blank = {0};
    int found = 1;
    vf_rgb8_resize_buffer(&blank, 320, 240);
    memset(blank.data, 128, 320 * 240 * 3);
    double quad[8];
    CHECK(vf_calib_find_board(&blank, &board, uv, quad, &found) == VF_OK && !found,
          "blank frame");

    vf_calib_options opt;
    vf_calib_defaults(&opt);
    vf_calib_result res;
    CHECK(vf_calib_solve(&set, &board, &opt, &res) == VF_OK, "%s", vf_error_message());
    const vf_camera *c = &res.camera;
    printf("fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f k2 %.4f p1 %.5f p2 %.5f rms %.3f px "
           "(OpenCV %.3f), %d views, OpenCV %.3f s, Ceres %.3f s\n",
           c->fx, c->fy, c->cx, c->cy, c->k1, c->k2, c->p1, c->p2, res.rms, res.rms_opencv,
           res.used, res.seconds_opencv, res.seconds_ceres);
    CHECK_NEAR(c->fx, lens.fx, 0.005 * lens.fx);
    CHECK_NEAR(c->fy, lens.fy, 0.005 * lens.fy);
    CHECK_NEAR(c->cx, lens.cx, 2.0);
    CHECK_NEAR(c->cy, lens.cy, 2.0);
    CHECK_NEAR(c->k1, lens.k1, 0.02);
    CHECK(res.rms < 0.3, "rms %.3f px", res.rms);
    CHECK(res.used == views && res.outliers == 0, "%d used, %d outliers", res.used, res.outliers);

    /* the camera file has the keys `poses --camera` reads */
    char path[4096];
    snprintf(path, sizeof path, "%s/camera.json", vf_test_tmpdir());
    CHECK(vf_calib_save_camera(path, &res, &set, &board) == VF_OK, "%s", vf_error_message());
    json_t *doc = NULL;
    CHECK(vf_json_load(path, &doc) == VF_OK, "%s", vf_error_message());
    CHECK_NEAR(json_number_value(json_object_get(doc, "fl_x")), c->fx, 1e-6);
    CHECK(json_integer_value(json_object_get(doc, "w")) == 640, "w");
    CHECK(json_array_size(json_object_get(doc, "per_view")) == (size_t)views, "per-view errors");
    json_decref(doc);

    /* too few boards: a clear input error */
    CHECK(vf_calib_solve(&few, &board, &opt, &res) == VF_EINPUT, "3 views refused");
    CHECK(strstr(vf_error_message(), "found in only 3"), "message: %s", vf_error_message());

    vf_calib_views_free(&set);
    vf_calib_views_free(&few);
    vf_rgb8_free(&texture);
    vf_rgb8_free(&img);
    vf_rgb8_free(&blank);
    free(uv);
}

/* A ChArUco board pushed partly out of the frame: views that show only some corners count,
 * and give the lens back as well as whole checkerboards do. */
static void test_charuco(void)
{
    vf_calib_board board = {7, 5, 0.04, 0.03, 0};
    CHECK(vf_charuco_dictionary("4X4_50", &board.dictionary) == VF_OK, "%s", vf_error_message());
    CHECK(vf_charuco_dictionary("5x5_7", &board.dictionary) == VF_EINPUT &&
              strstr(vf_error_message(), "5x5_7"),
          "unknown dictionary named");
    vf_charuco_dictionary("4x4_50", &board.dictionary);
    vf_rgb8 texture = {0}, img = {0};
    const int square_px = 64, views = 14, corners = 35;
    CHECK(vf_calib_board_image(&board, square_px, &texture) == VF_OK, "%s", vf_error_message());
    double texel = board.square / square_px, uv[2 * 35], quad[8];
    vf_calib_views set = {0};
    int partial = 0;
    for (int k = 0; k < views; k++) {
        int found = 0;
        CHECK(board_view(&texture, texel, k, 0.2, 0.45, &img) == VF_OK, "%s", vf_error_message());
        CHECK(vf_calib_find_board(&img, &board, uv, quad, &found) == VF_OK, "%s",
              vf_error_message());
        set.frames_seen++;
        if (!found)
            continue;
        int seen = 0;
        for (int i = 0; i < corners; i++)
            seen += !isnan(uv[2 * i]);
        partial += seen < corners;
        CHECK(vf_calib_views_add(&set, img.width, img.height, "view", uv, quad, corners) == VF_OK,
              "add");
    }
    printf("ChArUco: found in %d of %d views, %d of them partial\n", set.count, views, partial);
    CHECK(set.count >= views - 2, "ChArUco board found in %d of %d views", set.count, views);
    CHECK(partial >= 3, "only %d partial views: the test should push the board out", partial);

    vf_calib_options opt;
    vf_calib_defaults(&opt);
    vf_calib_result res;
    CHECK(vf_calib_solve(&set, &board, &opt, &res) == VF_OK, "%s", vf_error_message());
    const vf_camera *c = &res.camera;
    printf("ChArUco: fx %.2f fy %.2f cx %.2f cy %.2f k1 %.4f rms %.3f px, %d views\n", c->fx,
           c->fy, c->cx, c->cy, c->k1, res.rms, res.used);
    CHECK_NEAR(c->fx, lens.fx, 0.005 * lens.fx);
    CHECK_NEAR(c->fy, lens.fy, 0.005 * lens.fy);
    CHECK_NEAR(c->cx, lens.cx, 2.0);
    CHECK_NEAR(c->cy, lens.cy, 2.0);
    CHECK(res.rms < 0.5, "rms %.3f px", res.rms);

    /* more markers than the dictionary has codes: refused, not drawn wrong */
    vf_calib_board big = {19, 14, 0.02, 0.015, board.dictionary};
    CHECK(vf_calib_board_image(&big, 8, &img) == VF_EINPUT && strstr(vf_error_message(), "--dict"),
          "a 20 x 15 board with 4x4_50 refused: %s", vf_error_message());
    vf_calib_views_free(&set);
    vf_rgb8_free(&texture);
    vf_rgb8_free(&img);
}

static void test_picks_parse(void)
{
    vf_pick p[4];
    int n;
    CHECK(vf_parse_picks("a.jpg:10,20.5;b:3,4", p, 4, &n) == VF_OK && n == 2, "two picks");
    CHECK(!strcmp(p[0].frame, "a.jpg") && p[0].v == 20.5 && !strcmp(p[1].frame, "b"), "fields");
    CHECK(vf_parse_picks("a.jpg:10,20", p, 4, &n) == VF_EINPUT, "one pick is not enough");
    CHECK(vf_parse_picks("a.jpg:10;b:1,2", p, 4, &n) == VF_EINPUT, "missing v");
    CHECK(vf_parse_picks("a.jpg10,2;b:1,2", p, 4, &n) == VF_EINPUT, "missing colon");
}

/* ---- a posed workspace with a marker of side 0.5 units on the ground ---- */

#define MARKER_ID 37
#define MARKER_UNITS 0.5
#define SCENE_FRAMES 6

/* A camera at p looking at the origin, z up: c2w (OpenGL axes). */
static void look_at_origin(const double p[3], double c2w_gl[16])
{
    double f[3], x[3], y[3], n = sqrt(p[0] * p[0] + p[1] * p[1] + p[2] * p[2]);
    for (int i = 0; i < 3; i++)
        f[i] = -p[i] / n;
    double xn = hypot(f[1], f[0]);
    x[0] = f[1] / xn, x[1] = -f[0] / xn, x[2] = 0; /* f x (0,0,1), normalized */
    y[0] = f[1] * x[2] - f[2] * x[1], y[1] = f[2] * x[0] - f[0] * x[2];
    y[2] = f[0] * x[1] - f[1] * x[0];
    double c2w_cv[16] = {x[0], y[0], f[0], p[0], x[1], y[1], f[1], p[1],
                         x[2], y[2], f[2], p[2], 0,    0,    0,    1};
    vf_c2w_cv_to_gl(c2w_cv, c2w_gl);
}

static vf_status make_scene(const char *root, vf_dataset *ds)
{
    vf_workspace ws;
    vf_stage stage;
    vf_rgb8 texture = {0}, img = {0};
    const int cell_px = 20;
    double texel = MARKER_UNITS / (7 * cell_px), half = 4.5 * cell_px * texel; /* 9 cells */
    vf_status status = vf_workspace_open(root, 1, &ws);
    if (status == VF_OK)
        status = vf_stage_begin(&ws, "poses", &stage);
    if (status != VF_OK)
        return status;
    vf_aruco_image(MARKER_ID, cell_px, &texture);
    ds->count = SCENE_FRAMES;
    ds->frames = calloc(SCENE_FRAMES, sizeof *ds->frames);
    char dir[VF_PATH_MAX], name[32];
    vf_path_join(dir, sizeof dir, stage.dir, "images");
    vf_mkdirs(dir);
    for (int k = 0; k < SCENE_FRAMES && status == VF_OK; k++) {
        vf_frame *f = &ds->frames[k];
        double a = 2 * M_PI * k / SCENE_FRAMES + 0.3, elev = 0.7 + 0.15 * (k % 3);
        double p[3] = {2.2 * cos(elev) * cos(a), 2.2 * cos(elev) * sin(a), 2.2 * sin(elev)};
        f->camera = lens;
        look_at_origin(p, f->c2w);
        /* texture -> world: x = x_tex - half, y = half - y_tex (printed side up, seen from
           above without mirroring); then world -> camera */
        double w2c[9], rot[9], t[3], off[3] = {-half, half, 0}, roff[3];
        const double flip[9] = {1, 0, 0, 0, -1, 0, 0, 0, -1};
        vf_c2w_gl_to_w2c_cv(f->c2w, w2c, t);
        vf_mat3_mul(w2c, flip, rot);
        vf_mat3_apply(w2c, off, roff);
        for (int i = 0; i < 3; i++)
            t[i] += roff[i];
        status = vf_calib_render_plane(&f->camera, rot, t, &texture, texel, 230, 2, &img);
        snprintf(name, sizeof name, "frame_%02d.png", k);
        vf_path_join(f->image_path, sizeof f->image_path, dir, name);
        if (status == VF_OK)
            status = vf_rgb8_save(f->image_path, &img);
    }
    char path[VF_PATH_MAX];
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, stage.dir, "transforms.json");
    if (status == VF_OK)
        status = vf_dataset_save(path, ds);
    if (status == VF_OK)
        status = vf_stage_commit(&stage, NULL, NULL);
    else
        vf_stage_abort(&stage);
    vf_dataset_free(ds); /* again from where the commit put it */
    if (status == VF_OK)
        status = vf_workspace_path(&ws, "poses", "transforms.json", path, sizeof path);
    if (status == VF_OK)
        status = vf_dataset_load(path, ds);
    vf_workspace_close(&ws);
    vf_rgb8_free(&texture);
    vf_rgb8_free(&img);
    return status;
}

/* Where world point X shows in frame f. */
static vf_pick project(const vf_dataset *ds, int f, const double X[3])
{
    double rot[9], t[3], p[3];
    vf_pick pick = {{0}, 0, 0};
    vf_c2w_gl_to_w2c_cv(ds->frames[f].c2w, rot, t);
    vf_mat3_apply(rot, X, p);
    for (int i = 0; i < 3; i++)
        p[i] += t[i];
    vf_camera_project(&ds->frames[f].camera, p, &pick.u, &pick.v);
    snprintf(pick.frame, sizeof pick.frame, "frame_%02d", f);
    return pick;
}

static void test_scale(void)
{
    char root[4096];
    snprintf(root, sizeof root, "%s/ws", vf_test_tmpdir());
    vf_dataset ds = {0};
    CHECK(make_scene(root, &ds) == VF_OK, "%s", vf_error_message());
    vf_workspace ws;
    CHECK(vf_workspace_open(root, 0, &ws) == VF_OK, "%s", vf_error_message());
    double s = 0;
    CHECK(!vf_workspace_metres_per_unit(&ws, &s), "no scale before calib scale");

    /* markers are read with the right id and corners */
    vf_rgb8 img = {0};
    vf_marker m[8];
    int count = 0;
    CHECK(vf_rgb8_load(ds.frames[1].image_path, &img) == VF_OK, "%s", vf_error_message());
    CHECK(vf_aruco_detect(&img, m, 8, &count) == VF_OK && count == 1 && m[0].id == MARKER_ID,
          "%d markers, id %d", count, count ? m[0].id : -1);
    double h = 0.5 * MARKER_UNITS, corner0[3] = {-h, h, 0}; /* top-left as printed */
    vf_pick expect = project(&ds, 1, corner0);
    if (count)
        CHECK(hypot(m[0].corners[0] - expect.u, m[0].corners[1] - expect.v) < 0.5,
              "corner 0 at %.2f,%.2f, expected %.2f,%.2f", m[0].corners[0], m[0].corners[1],
              expect.u, expect.v);
    vf_rgb8_free(&img);

    /* marker of 100 mm = 0.5 units: 0.2 m per unit */
    json_t *details = NULL;
    CHECK(vf_scale_from_marker(&ws, MARKER_ID, 0.1, &s, &details) == VF_OK, "%s",
          vf_error_message());
    printf("marker scale %.5f m/unit (true 0.2)\n", s);
    CHECK_NEAR(s, 0.2, 0.002);
    json_decref(details);
    details = NULL;
    CHECK(vf_scale_from_marker(&ws, MARKER_ID + 1, 0.1, &s, &details) == VF_EINPUT,
          "absent id refused");
    CHECK(strstr(vf_error_message(), "found in 0 of 6"), "%s", vf_error_message());

    /* two points 0.8 units apart, picked in three frames each; 0.8 units = 160 mm */
    double a[3] = {-0.3, 0.2, 0.1}, b[3] = {0.5, 0.2, 0.1};
    vf_pick p1[3] = {project(&ds, 0, a), project(&ds, 2, a), project(&ds, 4, a)};
    vf_pick p2[3] = {project(&ds, 1, b), project(&ds, 3, b), project(&ds, 5, b)};
    CHECK(vf_scale_from_picks(&ws, p1, 3, p2, 3, 0.16, &s, &details) == VF_OK, "%s",
          vf_error_message());
    CHECK_NEAR(s, 0.2, 1e-6);
    json_decref(details);
    vf_pick missing = p1[0];
    strcpy(missing.frame, "nope");
    p1[0] = missing;
    CHECK(vf_scale_from_picks(&ws, p1, 3, p2, 3, 0.16, &s, &details) == VF_EINPUT &&
              strstr(vf_error_message(), "nope"),
          "unknown frame named: %s", vf_error_message());
    vf_workspace_close(&ws);

    /* the stage stores it where other commands find it */
    vf_scale_request req = {.marker = MARKER_ID, .size_m = 0.1};
    json_t *result = NULL;
    CHECK(vf_workspace_open(root, 0, &ws) == VF_OK, "%s", vf_error_message());
    CHECK(vf_calib_scale_run(&ws, &req, &result) == VF_OK && result, "calib scale stage: %s",
          vf_error_message());
    json_decref(result);
    CHECK(vf_workspace_metres_per_unit(&ws, &s), "scale stored");
    CHECK_NEAR(s, 0.2, 0.002);
    vf_workspace_close(&ws);
    vf_dataset_free(&ds);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    vf_log_set_quiet(1);
    CHECK_CASE(test_picks_parse);
    CHECK_CASE(test_intrinsics);
    CHECK_CASE(test_charuco);
    CHECK_CASE(test_scale);
    return check_finish();
}
