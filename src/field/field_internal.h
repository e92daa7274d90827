/* src/field/field_internal.h: the radiance-field engine's internals, shared by the src/field sources
 * and the unit tests (not part of the public API in vf/field.h).
 *
 * The model is an explicit voxel grid (DVGO-style density, Plenoxels-style colour):
 *
 *   - grid points on a regular lattice over an axis-aligned box, FIELD_CH floats per point:
 *     channel 0 is the raw density d, channels 1..12 the degree-1 spherical-harmonics colour
 *     logits (colour k, basis b at 1 + 4k + b with basis (1, x, y, z) of the unit view
 *     direction), channels 13..15 are padding so that one point is one 64-byte cache line
 *     (on CPUs that convert half precision, the renderer reads a copy in half precision, 32
 *     bytes a point: render_march.c);
 *   - values between points are trilinear; density sigma = softplus(d + shift) * scale per
 *     world unit; colour = sigmoid(SH logits . basis(direction));
 *   - a ray is sampled every `step` world units; sample i gets alpha_i = 1 - exp(-sigma_i step)
 *     and the usual front-to-back compositing C = sum T_i alpha_i c_i + T_end * background;
 *   - an occupancy bitfield (one bit per cell) says where density may be visible, and each
 *     cell's distance to the nearest occupied cell lets the march jump over empty space; the
 *     march stops when the transmittance T falls below a threshold (early termination).
 *
 * A field may have a second, coarser grid around the first (the background of a real scene);
 * a ray then marches the outer grid up to the inner box, the inner grid inside it, and the
 * outer grid again behind it. */
#ifndef VF_FIELD_INTERNAL_H
#define VF_FIELD_INTERNAL_H

#include <math.h>
#include <stddef.h>
#include <stdint.h>

#include "vf/camera.h"
#include "vf/field.h"

#define FIELD_CH 16         /* floats per grid point */
#define FIELD_CH_USED 13    /* density + 12 SH coefficients */
#define FIELD_CH_DENSITY 0
#define FIELD_CH_SH 1       /* colour k, SH basis b: FIELD_CH_SH + 4 * k + b */
#define FIELD_MAX_RADIUS 32 /* empty-space radii are counted up to this many cells */
#define FIELD_MAX_GRIDS 2
#define FIELD_EMPTY_DENSITY (-30.0f) /* raw density of carved-away space */
/* Rendering skips samples below this opacity. Against a threshold of 1e-3: chair test PSNR
 * 34.15 -> 34.11 dB, fox held-out photos unchanged (21.36 dB), a 224x224 render about a fifth
 * faster. */
#define FIELD_VISIBLE_ALPHA 3e-3f

typedef struct field_grid {
    int dim[3];        /* grid points along x, y, z */
    float lo[3];       /* world position of point (0, 0, 0) */
    float hi[3];       /* world position of the last point */
    float voxel;       /* spacing between points, the same on every axis */
    size_t points;     /* dim[0] * dim[1] * dim[2] */
    float *values;     /* points * FIELD_CH floats, 64-byte aligned */
    uint16_t *half;    /* the renderer's copy of values in IEEE half precision (NULL until the
                          first render; always without FIELD_RENDER_HALF) */
    int cells[3];      /* dim - 1: the trilinear cells */
    uint64_t *cell_bits; /* one bit per cell: 1 when the cell may hold visible density */
    uint8_t *empty_radius; /* per cell: Chebyshev distance, in cells, to the nearest occupied
                              cell (0 when occupied, at most FIELD_MAX_RADIUS): see
                              empty_space.c */
    int occ_lo[3], occ_hi[3]; /* cells [occ_lo, occ_hi) hold every occupied cell (a tight box
                                 for clipping rays); occ_lo >= occ_hi when none is occupied */
} field_grid;

