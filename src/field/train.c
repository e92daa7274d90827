/* The training loop: random batches of rays from every training pixel, forward and backward
 * through the grids, sparse Adam; coarse-to-fine upsampling and occupancy refreshes on a
 * schedule that follows the fraction of the budget (time or steps) used so far.
 *
 * A step waits on memory: the grids are hundreds of megabytes and every sample and every
 * touched point is a cache miss. The marcher prefetches the next sample
 * (field_prefetch_sample), the optimizer the points it updates next (adam.c). Same steps, same
 * field, sooner: the fox (our poses) 1500 steps in 42.5 s instead of 56.8 (the forward march
 * alone 7-8% faster); 3 minutes hold 4609 steps instead of 3570 (26.44 against 26.28 dB
 * held-out), the shoes 3695 instead of 2657, the clock 3137 / 2650, the apple 4754 / 3547. */
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "trainer_internal.h"
#include "vf/log.h"

#define OCCUPANCY_EVERY 32 /* steps between occupancy refreshes */

void vf_field_train_defaults(vf_field_train_options *opt)
{
    memset(opt, 0, sizeof *opt);
    opt->seconds = 180;
    opt->steps = 0;
    opt->batch_rays = 8192;
    opt->max_points = 0;
    opt->levels = 0;
    opt->upsample_end = 0.3;
    opt->background[0] = opt->background[1] = opt->background[2] = 1.0f;
    opt->surroundings = VF_SURROUNDINGS_AUTO;
    opt->color = VF_COLOR_VIEW;
    opt->background_scale = 4.0f;
    opt->box_scale = 0;
    opt->step_ratio = 0;
    opt->lr_density = 0.1f;
    opt->lr_color = 0.05f;
    opt->tv_density = 0;
    opt->tv_color = -1;
    opt->tv_view = 0;
    opt->opaque = 0.1f;
    opt->distortion = 0.01f;
    opt->depth = 10;
    opt->prune_alpha = 0.1f;
    opt->appearance = 0;
    opt->seed = 1;
    opt->threads = 0;
}

static vf_status check_options(const vf_field_train_options *o)
{
    if (!(o->seconds > 0) && o->steps <= 0)
        return vf_fail(VF_EINPUT, "give a training time (seconds > 0) or a number of steps");
    if (o->batch_rays < 64 || o->batch_rays > (1 << 22))
        return vf_fail(VF_EINPUT, "batch of %d rays is out of range", o->batch_rays);
    if (o->max_points != 0 && (!(o->max_points >= 1000) || o->max_points > 1e9))
        return vf_fail(VF_EINPUT, "grid of %g points is out of range", o->max_points);
    if (o->levels < 0 || o->levels > 8)
        return vf_fail(VF_EINPUT, "levels must be 1..8 (or 0: automatic)");
    if (!(o->tv_density >= 0 && o->tv_density <= 1) || !(o->tv_color <= 1))
        return vf_fail(VF_EINPUT, "smoothing weights must be at most 1 (density: at least 0)");
    if ((unsigned)o->surroundings > VF_SURROUNDINGS_NONE)
        return vf_fail(VF_EINPUT, "unknown surroundings model %d", (int)o->surroundings);
    if (!(o->tv_view >= 0 && o->tv_view <= 1))
        return vf_fail(VF_EINPUT, "view-dependence smoothing %g is out of range", o->tv_view);
    if ((unsigned)o->color > VF_COLOR_DIFFUSE)
        return vf_fail(VF_EINPUT, "unknown colour model %d", (int)o->color);
    if (o->step_ratio != 0 && !(o->step_ratio >= 0.1f && o->step_ratio <= 2.0f))
        return vf_fail(VF_EINPUT, "step ratio %g is out of range (0.1 to 2 voxels)",
                       o->step_ratio);
    if (!(o->opaque >= 0 && o->opaque <= 100))
        return vf_fail(VF_EINPUT, "opacity weight %g is out of range", o->opaque);
    if (!(o->distortion >= 0 && o->distortion <= 100))
        return vf_fail(VF_EINPUT, "distortion weight %g is out of range", o->distortion);
    if (!(o->depth >= 0 && o->depth <= 1e4))
        return vf_fail(VF_EINPUT, "depth weight %g is out of range", o->depth);
    if (!(o->appearance >= 0 && o->appearance <= 1))
        return vf_fail(VF_EINPUT, "appearance learning rate %g is out of range", o->appearance);
    if (!(o->prune_alpha >= 0 && o->prune_alpha < 1))
        return vf_fail(VF_EINPUT, "prune_alpha must be in [0, 1)");
    return VF_OK;
}

