/* Where the object is: the scene box the cameras look at, the visual hull carved from alpha
 * masks, the coarse starting grid, and the pixels worth training on. */
#include <stdlib.h>
#include <string.h>

#include "trainer_internal.h"
#include "vf/log.h"

#define POINTS_REACH_MARGIN 1.1 /* the outer grid's half-size over the sparse points' reach */

void vf__trainer_scene_center(const vf_field_trainer *t, double center[3], double *distance)
{
    /* The point nearest to every optical axis: sum_i (I - d_i d_i^T) (p - o_i) = 0. */
    double a[3][3] = {{0}}, b[3] = {0};
    for (int i = 0; i < t->view_count; i++) {
        const double *m = t->views[i].c2w;
        double o[3] = {m[3], m[7], m[11]}, d[3] = {-m[2], -m[6], -m[10]};
        double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        for (int r = 0; r < 3; r++)
            d[r] /= n;
        for (int r = 0; r < 3; r++)
            for (int c = 0; c < 3; c++) {
                double p = (r == c) - d[r] * d[c];
                a[r][c] += p;
                b[r] += p * o[c];
            }
    }
    double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                 a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                 a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    if (fabs(det) > 1e-6 * t->view_count * t->view_count * t->view_count) {
        for (int k = 0; k < 3; k++) { /* Cramer's rule */
            double m[3][3];
            memcpy(m, a, sizeof m);
            for (int r = 0; r < 3; r++)
                m[r][k] = b[r];
            center[k] = (m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
                         m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
                         m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0])) /
                        det;
        }
    } else { /* all axes parallel (one view, or a forward-facing rig): the world origin */
        center[0] = center[1] = center[2] = 0;
    }
    double sum = 0;
    for (int i = 0; i < t->view_count; i++) {
        const double *m = t->views[i].c2w;
        double dx = m[3] - center[0], dy = m[7] - center[1], dz = m[11] - center[2];
        sum += sqrt(dx * dx + dy * dy + dz * dz);
    }
    *distance = t->view_count ? sum / t->view_count : 1.0;
    if (!(*distance > 0))
        *distance = 1.0;
}

/* Pixel coordinates of world point p in view v and its depth; 0 when behind the camera. */
static int project(const train_view *v, const double p[3], double *u, double *y, double *depth)
{
    const double *m = v->c2w;
    double d[3] = {p[0] - m[3], p[1] - m[7], p[2] - m[11]};
    /* camera coordinates, OpenGL axes: the transpose of the rotation */
    double xc = m[0] * d[0] + m[4] * d[1] + m[8] * d[2];
    double yc = m[1] * d[0] + m[5] * d[1] + m[9] * d[2];
    double zc = m[2] * d[0] + m[6] * d[1] + m[10] * d[2];
    *depth = -zc;
    if (*depth <= 1e-6)
        return 0;
    if (vf_camera_has_distortion(&v->camera)) {
        double p_cv[3] = {xc, -yc, -zc};
        return vf_camera_project(&v->camera, p_cv, u, y);
    }
    *u = v->camera.cx + v->camera.fx * xc / *depth;
    *y = v->camera.cy - v->camera.fy * yc / *depth;
    return 1;
}

/* `mask` grown by `radius` pixels (square max filter as two 1-D passes); malloc'd. */
static uint8_t *dilate(const uint8_t *mask, int w, int h, int radius)
{
    uint8_t *tmp = calloc((size_t)w * h, 1), *out = calloc((size_t)w * h, 1);
    if (!tmp || !out) {
        free(tmp);
        free(out);
        return NULL;
    }
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            if (mask[(size_t)y * w + x])
                for (int dx = x - radius < 0 ? -x : -radius; dx <= radius && x + dx < w; dx++)
                    tmp[(size_t)y * w + x + dx] = 1;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            if (tmp[(size_t)y * w + x])
                for (int dy = y - radius < 0 ? -y : -radius; dy <= radius && y + dy < h; dy++)
                    out[(size_t)(y + dy) * w + x] = 1;
    free(tmp);
    return out;
}

/* The masked views' masks dilated so that a point `spacing` from a silhouette survives:
 * radius = the projected half-diagonal of a cell at the nearest depth, plus a pixel. */
