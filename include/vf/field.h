/* vf/field.h: radiance fields: fit one to posed photos of an object, render new views of it.
 *
 * A vf_field is an explicit voxel grid (density plus degree-1 spherical-harmonics colour),
 * trained on the CPU in minutes and rendered in milliseconds by ray marching with empty-space
 * skipping and early termination. Typical use:
 *
 *     vf_field_trainer *t;
 *     vf_field_train_options opt;
 *     vf_field_train_defaults(&opt);
 *     opt.seconds = 180;
 *     vf_field_trainer_create(&opt, &t);
 *     for (each posed image)
 *         vf_field_trainer_add_view(t, &camera, c2w, &image);  // copied; free yours after
 *     vf_field_trainer_start(t);
 *     while (vf_field_trainer_step(t, &status) == VF_OK && !status.done)
 *         ... report status, checkpoint now and then ...
 *     vf_field_save(vf_field_trainer_field(t), "model.vff");
 *     vf_field_trainer_free(t);
 *
 *     vf_field *f;
 *     vf_field_load("model.vff", &f);
 *     vf_image img = {0};
 *     vf_field_render(f, &camera, c2w, &img);   // allocates img; vf_image_free() it
 *     vf_field_free(f);
 *
 * Conventions: camera-to-world matrices are row-major 4x4 doubles in OpenGL camera axes (x
 * right, y up, looking along -z), as in vf/dataset.h. Rendered images are 3-channel float RGB
 * in 0..1, the field's background colour where rays see nothing.
 *
 * Threads: rendering and training use every core (OpenMP). A vf_field may be rendered from
 * several threads at once; a trainer is used by one thread.
 *
 * On CPUs with F16C or AVX-512 the renderer reads a half-precision copy of the field's grids
 * (half as much memory again), made by the first render of a field and by the first render
 * after training or the object cut changed it: a few hundred milliseconds for a capture's
 * field, once. A VF_PORTABLE build reads the floats.
 *
 * Memory: create/load functions allocate the object; the caller frees it with the matching
 * free function. Images passed in are borrowed (copied where kept); images filled by a
 * render function belong to the caller. */
#ifndef VF_FIELD_H
#define VF_FIELD_H

#include <stddef.h>
#include <stdint.h>

#include "vf/camera.h"
#include "vf/error.h"
#include "vf/image.h"
#include "vf/pose.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_field vf_field;

/* ---- rendering --------------------------------------------------------------------------- */

/* Render the view of camera `cam` placed at c2w into `out` (RGB float). When out->data is
 * NULL, or out's size or channel count differ from the camera's, out is (re)allocated;
 * otherwise its pixels are overwritten in place, so a render loop allocates nothing. */
vf_status vf_field_render(const vf_field *f, const vf_camera *cam, const double c2w[16],
                          vf_image *out);

/* Render n views (c2w: n row-major 4x4 matrices, one after another) with the same camera into
 * out[0..n-1], each handled as in vf_field_render. For the attack loop: no file I/O, and no
 * allocation after the first call with the same images. */
vf_status vf_field_render_batch(const vf_field *f, const vf_camera *cam, const double *c2w, int n,
                                vf_image *out);

/* Render n ViewFool viewpoints (vf/pose.h: vf_viewpoint_to_c2w) with the same camera into
 * out[0..n-1], as vf_field_render_batch does. This is the attack's renderer. */
vf_status vf_field_render_viewpoints(const vf_field *f, const vf_camera *cam,
                                     const vf_viewpoint *viewpoints, int n, vf_image *out);

/* The field's opacity (1 - transmittance, 0..1) at each pixel of the view, into `out` (one
 * channel, (re)allocated as in vf_field_render): its silhouette. */
vf_status vf_field_render_opacity(const vf_field *f, const vf_camera *cam, const double c2w[16],
                                  vf_image *out);

/* The distance along each pixel's ray (world units; the ray's direction is a unit vector) to
 * the surface it sees: the opacity-weighted mean distance of its samples where the opacity is
 * over a half, else INFINITY (one channel, (re)allocated as in vf_field_render). */
vf_status vf_field_render_depth(const vf_field *f, const vf_camera *cam, const double c2w[16],
                                vf_image *out);

/* The pinhole camera whose size x size image equals what a classifier sees of a training
 * photo: the photo resized so its shorter side is size * 256 / 224, then centre-cropped to
 * size x size (vf_classifier_preprocess). Lens distortion is dropped. */
vf_camera vf_field_classifier_camera(const vf_field *f, int size);

/* The colour of rays that see nothing (white for objects on transparent backgrounds). */
void vf_field_background(const vf_field *f, float rgb[3]);