/* The model behind the public vf_field handle. */
struct vf_field {
    int grid_count;                    /* 1, or 2 with an outer (background) grid */
    field_grid grids[FIELD_MAX_GRIDS]; /* grids[0] is the object; grids[1] surrounds it */
    float density_shift;   /* sigma = softplus(d + density_shift) * density_scale */
    float density_scale;
    float step_ratio;      /* sample spacing in voxels of the grid being marched */
    float background[3];   /* colour of rays that leave the field */
    float occupancy_alpha; /* a cell is empty when no corner reaches this alpha per step */
    float stop_transmittance; /* rendering stops a ray below this transmittance */
    vf_camera camera;      /* a reference training camera (intrinsics) */
    double scene_center[3]; /* the point the cameras look at */
    double camera_distance; /* their mean distance to it */
    int half_stale;         /* values changed since the grids' half copies were made */
};

/* Whatever writes grid values in place calls this: the next render remakes the renderer's
 * half-precision copies (a grid allocated anew has none, and gets them on its first render). */
static inline void vf__field_values_changed(vf_field *f)
{
    f->half_stale = 1;
}

/* ---- grid.c: storage, trilinear resampling, occupancy -------------------------------- */

/* Allocate a grid of dim points from lo with the given spacing; values zeroed, occupancy all
 * set. */
vf_status vf__field_grid_alloc(field_grid *g, const int dim[3], const float lo[3], float voxel);
void vf__field_grid_free(field_grid *g);

/* Memory for big arrays: 64-byte aligned, zeroed, huge pages where the kernel offers them.
 * Release with free(). NULL when out of memory. */
void *vf__field_alloc(size_t bytes);

/* Make `out` a grid over (at least) the same box with the new spacing, its values the
 * trilinear resampling of `src`. */
vf_status vf__field_grid_resample(const field_grid *src, float voxel, field_grid *out);

/* Recompute the occupancy of a grid from its densities: a cell is occupied when one of its
 * corners has alpha >= threshold for a step of step_world. */
void vf__field_grid_update_occupancy(field_grid *g, const vf_field *f, float step_world);

/* Set all occupancy bits (used before the densities mean anything). */
void vf__field_grid_fill_occupancy(field_grid *g);

/* Recompute empty_radius from the occupancy bits; scratch holds one byte per cell. */
void vf__field_grid_update_empty_radius(field_grid *g, uint8_t *scratch);

/* Plain comparisons: fminf/fmaxf keep NaN semantics and are library calls unless -ffast-math. */
static inline float field_min(float a, float b) { return a < b ? a : b; }

static inline float field_max(float a, float b)
{
    return a > b ? a : b;
}

/* A ray's samples in one grid, in cell units: sample k (a whole number kept as a float) sits
 * at u0 + k * du, ray parameter t0 + k * step. */
typedef struct field_lattice {
    float u0[3], du[3];
    float samples_per_cell[3]; /* 0.999 / |du| per axis (1e30 when du is 0): a hair short, so
                                  that rounding cannot put a jump on its box's far face */
} field_lattice;

static inline void field_lattice_init(field_lattice *l, const field_grid *g, const float origin[3],
                                      const float dir[3], float t0, float step)
{
    const float inv_voxel = 1.0f / g->voxel;
    for (int a = 0; a < 3; a++) {
        l->u0[a] = (origin[a] + t0 * dir[a] - g->lo[a]) * inv_voxel;
        l->du[a] = dir[a] * step * inv_voxel;
        l->samples_per_cell[a] = l->du[a] != 0 ? 0.999f / fabsf(l->du[a]) : 1e30f;
    }
}

/* Jumping over empty space: sample k at grid position u lies in cell c of empty-space radius
 * r > 0, so every cell within Chebyshev distance r - 1 of c is empty (empty_space.c). Returns
 * the first sample past that box of cells (at least k + 1).
 * Per axis the ray has (r + e) cells to go, e in [-1, 0] being minus the distance from u back to
 * the face of its cell behind it (-1 at most: a position outside the grid is clamped into the
 * edge cell). Everything but r is known before r is loaded, so the jump adds only an FMA, a
 * min and a floor to the march's chain of dependent loads, the renderer's bottleneck. Each
 * FMA is >= 0 exactly (|e * n| <= n <= r * n), so the result is never below k + 1. */
