/* src/field/trainer_internal.h: the training state shared by train.c (the loop),
 * train_views.c (the photos as rays), carve.c (scene box, visual hull), adam.c (optimizer,
 * and the photos' appearance) and model_io.c (checkpoints). */
#ifndef VF_FIELD_TRAINER_INTERNAL_H
#define VF_FIELD_TRAINER_INTERNAL_H

#include "field_internal.h"
#include "vf/rng.h"

/* Training rays come in square tiles of pixels: neighbouring rays meet the same grid points,
 * so a thread marching a tile finds them in its cache. Larger tiles give more steps, smaller
 * ones more varied batches; at 3 minutes, 2x2 against 4x4 (two runs each where given): the
 * fox (dataset poses) 1831, 1684 against 3137, 3051 steps, +0.32, +0.23 dB held-out; the shoes
 * video -0.19, -0.27 dB; the wall clock -0.13; the apple +0.13; the chair (1 minute) -0.02; the
 * lego -0.03; renders named like the photos: the fox 24, 12% against 18, 18%, the shoes 65,
 * 61% against 56, 58%, the clock 50 against 55%, the apple 21 against 26%. No clear gain, so
 * 4 stays. 8x8 gave the fox 4089 steps but 23.20 dB (-2), 1x1 619 steps, 25.33 dB. */
#define TRAIN_TILE 4

/* The opacity per step of a fresh grid's points at the coarsest level (DVGO's
 * initialization), and the occupancy threshold training starts with: just under it, so that
 * a fresh grid is fully occupied and a cell is pruned once all its corners have faded (train.c
 * raises the threshold later, prune_alpha). Starting the fox at 0.01 gave 22.05 and 22.03 dB
 * held-out in two runs, against 21.72 and 21.63 dB at 0.005 and 21.09 dB at 1e-4. */
#define TRAIN_ALPHA_INIT 0.01
#define TRAIN_OCCUPANCY_ALPHA (0.99 * TRAIN_ALPHA_INIT)

/* Undistorted normalized image coordinates (OpenCV axes) of every pixel centre of a camera,
 * shared by the views that use the same camera. */
typedef struct ray_table {
    vf_camera camera;
    float *xy; /* 2 floats a pixel */
} ray_table;

/* A training pixel whose ray sees a sparse point of structure from motion, and the point's
 * distance from the camera (world units). */
typedef struct depth_ray {
    uint32_t pixel;
    float distance;
} depth_ray;

typedef struct train_view {
    vf_camera camera;
    double c2w[16];
    size_t first_pixel; /* index of its pixel (0, 0) in the trainer's pixel arrays */
    int table;          /* its ray table */
    uint8_t *mask;      /* alpha > 0 (1 byte a pixel); NULL for opaque photos */
} train_view;

/* Adam state for every grid, and each thread's gradient sink. */
typedef struct field_adam {
    float *m[FIELD_MAX_GRIDS], *v[FIELD_MAX_GRIDS];
    int t; /* steps since the moments were reset */
    float beta1, beta2, eps;
    int threads;
    field_grad_sink *sinks; /* one per thread */
} field_adam;

struct vf_field_trainer {
    vf_field_train_options opt;
    int threads;

    /* the photos */
    train_view *views;
    int view_count, view_capacity;
    uint8_t *rgb; /* 3 bytes a pixel, background composited */
    size_t pixels, pixel_capacity;
    ray_table *tables;
    int table_count;
    int has_alpha; /* any view came with alpha: carve with it, train on rays near the hull */
    uint32_t *pool; /* top-left pixels of the tiles worth training on */
    size_t pool_size;
    depth_ray *depth_rays; /* pixels that see a sparse point (vf_field_trainer_add_view_points) */
    size_t depth_count, depth_capacity;

    /* the model and its optimizer */
    vf_field *field;
    field_adam adam;
    field_scratch *scratch; /* one per thread */
    int level;
    float final_voxel;
    vf_rng rng;

    /* each photo's appearance (opaque photos, opt.appearance > 0): the render's colour c is
     * compared as (1 + gain) * c + offset; 6 floats a view (gain, offset), their Adam moments,
     * and each thread's gradients (6 doubles a view) */
    float *appearance, *appearance_m, *appearance_v;
    double *appearance_grad;
    int appearance_t;

