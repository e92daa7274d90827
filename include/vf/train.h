/* vf/train.h: the train stage, a radiance field fitted to a workspace's posed images.
 *
 *     vf_train_options o;
 *     vf_train_defaults(&o);
 *     o.steps = 1500;                           // a step budget instead of 3 minutes
 *     json_t *report;
 *     vf_status s = vf_train_run(&ws, &o, &report);   // WS/train/ committed
 *
 * The views are the workspace's training views (vf_dataset_load_training: the poses stage's
 * undistorted frames, or an imported posed set). Every holdout-th view (the middle one of
 * each run of holdout) is held out, scored after training (PSNR, SSIM against the photo
 * composited on the field's background) and shown beside its render in held_out.jpg. The
 * trainer (vf/field.h) checkpoints into the staging folder every 30 s; a later run resumes
 * from that checkpoint unless `restart` is set, and the checkpoint goes only once the stage is
 * committed. Output: WS/train/model.vff (VF_FIELD_FILE), report.json (mode "scene" or
 * "object", views, held_out_views, steps, seconds, surroundings, color, view_smoothing, field,
 * grid, bytes, appearance [the per-photo appearance's learning rate, 0 when off],
 * depth_points [sightings of sparse points in the training photos handed to the
 * depth loss, which drops any that fall outside their photo; 0 when it was off or had none],
 * held_out_psnr/ssim, held_out [per view], training_psnr [as many training views, spread
 * over them, scored the same way; training_scored per view], psnr_gap [training_psnr minus
 * held_out_psnr, inside the masks in object mode], object_check [where a poses stage's
 * sparse points show the object: {views, missing, iou_mean, iou_min, training_views,
 * training_missing, training_iou_mean, present_iou, conclusive}, the object's overlap in
 * held-out photo and render, vf_photo_scoring; conclusive when the training views' mean
 * reaches present_iou]), held_out.jpg. A gap over VF_TRAIN_GAP_WARN_DB is a warning: the
 * field fits its photos and is fog between them; so are held-out views without the object
 * clearly more often (by a quarter of them) than the training views, when conclusive. */
#ifndef VF_TRAIN_H
#define VF_TRAIN_H

#include <jansson.h>

#include "vf/error.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The default budgets. A 3D model's 100 renders get longer: the glass vase's field, trained 3
 * minutes (6178 steps), was named "vase" at 44% of the training views against 64% for the
 * model's own renders; at 5 minutes (9561 steps) 62%. */
#define VF_TRAIN_MINUTES 3.0
#define VF_TRAIN_MINUTES_MODEL 5.0

/* The train/held-out PSNR gap above which train warns (dB). The fox video (3 minutes): held-out
 * 28.15 dB, as many training views 28.20 dB (0.05 above); the phone
 * capture of issue 55, whose held-out views were fog, 6-12 dB below. */
#define VF_TRAIN_GAP_WARN_DB 4.0

typedef struct vf_train_options {
    double minutes; /* wall-time budget; 0: automatic (the default): VF_TRAIN_MINUTES_MODEL for
                       a workspace made from a 3D model, VF_TRAIN_MINUTES for photos */
    int steps;      /* > 0: this many optimizer steps instead of minutes */
    int holdout;    /* hold out every holdout-th view for scoring; 0 none (10) */
    vf_field_surroundings surroundings; /* VF_SURROUNDINGS_AUTO, see vf/field.h */
    vf_field_color color;               /* VF_COLOR_VIEW, see vf/field.h */
    double view_smoothing; /* the field's tv_view (vf/field.h); < 0: automatic (-1): 1e-4 for a
                              workspace made from a 3D model, whose Blender renders carry
                              Monte-Carlo noise, 0 for photos */
    double depth;          /* the field's depth-loss weight (vf/field.h) on the sparse points
                              of a poses stage; < 0: the trainer's default (-1); 0: off */
    int appearance;        /* opaque photos: learn each photo's colour gain and offset with the
                              field (vf/field.h appearance), so that its exposure and white
                              balance are not drawn into the field; renders show the photos'
                              mean. Off by default (measured there) */
    int restart;                        /* ignore a checkpoint of an interrupted run */
    /* Object mode (vf/cutout.h): cut the object out of every photo with the help of the
     * poses stage's sparse points; train on the whole photos as in scene mode; then the
     * training views' cuts vote the object out of the field and the surface it stands on
     * goes (vf_field_cut_object), the rest rendered on white. WS/train/object/ keeps the
     * cut-out views (RGBA), their transforms.json and masks.jpg; report.json says "mode":
     * "object" with the cut's figures ("cutout", its "field_cut") and the held-out PSNR
     * inside the object's masks (held_out_psnr_object), a held-out photo's mask being the
     * field's silhouette in it (opacity over a half), as held_out.jpg shows. Needs a poses
     * stage (a posed import has no sparse points). */
    int object_only;
} vf_train_options;

