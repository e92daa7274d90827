/* The train stage (vf/train.h): views in, a field, its held-out scores and sheet out. */
#include "vf/train.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/colmap_model.h"
#include "vf/cutout.h"
#include "vf/dataset.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/metrics.h"
#include "vf/object3d.h"
#include "vf/plot.h"

#define CHECKPOINT_SECONDS 30.0
#define CHECKPOINT_FILE "checkpoint.vfc"
/* Object mode's cut of the scene field (vf_field_cut_object). A grid point goes when half the
 * views that see it find it outside their mask: against a quarter, held-out PSNR inside the
 * GrabCut masks (4500-step fields) fox 15.5 -> 20.5 dB, shoes 17.5 -> 21.9, apple 13.2 ->
 * 18.5 (one wrong mask in four no longer cuts the object). The surface's clearance takes the
 * shoes' papers and the floor's skirt and leaves the fox's mount (0.06 cut into the mount). */
#define OBJECT_VOTE_SHARE 0.5
#define OBJECT_SURFACE_CLEARANCE 0.02
/* The smoothing of the colour's direction terms for a 3D model's renders (vf/field.h tv_view:
 * their Monte-Carlo noise would become speckle; clean photos lose detail with it). */
#define MODEL_VIEW_SMOOTHING 1e-4f

void vf_train_defaults(vf_train_options *o)
{
    *o = (vf_train_options){.minutes = 0, .holdout = 10, .surroundings = VF_SURROUNDINGS_AUTO,
                            .color = VF_COLOR_VIEW, .view_smoothing = -1, .depth = -1};
}

double vf_train_minutes(const vf_train_options *o, int from_model)
{
    return o->minutes > 0 ? o->minutes : from_model ? VF_TRAIN_MINUTES_MODEL : VF_TRAIN_MINUTES;
}

vf_status vf_train_options_check(const vf_train_options *o)
{
    if (!(o->minutes >= 0 && o->minutes <= 600))
        return vf_fail(VF_EINPUT,
                       "training time must be 0 (the default budget) to 600 minutes, not %g",
                       o->minutes);
    if (!(o->depth < 0 || o->depth <= 1000))
        return vf_fail(VF_EINPUT, "the depth weight must be 0 to 1000, not %g", o->depth);
    if (o->steps < 0 || o->holdout < 0 || o->holdout == 1)
        return vf_fail(VF_EINPUT, "steps must be >= 0 and holdout 0 or from 2 up");
    return VF_OK;
}

static int is_held_out(int frame, int holdout)
{
    return holdout > 0 && frame % holdout == holdout / 2;
}

/* Decode and hand the training views to the trainer, each with the sparse points it sees
 * (points may be NULL); returns whether any has alpha and how many points went in. */
static vf_status add_training_views(vf_field_trainer *t, const vf_dataset *views,
                                    const vf_colmap_view_points *points, int holdout,
                                    int *with_alpha, long *points_added)
{
    vf_status status = VF_OK;
    vf_progress progress;
    vf_progress_begin(&progress, "loading views", (size_t)views->count, "images");
    for (int i = 0; i < views->count && status == VF_OK; i++) {
        if (is_held_out(i, holdout))
            continue;
        vf_image img = {0};
        status = vf_image_load(views->frames[i].image_path, &img);
        if (status == VF_OK) {
            *with_alpha |= img.channels == 4;
            status =
                vf_field_trainer_add_view(t, &views->frames[i].camera, views->frames[i].c2w, &img);
        }
        if (status == VF_OK && points) {
            status = vf_field_trainer_add_view_points(t, points->xyz[i], points->count[i]);
            *points_added += points->count[i];
        }
        vf_image_free(&img);
        vf_progress_update(&progress, (size_t)i + 1, NULL);
    }
    if (status == VF_OK)
        vf_progress_end(&progress);
    return status;
}

/* The sparse points each photo of a real capture sees (depth supervision, vf/field.h); none
 * (a zeroed set) for posed imports and 3D models, which have no poses stage. */
