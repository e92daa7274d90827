/* The poses stage (vf/poses.h): the flow, the normalization and the outputs; the COLMAP
 * steps are in poses_colmap.c. */
#define _GNU_SOURCE
#include "vf/poses.h"

#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "poses_internal.h"
#include "vf/dataset.h"
#include "vf/ingest.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/normalize.h"
#include "vf/sfm_export.h"

/* The auto matcher (see choose_methods and docs/capture_and_poses.md). */
#define EXHAUSTIVE_MAX_FRAMES 40  /* any capture: all pairs are affordable and the surest */
/* unordered photos: all pairs up to here, then retrieval. Measured by bench_poses (rendered
 * views of the antique camera in the room, 1024 features): at 50 photos all pairs took 133 s and
 * retrieval 157 s; at 100, 482 s and 341 s (unchecked), both 0.08 deg off; 80 sits in that
 * bracket. */
#define EXHAUSTIVE_MAX_PHOTOS 80

static int one_of(const char *value, const char *const *choices)
{
    for (; *choices; choices++)
        if (!strcmp(value, *choices))
            return 1;
    return 0;
}

void vf_poses_defaults(vf_poses_options *o)
{
    *o = (vf_poses_options){.matcher = "auto",
                            .camera_model = "auto",
                            .overlap = 10,
                            .max_features = 2048,
                            .min_registered = 0.5,
                            .undistort = 1,
                            .check = 1};
}

vf_status vf_poses_options_check(const vf_poses_options *o)
{
    static const char *const matchers[] = {"auto", "sequential", "exhaustive", "retrieval", NULL};
    static const char *const models[] = {
        "auto", "OPENCV", "SIMPLE_RADIAL", "RADIAL", "PINHOLE", "SIMPLE_PINHOLE", NULL};
    if (!o->matcher || !one_of(o->matcher, matchers))
        return vf_fail(VF_EINPUT, "--matcher: use auto, sequential, exhaustive or retrieval");
    if (!o->camera_model || !one_of(o->camera_model, models))
        return vf_fail(VF_EINPUT, "--camera-model: use auto, OPENCV, SIMPLE_RADIAL, RADIAL, "
                                  "PINHOLE or SIMPLE_PINHOLE");
    if (o->has_intrinsics && strcmp(o->camera_model, "auto"))
        return vf_fail(VF_EINPUT, "known intrinsics choose the camera model themselves: drop "
                                  "--camera-model");
    if (o->vocab_tree && !vf_is_file(o->vocab_tree))
        return vf_fail(VF_EINPUT, "--vocab-tree: %s does not exist", o->vocab_tree);
    if (o->overlap < 1 || o->max_features < 100 ||
        !(o->min_registered > 0 && o->min_registered <= 1))
        return vf_fail(VF_EINPUT, "poses: overlap >= 1, max_features >= 100 and min_registered "
                                  "in (0, 1] are needed");
    return VF_OK;
}

/* Frames of a video (in capture order) beyond EXHAUSTIVE_MAX_FRAMES are matched by
 * retrieval too, not with their neighbours: a walk around the object comes back to where it
 * started, and neighbour matching never closes that loop. Measured on a studio capture of the
 * water bottle (100 of 180 frames, 270x480, two loops; true poses known): sequential 64 s,
 * 2.56 deg and 5.3% of the camera distance off (1.93 deg with SIMPLE_RADIAL); retrieval 160 s,
 * 0.15 deg and 0.26%; all pairs 225 s, 0.16 deg. */
const char *vf_poses_auto_matcher(int frames, int ordered)
{
    return frames <= EXHAUSTIVE_MAX_FRAMES                ? "exhaustive"
           : !ordered && frames <= EXHAUSTIVE_MAX_PHOTOS ? "exhaustive"
                                                          : "retrieval";
}

/* Fit the known intrinsics to the frames' size (a calibration at another resolution of the
 * same aspect is scaled). */
static vf_status fit_known_camera(const vf_sfm_images *frames, vf_camera *cam)
{
    if (frames->size_groups > 1)
        return vf_fail(VF_EINPUT,
                       "the frames come in %d sizes, but known intrinsics fit one; "
                       "drop --intrinsics/--camera or ingest frames of one size",
                       frames->size_groups);
    int w = frames->frames[0].width, h = frames->frames[0].height;
    if (cam->width == 0) { /* --intrinsics: stated for the frames as they are */
        cam->width = w;
        cam->height = h;
    } else if (cam->width != w || cam->height != h) {
        if (abs(cam->width * h - cam->height * w) > (w > h ? w : h) / 50)
            return vf_fail(VF_EINPUT,
                           "the camera file is for %dx%d images, the frames are %dx%d "
                           "(another aspect ratio or orientation)",
                           cam->width, cam->height, w, h);
        *cam = vf_camera_scaled(cam, w, h);
    }
    return VF_OK;
}