static uint8_t **dilated_masks(const vf_field_trainer *t, double spacing, double near_depth)
{
    uint8_t **masks = calloc((size_t)t->view_count, sizeof *masks);
    if (!masks)
        return NULL;
    int failed = 0;
#pragma omp parallel for schedule(dynamic) reduction(| : failed)
    for (int i = 0; i < t->view_count; i++) {
        const train_view *v = &t->views[i];
        if (!v->mask)
            continue;
        int radius = (int)ceil(0.87 * spacing * fmax(v->camera.fx, v->camera.fy) / near_depth) + 1;
        masks[i] = dilate(v->mask, v->camera.width, v->camera.height, radius);
        failed |= masks[i] == NULL;
    }
    if (failed) {
        for (int i = 0; i < t->view_count; i++)
            free(masks[i]);
        free(masks);
        return NULL;
    }
    return masks;
}

static void free_masks(const vf_field_trainer *t, uint8_t **masks)
{
    for (int i = 0; masks && i < t->view_count; i++)
        free(masks[i]);
    free(masks);
}

/* Whether world point p is outside the visual hull: masked views see it on a (dilated)
 * transparent pixel (one is enough for exact masks; opt.carve_share of the views that see it
 * for masks that may err), or no view sees it at all (nothing was filmed there: a capture that
 * covers only an arc would otherwise keep every corner of the box, and the field would fill
 * them with fog). */
static int carved(const vf_field_trainer *t, uint8_t *const *masks, const double p[3])
{
    int seen = 0, transparent = 0;
    for (int i = 0; i < t->view_count; i++) {
        const train_view *v = &t->views[i];
        double u, y, depth;
        if (!project(v, p, &u, &y, &depth) || u < 0 || y < 0 || u >= v->camera.width ||
            y >= v->camera.height)
            continue;
        seen++;
        if (masks[i] && !masks[i][(size_t)y * v->camera.width + (size_t)u]) {
            if (!(t->opt.carve_share > 0))
                return 1;
            transparent++;
        }
    }
    return !seen || (transparent > 0 && transparent >= t->opt.carve_share * seen);
}

/* Carve a lattice of n^3 points over [lo, hi]; shrink [lo, hi] to the bounding box of what
 * survives (plus a margin). Returns the number of surviving points. */
static size_t shrink_box(const vf_field_trainer *t, double lo[3], double hi[3], int n,
                         double near_depth)
{
    double spacing = (hi[0] - lo[0]) / (n - 1);
    uint8_t **masks = dilated_masks(t, spacing, near_depth);
    if (!masks)
        return 0;
    double bmin[3] = {1e30, 1e30, 1e30}, bmax[3] = {-1e30, -1e30, -1e30};
    size_t kept = 0;
#pragma omp parallel for schedule(dynamic) reduction(min : bmin[:3]) reduction(max : bmax[:3]) \
    reduction(+ : kept)
    for (int z = 0; z < n; z++)
        for (int y = 0; y < n; y++)
            for (int x = 0; x < n; x++) {
                double p[3] = {lo[0] + x * (hi[0] - lo[0]) / (n - 1),
                               lo[1] + y * (hi[1] - lo[1]) / (n - 1),
                               lo[2] + z * (hi[2] - lo[2]) / (n - 1)};
                if (carved(t, masks, p))
                    continue;
                kept++;
                for (int a = 0; a < 3; a++) {
                    bmin[a] = fmin(bmin[a], p[a]);
                    bmax[a] = fmax(bmax[a], p[a]);
                }
            }
    free_masks(t, masks);
    if (kept)
        for (int a = 0; a < 3; a++) {
            lo[a] = fmax(lo[a], bmin[a] - 1.5 * spacing);
            hi[a] = fmin(hi[a], bmax[a] + 1.5 * spacing);
        }
    return kept;
}