static vf_status load_view_points(const vf_workspace *ws, const vf_dataset *views,
                                  vf_colmap_view_points *out)
{
    memset(out, 0, sizeof *out);
    char dir[VF_PATH_MAX], file[VF_PATH_MAX];
    vf_status status = vf_workspace_path(ws, "poses", "", dir, sizeof dir);
    if (status == VF_OK)
        status = vf_path_join(file, sizeof file, dir, "points3D.txt");
    if (status != VF_OK || !vf_workspace_has_stage(ws, "poses") || !vf_is_file(file))
        return status;
    const char **names = malloc(((size_t)views->count + 1) * sizeof *names);
    if (!names)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; i < views->count; i++)
        names[i] = views->frames[i].image_path;
    status = vf_colmap_view_points_load(dir, names, views->count, out);
    free(names);
    return status;
}

/* Object mode: the object's mask in each view (vf/cutout.h), as cut-outs written into the
 * staging folder's object/ (kept from an interrupted run); *cut gets that set. */
static vf_status cut_out_object(const vf_workspace *ws, const char *stage_dir,
                                const vf_dataset *views, vf_dataset *cut, json_t **cut_report)
{
    char points_dir[VF_PATH_MAX], out_dir[VF_PATH_MAX], kept[VF_PATH_MAX];
    vf_status status = vf_workspace_path(ws, "poses", "", points_dir, sizeof points_dir);
    if (status == VF_OK && !vf_workspace_has_stage(ws, "poses"))
        return vf_fail(VF_EINPUT, "object mode needs the sparse points of 'vfcapture poses'; %s "
                                  "is a posed import without them",
                       ws->root);
    if (status == VF_OK)
        status = vf_path_join(out_dir, sizeof out_dir, stage_dir, "object");
    if (status == VF_OK)
        status = vf_path_join(kept, sizeof kept, out_dir, "cutout.json");
    if (status == VF_OK && vf_is_file(kept) && vf_json_load(kept, cut_report) == VF_OK) {
        char transforms[VF_PATH_MAX];
        status = vf_path_join(transforms, sizeof transforms, out_dir, "transforms.json");
        if (status == VF_OK)
            status = vf_dataset_load(transforms, cut);
    } else if (status == VF_OK) {
        vf_cutout_options o;
        vf_cutout_defaults(&o);
        status = vf_cutout_views(views, points_dir, out_dir, &o, cut, cut_report);
        if (status == VF_OK)
            status = vf_json_save(kept, *cut_report);
    }
    if (status == VF_OK && cut->count != views->count)
        status = vf_fail(VF_EINPUT, "%s holds %d cut-out views for %d photos: run train again "
                                    "with --restart",
                         out_dir, cut->count, views->count);
    return status;
}

/* Object mode, after training on the whole photos: the training views' masks (the cut-outs'
 * alpha; held-out views have no say) vote the object out of the field, and the surface it
 * stands on goes (vf_field_cut_object). Adds what was done to cut_report. */