/* Resolve "auto" for the matcher and the camera model, and say what was chosen and why.
 * Matching is chosen by what the frames are, not only how many: sequential matching of a
 * photo folder pairs frames by file name, and with names not in capture order it gives a
 * confident, wrong model (measured: 51 hash-named phone photos registered 51/51, 11.4 deg
 * off; all pairs: 0.54 deg). */
static void choose_methods(poses_run *run, const char *source)
{
    const vf_poses_options *opt = run->opt;
    int n = run->frames.count;
    if (run->posed) {
        run->matcher = strcmp(opt->matcher, "auto") ? opt->matcher : "poses";
        run->camera_model = vf_camera_has_distortion(&opt->known) ? "OPENCV" : "PINHOLE";
        vf_info("a posed set: its poses and camera (%s) are kept, COLMAP triangulates points",
                run->camera_model);
        if (strcmp(run->matcher, "poses"))
            vf_info("matching with %s", run->matcher);
        return;
    }
    int ordered = !strcmp(source, "video") || !strcmp(source, "camera");
    run->matcher = strcmp(opt->matcher, "auto") ? opt->matcher : vf_poses_auto_matcher(n, ordered);
    const char *why = strcmp(opt->matcher, "auto") ? ""
                      : n <= EXHAUSTIVE_MAX_FRAMES ? " (few frames)"
                      : ordered ? " (frames of a video: retrieval closes the loop around the "
                                  "object, which neighbour matching does not)"
                                : " (photos: file names say nothing about where they were taken)";
    if (!strcmp(run->matcher, "sequential"))
        vf_info("matching each frame with its next %d (and 2^k ahead)%s%s", opt->overlap,
                opt->vocab_tree ? ", with loop detection" : "", why);
    else if (!strcmp(run->matcher, "retrieval"))
        vf_info("matching each of %d frames with its %d most similar (vocabulary tree)%s", n,
                RETRIEVAL_IMAGES < n - 1 ? RETRIEVAL_IMAGES : n - 1, why);
    else
        vf_info("matching all %d pairs of %d frames%s", n * (n - 1) / 2, n, why);

    if (opt->has_intrinsics)
        run->camera_model = vf_camera_has_distortion(&opt->known) ? "OPENCV" : "PINHOLE";
    else if (strcmp(opt->camera_model, "auto"))
        run->camera_model = opt->camera_model;
    else
        run->camera_model = run->frames.background_fraction > 0.4 ? "SIMPLE_RADIAL" : "OPENCV";
    vf_info("camera model %s%s", run->camera_model,
            opt->has_intrinsics ? " (known intrinsics, not refined)"
            : !strcmp(run->camera_model, "SIMPLE_RADIAL") && !strcmp(opt->camera_model, "auto")
                ? " (background removed: few features, so a simpler lens)"
                : "");
}

static vf_status prepare_frames(poses_run *run, const vf_workspace *ws)
{
    static const float white[3] = {1, 1, 1};
    char ingest_images[VF_PATH_MAX];
    double start = vf_now();
    vf_status status =
        vf_workspace_path(ws, "ingest", "images", ingest_images, sizeof ingest_images);
    if (status == VF_OK)
        status = vf_sfm_images_prepare(ingest_images, run->images, white, &run->frames);
    if (status == VF_OK && run->opt->has_intrinsics)
        status = fit_known_camera(&run->frames, &run->opt->known);
    json_object_set_new(run->seconds, "prepare", vf_json_number(vf_now() - start));
    if (status == VF_OK && run->frames.count < 3)
        status = vf_fail(VF_EINPUT,
                         "only %d frames in WS/ingest/images: structure from motion "
                         "needs at least 3 (better 20 or more)",
                         run->frames.count);
    return status;
}

/* Fewer than opt->min_registered of the frames in the model is an input problem. */
static vf_status check_registration(const poses_run *run)
{
    int registered = run->model.image_count, total = run->frames.count;
    if (registered >= run->opt->min_registered * total)
        return VF_OK;
    char split[96] = "";
    if (run->model_count > 1)
        snprintf(split, sizeof split, " (the scene fell apart into %d separate models)",
                 run->model_count);
    return vf_fail(VF_EINPUT,
                   "COLMAP registered only %d of %d frames%s; this usually means blurry frames, "
                   "too little texture (plain or removed backgrounds), or too little overlap "
                   "between frames: try sharper frames taken closer together, --matcher "
                   "exhaustive, --camera-model SIMPLE_RADIAL or more --max-features",
                   registered, total, split);
}