vf_status vf_field_trainer_create(const vf_field_train_options *opt, vf_field_trainer **out)
{
    *out = NULL;
    vf_status status = check_options(opt);
    if (status != VF_OK)
        return status;
    vf_field_trainer *t = calloc(1, sizeof *t);
    if (!t)
        return vf_fail(VF_EINTERNAL, "out of memory");
    t->opt = *opt;
    t->threads = opt->threads > 0 ? opt->threads : omp_get_max_threads();
    vf_rng_seed(&t->rng, opt->seed);
    *out = t;
    return VF_OK;
}

void vf_field_trainer_free(vf_field_trainer *t)
{
    if (!t)
        return;
    vf__trainer_views_free(t);
    vf__field_adam_free(&t->adam);
    for (int i = 0; t->scratch && i < t->threads; i++)
        free(t->scratch[i].samples);
    free(t->scratch);
    free(t->appearance);
    free(t->appearance_grad);
    vf_field_free(t->field);
    free(t);
}

const vf_field_train_options *vf_field_trainer_options(const vf_field_trainer *t)
{
    return &t->opt;
}

const vf_field *vf_field_trainer_field(const vf_field_trainer *t)
{
    return t->field;
}

vf_field *vf_field_trainer_take_field(vf_field_trainer *t)
{
    vf_field *f = t->field;
    t->field = NULL;
    t->done = 1;
    return f;
}

/* (Re)size every thread's sample records for the current grids. */
static vf_status alloc_scratch(vf_field_trainer *t)
{
    if (!t->scratch && !(t->scratch = calloc((size_t)t->threads, sizeof *t->scratch)))
        return vf_fail(VF_EINTERNAL, "out of memory");
    int capacity = vf__field_max_samples(t->field);
    for (int i = 0; i < t->threads; i++) {
        free(t->scratch[i].samples);
        t->scratch[i].samples = malloc((size_t)capacity * sizeof(field_sample));
        t->scratch[i].capacity = capacity;
        if (!t->scratch[i].samples)
            return vf_fail(VF_EINTERNAL, "out of memory");
    }
    return VF_OK;
}

/* Everything that depends on the grid sizes: occupancy, optimizer state, scratch. */
static vf_status prepare_level(vf_field_trainer *t)
{
    vf_field *f = t->field;
    for (int i = 0; i < f->grid_count; i++)
        vf__field_grid_update_occupancy(&f->grids[i], f, f->step_ratio * f->grids[i].voxel);
    vf_status status = vf__field_adam_alloc(&t->adam, f, t->threads);
    if (status == VF_OK)
        status = alloc_scratch(t);
    return status;
}

vf_status vf_field_trainer_start(vf_field_trainer *t)
{
    if (t->started)
        return vf_fail(VF_EINTERNAL, "training already started");
    if (t->view_count == 0)
        return vf_fail(VF_EINPUT, "no training views");
    t->started = 1;
    t->start_time = vf_now();
    vf_status status = vf__trainer_build_grid(t);
    if (status == VF_OK)
        status = vf__trainer_build_pool(t);
    if (status == VF_OK)
        status = prepare_level(t);
    if (status == VF_OK)
        status = vf__trainer_alloc_appearance(t);
    return status;
}

