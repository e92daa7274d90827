/* The poses stage on a posed set (`ingest --transforms`): the set's poses and camera are kept,
 * and COLMAP only triangulates sparse points at them (point_triangulator). Those points are
 * what a posed import otherwise lacks: the depth loss of training, the normalization around
 * the object and object mode all read them (the fox, 3 minutes: 25.21 dB held-out without,
 * 27.38 dB with). */
#define _GNU_SOURCE
#include <errno.h>
#include <math.h>
#include <sqlite3.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "poses_internal.h"
#include "vf/log.h"

/* Two cameras are the same when every intrinsic agrees to a millionth of a pixel. */
static int same_camera(const vf_camera *a, const vf_camera *b)
{
    const double x[] = {a->fx - b->fx, a->fy - b->fy, a->cx - b->cx, a->cy - b->cy,
                        a->k1 - b->k1, a->k2 - b->k2, a->p1 - b->p1, a->p2 - b->p2};
    for (size_t i = 0; i < sizeof x / sizeof x[0]; i++)
        if (fabs(x[i]) > 1e-6)
            return 0;
    return a->width == b->width && a->height == b->height;
}

vf_status vf__poses_load_set(poses_run *run, const vf_workspace *ws)
{
    char path[VF_PATH_MAX];
    vf_status status = vf_workspace_path(ws, "ingest", "transforms.json", path, sizeof path);
    if (status == VF_OK)
        status = vf_dataset_load(path, &run->set);
    if (status != VF_OK)
        return status;
    if (run->opt->has_intrinsics || strcmp(run->opt->camera_model, "auto"))
        return vf_fail(VF_EINPUT, "WS/ingest is a posed set, which brings its own camera: drop "
                                  "--intrinsics, --camera and --camera-model");
    for (int i = 1; i < run->set.count; i++)
        if (!same_camera(&run->set.frames[i].camera, &run->set.frames[0].camera))
            return vf_fail(VF_EINPUT, "%s: frame %d has another camera than frame 0; "
                                      "triangulating at known poses needs one camera",
                           path, i);
    run->opt->known = run->set.frames[0].camera;
    run->opt->has_intrinsics = 1;
    return VF_OK;
}

/* The set's frame behind a prepared frame: the same file name (ingest copied the set's images
 * into WS/ingest/images, where the poses stage found them). */
static const vf_frame *set_frame(const poses_run *run, const vf_sfm_frame *f)
{
    char mine[256], theirs[256];
    vf_path_basename(mine, sizeof mine, f->source, 0);
    for (int i = 0; i < run->set.count; i++) {
        vf_path_basename(theirs, sizeof theirs, run->set.frames[i].image_path, 0);
        if (!strcmp(mine, theirs))
            return &run->set.frames[i];
    }
    return NULL;
}

static const vf_frame *frame_named(const poses_run *run, const char *colmap_name)
{
    for (int i = 0; i < run->frames.count; i++)
        if (!strcmp(run->frames.frames[i].name, colmap_name))
            return set_frame(run, &run->frames.frames[i]);
    return NULL;
}

/* Pairs worth matching: each frame with the POSED_NEIGHBOURS frames whose viewing directions
 * are nearest its own (photos that look at the object from far apart share no features).
 * Measured on the fox: 560 pairs, 9,680 points in 76 s of matching; all 1225 pairs, 9,900
 * points in 164 s. */
#define POSED_NEIGHBOURS 20
static vf_status write_pairs(const poses_run *run, const char *path, int *pair_count)
{
    int n = run->frames.count;
    const vf_frame **f = calloc((size_t)n, sizeof *f);
    double *cosine = malloc(sizeof *cosine * (size_t)n);
    unsigned char *paired = calloc((size_t)n * (size_t)n, 1);
    FILE *out = fopen(path, "w");
    vf_status status =
        f && cosine && paired && out ? VF_OK : vf_fail(VF_EINTERNAL, "cannot write %s", path);
    for (int i = 0; status == VF_OK && i < n; i++)
        if (!(f[i] = set_frame(run, &run->frames.frames[i])))
            status = vf_fail(VF_EINPUT, "%s is not in WS/ingest/transforms.json",
                             run->frames.frames[i].source);
    *pair_count = 0;
    for (int i = 0; status == VF_OK && i < n; i++) {
        for (int j = 0; j < n; j++) /* the cameras look along -z: compare their z columns */
            cosine[j] = f[i]->c2w[2] * f[j]->c2w[2] + f[i]->c2w[6] * f[j]->c2w[6] +
                        f[i]->c2w[10] * f[j]->c2w[10];
        cosine[i] = -INFINITY;
        for (int k = 0; k < POSED_NEIGHBOURS && k < n - 1; k++) {
            int best = 0;
            for (int j = 1; j < n; j++)
                if (cosine[j] > cosine[best])
                    best = j;
            cosine[best] = -INFINITY;
            int a = i < best ? i : best, b = i < best ? best : i;
            if (!paired[(size_t)a * (size_t)n + (size_t)b]++) {
                fprintf(out, "%s %s\n", run->frames.frames[a].name, run->frames.frames[b].name);
                (*pair_count)++;
            }
        }
    }
    if (out && (ferror(out) | fclose(out)) && status == VF_OK)
        status = vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(errno));
    free(f);
    free(cosine);
    free(paired);
    return status;
}