static json_t *check_json(const poses_check *c)
{
    const vf_pose_agreement *g = &c->agreement;
    json_t *j = json_pack("{s:s, s:i, s:i, s:o}", "verdict", c->verdict, "sampled", c->sampled,
                          "registered", c->registered, "seconds", vf_json_number(c->seconds));
    if (c->registered >= 3)
        json_object_update_new(j,
                               json_pack("{s:o, s:o, s:o, s:i, s:o}", "rotation_median_deg",
                                         vf_json_number(g->rot_median), "rotation_p90_deg",
                                         vf_json_number(g->rot_p90), "rotation_max_deg",
                                         vf_json_number(g->rot_max), "over_5deg", g->rot_over_5deg,
                                         "position_median", vf_json_number(g->pos_median)));
    return j;
}

/* Matching again, all pairs, after an automatic choice gave a model that cannot be trusted
 * (the pairs matched so far are reused). */
static vf_status fall_back_to_all_pairs(poses_run *run)
{
    run->fallback = run->matcher;
    run->matcher = "exhaustive";
    vf_status status = vf__poses_match(run);
    if (status == VF_OK)
        status = vf__poses_map(run);
    if (status == VF_OK)
        status = check_registration(run);
    return status;
}

/* Is the model to be trusted? Too few frames registered is an error (check_registration). A
 * model from sequential or retrieval matching is then compared with all-pairs matching of a
 * sample of its frames (vf__poses_check): a confidently wrong model registers every frame and
 * looks fine by every count. When an automatic choice of matcher fails either test it falls
 * back to all pairs; a matcher the user chose is an error. */
static vf_status verify_model(poses_run *run)
{
    int chosen = strcmp(run->opt->matcher, "auto") != 0;
    int exhaustive = !strcmp(run->matcher, "exhaustive");
    if (run->model.image_count < run->opt->min_registered * run->frames.count) {
        if (chosen || exhaustive)
            return check_registration(run);
        vf_warn("only %d of %d frames registered with %s matching; matching all pairs instead",
                run->model.image_count, run->frames.count, run->matcher);
        return fall_back_to_all_pairs(run);
    }
    if (!run->opt->check || exhaustive)
        return VF_OK;
    poses_check check;
    vf_status status = vf__poses_check(run, &check);
    if (status != VF_OK)
        return status;
    run->check = check_json(&check);
    const vf_pose_agreement *g = &check.agreement;
    if (!strcmp(check.verdict, "inconclusive")) {
        vf_warn("registration check: only %d of %d sampled frames registered when matched all "
                "pairs on their own (too far apart); the model could not be checked",
                check.registered, check.sampled);
        return VF_OK;
    }
    if (!strcmp(check.verdict, "agrees")) {
        vf_info("registration check: %d frames matched all pairs agree with the model "
                "(rotations %.2f deg, positions %.2f%% of their spread off, medians)",
                check.registered, g->rot_median, 100 * g->pos_median);
        return VF_OK;
    }
    if (chosen)
        return vf_fail(VF_EINPUT,
                       "%s matching gave a model that disagrees with all-pairs matching of %d "
                       "of its frames (rotations %.1f deg, positions %.1f%% of their spread "
                       "off, medians): its poses are likely wrong; use --matcher exhaustive, "
                       "or --no-check to keep it",
                       run->matcher, check.registered, g->rot_median, 100 * g->pos_median);
    vf_warn("registration check: the %s model disagrees with all-pairs matching of %d of its "
            "frames (rotations %.1f deg, positions %.1f%% of their spread off, medians); "
            "matching all pairs instead",
            run->matcher, check.registered, g->rot_median, 100 * g->pos_median);
    return fall_back_to_all_pairs(run);
}

/* The normalization of run->model, from its cameras and points. */
static vf_status normalize_model(const poses_run *run, vf_normalization *norm)
{
    const vf_colmap_model *m = &run->model;
    double *c2w = malloc((size_t)m->image_count * 16 * sizeof *c2w);
    double *points = malloc((size_t)(m->point_count + 1) * 3 * sizeof *points);
    vf_status status = VF_OK;
    if (!c2w || !points)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < m->image_count; i++)
        vf_colmap_image_c2w(&m->images[i], c2w + 16 * i);
    for (int i = 0; status == VF_OK && i < m->point_count; i++)
        memcpy(points + 3 * i, m->points[i].xyz, 3 * sizeof *points);
    if (status == VF_OK)
        status = vf_normalize_scene(c2w, m->image_count, points, m->point_count, norm);
    free(c2w);
    free(points);
    return status;
}