/* Set the density of carved points of grid g to "empty". */
static vf_status carve_grid(const vf_field_trainer *t, field_grid *g, double near_depth)
{
    uint8_t **masks = dilated_masks(t, g->voxel, near_depth);
    if (!masks)
        return vf_fail(VF_EINTERNAL, "out of memory");
#pragma omp parallel for schedule(dynamic)
    for (int z = 0; z < g->dim[2]; z++)
        for (int y = 0; y < g->dim[1]; y++)
            for (int x = 0; x < g->dim[0]; x++) {
                double p[3] = {g->lo[0] + x * g->voxel, g->lo[1] + y * g->voxel,
                               g->lo[2] + z * g->voxel};
                if (carved(t, masks, p)) {
                    size_t i = (size_t)x + (size_t)g->dim[0] * ((size_t)y + (size_t)g->dim[1] * z);
                    g->values[i * FIELD_CH + FIELD_CH_DENSITY] = FIELD_EMPTY_DENSITY;
                }
            }
    free_masks(t, masks);
    return VF_OK;
}

/* A grid over [lo, hi] with the given spacing. */
static vf_status grid_over(field_grid *g, const double lo[3], const double hi[3], double voxel)
{
    int dim[3];
    float lo_f[3];
    for (int a = 0; a < 3; a++) {
        dim[a] = (int)ceil((hi[a] - lo[a]) / voxel - 1e-6) + 1;
        dim[a] = dim[a] < 2 ? 2 : dim[a];
        /* centre the lattice on the box */
        lo_f[a] = (float)(0.5 * (lo[a] + hi[a]) - 0.5 * (dim[a] - 1) * voxel);
    }
    return vf__field_grid_alloc(g, dim, lo_f, (float)voxel);
}

/* Fill in the options left automatic (vf/field.h), once it is known whether an outer grid
 * models the surroundings. They are kept in the options, so a checkpoint keeps them too.
 *
 * Opaque photos with surroundings are few views of a lot of detail. Alone, a finer grid or
 * more steps only fit the training views better and the held-out ones worse (the fox, 2.1M
 * points, 3000 steps: 23.5 dB held-out; 8.4M points: 21.2; 12000 steps: 22.6). A smoother
 * colour and a longer coarse-to-fine ramp make them generalise, and then the finer grid pays:
 * the fox in 3 minutes, held-out PSNR 23.69 dB (2.1M points, 3 levels, no smoothing) ->
 * 24.32 (tv_color 1e-4) -> 25.06 (and 4M points, 5 levels) -> 25.46 (6M points, 6 levels).
 * At 5500 steps: tv_color 1e-4 24.29 dB, with 4 / 5 / 7 levels 24.66 / 24.69 / 24.42; at
 * 3000 steps tv_color 3e-5 / 1e-4 / 3e-4 / 1e-3: 23.97 / 23.99 / 23.72 / 23.02 dB; total
 * variation on the density hurt (1e-3: 22.08 dB). With the depth and distortion losses, 4500
 * steps, tv_color 1e-4 -> 3e-5 (held-out PSNR, renders named like the photos): the fox 26.46
 * -> 26.66 dB, 16 -> 20%; the shoes 30.26 -> 30.72, 62 -> 51%; the clock 23.56 -> 23.58, 40
 * -> 40%; the apple 23.13 -> 23.00, 16 -> 21%: kept at 1e-4 (0 on the fox: 26.68 dB, 12%).
 * Photos with alpha (clean renders, cut-outs) keep the sharpest fit: 2.1M points, 3 levels,
 * no smoothing. */
void vf__field_resolve_automatic(vf_field_train_options *o, int outer)
{
    /* The 6M points need about 4500 steps (3 minutes on 2 cores) to pay; a shorter budget
     * gets proportionally fewer, 2M at least. At 1 minute, 6M -> 2M points: the fox 21.26 ->
     * 23.02 dB held-out (796 -> 1534 steps), the shoes video 25.29 -> 26.90 dB, the render
     * named like the photo 0 -> 6% and 1 -> 18%. */
    const double budget = o->seconds > 0 ? o->seconds / 180.0 : o->steps / 4500.0;
    if (o->max_points == 0)
        o->max_points = outer ? 6e6 * fmin(fmax(budget, 1.0 / 3), 1) : 128.0 * 128.0 * 128.0;
    if (o->levels == 0)
        o->levels = outer ? 6 : 3;
    if (o->tv_color < 0)
        o->tv_color = outer ? 1e-4f : 0.0f;
}

/* The spacing of level `level` when the finest spacing is `finest` (2x the points a level). */
static double level_voxel(const vf_field_trainer *t, double finest, int level)
{
    return finest * pow(2.0, (t->opt.levels - 1 - level) / 3.0);
}