vf_status vf__poses_match_posed(poses_run *run)
{
    char pairs[VF_PATH_MAX];
    int count = 0;
    vf_status status = vf_path_join(pairs, sizeof pairs, run->scratch, "pairs.txt");
    if (status == VF_OK)
        status = write_pairs(run, pairs, &count);
    if (status != VF_OK)
        return status;
    vf_info("matching %d pairs: each frame with its %d nearest in viewing direction (the set's "
            "poses)",
            count, POSED_NEIGHBOURS);
    vf_args a = {0};
    vf_args_add(&a, "matches_importer");
    vf_args_opt(&a, "--database_path", "%s", run->database);
    vf_args_opt(&a, "--match_list_path", "%s", pairs);
    vf_args_opt(&a, "--match_type", "pairs");
    vf_args_opt(&a, "--SiftMatching.use_gpu", "0");
    return vf__poses_run_step(run, "COLMAP: matching neighbouring views", &a);
}

/* cameras.txt and images.txt of a model at the set's poses, one image per row of the
 * database (point_triangulator finds an image's features by its database id), no points. */
static vf_status write_known_model(poses_run *run, const char *dir)
{
    char path[VF_PATH_MAX];
    sqlite3 *db = NULL;
    sqlite3_stmt *stmt = NULL;
    if (sqlite3_open_v2(run->database, &db, SQLITE_OPEN_READONLY, NULL) != SQLITE_OK ||
        sqlite3_prepare_v2(db, "SELECT image_id, name, camera_id FROM images", -1, &stmt,
                           NULL) != SQLITE_OK) {
        vf_status status = vf_fail(VF_EINTERNAL, "cannot read %s: %s", run->database,
                                   db ? sqlite3_errmsg(db) : "cannot open");
        sqlite3_close(db);
        return status;
    }
    FILE *images = NULL, *cameras = NULL, *points = NULL;
    vf_status status = vf_path_join(path, sizeof path, dir, "images.txt");
    if (status == VF_OK && !(images = fopen(path, "w")))
        status = vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(errno));
    int camera_id = -1, rc, written = 0;
    while (status == VF_OK && (rc = sqlite3_step(stmt)) == SQLITE_ROW) {
        const char *name = (const char *)sqlite3_column_text(stmt, 1);
        const vf_frame *f = name ? frame_named(run, name) : NULL;
        if (!f) {
            status = vf_fail(VF_EINTERNAL, "%s: image %s is not a prepared frame", run->database,
                             name ? name : "(null)");
            break;
        }
        double R[9], t[3], q[4];
        vf_c2w_gl_to_w2c_cv(f->c2w, R, t);
        vf_rot_to_quat(R, q);
        camera_id = sqlite3_column_int(stmt, 2); /* one: the extractor made one per folder */
        fprintf(images, "%d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %d %s\n\n",
                sqlite3_column_int(stmt, 0), q[0], q[1], q[2], q[3], t[0], t[1], t[2], camera_id,
                name);
        written++;
    }
    sqlite3_finalize(stmt);
    sqlite3_close(db);
    if (status == VF_OK && written != run->frames.count)
        status = vf_fail(VF_EINTERNAL, "%s lists %d images, %d frames were prepared",
                         run->database, written, run->frames.count);
    const vf_camera *c = &run->opt->known;
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, dir, "cameras.txt");
    if (status == VF_OK) {
        if (!(cameras = fopen(path, "w")))
            status = vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(errno));
        else if (vf_camera_has_distortion(c))
            fprintf(cameras, "%d OPENCV %d %d %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n",
                    camera_id, c->width, c->height, c->fx, c->fy, c->cx, c->cy, c->k1, c->k2,
                    c->p1, c->p2);
        else
            fprintf(cameras, "%d PINHOLE %d %d %.17g %.17g %.17g %.17g\n", camera_id, c->width,
                    c->height, c->fx, c->fy, c->cx, c->cy);
    }
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, dir, "points3D.txt");
    if (status == VF_OK && !(points = fopen(path, "w")))
        status = vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(errno));
    FILE *files[] = {images, cameras, points};
    for (int i = 0; i < 3; i++)
        if (files[i] && (ferror(files[i]) | fclose(files[i])) && status == VF_OK)
            status = vf_fail(VF_EINTERNAL, "cannot write the model in %s", dir);
    return status;
}