/* transforms(.json or _undistorted.json) for `model`, images under image_dir. */
static vf_status save_transforms(const poses_run *run, const vf_colmap_model *model,
                                 const vf_similarity *s, const char *image_dir, const char *file)
{
    char path[VF_PATH_MAX];
    vf_dataset ds;
    vf_status status = vf_path_join(path, sizeof path, run->stage.dir, file);
    if (status == VF_OK)
        status = vf_sfm_dataset(model, s, image_dir, &ds);
    if (status == VF_OK) {
        status = vf_dataset_save(path, &ds);
        vf_dataset_free(&ds);
    }
    return status;
}

static vf_status export_outputs(poses_run *run, vf_normalization *norm)
{
    char path[VF_PATH_MAX];
    vf_status status = normalize_model(run, norm);
    const vf_similarity *s = &norm->object_from_world;
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, run->stage.dir, VF_NORMALIZATION_FILE);
    if (status == VF_OK)
        status = vf_sfm_save_normalization(path, norm);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, run->stage.dir, "points3D.txt");
    if (status == VF_OK)
        status = vf_sfm_save_points(path, &run->model, s);
    if (status == VF_OK)
        status = save_transforms(run, &run->model, s, run->images, "transforms.json");
    if (status != VF_OK || !run->opt->undistort)
        return status;
    vf_colmap_model undistorted;
    if ((status = vf__poses_undistort(run, &undistorted)) != VF_OK)
        return status;
    if ((status = vf_path_join(path, sizeof path, run->stage.dir, "undistorted/images")) == VF_OK)
        status = save_transforms(run, &undistorted, s, path, "transforms_undistorted.json");
    vf_colmap_model_free(&undistorted);
    return status;
}

static json_t *cameras_json(const vf_colmap_model *m)
{
    json_t *list = json_array();
    for (int i = 0; i < m->camera_count; i++) {
        const vf_colmap_camera *c = &m->cameras[i];
        json_t *params = json_array();
        for (int k = 0; k < c->param_count; k++)
            json_array_append_new(params, vf_json_number(c->params[k]));
        json_array_append_new(list, json_pack("{s:i, s:s, s:i, s:i, s:o}", "id", c->id, "model",
                                              c->model, "width", c->width, "height", c->height,
                                              "params", params));
    }
    return list;
}

static json_t *unregistered_json(const poses_run *run)
{
    json_t *list = json_array();
    for (int i = 0; i < run->frames.count; i++) {
        int found = 0;
        for (int j = 0; j < run->model.image_count && !found; j++)
            found = !strcmp(run->frames.frames[i].name, run->model.images[j].name);
        if (!found)
            json_array_append_new(list, json_string(run->frames.frames[i].name));
    }
    return list;
}

static json_t *summarize(const poses_run *run, const vf_normalization *norm)
{
    const vf_colmap_model *m = &run->model;
    json_t *j = json_pack(
        "{s:i, s:i, s:i, s:o, s:o, s:i, s:s, s:s, s:o, s:s, s:s, s:o, s:O}", "registered",
        m->image_count, "total", run->frames.count, "models", run->model_count, "unregistered",
        unregistered_json(run), "reprojection_error_px",
        vf_json_number(vf_colmap_model_reprojection_error(m)), "points", m->point_count, "matcher",
        run->matcher, "camera_model", run->camera_model, "cameras", cameras_json(m), "up_method",
        norm->up_method, "center_method", norm->center_method, "scale_to_object",
        vf_json_number(norm->object_from_world.scale), "seconds", run->seconds);
    json_object_set(j, "check", run->check ? run->check : json_null());
    json_object_set_new(j, "mapping", json_string(run->posed     ? "known poses"
                                                  : run->relaxed ? "relaxed"
                                                                 : "default"));
    if (run->posed) /* how well the set's poses fit its photos (poses_known.c) */
        json_object_set_new(j, "matches_explained", vf_json_number(run->explained));
    if (run->fallback) /* the matcher first chosen, whose model was not trusted */
        json_object_set_new(j, "fallback_from", json_string(run->fallback));
    return j;
}

/* Was WS/ingest a posed set (`ingest --transforms`)? */
static int posed_set(const vf_workspace *ws)
{
    const json_t *params = json_object_get(vf_workspace_stage_record(ws, "ingest"), "params");
    return !strcmp(json_string_value(json_object_get(params, "source")) ?: "", "transforms");
}