vf_status vf_field_trainer_resume(vf_field_trainer *t, const char *path)
{
    if (t->started)
        return vf_fail(VF_EINTERNAL, "training already started");
    if (t->view_count == 0)
        return vf_fail(VF_EINPUT, "no training views");
    vf_status status = vf__trainer_checkpoint_read(t, path);
    if (status == VF_OK)
        status = vf__trainer_build_pool(t);
    if (status == VF_OK)
        status = alloc_scratch(t);
    if (status != VF_OK)
        return status;
    t->started = 1;
    t->start_time = vf_now();
    return VF_OK;
}

static double elapsed(const vf_field_trainer *t)
{
    return t->elapsed_before + (vf_now() - t->start_time);
}

static double budget_fraction(const vf_field_trainer *t)
{
    if (t->opt.seconds > 0)
        return elapsed(t) / t->opt.seconds;
    return (double)t->step / t->opt.steps;
}

/* The coarse-to-fine level for a budget fraction: evenly spaced up to upsample_end. */
static int level_at(const vf_field_trainer *t, double fraction)
{
    int last = t->opt.levels - 1;
    if (last == 0 || fraction >= t->opt.upsample_end)
        return last;
    int level = (int)(fraction / t->opt.upsample_end * last) + 0;
    return level > last ? last : level;
}

/* The occupancy threshold (opacity per step) at a budget fraction. Cells where no corner
 * reaches it are skipped by training and rendering; they get no gradient, so they stay
 * pruned. It starts at TRAIN_OCCUPANCY_ALPHA and, once the finest level is reached, rises
 * geometrically to prune_alpha at PRUNE_END of the budget. Without the rise, photos of a real
 * scene train into haze: faint density in every cell standing in for surfaces (the fox grid
 * kept 100% of its cells, ~280 samples a training ray); pruning the faint cells makes the
 * survivors become the surfaces. At 3 minutes, fox held-out PSNR 21.2 -> 21.7..22.05 dB (four
 * runs) with 54 samples a ray, chair test 34.28 -> 34.79 dB, lego 31.93 -> 32.64 dB; renders
 * 2-4x faster. Ending at 0.07 or 0.15 instead of 0.1: fox 22.05 and 21.08 dB. */
#define PRUNE_END 0.7
#define PRUNE_MIN_STEPS 1200 /* a short budget ramps no faster than over this many steps */
static float occupancy_alpha_at(const vf_field_trainer *t, double fraction)
{
    const double start = TRAIN_OCCUPANCY_ALPHA, end = t->opt.prune_alpha;
    if (!(end > start) || fraction <= t->opt.upsample_end)
        return (float)start;
    double x = (fraction - t->opt.upsample_end) / (PRUNE_END - t->opt.upsample_end);
    /* a field pruned before its surfaces formed loses them: the fox trained for one minute
     * (875 steps) kept 0.5% of its cells and reached 16.5 dB */
    x = fmin(x, (double)t->step / PRUNE_MIN_STEPS);
    return (float)(start * pow(end / start, x < 1 ? x : 1));
}

/* Go one level finer: resample every grid at 2^(1/3) times smaller spacing. */
static vf_status upsample(vf_field_trainer *t)
{
    vf_field *f = t->field;
    t->level++;
    double factor = pow(2.0, (t->opt.levels - 1 - t->level) / 3.0);
    for (int i = 0; i < f->grid_count; i++) {
        field_grid finer;
        /* the outer grid keeps its ratio to the inner one */
        float level_voxel = (float)(i == 0 ? t->final_voxel * factor
                                           : f->grids[i].voxel / pow(2.0, 1.0 / 3.0));
        vf_status status = vf__field_grid_resample(&f->grids[i], level_voxel, &finer);
        if (status != VF_OK)
            return status;
        vf__field_grid_free(&f->grids[i]);
        f->grids[i] = finer;
    }
    vf__field_adam_free(&t->adam);
    return prepare_level(t);
}