    /* progress */
    int started, done;
    int step;
    double start_time;     /* vf_now() at start (or resume) */
    double elapsed_before; /* training seconds of the run a checkpoint continued */
    double loss_avg;       /* running mean of recent batch losses */
    int loss_count;
    double last_samples_per_ray, last_step_ms, last_optimizer_ms, last_touched;
};

/* ---- train_views.c -------------------------------------------------------------------- */

/* The ray through pixel `p` (global pixel index) and its target colour. */
void vf__trainer_pixel_ray(const vf_field_trainer *t, size_t p, field_ray *ray, float rgb[3]);

/* Which view a global pixel index belongs to. */
int vf__trainer_pixel_view(const vf_field_trainer *t, size_t p);

/* How far the sparse points (vf_field_trainer_add_view_points) reach from `center`: the
 * `share` quantile of their sightings' largest per-axis distance from it; 0 without points. */
double vf__trainer_points_reach(const vf_field_trainer *t, const double center[3], double share);

/* What the photographer centred: the per-axis median of the sparse-point sightings that lie
 * within `central` (a tangent of the angle off the optical axis) of their photo's centre.
 * Returns 0 (center untouched) with fewer than 32 such sightings. */
int vf__trainer_points_center(const vf_field_trainer *t, double central, double center[3]);

/* A fingerprint of the views (sizes, cameras, poses, pixels) so a checkpoint can tell it is
 * resumed on the same data. */
uint64_t vf__trainer_views_fingerprint(const vf_field_trainer *t);

void vf__trainer_views_free(vf_field_trainer *t);

/* ---- carve.c ------------------------------------------------------------------------- */

/* Where the cameras look (the point nearest all optical axes) and their mean distance to it. */
void vf__trainer_scene_center(const vf_field_trainer *t, double center[3], double *distance);

/* Fill in the options left automatic (grid size, levels, colour smoothing: vf/field.h) for a
 * capture with (outer = 1) or without an outer grid around the object. */
void vf__field_resolve_automatic(vf_field_train_options *o, int outer);

/* Build the object grid: place the box, carve it with the views' alpha masks (visual hull),
 * shrink the box to what is left, and fill the grid at the coarsest level. */
vf_status vf__trainer_build_grid(vf_field_trainer *t);

/* The pixels whose rays pass through occupied space (for views with alpha); all pixels of
 * opaque views. */
vf_status vf__trainer_build_pool(vf_field_trainer *t);

/* ---- model_io.c ---------------------------------------------------------------------- */

/* Load a checkpoint's field, optimizer state and schedule position into t (views already
 * added; pool and scratch are left to the caller). */
vf_status vf__trainer_checkpoint_read(vf_field_trainer *t, const char *path);

/* ---- adam.c -------------------------------------------------------------------------- */

/* Allocate moments and per-thread gradient sinks for the field's current grids. */
vf_status vf__field_adam_alloc(field_adam *adam, const vf_field *f, int threads);
void vf__field_adam_free(field_adam *adam);

/* Apply one Adam step to every point touched since the last step, summing the threads'
 * gradients (plus total variation when weights are non-zero: tv_view on the degree-1
 * harmonics alone), then clear the sinks.
 * lr[ch] is the learning rate of channel ch. */
void vf__field_adam_step(field_adam *adam, vf_field *f, const float lr[FIELD_CH], float tv_density,
                         float tv_color, float tv_view);

/* Each opaque photo's appearance (gain and offset per channel, from 0), their Adam moments
 * and the threads' gradients, when opt.appearance asks for them and they are missing. */
vf_status vf__trainer_alloc_appearance(vf_field_trainer *t);

/* One Adam step on the photos' appearance from the threads' gradients (cleared), then the
 * mean over the photos taken out: the field keeps the photos' mean look, which renders show. */
void vf__trainer_appearance_step(vf_field_trainer *t, float lr);

/* Number of distinct points touched (for statistics). */
size_t vf__field_adam_touched(const field_adam *adam);

#endif