/* The feature matches between frames that COLMAP verified (two-view geometry inliers). */
static vf_status verified_matches(const char *database, long long *count)
{
    sqlite3 *db = NULL;
    sqlite3_stmt *stmt = NULL;
    *count = 0;
    int ok = sqlite3_open_v2(database, &db, SQLITE_OPEN_READONLY, NULL) == SQLITE_OK &&
             sqlite3_prepare_v2(db, "SELECT SUM(rows) FROM two_view_geometries WHERE rows > 0",
                                -1, &stmt, NULL) == SQLITE_OK &&
             sqlite3_step(stmt) == SQLITE_ROW;
    if (ok)
        *count = sqlite3_column_int64(stmt, 0);
    vf_status status = ok ? VF_OK
                          : vf_fail(VF_EINTERNAL, "cannot read %s: %s", database,
                                    db ? sqlite3_errmsg(db) : "cannot open");
    sqlite3_finalize(stmt);
    sqlite3_close(db);
    return status;
}

/* Do the set's poses fit its photos? Points triangulated at right poses take in a good share
 * of the feature matches between frames; at wrong ones (another photo's pose, another axis
 * convention) few survive. The share: observations of points over the matches' ends. Measured:
 * the fox 0.19 (50 frames, 20 neighbours each) and 0.29 (13 frames), the NeRF-synthetic chair
 * 0.20; the 13 fox frames with their poses shuffled 0.03 (291 points, 1.25 px). */
#define POSED_MIN_EXPLAINED 0.10
static vf_status check_explained(poses_run *run)
{
    long long matches, observations = 0;
    vf_status status = verified_matches(run->database, &matches);
    for (int i = 0; i < run->model.point_count; i++)
        observations += run->model.points[i].track_length;
    run->explained = matches > 0 ? (double)observations / (2.0 * (double)matches) : 0;
    if (status != VF_OK || matches == 0 || run->explained >= POSED_MIN_EXPLAINED)
        return status; /* no match at all: too few features, said below */
    return vf_fail(VF_EINPUT, "the set's poses do not fit its photos: points at those poses take "
                              "in %.0f%% of the features matched between frames (right poses: "
                              "19-29%%); check that its poses are camera-to-world in OpenGL axes "
                              "(NeRF's convention) and belong to these images",
                   100 * run->explained);
}

vf_status vf__poses_triangulate(poses_run *run)
{
    char known[VF_PATH_MAX], sparse[VF_PATH_MAX], text[VF_PATH_MAX];
    vf_status status = vf_path_join(known, sizeof known, run->scratch, "known");
    if (status == VF_OK)
        status = vf_path_join(sparse, sizeof sparse, run->scratch, "triangulated");
    if (status == VF_OK)
        status = vf_path_join(text, sizeof text, run->scratch, "triangulated_text");
    if (status == VF_OK)
        status = vf_mkdirs(known);
    if (status == VF_OK)
        status = vf_mkdirs(sparse);
    if (status == VF_OK)
        status = write_known_model(run, known);
    if (status != VF_OK)
        return status;
    /* the poses stay as given; the intrinsics too (the set's) */
    vf_args a = {0};
    vf_args_add(&a, "point_triangulator");
    vf_args_opt(&a, "--database_path", "%s", run->database);
    vf_args_opt(&a, "--image_path", "%s", run->images);
    vf_args_opt(&a, "--input_path", "%s", known);
    vf_args_opt(&a, "--output_path", "%s", sparse);
    vf_args_opt(&a, "--Mapper.ba_refine_focal_length", "0");
    vf_args_opt(&a, "--Mapper.ba_refine_principal_point", "0");
    vf_args_opt(&a, "--Mapper.ba_refine_extra_params", "0");
    status = vf__poses_run_step(run, "COLMAP: triangulating points at the set's poses", &a);
    if (status == VF_OK)
        status = vf__poses_convert_to_text(run, sparse, text);
    vf_colmap_model_free(&run->model);
    if (status == VF_OK)
        status = vf_colmap_model_load(text, &run->model);
    if (status != VF_OK)
        return status;
    snprintf(run->model_dir, sizeof run->model_dir, "%s", sparse);
    run->model_count = 1;
    if ((status = check_explained(run)) != VF_OK)
        return status;
    if (run->model.point_count == 0)
        return vf_fail(VF_EINPUT, "COLMAP triangulated no points at the set's poses: its photos "
                                  "share too few features (a posed set trains without this "
                                  "stage)");
    vf_info("%d points triangulated at the set's poses (reprojection error %.2f px; they take "
            "in %.0f%% of the matched features)",
            run->model.point_count, vf_colmap_model_reprojection_error(&run->model),
            100 * run->explained);
    return vf__poses_keep_model_text(run, text);
}