#define DEPTH_SHARE 8 /* one ray in this many of a batch sees a sparse point, when used */
#define DEPTH_END 0.5  /* share of the budget after which the depth loss stops */

/* Whether rays through sparse points get the depth loss now. It places the geometry while the
 * grid is coarse and stops halfway: sparse points sit on edges and corners, where a pixel sees
 * both sides, and pulling such rays to one distance to the end cost the training views their
 * sharpness. Measured at 4500 steps on the poses stage's captures (held-out PSNR, renders
 * named like the photos), without -> weight 10 over the first half: the fox (50 photos)
 * 25.71 -> 26.32 dB, 2 -> 4%, the steps 4.7 -> 2.7 minutes (8 samples a training ray, not
 * 13); the shoes video 29.90 -> 30.50 dB, 43 -> 56%; the wall clock (two seeds) 21.60 / 21.53
 * -> 22.27 / 22.36 dB, 54 / 38 -> 43 / 38%. On the clock, weight 10 to the end: 22.10 dB,
 * 30%; weight 1 to the end 21.78 dB, 43%; 0.1 to the end 21.74 dB, 35%. */
static int uses_depth(const vf_field_trainer *t)
{
    return t->opt.depth > 0 && t->depth_count > 0 && !t->has_alpha &&
           budget_fraction(t) < DEPTH_END;
}

/* A batch of about n training pixels: random tiles (drawn with replacement) expanded to their
 * pixels, then (with depth supervision) random pixels that see a sparse point; each ray's
 * random offset of its first sample and its point's distance (0: none). Returns the number of
 * rays. */
static int draw_batch(vf_field_trainer *t, uint32_t *pixels, float *jitter, float *depth, int n)
{
    int count = 0;
    const int depth_rays = uses_depth(t) ? n / DEPTH_SHARE : 0;
    memset(depth, 0, (size_t)n * sizeof *depth);
    while (count + TRAIN_TILE * TRAIN_TILE <= n - depth_rays) {
        uint32_t corner = t->pool[vf_rng_below(&t->rng, t->pool_size)];
        const train_view *v = &t->views[vf__trainer_pixel_view(t, corner)];
        const int w = v->camera.width, h = v->camera.height;
        size_t local = corner - v->first_pixel;
        int x0 = (int)(local % (size_t)w), y0 = (int)(local / (size_t)w);
        for (int y = y0; y < y0 + TRAIN_TILE && y < h; y++)
            for (int x = x0; x < x0 + TRAIN_TILE && x < w; x++) {
                pixels[count] = (uint32_t)(v->first_pixel + (size_t)y * w + x);
                jitter[count++] = (float)vf_rng_uniform(&t->rng);
            }
    }
    for (int i = 0; i < depth_rays; i++) {
        const depth_ray *d = &t->depth_rays[vf_rng_below(&t->rng, t->depth_count)];
        pixels[count] = d->pixel;
        depth[count] = d->distance;
        jitter[count++] = (float)vf_rng_uniform(&t->rng);
    }
    return count;
}

#define DISTORTION_START 0.7 /* share of the budget before the distortion loss starts */