vf_status vf__trainer_build_grid(vf_field_trainer *t)
{
    double center[3], distance;
    vf__trainer_scene_center(t, center, &distance);
    const vf_camera *cam = &t->views[0].camera;
    double tan_half = fmin(0.5 * cam->width / cam->fx, 0.5 * cam->height / cam->fy);
    /* Opaque photos with sparse points: the boxes go round what lies at the middle of the
     * photos, not where the optical axes meet, which a capture from one side puts near the
     * wall or the desk (the fox: its face and snout 1.2 to 1.9 units in front of that point,
     * out of the object box and in the coarse outer grid). Their size stays the view's at the
     * cameras' distance. 4500 steps, held-out PSNR and renders named like the photos: the fox
     * 26.46 -> 27.18 dB, 16 -> 48%; the shoes 30.26 -> 30.27 dB, 62 -> 55%; the wall clock
     * 23.56 -> 23.13 dB, 40 -> 50%; the apple 23.13 -> 22.99 dB, 16 -> 26%. The median
     * leans to the most textured part: the clock's face, its base left below the box to the
     * outer grid, blurred. Centred between the 5% and 95% quantiles instead (3 minutes,
     * seeds 1, 2): its base sharp, its crest now cut; 22.27 / 22.44 -> 22.33 / 22.36 dB,
     * named like the photos 51 / 54 -> 54 / 54%; with a 1.0 box, all of it inside: 22.01 /
     * 22.01 dB, 54 / 51%. Its glass, rendered as dark speckle, is what the classifier reads
     * as a barometer or a switch, not its edges: kept the median. */
    if (!t->has_alpha && t->opt.surroundings != VF_SURROUNDINGS_NONE &&
        vf__trainer_points_center(t, 0.25 * tan_half, center))
        vf_info("object box centred on the sparse points at the photos' middles: (%.2f, %.2f, "
                "%.2f)", center[0], center[1], center[2]);
    /* Opaque photos with an outer grid: a box over 80% of the view, whose finer voxels go to
     * the object while the outer grid takes the room. The fox at 3 minutes: 23.05 dB held-out
     * with a 0.6 box against 20.85 dB with the box over the whole view; a 0.45 box gave 20.43
     * dB (measured with 2M grid points, 3 levels and no colour smoothing, no sparse points).
     * With the depth and distortion losses, 4500 steps, 0.6 -> 0.8: the fox 26.31 -> 26.46
     * dB, renders named like the photos 2 -> 16%; the shoes 30.48 -> 30.26 dB, 56 -> 62%; the
     * wall clock (seeds 1, 2) 22.16 / 22.18 -> 22.67 / 22.75 dB, 49 / 41 -> 49 / 54% (at 0.6
     * the box cut off its crest and its base, left to the coarse outer grid); the apple
     * 17.27 -> 17.52 dB, 5 -> 37%. */
    const vf_field_surroundings around = t->opt.surroundings;
    const int outer = !t->has_alpha && around != VF_SURROUNDINGS_NONE;
    vf__field_resolve_automatic(&t->opt, outer);
    double box_scale = t->opt.box_scale > 0 ? t->opt.box_scale
                       : t->has_alpha       ? 1.2
                       : outer              ? 0.8
                                            : 1.0;
    double view_half = distance * tan_half, half = box_scale * view_half;
    double lo[3], hi[3];
    for (int a = 0; a < 3; a++) {
        lo[a] = center[a] - half;
        hi[a] = center[a] + half;
    }
    double near_depth = fmax(distance - half * sqrt(3.0), 0.05 * distance);

    vf_field *f = calloc(1, sizeof *f);
    if (!f)
        return vf_fail(VF_EINTERNAL, "out of memory");
    t->field = f;
    f->camera = *cam;
    memcpy(f->scene_center, center, sizeof f->scene_center);
    f->camera_distance = distance;
    memcpy(f->background, t->opt.background, sizeof f->background);
    /* a sample a voxel, not two, in an opaque capture: half the samples for the same fit (the
     * fox at 3 minutes: 23.44 and 22.97 dB held-out, against 23.05, 23.10 and 23.13 dB) */
    f->step_ratio = t->opt.step_ratio > 0 ? t->opt.step_ratio : outer ? 1.0f : 0.5f;
    f->occupancy_alpha = (float)TRAIN_OCCUPANCY_ALPHA;
    /* Renders end a ray once 99% of it is covered (the chair's test PSNR 34.12 dB, 34.11 at
     * 99.9%, a 224 render a tenth faster), or 95% with a room around the object: what
     * is left of a ray then lies behind a surface, and renormalizing it over the opacity met
     * (render_march.c) costs little. On the four captures' 4500-step fields, 224 views at
     * every photo's pose in one process alternating, 99% (the rest white) -> 95%: 6-11%
     * faster a view, 11-14% in batches (fox 20.6 -> 18.6 ms, shoes 22.3 -> 19.9, clock 25.6 ->
     * 23.1, apple 32.1 -> 30.0), renders 49-54 dB from ones marched to 1e-4 (51-56 dB before),
     * held-out PSNR within 0.04 dB, named like the photos 98 of 199 times (97 before); 90%:
     * another 5% faster, 43-46 dB, 94 of 199. On white, the chair's thin edges let the white
     * through: its test PSNR 34.22 dB at 99%, 34.19 at 98%, 34.15 at 97%, 34.03 at 95%. */
    f->stop_transmittance = outer ? 5e-2f : 1e-2f;

    if (t->has_alpha) {
        size_t kept = shrink_box(t, lo, hi, 96, near_depth);
        if (!kept)
            return vf_fail(VF_EINPUT, "the alpha masks leave nothing of the object: are the "
                                      "poses right?");
        vf_info("visual hull: box %.2f x %.2f x %.2f around (%.2f, %.2f, %.2f)", hi[0] - lo[0],
                hi[1] - lo[1], hi[2] - lo[2], 0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]),
                0.5 * (lo[2] + hi[2]));
    }
    double volume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    t->final_voxel = (float)cbrt(volume / t->opt.max_points);
    double voxel0 = level_voxel(t, t->final_voxel, 0);
    vf_status status = grid_over(&f->grids[0], lo, hi, voxel0);
    if (status != VF_OK)
        return status;
    f->grid_count = 1;

    /* density: sigma = softplus(d + shift) / final_voxel, shifted so that d = 0 gives a faint
     * TRAIN_ALPHA_INIT per step at the coarsest level */
    f->density_scale = 1.0f / t->final_voxel;
    double softplus_shift =
        -log(1.0 - TRAIN_ALPHA_INIT) / (f->density_scale * f->step_ratio * voxel0);
    f->density_shift = (float)log(expm1(softplus_shift));

    if (t->has_alpha && (status = carve_grid(t, &f->grids[0], near_depth)) != VF_OK)
        return status;
    vf__field_values_changed(f);

    if (outer) {
        /* a coarse outer grid for what lies around the object box: without it an opaque
         * capture's room is fitted inside the box, as haze (the fox: 21.4 dB held-out) */
        double outer_half = fmax(t->opt.background_scale * view_half, 1.5 * half), olo[3], ohi[3];
        /* ...and out to the room structure from motion saw, past 98% of the sparse points'
         * sightings (at most 4x as far): rays that leave the outer grid see the background
         * colour, so a room beyond it trains into white holes. The apple of CO3D, its floor
         * and chairs 10-12 units out against the default 4.5: held-out 17.27 -> 23.11 dB at
         * an outer half-size of 11.1 (4500 steps). */
        const double room = fmin(POINTS_REACH_MARGIN * vf__trainer_points_reach(t, center, 0.98),
                                 4.0 * t->opt.background_scale * view_half);
        if (room > outer_half) {
            vf_info("outer grid: half-size %.1f, out to the room the sparse points show (%.1f "
                    "without them)", room, outer_half);
            outer_half = room;
        }
        for (int a = 0; a < 3; a++) {
            olo[a] = center[a] - outer_half;
            ohi[a] = center[a] + outer_half;
        }
        double outer_voxel = level_voxel(t, 2.0 * outer_half / cbrt(t->opt.max_points / 2), 0);
        if ((status = grid_over(&f->grids[1], olo, ohi, outer_voxel)) != VF_OK)
            return status;
        f->grid_count = 2;
    }
    for (int i = 0; i < f->grid_count; i++)
        vf__field_grid_update_occupancy(&f->grids[i], f, f->step_ratio * f->grids[i].voxel);
    return VF_OK;
}