static inline float field_lattice_skip(const field_lattice *l, float k, const float u[3],
                                       const int c[3], int radius)
{
    float exit[3];
    const float r = (float)radius;
    for (int a = 0; a < 3; a++) {
        const float n = l->samples_per_cell[a];
        const float e = l->du[a] >= 0 ? (float)c[a] - u[a] : u[a] - (float)c[a] - 1.0f;
        exit[a] = fmaf(r, n, field_max(e, -1.0f) * n);
    }
    return floorf(k + 1.0f + field_min(field_min(exit[0], exit[1]), exit[2]));
}

/* For functions that only prefetch: GCC takes such a function for one without effects and
 * drops its calls unless they are inlined first. */
#define FIELD_ALWAYS_INLINE inline __attribute__((always_inline))

/* Ask the caches for what sample k of lattice l in grid g will read: its cell's empty-space
 * radius and the 8 corner points (in four places far apart in memory) of `values`, an array of
 * point_bytes a point laid out as the grid's values. The marchers wait on these loads, not on
 * arithmetic; asked for one sample ahead, they arrive while the current sample is worked on
 * (measured in render_march.c and train.c). */
static FIELD_ALWAYS_INLINE void field_prefetch_points(const field_grid *g, const field_lattice *l,
                                                      float k, const void *values,
                                                      size_t point_bytes)
{
    size_t cell = 0, point = 0, cell_stride = 1, point_stride = 1;
    for (int a = 0; a < 3; a++) {
        int c = (int)(l->u0[a] + k * l->du[a]);
        c = c < 0 ? 0 : c >= g->cells[a] ? g->cells[a] - 1 : c;
        cell += cell_stride * (size_t)c;
        point += point_stride * (size_t)c;
        cell_stride *= (size_t)g->cells[a];
        point_stride *= (size_t)g->dim[a];
    }
    const char *v = (const char *)values + point * point_bytes;
    const size_t ox = point_bytes, oy = (size_t)g->dim[0] * ox, oz = oy * (size_t)g->dim[1];
    __builtin_prefetch(g->empty_radius + cell);
    __builtin_prefetch(v);
    __builtin_prefetch(v + ox);
    __builtin_prefetch(v + oy);
    __builtin_prefetch(v + oy + ox);
    __builtin_prefetch(v + oz);
    __builtin_prefetch(v + oz + ox);
    __builtin_prefetch(v + oz + oy);
    __builtin_prefetch(v + oz + oy + ox);
}

/* The same for the float values (the training march). */
static FIELD_ALWAYS_INLINE void field_prefetch_sample(const field_grid *g, const field_lattice *l,
                                                      float k)
{
    field_prefetch_points(g, l, k, g->values, FIELD_CH * sizeof(float));
}

/* The raw density d at which a step of step_world reaches opacity `alpha`: alpha >= threshold
 * exactly when d >= the value returned (softplus is monotonic). */
float vf__field_density_threshold(const vf_field *f, float alpha, float step_world);

/* Number of occupied cells. */
size_t vf__field_grid_occupied_cells(const field_grid *g);

static inline int field_cell_occupied(const field_grid *g, size_t cell)
{
    return (int)((g->cell_bits[cell >> 6] >> (cell & 63)) & 1u);
}

/* ---- march.c: one ray, forward and backward -------------------------------------------- */

typedef struct field_ray {
    float origin[3];
    float dir[3]; /* unit length */
    float tmin, tmax;
} field_ray;