static vf_status cut_field(vf_field *field, const vf_dataset *cut, int holdout,
                           json_t *cut_report)
{
    vf_field_cut_view *votes = calloc((size_t)cut->count, sizeof *votes);
    uint8_t **masks = calloc((size_t)cut->count, sizeof *masks);
    vf_status status = votes && masks ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    int n = 0;
    for (int i = 0; i < cut->count && status == VF_OK; i++) {
        if (is_held_out(i, holdout))
            continue;
        vf_image img = {0};
        status = vf_image_load(cut->frames[i].image_path, &img);
        if (status == VF_OK && (img.channels != 4 || img.width != cut->frames[i].camera.width ||
                                img.height != cut->frames[i].camera.height))
            status = vf_fail(VF_EINPUT, "%s is not the cut-out of its view: run train again "
                                        "with --restart",
                             cut->frames[i].image_path);
        const size_t pixels = (size_t)img.width * img.height;
        if (status == VF_OK && !(masks[n] = malloc(pixels)))
            status = vf_fail(VF_EINTERNAL, "out of memory");
        for (size_t p = 0; status == VF_OK && p < pixels; p++)
            masks[n][p] = img.data[4 * p + 3] > 0.5f;
        if (status == VF_OK) {
            votes[n].camera = cut->frames[i].camera;
            memcpy(votes[n].c2w, cut->frames[i].c2w, sizeof votes[n].c2w);
            votes[n].mask = masks[n];
            n++;
        }
        vf_image_free(&img);
    }
    double plane[4], kept = 0;
    const json_t *surface = json_object_get(cut_report, "surface");
    const int has_plane = json_array_size(surface) == 4;
    for (int k = 0; k < 4 && has_plane; k++)
        plane[k] = json_number_value(json_array_get(surface, (size_t)k));
    if (status == VF_OK && n == 0)
        status = vf_fail(VF_EINPUT, "object mode needs training views to cut the object out");
    if (status == VF_OK && !has_plane) /* the wall clock: its face is the dominant plane */
        vf_warn("object mode: no surface under the object was found, so nothing is cut away "
                "with it (the views vote only on what they see): look at WS/train/held_out.jpg "
                "once trained");
    if (status == VF_OK) {
        vf_info("cutting the object out of the field: %d views' masks vote%s", n,
                has_plane ? ", the surface under it goes" : "");
        status = vf_field_cut_object(field, votes, n, OBJECT_VOTE_SHARE, has_plane ? plane : NULL,
                                     OBJECT_SURFACE_CLEARANCE, &kept);
    }
    if (status == VF_OK)
        json_object_set_new(cut_report, "field_cut",
                            json_pack("{s:i, s:o, s:b, s:o, s:o}", "voting_views", n, "vote_share",
                                      vf_json_number(OBJECT_VOTE_SHARE), "surface_removed",
                                      has_plane, "surface_clearance",
                                      vf_json_number(OBJECT_SURFACE_CLEARANCE), "kept_share",
                                      vf_json_number(kept)));
    for (int i = 0; i < cut->count && masks; i++)
        free(masks[i]);
    free(masks);
    free(votes);
    return status;
}

/* Train until the budget is used, checkpointing now and then. */
static vf_status run_training(vf_field_trainer *t, const char *checkpoint,
                              vf_field_train_status *st)
{
    vf_progress progress;
    vf_progress_begin(&progress, "training", 1000, "");
    double last_checkpoint = vf_now();
    vf_status status = VF_OK;
    memset(st, 0, sizeof *st);
    while (status == VF_OK && !st->done) {
        status = vf_field_trainer_step(t, st);
        if (status == VF_OK && st->step % 25 == 0) {
            char note[160];
            snprintf(note, sizeof note, "step %d  loss %.5f  train PSNR %.2f dB  %.0f s left",
                     st->step, st->loss, st->psnr, st->seconds_left);
            vf_progress_update(&progress, (size_t)(1000 * st->fraction), note);
        }
        if (status == VF_OK && vf_now() - last_checkpoint > CHECKPOINT_SECONDS && !st->done) {
            status = vf_field_trainer_save_checkpoint(t, checkpoint);
            last_checkpoint = vf_now();
        }
    }
    if (status == VF_OK)
        vf_progress_end(&progress);
    return status;
}

#define SHEET_PAIRS 6    /* held-out photos shown beside their renders */
#define SHEET_HEIGHT 240 /* pixels of a tile */

/* A copy of img SHEET_HEIGHT pixels high, for the contact sheet. */
static vf_status sheet_tile(const vf_image *img, vf_image *out)
{
    int w = (int)lround((double)img->width * SHEET_HEIGHT / img->height);
    return vf_image_resize(img, w > 0 ? w : 1, SHEET_HEIGHT, out);
}

