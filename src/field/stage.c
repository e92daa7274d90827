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
#include "vf/pose.h"
#include "vf/rgb8.h"
#include "vf/stats.h"

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

void vf_train_object_points(const vf_workspace *ws, const vf_field *field, const vf_dataset *views,
                            vf_object_points *out)
{
    memset(out, 0, sizeof *out);
    char dir[VF_PATH_MAX];
    double *cameras = malloc(((size_t)views->count + 1) * 3 * sizeof *cameras);
    if (!cameras || !vf_workspace_has_stage(ws, "poses") ||
        vf_workspace_path(ws, "poses", "", dir, sizeof dir) != VF_OK) {
        free(cameras);
        return;
    }
    for (int i = 0; i < views->count; i++)
        vf_mat4_translation(views->frames[i].c2w, cameras + 3 * i);
    vf_cutout_options o;
    vf_cutout_defaults(&o);
    vf_status status = vf_object_points_find(dir, cameras, views->count, &o, out);
    if (status == VF_EINPUT) { /* none where the cameras look: where the photos' middles are */
        vf_error_clear();
        vf_field_info info;
        vf_field_get_info(field, &info);
        for (int k = 0; k < 3; k++)
            o.centre[k] = 0.5 * (info.box_lo[k] + info.box_hi[k]);
        status = vf_object_points_find(dir, cameras, views->count, &o, out);
    }
    if (status != VF_OK) {
        vf_info("the renders are not checked for the object: %s", vf_error_message());
        vf_error_clear();
        vf_object_points_free(out);
        memset(out, 0, sizeof *out);
    } else {
        vf_info("renders checked for the object: %d of the %d sparse points near it are the "
                "object%s",
                out->count, out->candidates,
                out->has_plane ? ", the surface under it left out" : " (no surface found)");
    }
    free(cameras);
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

#define OBJECT_CHECK_SIDE 480 /* the present check's working size (GrabCut's, vf/cutout.h) */
/* Held-out views missing the object are a warning when their share exceeds the training
 * views' by this. */
#define OBJECT_MISSING_MARGIN 0.25
/* The object's region (below): a cell is REGION_LINK times the points' median spacing and at
 * least 1/REGION_MIN_CELLS of their longest extent; REGION_REACH cells around a cell with a
 * point belong to it. */
#define REGION_LINK 3
#define REGION_MIN_CELLS 24
#define REGION_REACH 1

/* The object's region: the cells of a grid over its sparse points that hold one, and their
 * neighbours (its sides without texture have no points); the spacing's cell is the link of
 * vf/cutout.h's grouping, and the floor keeps dense patches (the spray can's label) from
 * leaving a thin shell. A box around the points took in the quilted bed under
 * banana_apple_photos' banana, which is no plane. */
typedef struct object_region {
    double lo[3], cell, side; /* side: the points' longest extent */
    int dim[3];
    uint8_t *in;
} object_region;

static vf_status object_region_make(const vf_object_points *pts, object_region *r)
{
    const int n = pts->count;
    double hi[3], *nearest = malloc(((size_t)n + 1) * sizeof *nearest);
    if (!nearest)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int k = 0; k < 3; k++)
        r->lo[k] = INFINITY, hi[k] = -INFINITY;
    for (int i = 0; i < n; i++) {
        const double *p = pts->xyz + 3 * i;
        nearest[i] = INFINITY;
        for (int j = 0; j < n; j++) {
            const double *q = pts->xyz + 3 * j, d[3] = {p[0] - q[0], p[1] - q[1], p[2] - q[2]};
            if (j != i)
                nearest[i] = fmin(nearest[i], d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        }
        for (int k = 0; k < 3; k++)
            r->lo[k] = fmin(r->lo[k], p[k]), hi[k] = fmax(hi[k], p[k]);
    }
    vf_sort_doubles(nearest, n);
    const double side = fmax(hi[0] - r->lo[0], fmax(hi[1] - r->lo[1], hi[2] - r->lo[2]));
    r->cell =
        fmax(REGION_LINK * sqrt(vf_sorted_quantile(nearest, n, 0.5)), side / REGION_MIN_CELLS);
    r->side = side;
    free(nearest);
    if (!(r->cell > 0 && isfinite(r->cell)))
        r->cell = 1e-3;
    size_t cells = 1;
    for (int k = 0; k < 3; k++) {
        r->lo[k] -= REGION_REACH * r->cell;
        r->dim[k] = (int)((hi[k] - r->lo[k]) / r->cell) + REGION_REACH + 1;
        cells *= (size_t)r->dim[k];
    }
    if (!(r->in = calloc(cells, 1)))
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; i < pts->count; i++) {
        int c[3];
        for (int k = 0; k < 3; k++)
            c[k] = (int)((pts->xyz[3 * i + k] - r->lo[k]) / r->cell);
        for (int z = c[2] - REGION_REACH; z <= c[2] + REGION_REACH; z++)
            for (int y = c[1] - REGION_REACH; y <= c[1] + REGION_REACH; y++)
                for (int x = c[0] - REGION_REACH; x <= c[0] + REGION_REACH; x++)
                    if (x >= 0 && y >= 0 && z >= 0 && x < r->dim[0] && y < r->dim[1] &&
                        z < r->dim[2])
                        r->in[((size_t)z * r->dim[1] + y) * r->dim[0] + x] = 1;
    }
    return VF_OK;
}