/* What the backward pass needs of one sample. */
typedef struct field_sample {
    uint32_t base;    /* index of the cell's lowest corner point */
    uint8_t grid;     /* which grid */
    float frac[3];    /* position inside the cell, 0..1 per axis */
    float alpha;      /* opacity of the sample's step */
    float trans;      /* transmittance in front of the sample */
    float rgb[3];     /* colour */
    float dtau;       /* d(sigma * step) / d(raw density) */
    float t;          /* ray distance */
} field_sample;

/* Scratch of one thread: sample records for the backward pass. */
typedef struct field_scratch {
    field_sample *samples;
    int capacity;
} field_scratch;

typedef struct field_march_result {
    float rgb[3];      /* composited colour, background included */
    float trans;       /* transmittance left at the end (weight of the background) */
    float depth;       /* expected ray distance of the surface (weighted by alpha) */
    int count;         /* samples recorded (or taken, when not recording) */
    int overflow;      /* 1 when the scratch was too small and the ray was cut short */
} field_march_result;

/* The largest number of samples a ray can take in the field. */
int vf__field_max_samples(const vf_field *f);

/* March one ray front to back. jitter (0..1) offsets the first sample within its step;
 * min_trans ends the ray early. With `rec` the samples are recorded for vf__field_backward(). */
void vf__field_march(const vf_field *f, const field_ray *ray, float jitter, float min_trans,
                     field_scratch *rec, field_march_result *out);

/* Where the gradient of one thread goes: dense per-grid gradient arrays the size of the values,
 * plus a list of the points touched since the last optimizer step (flag per point). */
typedef struct field_grad_sink {
    float *grad[FIELD_MAX_GRIDS];
    uint8_t *touched[FIELD_MAX_GRIDS];
    uint32_t *list[FIELD_MAX_GRIDS];
    size_t count[FIELD_MAX_GRIDS];
} field_grad_sink;

/* The weights of a ray's losses beside its colour's. */
typedef struct field_ray_losses {
    float opaque;     /* times the transmittance left for the background (0 for rays that may
                         see nothing) */
    float distortion; /* times mip-NeRF 360's distortion loss of the ray's weights w_i at
                         distances s_i (ray distance over the camera distance):
                         sum_ij w_i w_j |s_i - s_j| + 1/3 sum_i w_i^2 ds_i */
    float depth;      /* times the depth loss sum_i w_i (s_i - depth_target)^2: the ray's pixel
                         sees a sparse point at distance depth_target (0: no such point) */
    float depth_target;
} field_ray_losses;

/* Accumulate dL/dvalues for one marched ray into the sink: L is the colour loss, given by
 * dL/drgb of the composited colour, plus the losses weighted by `losses`. `res` is the forward
 * result of the same ray. */
void vf__field_backward(const vf_field *f, const field_ray *ray, const field_scratch *rec,
                        const field_march_result *res, const float dl_drgb[3],
                        field_ray_losses losses, field_grad_sink *sink);

/* The distortion loss of a recorded ray (field_ray_losses), summed in double: the reference
 * the gradient test checks vf__field_backward against. */
double vf__field_distortion_loss(const vf_field *f, const field_sample *samples, int count);

/* The depth loss of a recorded ray (field_ray_losses) for a point at distance `target`. */
double vf__field_depth_loss(const vf_field *f, const field_sample *samples, int count,
                            float target);

/* Clip a ray to a box; returns 0 when it misses. */
int vf__field_ray_box(const field_ray *ray, const float lo[3], const float hi[3], float *t0,
                      float *t1);

/* A stretch [ta, tb) of a ray inside one grid; the march's lattice is anchored at ta. */
typedef struct field_segment {
    int grid;
    float ta, tb;
} field_segment;

/* The segments of a ray in marching order: the outer grid in front of the inner box, the
 * inner box, the outer grid behind it. Returns how many (0 to 3). */
int vf__field_ray_segments(const vf_field *f, const field_ray *ray, field_segment out[3]);

/* ---- render_march.c: rays forward only, as fast as they go ------------------------------ */