#define ERROR_GAIN 4.0f /* error images: |render - photo| x 4, so 0.25 off shows white */

/* DIR/render_NNN.png and DIR/error_NNN.png of one view. */
static vf_status save_view(const char *dir, int index, const vf_image *render,
                           const vf_image *photo)
{
    char path[VF_PATH_MAX];
    vf_image error = {0};
    snprintf(path, sizeof path, "%s/render_%03d.png", dir, index);
    vf_status status = vf_image_save(path, render);
    if (status == VF_OK)
        status = vf_image_error_map(render, photo, ERROR_GAIN, &error);
    snprintf(path, sizeof path, "%s/error_%03d.png", dir, index);
    if (status == VF_OK)
        status = vf_image_save(path, &error);
    vf_image_free(&error);
    return status;
}

/* Whether frame i is one `how` scores (k counts the frames its rule picks before i). */
static int scored(const vf_photo_scoring *how, int i, int *k)
{
    int picked = !how->holdout || is_held_out(i, how->holdout) != how->training;
    if (!picked)
        return 0;
    return (*k)++ % (how->stride > 1 ? how->stride : 1) == 0;
}

vf_status vf_field_score_photos(const vf_field *f, const vf_dataset *views,
                                const vf_photo_scoring *how, json_t *list, vf_photo_scores *out)
{
    double object_sum = 0, psnr_sum = 0, ssim_sum = 0;
    int object_n = 0, n = 0, tiles = 0, chosen = 0;
    float bg[3];
    vf_field_background(f, bg);
    vf_image sheet[2 * SHEET_PAIRS] = {{0}};
    char captions[2 * SHEET_PAIRS][96];
    vf_status status = VF_OK;
    for (int i = 0, k = 0; i < views->count; i++)
        chosen += scored(how, i, &k);
    vf_progress progress;
    vf_progress_begin(&progress, how->training ? "scoring training views" : "scoring",
                      (size_t)chosen, "views");
    for (int i = 0, k = 0; i < views->count && status == VF_OK; i++) {
        if (!scored(how, i, &k))
            continue;
        const vf_frame *frame = &views->frames[i];
        vf_image raw = {0}, photo = {0}, render = {0}; /* raw: a cut-out's alpha is its mask */
        status = vf_image_load(frame->image_path, &raw);
        if (status == VF_OK && how->object_cut)
            status = vf_field_cut_photo(f, &frame->camera, frame->c2w, &raw);
        if (status == VF_OK)
            status = vf_image_to_rgb(&raw, bg, &photo);
        if (status == VF_OK)
            status = vf_field_render(f, &frame->camera, frame->c2w, &render);
        if (status == VF_OK && raw.channels == 4) { /* the PSNR inside the photo's mask */
            double p = vf_image_psnr_masked(&render, &photo, &raw);
            if (p >= 0)
                object_sum += p, object_n++;
        }
        vf_image_free(&raw);
        if (status == VF_OK && how->save_dir)
            status = save_view(how->save_dir, n, &render, &photo);
        if (status == VF_OK) {
            double psnr = vf_image_psnr(&render, &photo), ssim = vf_image_ssim(&render, &photo);
            psnr_sum += psnr;
            ssim_sum += ssim;
            n++;
            char name[VF_PATH_MAX];
            vf_path_basename(name, sizeof name, frame->image_path, 0);
            json_array_append_new(list,
                                  json_pack("{s:s, s:o, s:o}", "image", name, "psnr",
                                            vf_json_number(psnr), "ssim", vf_json_number(ssim)));
            if (how->sheet_path && tiles < 2 * SHEET_PAIRS) {
                snprintf(captions[tiles], sizeof captions[tiles], "photo %.80s", name);
                status = sheet_tile(&photo, &sheet[tiles++]);
                snprintf(captions[tiles], sizeof captions[tiles], "render\n%.1f dB", psnr);
                if (status == VF_OK)
                    status = sheet_tile(&render, &sheet[tiles++]);
            }
        }
        vf_image_free(&photo);
        vf_image_free(&render);
        vf_progress_update(&progress, (size_t)n, NULL);
    }
    if (status == VF_OK)
        vf_progress_end(&progress);
    if (status == VF_OK && tiles > 0) {
        const char *caption_list[2 * SHEET_PAIRS];
        for (int i = 0; i < tiles; i++)
            caption_list[i] = captions[i];
        status = vf_contact_sheet(how->sheet_path, sheet, caption_list, NULL, tiles, 4);
    }
    for (int i = 0; i < tiles; i++)
        vf_image_free(&sheet[i]);
    *out = (vf_photo_scores){.count = n,
                             .psnr = n ? psnr_sum / n : NAN,
                             .ssim = n ? ssim_sum / n : NAN,
                             .psnr_object = object_n ? object_sum / object_n : NAN};
    return status;
}