/* Mark in `hit` (one byte a pixel of view v) every pixel a cell of g that may hold density
 * projects to (conservatively: a square around the cell centre). */
static void splat_cells(const train_view *v, const field_grid *g, uint8_t *hit)
{
    const int w = v->camera.width, h = v->camera.height;
    const double f = fmax(v->camera.fx, v->camera.fy);
    for (int z = 0; z < g->cells[2]; z++)
        for (int y = 0; y < g->cells[1]; y++)
            for (int x = 0; x < g->cells[0]; x++) {
                size_t c = (size_t)x + (size_t)g->cells[0] * ((size_t)y + (size_t)g->cells[1] * z);
                if (!field_cell_occupied(g, c))
                    continue;
                double p[3] = {g->lo[0] + (x + 0.5) * g->voxel, g->lo[1] + (y + 0.5) * g->voxel,
                               g->lo[2] + (z + 0.5) * g->voxel};
                double u, yy, depth;
                if (!project(v, p, &u, &yy, &depth)) {
                    memset(hit, 1, (size_t)w * h); /* a cell behind the camera: keep all */
                    return;
                }
                int r = (int)ceil(0.87 * g->voxel * f / depth) + 2;
                int x0 = (int)floor(u) - r, x1 = (int)floor(u) + r;
                int y0 = (int)floor(yy) - r, y1 = (int)floor(yy) + r;
                x0 = x0 < 0 ? 0 : x0;
                y0 = y0 < 0 ? 0 : y0;
                x1 = x1 >= w ? w - 1 : x1;
                y1 = y1 >= h ? h - 1 : y1;
                for (int py = y0; py <= y1; py++)
                    if (x0 <= x1)
                        memset(hit + (size_t)py * w + x0, 1, (size_t)(x1 - x0 + 1));
            }
}