static int object_region_has(const object_region *r, const double p[3])
{
    int c[3];
    for (int k = 0; k < 3; k++) {
        const double u = (p[k] - r->lo[k]) / r->cell;
        if (!(u >= 0 && u < r->dim[k]))
            return 0;
        c[k] = (int)u;
    }
    return r->in[((size_t)c[2] * r->dim[1] + c[1]) * r->dim[0] + c[0]];
}

/* Whether a render's pixel shows the object: its ray (origin o, unit direction d) crosses the
 * region, and the surface it sees (distance t) lies where it crosses, or in front of it by at
 * most OCCLUDER_REACH of the object's size: what stands just before the object in the photo
 * stands there in the render too, and the photo's cut-out holds it (banana_apple_photos'
 * apple before its banana, the synthesized scene's pillar before its box), while fog near the
 * camera, or the room seen through where the object should be, does not count. */
#define OCCLUDER_REACH 0.5
static int object_region_shows(const object_region *r, const double o[3], const double d[3],
                               double t)
{
    double t0 = 0, t1 = INFINITY; /* the ray's stretch inside the grid's box */
    for (int k = 0; k < 3; k++) {
        const double lo = r->lo[k], hi = r->lo[k] + r->dim[k] * r->cell;
        if (fabs(d[k]) < 1e-12) {
            if (o[k] < lo || o[k] > hi)
                return 0;
            continue;
        }
        double a = (lo - o[k]) / d[k], b = (hi - o[k]) / d[k];
        if (a > b) {
            const double swap = a;
            a = b, b = swap;
        }
        t0 = fmax(t0, a), t1 = fmin(t1, b);
    }
    if (!(t0 <= t1) || !isfinite(t) || t > t1 + r->cell || t < t0 - OCCLUDER_REACH * r->side)
        return 0;
    double enter = INFINITY, leave = -INFINITY;
    for (double u = t0; u <= t1; u += 0.5 * r->cell) {
        const double p[3] = {o[0] + u * d[0], o[1] + u * d[1], o[2] + u * d[2]};
        if (object_region_has(r, p)) {
            enter = fmin(enter, u);
            leave = u;
        }
    }
    return enter <= leave && t >= enter - OCCLUDER_REACH * r->side && t <= leave + r->cell;
}

/* The object's overlap in a photo and the field's render of it (vf_photo_scoring.object);
 * *iou gets -1 when the photo shows fewer than 3 of the object's points. A photo with its
 * background removed is its own cut-out (`alpha`, camera-sized, or NULL: GrabCut cuts it). */