/* What the renderer reads of a grid: a copy of its values in half precision where the CPU
 * converts halves to floats in one instruction (F16C, AVX-512: 4-10% faster renders), its
 * float values elsewhere (converting in software made VF_PORTABLE renders 60-80% slower). */
#if defined(__F16C__) || defined(__AVX512F__)
#define FIELD_RENDER_HALF 1
typedef uint16_t field_render_value;
#else
#define FIELD_RENDER_HALF 0
typedef float field_render_value;
#endif

/* Opacity of a step as a function of raw density, tabulated (see vf__field_render_setup_init). */
#define FIELD_ALPHA_TABLE 2048

/* Per-grid constants of a render, computed once per image. */
typedef struct field_render_grid {
    float step, scale_step;
    float visible_density; /* raw density below which a sample's alpha is negligible */
    float alpha_per_density; /* table entries per unit of raw density */
    float alpha[FIELD_ALPHA_TABLE + 1]; /* alpha at visible_density + i / alpha_per_density */
    float occ_lo[3], occ_hi[3]; /* world box of the occupied cells */
    int empty;                  /* no occupied cell */
    const field_render_value *values; /* the grid's values as the renderer reads them */
} field_render_grid;

typedef struct field_render_setup {
    field_render_grid grids[FIELD_MAX_GRIDS];
} field_render_setup;

/* The constants of a render of f, and (FIELD_RENDER_HALF) the half-precision copies of its
 * grids, made here when missing or stale (vf__field_values_changed; under a lock, so several
 * threads may set up renders of one field at once). Fails only when out of memory. */
vf_status vf__field_render_setup_init(const vf_field *f, field_render_setup *setup);

/* The distance to the surface each pixel of the view sees (camera width x height floats):
 * the opacity-weighted mean distance of its samples where the opacity is over a half, else
 * infinity. Rows spread over the cores (render.c). */
void vf__field_render_depth(const vf_field *f, const field_render_setup *setup,
                            const vf_camera *cam, const double c2w[16], float *depth);

/* The opacity of a sample of raw density d >= visible_density, from the grid's table. The
 * index is clamped both ways (and a NaN takes the last entry), so no value can read outside
 * the table. */
static inline float field_render_alpha(const field_render_grid *r, float d)
{
    const float u = (d - r->visible_density) * r->alpha_per_density;
    if (!(u < (float)FIELD_ALPHA_TABLE))
        return r->alpha[FIELD_ALPHA_TABLE];
    if (!(u > 0.0f))
        return r->alpha[0];
    const int i = (int)u;
    return r->alpha[i] + (u - (float)i) * (r->alpha[i + 1] - r->alpha[i]);
}

/* The forward march of vf__field_march without recording (same lattice of samples) for n rays,
 * for rendering: samples under FIELD_VISIBLE_ALPHA are skipped, rays are clipped to the
 * occupied cells, opacity comes from the setup's table, and a ray ended below min_trans is
 * renormalized over the opacity it met and reported opaque (see render_march.c). */
void vf__field_render_rays(const vf_field *f, const field_render_setup *setup,
                           const field_ray *rays, int n, float jitter, float min_trans,
                           field_march_result *out);

/* ---- render.c: rays of a camera ------------------------------------------------------- */

/* World-space ray through pixel centre (x + 0.5, y + 0.5) of a camera with camera-to-world
 * c2w (row-major, OpenGL axes). `unit_xy` is the undistorted normalized image point of the
 * pixel in OpenCV axes (x right, y down) or NULL for a pinhole computed from the camera. */
void vf__field_camera_ray(const vf_camera *cam, const double c2w[16], double x, double y,
                          field_ray *ray);

static inline float field_clamp01(float x) { return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x; }

static inline float field_softplus(float x)
{
    return x > 20.0f ? x : log1pf(expf(x));
}

static inline float field_sigmoid(float x)
{
    return 1.0f / (1.0f + expf(-x));
}

#endif