/* Facts about a field, for reports. */
typedef struct vf_field_info {
    int dim[3];              /* grid points of the object grid */
    float box_lo[3], box_hi[3]; /* its world box */
    float voxel;             /* its spacing, world units */
    int has_background_grid; /* 1 when a coarse outer grid models the surroundings */
    size_t points;           /* grid points in all grids */
    size_t occupied_cells;   /* cells that may hold visible density */
    size_t bytes;            /* memory the field holds (with its render copy, once made) */
} vf_field_info;

void vf_field_get_info(const vf_field *f, vf_field_info *info);

/* ---- model files ------------------------------------------------------------------------- */

/* Write the field to path (atomically): a header with magic and format version, the grids,
 * and a checksum. */
vf_status vf_field_save(const vf_field *f, const char *path);

/* Read a field written by vf_field_save. VF_EINPUT with a clear message when the file is
 * missing, not a field, from another format version, truncated or corrupt. */
vf_status vf_field_load(const char *path, vf_field **out);

#define VF_FIELD_FILE "model.vff" /* the train stage's field, WS/train/model.vff */

/* The trained field of a workspace. VF_EINPUT saying to run train first when there is none. */
struct vf_workspace;
vf_status vf_field_load_workspace(const struct vf_workspace *ws, vf_field **out);

/* Release a field; NULL is fine. */
void vf_field_free(vf_field *f);

/* ---- object mode: the object cut out of a field of the whole scene ----------------------- */

/* One photo's say on where the object is: its camera, pose, and mask (camera.width x
 * camera.height bytes, row-major, nonzero on the object; borrowed). */
typedef struct vf_field_cut_view {
    vf_camera camera;
    double c2w[16];
    const uint8_t *mask;
} vf_field_cut_view;

/* Cut the object out of a field trained on whole photos. Every grid point with visible
 * density is kept only when (a) fewer than `share` of the views that see it find it outside
 * their mask (a vote: a cut-out that errs in a view or two does not cut the object; a point
 * no view sees goes) and (b) with a plane (n.x + d = 0, n towards the cameras: the surface the
 * object stands on or hangs from; NULL for none), it lies at least `clearance` in front of it
 * (papers, a tablecloth, the wall's paint go with the surface). Without a plane a view
 * votes on a point only where it sees it, not hidden behind the field's surface (a wall
 * behind the object lies inside the masks of the views the object hides it from: they have
 * no say); with one, every view with the point in its picture votes (the views that see the
 * object's far side through it find that side inside their masks, and outvote the masks'
 * errors: visibility took the fox's held-out PSNR inside its masks from 15.6 to 12.9 dB).
 * Then the scraps go: pieces of what is left (connected grid points) under 5% of the
 * largest in the object grid, and pieces of the outer grid that do not reach the object box.
 * Everything else becomes empty
 * space, and the background white, as for background-removed photos. *kept_share (may be
 * NULL) gets the share of visible grid points kept. Views' masks are read, not kept. */
vf_status vf_field_cut_object(vf_field *f, const vf_field_cut_view *views, int n, double share,
                              const double *plane, double clearance, double *kept_share);

/* The field's silhouette in the view of cam from c2w: *mask gets cam->width x cam->height
 * bytes (malloc'd, row-major, 1 where the opacity is over a half), the mask of the object a
 * cut field (vf_field_cut_object) holds. max_side > 0 renders the opacity at most that many
 * pixels long and scales it up (nearest), for large frames; 0 renders at full size. */
vf_status vf_field_silhouette(const vf_field *f, const vf_camera *cam, const double c2w[16],
                              int max_side, uint8_t **mask);

/* Object mode: an RGB photo taken by cam from c2w becomes RGBA, its alpha the field's
 * silhouette there (the object as a cut field holds it: what train's held-out scores and
 * bench_field --cut compare renders with). VF_EINPUT when the photo is not cam's size. */
vf_status vf_field_cut_photo(const vf_field *f, const vf_camera *cam, const double c2w[16],
                             vf_image *photo);

/* ---- training ---------------------------------------------------------------------------- */

/* What the field models beyond the object box the cameras look at. */
typedef enum vf_field_surroundings {
    VF_SURROUNDINGS_AUTO = 0, /* opaque photos: a grid; photos with alpha: none (the default) */
    VF_SURROUNDINGS_GRID,     /* a coarser outer grid for the room, the desk, the wall */
    VF_SURROUNDINGS_NONE      /* nothing: the object box must explain every pixel */
} vf_field_surroundings;

/* "auto", "grid", "none"; vf_field_surroundings_parse returns -1 for any other name. */
const char *vf_field_surroundings_name(vf_field_surroundings s);
int vf_field_surroundings_parse(const char *name);