/* Append to the pool the tiles of view v that hold a useful pixel (useful == NULL: all). */
static void add_tiles(vf_field_trainer *t, const train_view *v, const uint8_t *useful, size_t *n)
{
    const int w = v->camera.width, h = v->camera.height;
    for (int ty = 0; ty < h; ty += TRAIN_TILE)
        for (int tx = 0; tx < w; tx += TRAIN_TILE) {
            int any = useful == NULL;
            for (int y = ty; !any && y < ty + TRAIN_TILE && y < h; y++)
                for (int x = tx; !any && x < tx + TRAIN_TILE && x < w; x++)
                    any = useful[(size_t)y * w + x];
            if (any) {
                if (t->pool)
                    t->pool[*n] = (uint32_t)(v->first_pixel + (size_t)ty * w + tx);
                (*n)++;
            }
        }
}

vf_status vf__trainer_build_pool(vf_field_trainer *t)
{
    free(t->pool);
    t->pool = NULL;
    uint8_t *useful = NULL;
    if (t->has_alpha) {
        if (!(useful = calloc(t->pixels, 1)))
            return vf_fail(VF_EINTERNAL, "out of memory");
#pragma omp parallel for schedule(dynamic)
        for (int i = 0; i < t->view_count; i++) {
            const train_view *v = &t->views[i];
            uint8_t *hit = useful + v->first_pixel;
            if (!v->mask)
                memset(hit, 1, (size_t)v->camera.width * v->camera.height);
            else
                splat_cells(v, &t->field->grids[0], hit);
        }
    }
    /* count, then fill */
    size_t n = 0, pixels = 0;
    for (int i = 0; i < t->view_count; i++)
        add_tiles(t, &t->views[i], useful ? useful + t->views[i].first_pixel : NULL, &n);
    if (!(t->pool = malloc((n ? n : 1) * sizeof *t->pool))) {
        free(useful);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
    t->pool_size = n;
    n = 0;
    for (int i = 0; i < t->view_count; i++)
        add_tiles(t, &t->views[i], useful ? useful + t->views[i].first_pixel : NULL, &n);
    for (size_t p = 0; useful && p < t->pixels; p++)
        pixels += useful[p];
    free(useful);
    if (t->has_alpha)
        vf_info("training on the %zu of %zu pixels whose rays can meet the object", pixels,
                t->pixels);
    return n ? VF_OK : vf_fail(VF_EINPUT, "no pixel sees the object");
}
