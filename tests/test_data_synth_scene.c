/* The poses and localize stages against exact ground truth, on a scene synthesized here: no
 * data from ../shared, no Blender. A small ray caster renders a textured scene (a box, a
 * pillar and a ball among smaller and farther boxes on a ground plane inside a round wall,
 * every surface a solid colour noise seeded by vf_rng, so SIFT finds a thousand or more
 * features a view and none repeats) through a pinhole camera of known focal length, in the
 * project's conventions (object frame z up, object at the origin, cameras placed by
 * vf_viewpoint_to_c2w, OpenGL axes).
 *
 * Cases (`test_data_synth_scene poses` runs one; localize builds the workspace it needs):
 *   - render: the renderer is deterministic, the views are textured everywhere, and a
 *     point projected by the known camera lands where the ray caster put it;
 *   - poses: 20 views on two rings go through vf_ingest_run (a photo folder) and
 *     vf_poses_run (all pairs, the known intrinsics): every view registers, and after a
 *     similarity alignment the poses agree with the ground truth (vf_pose_compare). The
 *     normalization is checked as well: the cameras look at the origin, are level and sit at
 *     a mean distance of 4, so the object frame must be the ground-truth frame up to a turn
 *     about z (normalize.h: the azimuth reference is a camera's);
 *   - localize: 4 new views at poses not in the training set (other heights, distances, off
 *     centre) are localized against the workspace; their poses, with the ground truth mapped
 *     into the object frame by the training cameras' alignment, agree; c2w_colmap maps onto
 *     c2w_object by normalization.json; and the same scene with another texture is reported
 *     as not localized;
 *   - cutout: the GrabCut masks of object mode against the box's true silhouettes;
 *   - train_object: object mode end to end (a field trained on the photos, cut in 3D): its
 *     silhouettes against the true ones;
 *   - train_scene: scene mode's check that the held-out renders show the object, on a
 *     trained field and on fog.
 * Limits are measured figures with room (see the comments at each check). About a minute on
 * 2 idle cores (COLMAP's matching and object mode's 600 training steps are most of it). */
#include <jansson.h>
#include <math.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "poses_helpers.h"
#include "vf/camera.h"
#include "vf/cutout.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/image.h"
#include "vf/ingest.h"
#include "vf/localize.h"
#include "vf/log.h"
#include "vf/pose.h"
#include "vf/poses.h"
#include "vf/rgb8.h"
#include "vf/rng.h"
#include "vf/train.h"
#include "vf/workspace.h"

#define WIDTH 320
#define HEIGHT 240
#define FOV_X_DEG 60.0
#define SUPERSAMPLE 2 /* per axis: 4 rays a pixel, so the fine texture does not alias */
#ifndef SEED
#define SEED 16 /* the scene's texture (-DSEED=... to measure others) */
#endif

/* ---- the scene ---- */

#define GROUND_Z (-0.6)
#define WALL_RADIUS 9.0
#define WALL_HEIGHT 6.0

enum {
    SURF_NONE,
    SURF_GROUND,
    SURF_WALL,
    SURF_BOX,
    SURF_PILLAR,
    SURF_BALL,
    SURF_NEAR, /* clutter between the object and the cameras */
    SURF_FAR,  /* clutter behind the cameras */
    SURF_COUNT
};

typedef struct box {
    double lo[3], hi[3];
} box;

static const box object_box = {{-0.55, -0.4, GROUND_Z}, {0.55, 0.4, 0.7}};
static const box pillar_box = {{-1.25, 0.55, GROUND_Z}, {-0.85, 0.95, 1.0}};
static const double ball_center[3] = {0.95, -0.8, GROUND_Z + 0.4};
static const double ball_radius = 0.4;

/* Clutter, so that the scene is not one plane with a box on it (a ground that fills most of
 * every view makes two-view geometry nearly planar, and COLMAP then sometimes starts from a
 * wrong pair and builds a wrong model): NEAR_BOXES small boxes around the object, inside the
 * cameras' ring, and FAR_BOXES tall ones between the cameras and the wall. A fixed layout. */
#define NEAR_BOXES 6
#define FAR_BOXES 8
static box clutter[NEAR_BOXES + FAR_BOXES];

static void make_clutter(void)
{
    vf_rng rng;
    vf_rng_seed(&rng, 7);
    for (int i = 0; i < NEAR_BOXES + FAR_BOXES; i++) {
        int near = i < NEAR_BOXES, k = near ? i : i - NEAR_BOXES;
        double turn = 2 * M_PI * (k + 0.4 * vf_rng_uniform(&rng)) / (near ? NEAR_BOXES : FAR_BOXES);
        double r = near ? 1.6 + 0.5 * vf_rng_uniform(&rng) : 5.5 + 2 * vf_rng_uniform(&rng);
        double half = near ? 0.12 + 0.13 * vf_rng_uniform(&rng) : 0.3 + 0.3 * vf_rng_uniform(&rng);
        double top = near ? 0.3 + 0.6 * vf_rng_uniform(&rng) : 1 + 1.5 * vf_rng_uniform(&rng);
        double cx = r * cos(turn), cy = r * sin(turn);
        clutter[i] = (box){{cx - half, cy - half * 1.3, GROUND_Z},
                           {cx + half, cy + half * 1.3, GROUND_Z + top}};
    }
}

/* Per surface: lattice seed and the cycle of its coarsest noise octave (scene units). The far
 * surfaces get coarser texture, so that it stays a few pixels wide there. */
typedef struct texture {
    uint64_t seed[SURF_COUNT];
} texture;

static const double base_cycle[SURF_COUNT] = {0, 1.2, 2.5, 0.5, 0.5, 0.4, 0.5, 1.2};

static texture make_texture(uint64_t seed)
{
    texture t;
    vf_rng rng;
    vf_rng_seed(&rng, seed);
    for (int i = 0; i < SURF_COUNT; i++)
        t.seed[i] = vf_rng_next(&rng);
    return t;
}