/* Forward and backward over a batch; returns the summed squared error. */
static double run_batch(vf_field_trainer *t, const uint32_t *pixels, const float *jitter,
                        const float *depth, int n, long *samples)
{
    long total = 0;
    const vf_field *f = t->field;
    /* d(squared error summed over the batch)/d(colour): Adam does not care about the scale,
     * and per-ray sums keep the gradients well above its epsilon */
    const float loss_scale = 2.0f / 3.0f;
    /* Rays of opaque photos end on a surface: an unconstrained field of a room learns faint
     * haze over the white background instead. The fox at 3 minutes: 20.85 and 21.08 dB
     * held-out with a weight of 0.1, 20.09 and 19.85 dB without (its rays also end sooner:
     * 1.7-2x the steps); 0.3 gave 21.68 dB with the whole-view box, but with the 0.6 box
     * (carve.c) 21.90 dB against 23.05-23.13 dB at 0.1. */
    /* The distortion loss waits until the finest grid has its geometry. 4500 steps, held-out
     * PSNR, 224 render (A/B in one process), renders named like the photos, without it and
     * at 0.01 from 70% of the budget, before the depth loss: the fox 25.47 / 25.57 dB, 27-32 /
     * 22-23 ms, 6 / 6%; the shoes video 29.90 / 29.67 dB, -10%, 43 / 48%; the wall clock
     * 21.60 / 22.06 dB, 35-40 / 30-34 ms, 54 / 35%. The fox at 0.01 from the start: 24.16 dB
     * (training rays 26.17 against 26.76), 15-20 ms; 0.003 from the start 25.23 dB, 21-22 ms;
     * 0.03 from 70% 25.54 dB, 21-23 ms; 0.1 from the start emptied the field (13.7 dB).
     * With the depth loss (our COLMAP poses, 0.6 box), without it and at 0.01 from 70%: the
     * fox 26.32 / 26.31 dB, 4 / 2%, 17.3-17.8 / 16.4-17.0 ms; the shoes 30.50 / 30.48 dB,
     * 56 / 56%, 16.7-18.1 / 15.5-17.2 ms; the clock (seeds 1, 2) 22.27, 22.36 / 22.16, 22.18
     * dB, 43, 38 / 49, 41%, 26.1-30.7 / 22.7-24.4 ms; the apple 17.35 / 17.27 dB, 11 / 5% (2
     * / 1 of 19 photos), 21.6-26.9 / 20.6-24.6 ms. With the depth loss the clock no longer
     * loses agreement, and every capture renders faster: on. */
    const int late = !t->has_alpha && budget_fraction(t) >= DISTORTION_START;
    const field_ray_losses losses = {.opaque = t->has_alpha ? 0.0f : t->opt.opaque,
                                     .distortion = late ? t->opt.distortion : 0.0f};
    const float inv_distance = 1.0f / (float)f->camera_distance;
    double sse = 0;
#pragma omp parallel for num_threads(t->threads) schedule(dynamic, TRAIN_TILE * TRAIN_TILE) reduction(+ : sse, total)
    for (int i = 0; i < n; i++) {
        const int me = omp_get_thread_num();
        field_ray ray;
        float target[3];
        field_march_result res;
        vf__trainer_pixel_ray(t, pixels[i], &ray, target);
        vf__field_march(f, &ray, jitter[i], 1e-4f, &t->scratch[me], &res);
        /* the photo sees (1 + gain) * c + offset, gain and offset 0 without its appearance */
        const float *a = NULL;
        double *grad = NULL;
        if (t->appearance) {
            const int v = vf__trainer_pixel_view(t, pixels[i]);
            a = t->appearance + 6 * (size_t)v;
            grad = t->appearance_grad + 6 * ((size_t)me * t->view_count + v);
        }
        float dl[3];
        for (int k = 0; k < 3; k++) {
            const float gain = a ? 1 + a[k] : 1.0f, offset = a ? a[3 + k] : 0.0f;
            const float err = gain * res.rgb[k] + offset - target[k];
            sse += (double)err * err;
            dl[k] = loss_scale * err * gain;
            if (grad) {
                grad[k] += loss_scale * err * res.rgb[k];
                grad[3 + k] += loss_scale * err;
            }
        }
        field_ray_losses ray_losses = losses;
        if (depth[i] > 0) {
            ray_losses.depth = t->opt.depth;
            ray_losses.depth_target = depth[i] * inv_distance;
        }
        if (res.count)
            vf__field_backward(f, &ray, &t->scratch[me], &res, dl, ray_losses, &t->adam.sinks[me]);
        total += res.count;
    }
    *samples = total;
    return sse;
}