void vf_train_defaults(vf_train_options *o);

/* The wall-time budget a training gets: o->minutes when set, else the default for photos or,
 * when from_model, for a 3D model's renders. */
double vf_train_minutes(const vf_train_options *o, int from_model);

/* VF_EINPUT naming the option that cannot run (minutes outside (0, 600], holdout 1). */
vf_status vf_train_options_check(const vf_train_options *o);

/* Train on an open workspace. *result (may be NULL) gets report.json's document (a new
 * reference). VF_EINPUT when there are fewer than 3 training views. */
vf_status vf_train_run(vf_workspace *ws, const vf_train_options *o, json_t **result);

struct vf_object_points;

/* Scoring a field against posed photos: the held-out views of `train` and the test sets of
 * `eval` go through the same loop. Each chosen photo is rendered at its pose and compared. */
typedef struct vf_photo_scoring {
    int holdout;            /* score frames i with i % holdout == holdout / 2 (train's held-out
                               views); 0: every frame */
    int training;           /* 1: score the frames the holdout rule leaves for training instead */
    int stride;             /* of the frames chosen, every stride-th (0, 1: all) */
    int object_cut;         /* cut each photo by the field's silhouette first (object mode) */
    const char *sheet_path; /* NULL, or a contact sheet of the first photo | render pairs */
    const char *save_dir;   /* NULL, or DIR/render_NNN.png and DIR/error_NNN.png per view */
    /* NULL, or the object's sparse points (vf/cutout.h): each view is also checked for the
     * object being where its photo shows it. The photo's cut-out (GrabCut seeded by those
     * points: the photo alone decides) against the render's pixels whose surface lies in the
     * object's region (the points' box grown by a tenth, in front of the surface it stands
     * on: the field alone decides), as intersection over union at the cut-out's working size.
     * Fog before the object, or the room seen through where it should be, leaves the
     * render's pixels out. */
    const struct vf_object_points *object;
} vf_photo_scoring;

/* A view shows the object when that overlap is at least this. */
#define VF_OBJECT_PRESENT_IOU 0.5

typedef struct vf_photo_scores {
    int count;                /* views scored */
    double psnr, ssim;        /* means (NAN without views) */
    double psnr_object;       /* mean PSNR inside the photos' masks: photos with alpha, or
                                 cut in object mode (else NAN) */
    int object_checked;       /* with `object`: views whose photo shows the object's points */
    int object_missing;       /* of those, views under VF_OBJECT_PRESENT_IOU */
    double object_iou_mean, object_iou_min; /* over them (NAN without) */
} vf_photo_scores;

/* The object's sparse points for that check, found as object mode finds them (vf/cutout.h),
 * or, where there are none near the point the cameras look at, around the field's object box,
 * where the photos' middles are (the fruit on the bed of banana_apple_photos lies 1.1 units
 * from that point). out->count is 0 (nothing to free) without a poses stage (posed imports, 3D models)
 * or where the points show no object there (said in an info line). */
void vf_train_object_points(const vf_workspace *ws, const vf_field *field, const vf_dataset *views,
                            struct vf_object_points *out);

/* Score; `list` (a JSON array) gets {"image", "psnr", "ssim"} per view, and "object_iou" with
 * `object` (null where the photo shows none of its points). Shows progress. */
vf_status vf_field_score_photos(const vf_field *f, const vf_dataset *views,
                                const vf_photo_scoring *how, json_t *list, vf_photo_scores *out);

#ifdef __cplusplus
}
#endif
#endif