static uint64_t mix64(uint64_t z)
{
    z += 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

/* Three values in [0, 1) at a lattice point. */
static void lattice(uint64_t seed, int64_t x, int64_t y, int64_t z, double out[3])
{
    uint64_t h = mix64(seed ^ mix64((uint64_t)x ^ mix64((uint64_t)y ^ mix64((uint64_t)z))));
    for (int c = 0; c < 3; c++)
        out[c] = (double)((h >> (21 * c)) & 0x1fffff) / (double)(1 << 21);
}

/* 3-channel value noise (smoothstep-weighted trilinear interpolation of the lattice). */
static void value_noise(uint64_t seed, const double p[3], double out[3])
{
    double f[3], w[3];
    int64_t i[3];
    for (int k = 0; k < 3; k++) {
        double fl = floor(p[k]);
        i[k] = (int64_t)fl;
        f[k] = p[k] - fl;
        w[k] = f[k] * f[k] * (3 - 2 * f[k]);
    }
    out[0] = out[1] = out[2] = 0;
    for (int corner = 0; corner < 8; corner++) {
        int dx = corner & 1, dy = (corner >> 1) & 1, dz = corner >> 2;
        double v[3], weight = (dx ? w[0] : 1 - w[0]) * (dy ? w[1] : 1 - w[1]) *
                              (dz ? w[2] : 1 - w[2]);
        lattice(seed, i[0] + dx, i[1] + dy, i[2] + dz, v);
        for (int c = 0; c < 3; c++)
            out[c] += weight * v[c];
    }
}

/* Albedo at p on a surface: 5 octaves of colour noise, contrast stretched. */
static void albedo(const texture *tex, int surf, const double p[3], double out[3])
{
    double freq = 1.0 / base_cycle[surf], amp = 1, total = 0, sum[3] = {0};
    for (int octave = 0; octave < 5; octave++) {
        double q[3], v[3];
        for (int k = 0; k < 3; k++)
            q[k] = p[k] * freq + 17.31 * octave; /* octaves' lattices do not line up */
        value_noise(tex->seed[surf] + (uint64_t)octave, q, v);
        for (int c = 0; c < 3; c++)
            sum[c] += amp * (v[c] - 0.5);
        total += amp;
        amp *= 0.8;
        freq *= 2.13;
    }
    for (int c = 0; c < 3; c++) {
        double x = 0.5 + 3.2 * sum[c] / total;
        out[c] = x < 0.02 ? 0.02 : x > 0.98 ? 0.98 : x;
    }
}

typedef struct hit {
    double t;
    int surf;
    double normal[3];
} hit;

static void try_box(const box *b, int surf, const double o[3], const double d[3], hit *h)
{
    double t0 = 0, t1 = INFINITY;
    int axis = -1, sign = 0;
    for (int k = 0; k < 3; k++) {
        if (fabs(d[k]) < 1e-12) {
            if (o[k] < b->lo[k] || o[k] > b->hi[k])
                return;
            continue;
        }
        double a = (b->lo[k] - o[k]) / d[k], c = (b->hi[k] - o[k]) / d[k];
        int s = -1;
        if (a > c) {
            double x = a;
            a = c;
            c = x;
            s = 1;
        }
        if (a > t0) {
            t0 = a;
            axis = k;
            sign = s;
        }
        if (c < t1)
            t1 = c;
    }
    if (axis < 0 || t0 > t1 || t0 >= h->t)
        return;
    h->t = t0;
    h->surf = surf;
    h->normal[0] = h->normal[1] = h->normal[2] = 0;
    h->normal[axis] = sign;
}

static void try_ball(const double o[3], const double d[3], hit *h)
{
    double oc[3], b = 0, c = -ball_radius * ball_radius;
    for (int k = 0; k < 3; k++) {
        oc[k] = o[k] - ball_center[k];
        b += oc[k] * d[k];
        c += oc[k] * oc[k];
    }
    double disc = b * b - c;
    if (disc < 0)
        return;
    double t = -b - sqrt(disc);
    if (t <= 0 || t >= h->t)
        return;
    h->t = t;
    h->surf = SURF_BALL;
    for (int k = 0; k < 3; k++)
        h->normal[k] = (oc[k] + t * d[k]) / ball_radius;
}

/* The nearest surface along the unit ray o + t d (cameras are inside the wall). */
static hit cast(const double o[3], const double d[3])
{
    hit h = {INFINITY, SURF_NONE, {0, 0, 0}};
    if (d[2] < 0) {
        double t = (GROUND_Z - o[2]) / d[2];
        double x = o[0] + t * d[0], y = o[1] + t * d[1];
        if (x * x + y * y < WALL_RADIUS * WALL_RADIUS)
            h = (hit){t, SURF_GROUND, {0, 0, 1}};
    }
    double a = d[0] * d[0] + d[1] * d[1], b = o[0] * d[0] + o[1] * d[1],
           c = o[0] * o[0] + o[1] * o[1] - WALL_RADIUS * WALL_RADIUS;
    if (a > 1e-12) {
        double t = (-b + sqrt(b * b - a * c)) / a, z = o[2] + t * d[2];
        if (t > 0 && t < h.t && z >= GROUND_Z && z <= GROUND_Z + WALL_HEIGHT)
            h = (hit){t, SURF_WALL,
                      {-(o[0] + t * d[0]) / WALL_RADIUS, -(o[1] + t * d[1]) / WALL_RADIUS, 0}};
    }
    try_box(&object_box, SURF_BOX, o, d, &h);
    try_box(&pillar_box, SURF_PILLAR, o, d, &h);
    for (int i = 0; i < NEAR_BOXES + FAR_BOXES; i++)
        try_box(&clutter[i], i < NEAR_BOXES ? SURF_NEAR : SURF_FAR, o, d, &h);
    try_ball(o, d, &h);
    return h;
}

/* Lambertian shading under a fixed light (the same from every view). */
static void shade(const texture *tex, const double o[3], const double d[3], double out[3])
{
    static const double light[3] = {0.42, -0.31, 0.85};
    hit h = cast(o, d);
    if (h.surf == SURF_NONE) { /* sky (not seen from the views below) */
        out[0] = 0.6, out[1] = 0.7, out[2] = 0.9;
        return;
    }
    double p[3], a[3], lambert = 0;
    for (int k = 0; k < 3; k++) {
        p[k] = o[k] + h.t * d[k];
        lambert += h.normal[k] * light[k];
    }
    albedo(tex, h.surf, p, a);
    double light_level = 0.45 + 0.55 * (lambert > 0 ? lambert : 0);
    for (int c = 0; c < 3; c++)
        out[c] = a[c] * light_level;
}

static vf_camera scene_camera(void)
{
    return vf_camera_from_fov(WIDTH, HEIGHT, FOV_X_DEG * M_PI / 180);
}

/* Render the view from c2w (OpenGL axes) as an RGB image. */
static vf_status render(const texture *tex, const double c2w_gl[16], vf_image *img)
{
    vf_camera cam = scene_camera();
    double c2w_cv[16], o[3];
    vf_c2w_gl_to_cv(c2w_gl, c2w_cv);
    vf_mat4_translation(c2w_cv, o);
    vf_status s = vf_image_alloc(img, WIDTH, HEIGHT, 3);
    for (int y = 0; s == VF_OK && y < HEIGHT; y++)
        for (int x = 0; x < WIDTH; x++) {
            double sum[3] = {0};
            for (int sy = 0; sy < SUPERSAMPLE; sy++)
                for (int sx = 0; sx < SUPERSAMPLE; sx++) {
                    double ray_cam[3], d[3], c[3];
                    vf_camera_pixel_ray(&cam, x + (sx + 0.5) / SUPERSAMPLE,
                                        y + (sy + 0.5) / SUPERSAMPLE, ray_cam);
                    vf_mat4_transform_dir(c2w_cv, ray_cam, d);
                    shade(tex, o, d, c);
                    for (int k = 0; k < 3; k++)
                        sum[k] += c[k];
                }
            for (int k = 0; k < 3; k++)
                img->data[((size_t)y * WIDTH + x) * 3 + k] =
                    (float)(sum[k] / (SUPERSAMPLE * SUPERSAMPLE));
        }
    return s;
}

static vf_status render_rgb8(const texture *tex, const double c2w_gl[16], vf_rgb8 *out)
{
    vf_image img = {0};
    vf_status s = render(tex, c2w_gl, &img);
    if (s == VF_OK)
        s = vf_rgb8_resize_buffer(out, WIDTH, HEIGHT);
    for (size_t i = 0; s == VF_OK && i < (size_t)WIDTH * HEIGHT * 3; i++)
        out->data[i] = (unsigned char)(img.data[i] * 255 + 0.5f);
    vf_image_free(&img);
    return s;
}

/* ---- the cameras ---- */

/* Training views: 12 on a ring 25 degrees above the ground, 8 on one at 50 degrees (upright
 * photos: phi = 180 - elevation), distances 4 +- 0.25 alternating, so that the mean distance
 * is exactly 4 and every optical axis passes through the origin. */
#define TRAIN_VIEWS 20
#define OBJECT_STEPS 600 /* object mode's training (test_train_object) */
#define FOG_STEPS 5      /* a field that is still fog (test_train_scene) */
static vf_viewpoint train_view(int i)
{
    if (i < 12)
        return (vf_viewpoint){.psi = -180 + 30 * i, .phi = 180 - 25, .dy = i % 2 ? 0.25 : -0.25};
    i -= 12;
    return (vf_viewpoint){.psi = -165 + 45 * i, .phi = 180 - 50, .dy = i % 2 ? -0.25 : 0.25};
}

/* New views for localize: between the training views, other heights and distances, and two
 * off centre (the optical axis misses the origin). */
#define NEW_VIEWS 4
static const vf_viewpoint new_views[NEW_VIEWS] = {
    {.psi = 15, .phi = 180 - 37, .dy = -0.4},
    {.psi = 100, .phi = 180 - 20, .dy = 0.5},
    {.psi = -140, .phi = 180 - 42, .dx = 0.25, .dz = 0.15},
    {.psi = -55, .phi = 180 - 30, .dx = -0.2, .dy = 0.3, .dz = -0.1},
};

/* ---- shared state: the posed workspace ---- */

static struct {
    int built;       /* 1: ok, -1: failed */
    char ws[VF_PATH_MAX];
    double gt[TRAIN_VIEWS][16];      /* ground truth, scene frame */
    double ours[TRAIN_VIEWS][16];    /* from WS/poses/transforms.json, object frame */
    int found[TRAIN_VIEWS];
    int registered;
    vf_similarity object_from_scene; /* ground truth aligned onto the object frame */
    double seconds_render, seconds_ingest, seconds_poses;
} posed;

/* Write the training views as PNG photos into `dir`. */
static int write_photos(const char *dir)
{
    texture tex = make_texture(SEED);
    int written = 0;
    vf_mkdirs(dir);
    for (int i = 0; i < TRAIN_VIEWS; i++) {
        vf_viewpoint v = train_view(i);
        vf_viewpoint_to_c2w(&v, posed.gt[i]);
        char name[64], path[VF_PATH_MAX];
        snprintf(name, sizeof name, "view_%02d.png", i);
        vf_path_join(path, sizeof path, dir, name);
        vf_image img = {0};
        if (render(&tex, posed.gt[i], &img) == VF_OK && vf_image_save(path, &img) == VF_OK)
            written++;
        vf_image_free(&img);
    }
    return written;
}

/* The training view index in an ingested frame's path (".../0003_view_03.jpg"), or -1. */
static int view_index(const char *path)
{
    const char *p = strstr(path, "view_");
    int i = p ? atoi(p + 5) : -1;
    return i >= 0 && i < TRAIN_VIEWS ? i : -1;
}

static void build_workspace(void)
{
    if (posed.built)
        return;
    posed.built = -1;
    char photos[VF_PATH_MAX];
    snprintf(photos, sizeof photos, "%s/photos", vf_test_tmpdir());
    snprintf(posed.ws, sizeof posed.ws, "%s/ws", vf_test_tmpdir());

    double start = vf_now();
    int written = write_photos(photos);
    posed.seconds_render = vf_now() - start;
    CHECK(written == TRAIN_VIEWS, "rendered %d of %d views", written, TRAIN_VIEWS);
    if (written != TRAIN_VIEWS)
        return;

    vf_ingest_request req;
    vf_ingest_request_defaults(&req);
    req.kind = VF_INGEST_PHOTOS;
    req.input = photos;
    json_t *summary = NULL;
    start = vf_now();
    vf_status s = vf_ingest_run(posed.ws, &req, &summary);
    posed.seconds_ingest = vf_now() - start;
    CHECK(s == VF_OK, "ingest: %s", vf_error_message());
    long long frames = json_integer_value(json_object_get(summary, "frames"));
    CHECK(frames == TRAIN_VIEWS, "ingest kept %lld of %d photos", frames, TRAIN_VIEWS);
    json_decref(summary);
    if (s != VF_OK)
        return;

    vf_workspace w;
    vf_poses_options opt;
    vf_poses_defaults(&opt);
    opt.matcher = "exhaustive";
    opt.has_intrinsics = 1; /* the renderer's pinhole, not refined: PINHOLE in COLMAP */
    opt.known = scene_camera();
    opt.undistort = 0; /* a pinhole: nothing to undistort */
    opt.max_features = 1024;
    summary = NULL;
    start = vf_now();
    s = vf_workspace_open(posed.ws, 0, &w);
    if (s == VF_OK) {
        s = vf_poses_run(&w, &opt, &summary);
        vf_workspace_close(&w);
    }
    posed.seconds_poses = vf_now() - start;
    CHECK(s == VF_OK, "poses: %s", vf_error_message());
    if (s != VF_OK)
        return;
    posed.registered = (int)json_integer_value(json_object_get(summary, "registered"));
    printf("poses: %d of %d registered in %lld model(s), %lld points, reprojection error "
           "%.3f px, camera model %s, up by %s, centre by %s\n",
           posed.registered, TRAIN_VIEWS, json_integer_value(json_object_get(summary, "models")),
           json_integer_value(json_object_get(summary, "points")),
           json_number_value(json_object_get(summary, "reprojection_error_px")),
           json_string_value(json_object_get(summary, "camera_model")),
           json_string_value(json_object_get(summary, "up_method")),
           json_string_value(json_object_get(summary, "center_method")));
    json_decref(summary);

    char path[VF_PATH_MAX];
    vf_dataset ds;
    s = vf_path_join(path, sizeof path, posed.ws, "poses/transforms.json");
    if (s == VF_OK)
        s = vf_dataset_load(path, &ds);
    CHECK(s == VF_OK, "our poses: %s", vf_error_message());
    if (s != VF_OK)
        return;
    for (int i = 0; i < ds.count; i++) {
        int k = view_index(ds.frames[i].image_path);
        CHECK(k >= 0 && !posed.found[k], "frame %s traced to one view", ds.frames[i].image_path);
        if (k < 0 || posed.found[k])
            continue;
        memcpy(posed.ours[k], ds.frames[i].c2w, sizeof posed.ours[k]);
        posed.found[k] = 1;
    }
    vf_dataset_free(&ds);

    /* the ground truth's camera centres aligned onto ours: scene frame -> object frame */
    double src[3 * TRAIN_VIEWS], dst[3 * TRAIN_VIEWS];
    int n = 0;
    for (int i = 0; i < TRAIN_VIEWS; i++)
        if (posed.found[i]) {
            vf_mat4_translation(posed.gt[i], src + 3 * n);
            vf_mat4_translation(posed.ours[i], dst + 3 * n);
            n++;
        }
    s = vf_similarity_umeyama(src, dst, n, &posed.object_from_scene);
    CHECK(s == VF_OK, "alignment: %s", vf_error_message());
    if (s == VF_OK)
        posed.built = 1;
}

/* ---- the cases ---- */

static double image_std(const vf_image *img, int x0, int y0, int w, int h)
{
    double sum = 0, sum2 = 0;
    int n = 0;
    for (int y = y0; y < y0 + h; y++)
        for (int x = x0; x < x0 + w; x++) {
            const float *p = img->data + ((size_t)y * img->width + x) * 3;
            double g = (p[0] + p[1] + p[2]) / 3;
            sum += g;
            sum2 += g * g;
            n++;
        }
    double mean = sum / n;
    return sqrt(sum2 / n - mean * mean);
}

/* The renderer: deterministic, textured in every part of the frame, and geometrically the
 * known camera (a point of the box projected by vf_camera_project is where the ray caster finds
 * box's edge). */
static void test_render(void)
{
    texture tex = make_texture(SEED);
    vf_viewpoint v = train_view(3);
    double c2w[16];
    vf_viewpoint_to_c2w(&v, c2w);
    vf_image a = {0}, b = {0};
    CHECK(render(&tex, c2w, &a) == VF_OK && render(&tex, c2w, &b) == VF_OK, "rendered");
    CHECK(a.data && b.data && !memcmp(a.data, b.data, sizeof(float) * WIDTH * HEIGHT * 3),
          "the same view twice is the same image");
    double lowest = INFINITY;
    for (int by = 0; by < 4; by++)
        for (int bx = 0; bx < 4; bx++) {
            double sd = image_std(&a, bx * WIDTH / 4, by * HEIGHT / 4, WIDTH / 4, HEIGHT / 4);
            lowest = sd < lowest ? sd : lowest;
        }
    printf("render: lowest grey standard deviation of the 16 tiles %.3f\n", lowest);
    CHECK(lowest > 0.04, "every part of the view is textured (lowest tile std %.3f)", lowest);

    /* a point on the box's top face, seen from view 3 (above it): the ray through its
     * projection hits the box there */
    vf_camera cam = scene_camera();
    double point[3] = {0.31, -0.27, object_box.hi[2]};
    double c2w_cv[16], w2c[16], pc[3], u, vv, ray[3], d[3], o[3];
    vf_c2w_gl_to_cv(c2w, c2w_cv);
    vf_mat4_rigid_inverse(c2w_cv, w2c);
    vf_mat4_transform_point(w2c, point, pc);
    CHECK(vf_camera_project(&cam, pc, &u, &vv) && u > 0 && u < WIDTH && vv > 0 && vv < HEIGHT,
          "the point is in view (%.1f, %.1f)", u, vv);
    vf_camera_pixel_ray(&cam, u, vv, ray);
    vf_mat4_transform_dir(c2w_cv, ray, d);
    vf_mat4_translation(c2w_cv, o);
    hit h = cast(o, d);
    double p[3], err = 0;
    for (int k = 0; k < 3; k++) {
        p[k] = o[k] + h.t * d[k];
        err += (p[k] - point[k]) * (p[k] - point[k]);
    }
    CHECK(h.surf == SURF_BOX && sqrt(err) < 1e-9, "the ray through the point's pixel hits it "
          "(surface %d, %.2g off)", h.surf, sqrt(err));
    vf_image_free(&a);
    vf_image_free(&b);
}

static double rot_error_deg(const double a[16], const double b[16])
{
    double ra[9], rb[9];
    vf_mat4_rotation(a, ra);
    vf_mat4_rotation(b, rb);
    return vf_rot_angle_deg(ra, rb);
}

static double position_error(const double a[16], const double b[16])
{
    double d = 0;
    for (int k = 0; k < 3; k++)
        d += (a[4 * k + 3] - b[4 * k + 3]) * (a[4 * k + 3] - b[4 * k + 3]);
    return sqrt(d);
}

/* Azimuth (degrees) of the horizontal direction (x, y). */
static double azimuth_deg(double x, double y)
{
    return atan2(y, x) * 180 / M_PI;
}

static double angle_diff_deg(double a, double b)
{
    double d = fmod(a - b, 360);
    d = d < -180 ? d + 360 : d > 180 ? d - 360 : d;
    return fabs(d);
}

static void test_poses(void)
{
    double start = vf_now();
    build_workspace();
    if (posed.built != 1)
        return;
    printf("render %.1f s, ingest %.1f s, poses %.1f s\n", posed.seconds_render,
           posed.seconds_ingest, posed.seconds_poses);
    CHECK(posed.registered == TRAIN_VIEWS, "every view registered (%d of %d)", posed.registered,
          TRAIN_VIEWS);
    const double *mine[TRAIN_VIEWS], *truth[TRAIN_VIEWS];
    int n = 0;
    for (int i = 0; i < TRAIN_VIEWS; i++)
        if (posed.found[i]) {
            mine[n] = posed.ours[i];
            truth[n++] = posed.gt[i];
        }
    CHECK(n == TRAIN_VIEWS, "every view in transforms.json (%d)", n);
    /* measured over 15 runs on 6 textures (COLMAP is not deterministic on 2 threads):
     * rotations median 0.03-0.07 deg, p90 0.06-0.09 deg; positions median 0.04-0.08%, p90
     * 0.07-0.16% of the camera distance. Limits 5x above. */
    vf_pose_agreement e = check_poses(mine, truth, n, (pose_limits){0.3, 0.5, 0.005, 0.01});
    CHECK(e.rot_over_5deg == 0, "no camera over 5 deg off (%d)", e.rot_over_5deg);

    /* The normalization against the exact ground truth: the scene frame is already the
     * object frame but for the azimuth reference, so the alignment must be a turn about z. */
    const vf_similarity *s = &posed.object_from_scene;
    double z[3] = {0, 0, 1}, rz[3];
    vf_mat3_apply(s->R, z, rz);
    double tilt = acos(rz[2] < 1 ? rz[2] : 1) * 180 / M_PI;
    double shift = sqrt(s->t[0] * s->t[0] + s->t[1] * s->t[1] + s->t[2] * s->t[2]);
    double turn = azimuth_deg(s->R[0], s->R[3]); /* where scene x went */
    printf("object frame vs scene frame: scale %.5f, up tilted %.3f deg, origin %.4f off, "
           "turned %.2f deg about z\n",
           s->scale, tilt, shift, turn);
    /* measured: scale within 0.04%, up within 0.03 deg, origin within 0.003 */
    CHECK(fabs(s->scale - 1) < 0.005, "scale %.5f (mean camera distance 4)", s->scale);
    CHECK(tilt < 0.3, "up is z (%.3f deg off)", tilt);
    CHECK(shift < 0.02, "the origin is where the cameras look (%.4f off)", shift);
    /* -y of the object frame is one training camera's horizontal direction (no cluster on one
     * side, so the first camera COLMAP lists): the turn is a multiple of 15 deg here */
    double nearest = INFINITY;
    for (int i = 0; i < TRAIN_VIEWS; i++) {
        vf_viewpoint v = train_view(i);
        double d = angle_diff_deg(turn, -v.psi);
        nearest = d < nearest ? d : nearest;
    }
    CHECK(nearest < 0.3, "-y points at a training camera (%.3f deg off the nearest)", nearest);
    printf("poses case: %.1f s\n", vf_now() - start);
}

static void test_localize(void)
{
    double start = vf_now();
    build_workspace();
    if (posed.built != 1)
        return;
    vf_localize_options opt;
    vf_localize_defaults(&opt);
    vf_localizer *loc = NULL;
    vf_workspace ws = {0};
    vf_status s = vf_workspace_open(posed.ws, 0, &ws);
    if (s == VF_OK)
        s = vf_localizer_open(&ws, &opt, &loc);
    vf_workspace_close(&ws);
    CHECK(s == VF_OK, "localizer: %s", vf_error_message());
    if (s != VF_OK)
        return;
    int points = 0, descriptors = 0;
    vf_localizer_map_size(loc, &points, &descriptors);
    printf("map: %d points, %d descriptors\n", points, descriptors);

    char path[VF_PATH_MAX];
    vf_similarity object_from_colmap, colmap_from_object;
    s = vf_path_join(path, sizeof path, posed.ws, "poses/normalization.json");
    if (s == VF_OK)
        s = vf_normalization_load(path, &object_from_colmap, &colmap_from_object);
    CHECK(s == VF_OK, "normalization.json: %s", vf_error_message());

    texture tex = make_texture(SEED);
    double rot[NEW_VIEWS], pos[NEW_VIEWS], worst_map = 0;
    int localized = 0;
    for (int i = 0; i < NEW_VIEWS; i++) {
        double gt[16], expected[16];
        vf_viewpoint_to_c2w(&new_views[i], gt);
        vf_similarity_apply_c2w(&posed.object_from_scene, gt, expected);
        /* through a JPEG file, as a photo would come */
        vf_rgb8 frame = {0};
        snprintf(path, sizeof path, "%s/new_%d.jpg", vf_test_tmpdir(), i);
        s = render_rgb8(&tex, gt, &frame);
        if (s == VF_OK)
            s = vf_rgb8_save(path, &frame);
        if (s == VF_OK)
            s = vf_rgb8_load(path, &frame);
        vf_localize_result r;
        if (s == VF_OK)
            s = vf_localize_frame(loc, &frame, &r);
        vf_rgb8_free(&frame);
        CHECK(s == VF_OK, "new view %d: %s", i, vf_error_message());
        if (s != VF_OK)
            continue;
        if (!r.localized) {
            printf("new view %d: %s\n", i, r.reason);
            continue;
        }
        rot[localized] = rot_error_deg(r.c2w_object, expected);
        pos[localized] = position_error(r.c2w_object, expected) / VF_CAMERA_DISTANCE;
        /* c2w_colmap and c2w_object are the same camera through normalization.json */
        double mapped[16];
        vf_similarity_apply_c2w(&object_from_colmap, r.c2w_colmap, mapped);
        double map_err = rot_error_deg(mapped, r.c2w_object) +
                         position_error(mapped, r.c2w_object);
        worst_map = map_err > worst_map ? map_err : worst_map;
        printf("new view %d (psi %.0f, phi %.0f): %d features, %d matches, %d inliers, %.2f px; "
               "rotation error %.3f deg, position error %.3f%% of the distance\n",
               i, new_views[i].psi, new_views[i].phi, r.features, r.matches, r.inliers,
               r.reprojection_px, rot[localized], 100 * pos[localized]);
        localized++;
    }
    CHECK(localized == NEW_VIEWS, "every new view localized (%d of %d)", localized, NEW_VIEWS);
    CHECK(worst_map < 1e-6, "normalization.json maps c2w_colmap onto c2w_object (%.2g)",
          worst_map);
    if (localized > 0) {
        double rot_med = quantile(rot, localized, 0.5), rot_max = quantile(rot, localized, 1);
        double pos_med = quantile(pos, localized, 0.5), pos_max = quantile(pos, localized, 1);
        printf("localize: rotation error median %.3f deg, max %.3f deg; position error median "
               "%.3f%%, max %.3f%% of the camera distance\n",
               rot_med, rot_max, 100 * pos_med, 100 * pos_max);
        /* measured over 6 runs: rotations median 0.07-0.12 deg, max 0.13 deg; positions
         * median 0.08-0.13%, max 0.34% of the camera distance; the fewest inliers 69 (view 1,
         * the lowest and farthest) */
        CHECK(rot_med < 0.3 && rot_max < 0.6, "rotation errors %.3f / %.3f deg", rot_med,
              rot_max);
        CHECK(pos_med < 0.005 && pos_max < 0.01, "position errors %.4f / %.4f", pos_med,
              pos_max);
    }

    /* the same geometry under another texture: nothing to match, so no pose */
    texture other = make_texture(SEED + 1);
    double c2w[16];
    vf_viewpoint_to_c2w(&new_views[0], c2w);
    vf_rgb8 frame = {0};
    vf_localize_result r;
    s = render_rgb8(&other, c2w, &frame);
    if (s == VF_OK)
        s = vf_localize_frame(loc, &frame, &r);
    vf_rgb8_free(&frame);
    CHECK(s == VF_OK && !r.localized, "another texture is not localized (%s)",
          s == VF_OK ? r.reason : vf_error_message());
    if (s == VF_OK)
        printf("another texture: %s\n", r.localized ? "localized!" : r.reason);
    vf_localizer_close(loc);
    printf("localize case: %.1f s\n", vf_now() - start);
}

/* The object's true mask in view i: pixels whose centre ray first hits the central box. */
static int true_mask(int i, uint8_t *mask)
{
    vf_camera cam = scene_camera();
    double c2w_cv[16], o[3], rot[9];
    vf_c2w_gl_to_cv(posed.gt[i], c2w_cv);
    vf_mat4_translation(c2w_cv, o);
    vf_mat4_rotation(c2w_cv, rot);
    int on = 0;
    for (int y = 0; y < HEIGHT; y++)
        for (int x = 0; x < WIDTH; x++) {
            double ray[3], d[3];
            vf_camera_pixel_ray(&cam, x + 0.5, y + 0.5, ray);
            vf_mat3_apply(rot, ray, d);
            on += mask[y * WIDTH + x] = cast(o, d).surf == SURF_BOX;
        }
    return on;
}

/* Masks against the true silhouettes, view by view: intersection over union. */
typedef struct iou_tally {
    double sum, min;
    int n, good; /* views, and those over 0.8 */
} iou_tally;

/* Add a view: ours and truth are WIDTH x HEIGHT, nonzero on the object. Returns its IoU. */
static double iou_add(iou_tally *t, const uint8_t *ours, const uint8_t *truth)
{
    int both = 0, either = 0;
    for (int j = 0; j < WIDTH * HEIGHT; j++) {
        both += ours[j] && truth[j];
        either += ours[j] || truth[j];
    }
    const double iou = either ? (double)both / either : 0;
    t->min = t->n == 0 || iou < t->min ? iou : t->min;
    t->sum += iou;
    t->good += iou > 0.8;
    t->n++;
    return iou;
}

/* Print the tally as `what` and check it: every view compared, a mean over 0.8, and three
 * views in four over 0.8. */
static void iou_check(const iou_tally *t, const char *what)
{
    printf("%s: intersection over union with the true silhouettes, mean %.3f, worst %.3f, %d "
           "of %d views over 0.8\n",
           what, t->n ? t->sum / t->n : 0, t->min, t->good, t->n);
    CHECK(t->n == TRAIN_VIEWS, "%s: every view compared (%d)", what, t->n);
    CHECK(t->n && t->sum / t->n > 0.8, "%s: mean IoU %.3f", what, t->n ? t->sum / t->n : 0);
    CHECK(t->good >= 3 * t->n / 4, "%s: %d of %d views over 0.8", what, t->good, t->n);
}

/* Object mode: the central box cut out of every training view (vf_cutout_views, from the
 * workspace's sparse points) against its true silhouette from the ray caster. */
static void test_cutout(void)
{
    build_workspace();
    if (posed.built != 1)
        return;
    char poses_dir[VF_PATH_MAX], out_dir[VF_PATH_MAX], path[VF_PATH_MAX];
    vf_path_join(poses_dir, sizeof poses_dir, posed.ws, "poses");
    vf_path_join(out_dir, sizeof out_dir, vf_test_tmpdir(), "object");
    vf_path_join(path, sizeof path, poses_dir, "transforms.json");
    vf_dataset views = {0}, cut = {0};
    json_t *report = NULL;
    vf_cutout_options o;
    vf_cutout_defaults(&o);
    double start = vf_now();
    vf_status s = vf_dataset_load(path, &views);
    if (s == VF_OK)
        s = vf_cutout_views(&views, poses_dir, out_dir, &o, &cut, &report);
    CHECK(s == VF_OK, "cutout: %s", vf_error_message());
    printf("cutout: %lld object points of %lld candidates (%lld on the ground) in %.1f s\n",
           json_integer_value(json_object_get(report, "object_points")),
           json_integer_value(json_object_get(report, "candidates")),
           json_integer_value(json_object_get(report, "on_surface")), vf_now() - start);
    CHECK(json_is_true(json_object_get(report, "surface_found")), "the ground is found");
    uint8_t *truth = malloc(WIDTH * HEIGHT);
    iou_tally t = {0};
    uint8_t *ours = malloc(WIDTH * HEIGHT);
    for (int i = 0; s == VF_OK && truth && ours && i < cut.count; i++) {
        int k = view_index(views.frames[i].image_path);
        vf_image rgba = {0};
        if (k < 0 || !true_mask(k, truth) ||
            vf_image_load(cut.frames[i].image_path, &rgba) != VF_OK || rgba.channels != 4 ||
            rgba.width != WIDTH || rgba.height != HEIGHT) {
            CHECK(0, "view %d: no mask to compare (%s)", i, cut.frames[i].image_path);
            vf_image_free(&rgba);
            continue;
        }
        for (int j = 0; j < WIDTH * HEIGHT; j++)
            ours[j] = rgba.data[4 * j + 3] > 0.5f;
        iou_add(&t, ours, truth);
        vf_image_free(&rgba);
    }
    free(truth);
    free(ours);
    /* measured: mean 0.90-0.92, 18-19 of 20 over 0.8 (a view or two lose a face to the
     * ground's colours: 0.28-0.32) */
    iou_check(&t, "cutout");
    json_decref(report);
    vf_dataset_free(&views);
    vf_dataset_free(&cut);
}

/* Object mode end to end (vf_train_run with object_only): a field trained on the whole
 * photos, cut out in 3D by the training views' masks (vf_field_cut_object); its silhouette
 * in every view (vf_field_silhouette, what score cuts re-captured frames by) against the
 * box's true one. */
static void test_train_object(void)
{
    build_workspace();
    if (posed.built != 1)
        return;
    vf_train_options o;
    vf_train_defaults(&o);
    o.object_only = 1;
    o.steps = OBJECT_STEPS;
    vf_workspace w;
    json_t *report = NULL;
    double start = vf_now();
    vf_status s = vf_workspace_open(posed.ws, 0, &w);
    if (s == VF_OK) {
        s = vf_train_run(&w, &o, &report);
        vf_workspace_close(&w);
    }
    CHECK(s == VF_OK, "train --object-only: %s", vf_error_message());
    if (s != VF_OK)
        return;
    const char *mode = json_string_value(json_object_get(report, "mode"));
    json_t *cut = json_object_get(json_object_get(report, "cutout"), "field_cut");
    printf("train --object-only: %d steps in %.1f s, mode %s, kept share %.3f, held-out PSNR "
           "inside the silhouettes %.2f dB\n",
           OBJECT_STEPS, vf_now() - start, mode ? mode : "?",
           json_number_value(json_object_get(cut, "kept_share")),
           json_number_value(json_object_get(report, "held_out_psnr_object")));
    CHECK(mode && strcmp(mode, "object") == 0, "the report says object mode");
    json_decref(report);

    char path[VF_PATH_MAX];
    vf_field *f = NULL;
    vf_dataset views = {0};
    vf_path_join(path, sizeof path, posed.ws, "train/" VF_FIELD_FILE);
    s = vf_field_load(path, &f);
    vf_path_join(path, sizeof path, posed.ws, "poses/transforms.json");
    if (s == VF_OK)
        s = vf_dataset_load(path, &views);
    CHECK(s == VF_OK, "the field and its views: %s", vf_error_message());
    uint8_t *truth = malloc(WIDTH * HEIGHT);
    iou_tally t = {0};
    for (int i = 0; s == VF_OK && truth && i < views.count; i++) {
        const vf_frame *fr = &views.frames[i];
        int k = view_index(fr->image_path);
        uint8_t *sil = NULL;
        if (k < 0 || !true_mask(k, truth) || fr->camera.width != WIDTH ||
            fr->camera.height != HEIGHT ||
            vf_field_silhouette(f, &fr->camera, fr->c2w, 0, &sil) != VF_OK) {
            CHECK(0, "view %d: no silhouette to compare (%s)", i, fr->image_path);
            free(sil);
            continue;
        }
        const double iou = iou_add(&t, sil, truth);
        if (iou < 0.8)
            printf("  view %d: intersection over union %.3f\n", k, iou);
        free(sil);
    }
    free(truth);
    /* measured over 4 runs: mean 0.878-0.886, 18 of 20 views over 0.8; the worst, view 2
     * (0.35-0.36), has the pillar in front of the box, kept with it: a point is kept when
     * most views that see it find it on the object, and most see the pillar before the box */
    iou_check(&t, "object mode, the field's silhouettes");
    vf_field_free(f);
    vf_dataset_free(&views);
}

/* One scene-mode training of the workspace, every 4th view held out; *report its report.json. */
static vf_status train_scene(int steps, json_t **report)
{
    vf_train_options o;
    vf_train_defaults(&o);
    o.steps = steps;
    o.holdout = 4;
    o.restart = 1;
    vf_workspace w;
    vf_status s = vf_workspace_open(posed.ws, 0, &w);
    if (s == VF_OK) {
        s = vf_train_run(&w, &o, report);
        vf_workspace_close(&w);
    }
    return s;
}

/* Scene mode, the default for photos with their surroundings: train's check that each
 * held-out render shows the object where its photo does (report.json object_check: the
 * photo's GrabCut cut-out against the render's surfaces in the object's region) finds it in
 * every held-out view of a field trained as object mode's, and in none of a field trained a
 * few steps (fog): the check can fail (and says it cannot vouch for itself, the training
 * views being fog too). The gap between training and held-out views stays small. */
static void test_train_scene(void)
{
    build_workspace();
    if (posed.built != 1)
        return;
    const struct {
        int steps, fog;
    } runs[] = {{OBJECT_STEPS, 0}, {FOG_STEPS, 1}};
    for (int r = 0; r < 2; r++) {
        json_t *report = NULL;
        vf_status s = train_scene(runs[r].steps, &report);
        CHECK(s == VF_OK, "train, %d steps: %s", runs[r].steps, vf_error_message());
        if (s != VF_OK)
            continue;
        const json_t *check = json_object_get(report, "object_check");
        const int views = (int)json_integer_value(json_object_get(check, "views")),
                  missing = (int)json_integer_value(json_object_get(check, "missing"));
        const double mean = json_number_value(json_object_get(check, "iou_mean")),
                     gap = json_number_value(json_object_get(report, "psnr_gap"));
        printf("train, scene mode, %d steps: held-out %.2f dB (%.2f dB below the training "
               "views); the object in %d of %d held-out renders, overlap %.3f on average, %.3f "
               "at worst (training views %.3f)\n",
               runs[r].steps, json_number_value(json_object_get(report, "held_out_psnr")), gap,
               views - missing, views, mean, json_number_value(json_object_get(check, "iou_min")),
               json_number_value(json_object_get(check, "training_iou_mean")));
        CHECK(views == TRAIN_VIEWS / 4, "every held-out view checked (%d)", views);
        if (runs[r].fog) {
            /* measured: 0 of 5, overlap 0.000 (the fog's surfaces, where it has any, lie far
             * from the box) */
            CHECK(missing == views && mean < 0.1,
                  "fog: %d of %d held-out renders found without the object, overlap %.3f", missing,
                  views, mean);
            /* fog in the training views as well: the check cannot vouch for itself there */
            CHECK(json_is_false(json_object_get(check, "conclusive")), "fog: not conclusive");
        } else {
            /* measured over 4 runs: 4 of 5 found, mean 0.69-0.75, training views 0.80-0.85,
             * gap 1.9-2.1 dB; the one below 0.5 is view 2 (0.32-0.45), where the pillar stands
             * before the box and the photo's cut-out takes it with the box (test_cutout's
             * worst view too) */
            CHECK(missing <= 1, "%d held-out renders found without the object", missing);
            CHECK(json_is_true(json_object_get(check, "conclusive")), "the check is conclusive");
            CHECK(mean > 0.6, "held-out overlap %.3f", mean);
            CHECK(json_number_value(json_object_get(check, "training_iou_mean")) > 0.7,
                  "training views' overlap %.3f",
                  json_number_value(json_object_get(check, "training_iou_mean")));
            CHECK(fabs(gap) < 3, "train/held-out gap %.2f dB", gap);
        }
        json_decref(report);
    }
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    make_clutter();
    CHECK_CASE(test_render);
    CHECK_CASE(test_poses);
    CHECK_CASE(test_localize);
    CHECK_CASE(test_cutout);
    CHECK_CASE(test_train_object);
    CHECK_CASE(test_train_scene);
    return check_finish();
}