/* How a point's colour may change with the direction it is seen from. */
typedef enum vf_field_color {
    VF_COLOR_VIEW = 0, /* degree-1 spherical harmonics (default; see tv_view) */
    VF_COLOR_DIFFUSE   /* one colour a point: the degree-1 terms stay zero. Better for matte
                          objects, ruinous for glass (see tv_view) */
} vf_field_color;

/* "view", "diffuse"; vf_field_color_parse returns -1 for any other name. */
const char *vf_field_color_name(vf_field_color c);
int vf_field_color_parse(const char *name);

/* The learning rate of `train --appearance` (vf_field_train_options.appearance). */
#define VF_FIELD_APPEARANCE_RATE 1e-3f

typedef struct vf_field_train_options {
    double seconds;          /* training time budget in wall-clock seconds (0: use steps) */
    int steps;               /* number of optimizer steps when seconds is 0 */
    int batch_rays;          /* rays per step */
    double max_points;       /* grid points of the finest object grid (about res^3; the
                                outer grid gets half as many). 0: automatic: for opaque
                                photos with an outer grid 6M with 3 minutes (or 4500 steps)
                                or more, proportionally fewer for less, 2M at least; else
                                128^3 (see levels) */
    int levels;              /* coarse-to-fine levels (each 2x the points of the one before).
                                0: automatic: 6 for opaque photos with an outer grid, else 3.
                                Few views of a detailed room overfit a fine grid unless it is
                                reached slowly and the colour smoothed (tv_color): the fox in
                                3 minutes, 23.7 dB held-out at 2.1M points and 3 levels, 25.5
                                at 6M points and 6 levels with the smoothing (carve.c) */
    double upsample_end;     /* fraction of the budget by which the finest level is reached */
    float background[3];     /* colour behind transparent pixels, and of rays that see nothing */
    vf_field_surroundings surroundings; /* opaque photos only: photos with alpha never get an
                                           outer grid (there is nothing around the object) */
    vf_field_color color;       /* colour model (VF_COLOR_VIEW) */
    float background_scale;     /* the outer grid's half-size, in units of the camera distance
                                   times tan(half the narrower field of view) (at least 1.5 times
                                   the object box's, and with sparse points out to 1.1 times
                                   where 98% of their sightings lie, up to 4x as far) */
    float box_scale;            /* object box half-size in the same units, around the point the
                                   optical axes meet, or for opaque photos with sparse points
                                   around those at the photos' middles (0: automatic: 1.2 for
                                   photos with alpha, before the visual hull shrinks it; 0.8 for
                                   opaque photos with an outer grid; 1 without) */
    float step_ratio;           /* sample spacing along a ray, in voxels of the grid marched
                                   (0: automatic: 0.5, or 1 for opaque photos with an outer grid) */
    float lr_density, lr_color; /* Adam learning rates (decay 10x over the run) */
    float tv_density;           /* total variation on the density (0: off) */
    float tv_color;             /* total variation on the colour (0: off; negative: automatic:
                                   1e-4 for opaque photos with an outer grid, where it keeps
                                   what few views see from becoming their own colours (fox
                                   held-out +0.6 dB), else 0: clean photos lose detail) */
    float tv_view;              /* total variation on the degree-1 harmonics alone (0: off).
                                   On noisy photos (Blender's 32-sample renders) the free
                                   harmonics learn each photo's noise as colour that flips with
                                   direction, a speckle the classifier reads; 1e-4 stops it
                                   (3D models keep 1e-4, photos 0; measured in docs/field.md) */
    float opaque;               /* opaque photos: weight of a loss on the transmittance a ray
                                   leaves for the background colour (every pixel sees a surface;
                                   without it a room trains into haze over the background) */
    float distortion;        /* opaque photos: weight of mip-NeRF 360's distortion loss over
                                the last 30% of the budget, which pulls each ray's weights
                                together into one short stretch: fewer samples a ray, renders
                                5-20% faster, held-out PSNR within 0.2 dB (default 0.01; 0
                                off; measurements in train.c) */
    float depth;             /* opaque photos with sparse points (vf_field_trainer_add_view_points):
                                weight of a loss sum_i w_i (s_i - s*)^2 on the rays through the
                                points' pixels (one ray in 8 of a batch), s* the point's
                                distance, over the first half of the budget: DS-NeRF's idea,
                                the surfaces placed where structure from motion saw them.
                                Default 10; 0 off (measurements in train.c) */
    float appearance;        /* opaque photos: learning rate of each photo's colour gain and
                                offset per channel (NeRF in the Wild's appearance, as an affine
                                colour map): the photo is compared with (1 + gain) * render +
                                offset, so its exposure and white balance are not drawn into
                                the field; the gains and offsets keep a mean of 0 over the
                                photos, and renders show that mean. 0 off (the default);
                                VF_FIELD_APPEARANCE_RATE is `train --appearance`. At 3 minutes
                                (bench_field, every 8th photo held out and shown at the mean):
                                the wall clock named like its photos 51 -> 62% and 54 -> 65%
                                (seeds 1, 2), held-out 22.27 -> 21.85 and 22.44 -> 21.85 dB
                                (colour matched to each photo: 22.57 -> 22.84 dB, seed 2);
                                the shoes 66 -> 69%, 30.14 -> 29.99 dB; the fox 40 -> 40%,
                                27.38 -> 26.43 dB; the apple 21 -> 21%, 22.93 -> 22.09 dB */
    float carve_share;       /* photos with alpha: a point of the box is carved away when at
                                least this share of the views that see it find it transparent
                                (0: one view is enough, for exact masks; cut-outs of real
                                photos err here and there, so object mode asks for more) */
    float prune_alpha;       /* by 70% of the budget (and 1200 steps at the earliest), cells
                                where no corner reaches this opacity per step are pruned (0: no
                                pruning ramp; see train.c) */
    uint64_t seed;
    int threads;             /* 0: all cores */
} vf_field_train_options;