/* Everything inside the staging folder; *summary on success. */
static vf_status run_stage(poses_run *run, const vf_workspace *ws, json_t **summary)
{
    char log_path[VF_PATH_MAX];
    vf_normalization norm;
    vf_status status = vf_path_join(run->scratch, sizeof run->scratch, run->stage.dir, ".colmap");
    if (status == VF_OK)
        status = vf_path_join(run->images, sizeof run->images, run->stage.dir, "images");
    if (status == VF_OK)
        status = vf_path_join(run->database, sizeof run->database, run->stage.dir, "database.db");
    if (status == VF_OK)
        status = vf_path_join(log_path, sizeof log_path, run->stage.dir, "colmap.log");
    if (status == VF_OK)
        status = vf_mkdirs(run->scratch);
    if (status == VF_OK)
        status = vf_colmap_open(&run->colmap, log_path);
    if (status == VF_OK && run->posed)
        status = vf__poses_load_set(run, ws);
    if (status == VF_OK)
        status = prepare_frames(run, ws);
    if (status != VF_OK)
        return status;
    char source[32];
    vf_ingest_source_kind(ws->root, source, sizeof source);
    choose_methods(run, source);
    status = vf__poses_extract_features(run);
    if (status == VF_OK)
        status = !strcmp(run->matcher, "poses") ? vf__poses_match_posed(run) : vf__poses_match(run);
    if (status == VF_OK && run->posed)
        status = vf__poses_triangulate(run);
    else if (status == VF_OK && (status = vf__poses_map(run)) == VF_OK)
        status = verify_model(run);
    if (status == VF_OK)
        status = export_outputs(run, &norm);
    if (status == VF_OK) {
        json_object_set_new(run->seconds, "total",
                            vf_json_number(vf_now() - run->stage.start_time));
        *summary = summarize(run, &norm);
        status = vf_remove_tree(run->scratch);
    }
    return status;
}

vf_status vf_poses_run(vf_workspace *ws, const vf_poses_options *o, json_t **summary)
{
    *summary = NULL;
    vf_status status = vf_poses_options_check(o);
    if (status != VF_OK)
        return status;
    if (!vf_workspace_has_stage(ws, "ingest"))
        return vf_fail(VF_EINPUT,
                       "workspace %s has no ingested frames: run 'vfcapture ingest "
                       "... -o %s' first",
                       ws->root, ws->root);
    vf_poses_options opt = *o; /* the known camera is fitted to the frames' size */
    poses_run run = {.opt = &opt, .seconds = json_object(), .posed = posed_set(ws)};
    status = vf_stage_begin(ws, "poses", &run.stage);
    if (status == VF_OK)
        status = run_stage(&run, ws, summary);
    vf_colmap_close(&run.colmap);
    if (status == VF_OK) {
        json_t *params =
            json_pack("{s:s, s:s, s:i, s:i, s:o, s:b, s:b}", "matcher", opt.matcher, "camera_model",
                      opt.camera_model, "overlap", opt.overlap, "max_features", opt.max_features,
                      "min_registered", vf_json_number(opt.min_registered), "known_intrinsics",
                      opt.has_intrinsics, "check", opt.check);
        status = vf_stage_commit(&run.stage, params, json_deep_copy(*summary));
    } else {
        status = vf_keep_failure_log(run.colmap.log_path, "COLMAP", status);
        vf_stage_abort(&run.stage);
    }
    if (status != VF_OK) {
        json_decref(*summary);
        *summary = NULL;
    }
    vf_colmap_model_free(&run.model);
    vf_sfm_images_free(&run.frames);
    vf_dataset_free(&run.set);
    json_decref(run.seconds);
    json_decref(run.check);
    return status;
}

vf_status vf_poses_move_set_frames(const vf_workspace *ws, vf_dataset *ds, int *moved)
{
    *moved = 0;
    const json_t *summary = json_object_get(vf_workspace_stage_record(ws, "poses"), "summary");
    const char *mapping = json_string_value(json_object_get(summary, "mapping"));
    if (!vf_workspace_has_stage(ws, "poses") || !mapping || strcmp(mapping, "known poses"))
        return VF_OK;
    vf_similarity object_from_set;
    vf_status status = vf_normalization_load_workspace(ws, &object_from_set, NULL, NULL);
    for (int i = 0; status == VF_OK && i < ds->count; i++) {
        double c2w[16];
        vf_similarity_apply_c2w(&object_from_set, ds->frames[i].c2w, c2w);
        memcpy(ds->frames[i].c2w, c2w, sizeof c2w);
    }
    *moved = status == VF_OK;
    return status;
}