vf_status vf_train_run(vf_workspace *ws, const vf_train_options *opt, json_t **result)
{
    vf_dataset views = {0};
    if (result)
        *result = NULL;
    vf_status status = vf_train_options_check(opt);
    if (status == VF_OK)
        status = vf_dataset_load_training(ws, &views, NULL);
    if (status != VF_OK)
        return status;
    int held = 0;
    for (int i = 0; i < views.count; i++)
        held += is_held_out(i, opt->holdout);
    if (views.count - held < 3) {
        vf_dataset_free(&views);
        return vf_fail(VF_EINPUT, "%s has %d posed views: too few to train on", ws->root,
                       views.count);
    }

    vf_object3d made_from;
    const int from_model = vf_object3d_load(ws, &made_from) == VF_OK;
    vf_error_clear();
    const double minutes = vf_train_minutes(opt, from_model);
    vf_field_train_options topt;
    vf_field_train_defaults(&topt);
    topt.seconds = opt->steps ? 0 : 60 * minutes;
    if (opt->steps)
        topt.steps = opt->steps;
    topt.surroundings = opt->surroundings;
    topt.color = opt->color;
    if (opt->view_smoothing >= 0)
        topt.tv_view = (float)opt->view_smoothing;
    else
        topt.tv_view = from_model ? MODEL_VIEW_SMOOTHING : 0.0f;
    if (opt->depth >= 0)
        topt.depth = (float)opt->depth;
    if (opt->appearance)
        topt.appearance = VF_FIELD_APPEARANCE_RATE;
    vf_field_trainer *t = NULL;
    vf_stage stage;
    char checkpoint[VF_PATH_MAX], model[VF_PATH_MAX], report_path[VF_PATH_MAX];
    int with_alpha = 0;
    status =
        opt->restart ? vf_stage_begin(ws, "train", &stage) : vf_stage_resume(ws, "train", &stage);
    if (status != VF_OK) {
        vf_dataset_free(&views);
        return status;
    }
    json_t *cut_report = NULL;
    vf_dataset cut = {0};
    char object_dir[VF_PATH_MAX];
    if (status == VF_OK)
        status = vf_path_join(checkpoint, sizeof checkpoint, stage.dir, CHECKPOINT_FILE);
    if (status == VF_OK)
        status = vf_path_join(object_dir, sizeof object_dir, stage.dir, "object");
    if (status == VF_OK && vf_is_file(checkpoint) && !opt->object_only != !vf_is_dir(object_dir))
        status = vf_fail(VF_EINPUT, "an interrupted run trained %s: run the same again, or add "
                                    "--restart to start over",
                         opt->object_only ? "on the whole photos" : "in object mode");
    if (status == VF_OK && opt->object_only)
        status = cut_out_object(ws, stage.dir, &views, &cut, &cut_report);
    vf_colmap_view_points points = {0};
    long point_total = 0;
    if (status == VF_OK)
        status = load_view_points(ws, &views, &points);
    if (status == VF_OK)
        status = vf_field_trainer_create(&topt, &t);
    if (status == VF_OK)
        status = add_training_views(t, &views, points.views ? &points : NULL, opt->holdout,
                                    &with_alpha, &point_total);
    vf_colmap_view_points_free(&points);
    if (status == VF_OK && vf_is_file(checkpoint)) {
        vf_info("resuming from the checkpoint of an interrupted run (--restart to start over)");
        status = vf_field_trainer_resume(t, checkpoint);
    } else if (status == VF_OK) {
        status = vf_field_trainer_start(t);
    }
    vf_field_train_status st;
    if (status == VF_OK) {
        if (opt->steps)
            vf_info("training on %d views (%d held out) for %d steps on all cores",
                    views.count - held, held, opt->steps);
        else
            vf_info("training on %d views (%d held out) for %.1f minutes on all cores",
                    views.count - held, held, minutes);
        status = run_training(t, checkpoint, &st);
    }

    json_t *report = json_pack("{s:s}", "mode", opt->object_only ? "object" : "scene");
    if (cut_report)
        json_object_set_new(report, "cutout", cut_report);
    double psnr = NAN, ssim = NAN, psnr_object = NAN;
    const vf_field *field = t ? vf_field_trainer_field(t) : NULL;
    vf_field *object = NULL; /* object mode: the trained field, cut */
    if (status == VF_OK && opt->object_only) {
        object = vf_field_trainer_take_field(t);
        status = object ? cut_field(object, &cut, opt->holdout, cut_report)
                        : vf_fail(VF_EINTERNAL, "out of memory");
        field = object;
    }
    char sheet[VF_PATH_MAX];
    if (status == VF_OK)
        status = vf_path_join(sheet, sizeof sheet, stage.dir, "held_out.jpg");
    vf_photo_scores scores = {0, NAN, NAN, NAN};
    json_t *held_out = json_array();
    if (status == VF_OK && held > 0)
        status = vf_field_score_photos(field, &views,
                                       &(vf_photo_scoring){.holdout = opt->holdout,
                                                           .object_cut = opt->object_only,
                                                           .sheet_path = sheet},
                                       held_out, &scores);
    json_object_set_new(report, "held_out", held_out);
    psnr = scores.psnr, ssim = scores.ssim, psnr_object = scores.psnr_object;
    /* as many training views, spread over them: the gap between the two is the sign of a
     * field that fits its photos and is fog between them */
    vf_photo_scores fit = {0, NAN, NAN, NAN};
    json_t *training = json_array();
    if (status == VF_OK && held > 0)
        status = vf_field_score_photos(field, &views,
                                       &(vf_photo_scoring){.holdout = opt->holdout,
                                                           .training = 1,
                                                           .stride = (views.count - held) / held,
                                                           .object_cut = opt->object_only},
                                       training, &fit);
    json_object_set_new(report, "training_scored", training);
    if (status == VF_OK)
        status = vf_path_join(model, sizeof model, stage.dir, VF_FIELD_FILE);
    if (status == VF_OK)
        status = vf_field_save(field, model);
    if (status == VF_OK) {
        vf_field_info info;
        vf_field_get_info(field, &info);
        /* what was modelled, which "auto" decides from the photos */
        const char *kind = opt->object_only ? "object cut out of the scene's field"
                           : info.has_background_grid ? "object box + outer grid"
                           : with_alpha               ? "object box (background-removed photos)"
                                                      : "object box only";
        json_object_update_new(report,
                               json_pack("{s:i, s:i, s:i, s:o, s:s, s:s, s:o, s:s, s:[i,i,i], s:I}",
                                         "views", views.count - held, "held_out_views", held,
                                         "steps", st.step, "seconds", vf_json_number(st.elapsed),
                                         "surroundings", info.has_background_grid ? "grid" : "none",
                                         "color", vf_field_color_name(opt->color), "view_smoothing",
                                         vf_json_number((double)topt.tv_view), "field", kind,
                                         "grid", info.dim[0], info.dim[1], info.dim[2], "bytes",
                                         (json_int_t)info.bytes));
        /* the trainer's automatic choices for this capture (vf/field.h) */
        const vf_field_train_options *used = vf_field_trainer_options(t);
        json_object_set_new(report, "color_smoothing", vf_json_number(used->tv_color));
        json_object_set_new(report, "levels", json_integer(used->levels));
        /* the distortion loss acts on opaque photos only */
        json_object_set_new(report, "distortion",
                            vf_json_number(with_alpha ? 0.0 : used->distortion));
        json_object_set_new(report, "appearance",
                            vf_json_number(with_alpha ? 0.0 : used->appearance));
        /* the training photos' sightings of sparse points given to the depth loss (0: off) */
        const long supervising = used->depth > 0 && !with_alpha ? point_total : 0;
        json_object_set_new(report, "depth_points", json_integer(supervising));
        if (supervising)
            vf_info("depth supervision: %ld sightings of sparse points", supervising);
        vf_info("field: %s, %s colour", kind,
                opt->color == VF_COLOR_DIFFUSE ? "diffuse" : "view-dependent");
        if (held)
            json_object_update_new(report,
                                   json_pack("{s:o, s:o}", "held_out_psnr", vf_json_number(psnr),
                                             "held_out_ssim", vf_json_number(ssim)));
        if (held && isfinite(psnr_object))
            json_object_set_new(report, "held_out_psnr_object", vf_json_number(psnr_object));
        if (held && fit.count > 0) {
            int masked = isfinite(psnr_object) && isfinite(fit.psnr_object);
            double fit_psnr = masked ? fit.psnr_object : fit.psnr,
                   gap = fit_psnr - (masked ? psnr_object : psnr);
            json_object_update_new(report, json_pack("{s:o, s:o}", "training_psnr",
                                                     vf_json_number(fit_psnr), "psnr_gap",
                                                     vf_json_number(gap)));
            if (gap > VF_TRAIN_GAP_WARN_DB)
                vf_warn("the held-out photos render %.1f dB below the training views: the field "
                        "fits its photos and guesses between them; look at WS/train/held_out.jpg, "
                        "and film more views between the photos",
                        gap);
        }
        status = vf_path_join(report_path, sizeof report_path, stage.dir, "report.json");
    }
    if (status == VF_OK)
        status = vf_json_save(report_path, report);
    vf_field_free(object);
    vf_field_trainer_free(t);
    vf_dataset_free(&views);
    vf_dataset_free(&cut);
    if (status != VF_OK) {
        json_decref(report);
        /* keep the staging folder (and its checkpoint) so the next run can resume */
        return status;
    }
    json_t *summary = held ? json_pack("{s:o, s:o, s:i}", "held_out_psnr", vf_json_number(psnr),
                                       "held_out_ssim", vf_json_number(ssim), "steps", st.step)
                           : json_pack("{s:i}", "steps", st.step);
    status = vf_stage_commit(
        &stage,
        json_pack("{s:o, s:i, s:i, s:s, s:s, s:o, s:o, s:b, s:b}", "minutes",
                  vf_json_number(minutes), "steps", opt->steps, "holdout", opt->holdout,
                  "surroundings", vf_field_surroundings_name(opt->surroundings), "color",
                  vf_field_color_name(opt->color), "view_smoothing",
                  vf_json_number((double)topt.tv_view), "depth", vf_json_number((double)topt.depth),
                  "appearance", opt->appearance, "object_only", opt->object_only),
        json_incref(summary));
    /* The checkpoint goes only once the stage is in place: after a failed commit the next run
     * resumes from it at its end instead of training again. */
    if (status == VF_OK &&
        vf_workspace_path(ws, "train", CHECKPOINT_FILE, checkpoint, sizeof checkpoint) == VF_OK)
        remove(checkpoint);
    if (status == VF_OK && result)
        *result = json_incref(report);
    json_decref(summary);
    json_decref(report);
    return status;
}