/* Fill in the defaults (3 minutes, 8192 rays a step, white background, surroundings
 * modelled for opaque photos, grid size, levels and colour smoothing automatic, depth loss
 * 10...). */
void vf_field_train_defaults(vf_field_train_options *opt);

typedef struct vf_field_trainer vf_field_trainer;

typedef struct vf_field_train_status {
    int step;              /* optimizer steps taken */
    double fraction;       /* how much of the budget (time or steps) is used, 0..1 */
    double elapsed;        /* training seconds so far (since vf_field_trainer_start) */
    double seconds_left;   /* estimate */
    double loss;           /* mean squared error of recent batches */
    double psnr;           /* training PSNR of recent batches (on rays that can see the object) */
    int level;             /* coarse-to-fine level, 0 first */
    double samples_per_ray; /* mean samples a training ray took in the last batch */
    double step_ms;        /* wall time of the last step: rays / optimizer */
    double optimizer_ms;
    double touched_points;  /* grid points the last step updated */
    double occupied;        /* fraction of the object grid's cells that may hold density */
    int done;              /* the budget is used up */
} vf_field_train_status;

/* Create a trainer with the given options (copied). */
vf_status vf_field_trainer_create(const vf_field_train_options *opt, vf_field_trainer **out);

/* Add one posed training image. `image` has 3 (RGB) or 4 (RGBA, straight alpha) channels and
 * the camera's size; its pixels are copied (8 bits per channel). With alpha, pixels are
 * composited on the background colour, and the alpha also carves the empty space around the
 * object (visual hull). */
vf_status vf_field_trainer_add_view(vf_field_trainer *t, const vf_camera *cam, const double c2w[16],
                                    const vf_image *image);

/* Depth supervision: the world points (3 doubles each) that structure from motion found in
 * the view added last, e.g. the sparse points whose tracks include its photo. Points that do
 * not project into the photo are ignored. Used when options.depth > 0 and the photos are
 * opaque. */
vf_status vf_field_trainer_add_view_points(vf_field_trainer *t, const double *xyz, int n);

/* Place the scene box, carve, build the coarse grid and start the clock. */
vf_status vf_field_trainer_start(vf_field_trainer *t);

/* One optimizer step (a batch of rays). Fills status; status->done is set once the budget is
 * used up, after which further calls do nothing. */
vf_status vf_field_trainer_step(vf_field_trainer *t, vf_field_train_status *status);

/* The trainer's options, with the automatic ones resolved once training has started or
 * resumed (for reports). */
const vf_field_train_options *vf_field_trainer_options(const vf_field_trainer *t);

/* The field being trained (borrowed: valid until the next step or vf_field_trainer_free). */
const vf_field *vf_field_trainer_field(const vf_field_trainer *t);

/* Hand the trained field to the caller (who frees it); the trainer can only be freed after. */
vf_field *vf_field_trainer_take_field(vf_field_trainer *t);

/* Save everything needed to continue (field, optimizer state, schedule position) to path,
 * atomically. The time it takes (seconds for a big grid: the optimizer state is twice the
 * field) is not charged to the training budget. */
vf_status vf_field_trainer_save_checkpoint(vf_field_trainer *t, const char *path);

/* Continue from a checkpoint instead of vf_field_trainer_start(), after adding the same
 * views. VF_EINPUT when it is corrupt, from another version, or was made with other views. */
vf_status vf_field_trainer_resume(vf_field_trainer *t, const char *path);

void vf_field_trainer_free(vf_field_trainer *t);

#ifdef __cplusplus
}
#endif
#endif