static vf_status object_overlap(const vf_field *f, const vf_frame *frame,
                                const vf_object_points *pts, const object_region *region,
                                uint8_t *alpha, double *iou)
{
    *iou = -1;
    vf_rgb8 photo = {0};
    uint8_t *mask = alpha;
    int seen = 3;
    vf_cutout_options o;
    vf_cutout_defaults(&o);
    vf_status status = alpha ? VF_OK : vf_rgb8_load(frame->image_path, &photo);
    if (status == VF_OK && !alpha)
        status = vf_cutout_mask(&photo, &frame->camera, frame->c2w, pts, &o, &mask, &seen);
    vf_rgb8_free(&photo);
    const vf_camera *full = &frame->camera;
    const double scale = fmin(1.0, (double)OBJECT_CHECK_SIDE / fmax(full->width, full->height));
    const vf_camera cam = vf_camera_scaled(full, (int)fmax(1, lround(full->width * scale)),
                                           (int)fmax(1, lround(full->height * scale)));
    vf_image depth = {0};
    if (status == VF_OK && seen >= 3)
        status = vf_field_render_depth(f, &cam, frame->c2w, &depth);
    if (status == VF_OK && seen >= 3) {
        double origin[3];
        vf_mat4_translation(frame->c2w, origin);
        long both = 0, either = 0;
        for (int y = 0; y < cam.height; y++)
            for (int x = 0; x < cam.width; x++) {
                const float t = depth.data[(size_t)y * cam.width + x];
                int in_render = 0;
                if (isfinite(t)) {
                    double d_cv[3], d[3], p[3];
                    vf_camera_pixel_ray(&cam, x + 0.5, y + 0.5, d_cv);
                    vf_mat4_transform_dir(frame->c2w, (double[3]){d_cv[0], -d_cv[1], -d_cv[2]}, d);
                    for (int k = 0; k < 3; k++)
                        p[k] = origin[k] + t * d[k];
                    in_render = object_region_shows(region, origin, d, t);
                    if (pts->has_plane) /* the surface under it is not the object */
                        in_render &= pts->plane[0] * p[0] + pts->plane[1] * p[1] +
                                         pts->plane[2] * p[2] + pts->plane[3] >
                                     OBJECT_SURFACE_CLEARANCE;
                }
                const int px = (int)fmin(full->width - 1, (x + 0.5) / scale),
                          py = (int)fmin(full->height - 1, (y + 0.5) / scale);
                const int in_photo = mask[(size_t)py * full->width + px] != 0;
                both += in_render && in_photo;
                either += in_render || in_photo;
            }
        *iou = either ? (double)both / (double)either : -1;
    }
    vf_image_free(&depth);
    if (mask != alpha)
        free(mask);
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
    double object_sum = 0, psnr_sum = 0, ssim_sum = 0, iou_sum = 0, iou_min = INFINITY;
    int object_n = 0, n = 0, tiles = 0, chosen = 0, iou_n = 0, missing = 0;
    float bg[3];
    vf_field_background(f, bg);
    vf_image sheet[2 * SHEET_PAIRS] = {{0}};
    char captions[2 * SHEET_PAIRS][96];
    vf_status status = VF_OK;
    for (int i = 0, k = 0; i < views->count; i++)
        chosen += scored(how, i, &k);
    object_region region = {0};
    if (how->object)
        status = object_region_make(how->object, &region);
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
        uint8_t *alpha = NULL; /* a background-removed photo's own cut-out (not object mode's:
                                  that alpha is the field's silhouette) */
        if (status == VF_OK && how->object && raw.channels == 4 && !how->object_cut) {
            const size_t pixels = (size_t)raw.width * raw.height;
            if (!(alpha = malloc(pixels)))
                status = vf_fail(VF_EINTERNAL, "out of memory");
            for (size_t i = 0; alpha && i < pixels; i++)
                alpha[i] = raw.data[4 * i + 3] > 0.5f;
        }
        vf_image_free(&raw);
        if (status == VF_OK && how->save_dir)
            status = save_view(how->save_dir, n, &render, &photo);
        double iou = -1;
        if (status == VF_OK && how->object)
            status = object_overlap(f, frame, how->object, &region, alpha, &iou);
        free(alpha);
        if (iou >= 0) {
            iou_sum += iou, iou_n++;
            iou_min = fmin(iou_min, iou);
            missing += iou < VF_OBJECT_PRESENT_IOU;
        }
        if (status == VF_OK) {
            double psnr = vf_image_psnr(&render, &photo), ssim = vf_image_ssim(&render, &photo);
            psnr_sum += psnr;
            ssim_sum += ssim;
            n++;
            char name[VF_PATH_MAX];
            vf_path_basename(name, sizeof name, frame->image_path, 0);
            json_t *scores = json_pack("{s:s, s:o, s:o}", "image", name, "psnr",
                                       vf_json_number(psnr), "ssim", vf_json_number(ssim));
            if (how->object)
                json_object_set_new(scores, "object_iou",
                                    iou >= 0 ? vf_json_number(iou) : json_null());
            json_array_append_new(list, scores);
            if (how->sheet_path && tiles < 2 * SHEET_PAIRS) {
                snprintf(captions[tiles], sizeof captions[tiles], "photo %.80s", name);
                status = sheet_tile(&photo, &sheet[tiles++]);
                if (iou >= 0)
                    snprintf(captions[tiles], sizeof captions[tiles],
                             "render\n%.1f dB, object %.2f%s", psnr, iou,
                             iou < VF_OBJECT_PRESENT_IOU ? " MISSING" : "");
                else
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
    free(region.in);
    *out = (vf_photo_scores){.count = n,
                             .psnr = n ? psnr_sum / n : NAN,
                             .ssim = n ? ssim_sum / n : NAN,
                             .psnr_object = object_n ? object_sum / object_n : NAN,
                             .object_checked = iou_n,
                             .object_missing = missing,
                             .object_iou_mean = iou_n ? iou_sum / iou_n : NAN,
                             .object_iou_min = iou_n ? iou_min : NAN};
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
    vf_object_points object_points = {0};
    if (status == VF_OK && held > 0)
        vf_train_object_points(ws, field, &views, &object_points);
    const vf_object_points *pts = object_points.count ? &object_points : NULL;
    vf_photo_scores scores = {.psnr = NAN, .ssim = NAN, .psnr_object = NAN};
    json_t *held_out = json_array();
    if (status == VF_OK && held > 0)
        status = vf_field_score_photos(field, &views,
                                       &(vf_photo_scoring){.holdout = opt->holdout,
                                                           .object_cut = opt->object_only,
                                                           .sheet_path = sheet,
                                                           .object = pts},
                                       held_out, &scores);
    json_object_set_new(report, "held_out", held_out);
    psnr = scores.psnr, ssim = scores.ssim, psnr_object = scores.psnr_object;
    /* as many training views, spread over them: the gap between the two is the sign of a
     * field that fits its photos and is fog between them */
    vf_photo_scores fit = {.psnr = NAN, .ssim = NAN, .psnr_object = NAN};
    json_t *training = json_array();
    if (status == VF_OK && held > 0)
        status = vf_field_score_photos(field, &views,
                                       &(vf_photo_scoring){.holdout = opt->holdout,
                                                           .training = 1,
                                                           .stride = (views.count - held) / held,
                                                           .object_cut = opt->object_only,
                                                           .object = pts},
                                       training, &fit);
    json_object_set_new(report, "training_scored", training);
    vf_object_points_free(&object_points);
    if (status == VF_OK && scores.object_checked > 0) {
        /* The training views are the check's own calibration. It must see the object in the
         * views the field was fitted to before its verdict on the others means anything (the
         * can of drink_can_video: its points take in the tiled floor, and its training views
         * overlap 0.23). And a cut-out misses now and then in any view (the fox: 11 of 45
         * training views under 0.5 on a field 28 dB good), so the warning is for held-out views
         * that miss the object clearly more often than the training views. */
        const int conclusive =
            fit.object_checked > 0 && fit.object_iou_mean >= VF_OBJECT_PRESENT_IOU;
        const double missing_share = (double)scores.object_missing / scores.object_checked,
                     training_share =
                         fit.object_checked ? (double)fit.object_missing / fit.object_checked : 0;
        json_object_set_new(report, "object_check",
                            json_pack("{s:i, s:i, s:o, s:o, s:i, s:i, s:o, s:o, s:b}", "views",
                                      scores.object_checked, "missing", scores.object_missing,
                                      "iou_mean", vf_json_number(scores.object_iou_mean), "iou_min",
                                      vf_json_number(scores.object_iou_min), "training_views",
                                      fit.object_checked, "training_missing", fit.object_missing,
                                      "training_iou_mean", vf_json_number(fit.object_iou_mean),
                                      "present_iou", vf_json_number(VF_OBJECT_PRESENT_IOU),
                                      "conclusive", conclusive));
        if (conclusive && missing_share > training_share + OBJECT_MISSING_MARGIN)
            vf_warn("%d of %d held-out renders do not show the object where its photo does "
                    "(overlap under %.1f; %d of %d training views): the field is fog or room "
                    "between the photos; look at WS/train/held_out.jpg",
                    scores.object_missing, scores.object_checked, VF_OBJECT_PRESENT_IOU,
                    fit.object_missing, fit.object_checked);
        else if (!conclusive)
            vf_info("the object check is inconclusive here: even the training views' renders "
                    "overlap the photos' cut-outs only %.2f (the sparse points or the cut-outs "
                    "do not outline this object)",
                    fit.object_iou_mean);
    }
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