static void fill_status(const vf_field_trainer *t, vf_field_train_status *s)
{
    memset(s, 0, sizeof *s);
    s->step = t->step;
    s->fraction = fmin(budget_fraction(t), 1.0);
    s->elapsed = elapsed(t);
    if (t->opt.seconds > 0)
        s->seconds_left = fmax(0.0, t->opt.seconds - s->elapsed);
    else
        s->seconds_left = t->step > 0 ? s->elapsed / t->step * (t->opt.steps - t->step) : 0;
    s->loss = t->loss_avg;
    s->psnr = t->loss_avg > 0 ? -10.0 * log10(t->loss_avg) : 0;
    s->level = t->level;
    s->samples_per_ray = t->last_samples_per_ray;
    s->step_ms = t->last_step_ms;
    s->optimizer_ms = t->last_optimizer_ms;
    s->touched_points = t->last_touched;
    if (t->field) {
        const field_grid *g = &t->field->grids[0];
        s->occupied = (double)vf__field_grid_occupied_cells(g) /
                      ((double)g->cells[0] * g->cells[1] * g->cells[2]);
    }
    s->done = t->done;
}

vf_status vf_field_trainer_step(vf_field_trainer *t, vf_field_train_status *status)
{
    if (!t->started || !t->field)
        return vf_fail(VF_EINTERNAL, "training has not started");
    double fraction = budget_fraction(t);
    if (t->done || fraction >= 1.0) {
        t->done = 1;
        fill_status(t, status);
        return VF_OK;
    }
    vf_status st = VF_OK;
    while (st == VF_OK && t->level < level_at(t, fraction))
        st = upsample(t);
    if (st != VF_OK)
        return st;
    vf_field *f = t->field;
    if (t->step % OCCUPANCY_EVERY == 0 && t->step > 0) {
        f->occupancy_alpha = occupancy_alpha_at(t, fraction);
        for (int i = 0; i < f->grid_count; i++)
            vf__field_grid_update_occupancy(&f->grids[i], f, f->step_ratio * f->grids[i].voxel);
    }

    const int n = t->opt.batch_rays;
    uint32_t *pixels = malloc((size_t)n * sizeof *pixels);
    float *jitter = malloc((size_t)n * sizeof *jitter), *depth = malloc((size_t)n * sizeof *depth);
    if (!pixels || !jitter || !depth) {
        free(pixels);
        free(jitter);
        free(depth);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
    double t0 = vf_now();
    int rays = draw_batch(t, pixels, jitter, depth, n);
    long samples = 0;
    double mse = run_batch(t, pixels, jitter, depth, rays, &samples) / (3.0 * rays);
    double t1 = vf_now();
    free(pixels);
    free(jitter);
    free(depth);

    /* learning rates decay exponentially to a tenth over the budget */
    float decay = (float)pow(0.1, fraction);
    float lr[FIELD_CH] = {0};
    lr[FIELD_CH_DENSITY] = t->opt.lr_density * decay;
    /* a diffuse field never moves its degree-1 terms off zero (basis b = 0 is the constant) */
    const int diffuse = t->opt.color == VF_COLOR_DIFFUSE;
    for (int ch = FIELD_CH_SH; ch < FIELD_CH_USED; ch++)
        lr[ch] = diffuse && (ch - FIELD_CH_SH) % 4 ? 0.0f : t->opt.lr_color * decay;
    t->last_touched = (double)vf__field_adam_touched(&t->adam);
    vf__field_adam_step(&t->adam, f, lr, t->opt.tv_density, t->opt.tv_color, t->opt.tv_view);
    if (t->appearance)
        vf__trainer_appearance_step(t, t->opt.appearance * decay);
    t->last_samples_per_ray = (double)samples / rays;
    t->last_step_ms = (t1 - t0) * 1000;
    t->last_optimizer_ms = (vf_now() - t1) * 1000;

    t->step++;
    /* running mean over about the last 50 steps */
    t->loss_count = t->loss_count < 50 ? t->loss_count + 1 : 50;
    t->loss_avg += (mse - t->loss_avg) / t->loss_count;
    if (budget_fraction(t) >= 1.0)
        t->done = 1;
    fill_status(t, status);
    return VF_OK;
}
