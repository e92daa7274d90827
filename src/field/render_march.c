/* The rendering ray marcher: field_march's forward pass, lean.
 *
 * It visits the same lattice of samples as field_march (t_k = t_start + (k + jitter) * step
 * from the grid box entry), so renders agree with what training optimized, but:
 *   - the ray is clipped to the box of occupied cells and starts at the first lattice point
 *     inside it;
 *   - empty space is jumped: a sample in an empty cell moves the march as far as the cell's
 *     empty-space radius allows (empty_space.c);
 *   - a sample blends all 16 floats of its 8 corner points as 16-lane vectors (one cache line
 *     each), added as a tree, not as one long chain of dependent additions;
 *   - samples under FIELD_VISIBLE_ALPHA are skipped by a raw-density threshold;
 *   - opacity comes from a table of raw density, and the colour's three sigmoids are one
 *     four-lane vector operation (fast_math.h). */

#include <string.h>

#include "fast_math.h"
#include "field_internal.h"

/* alpha(d) = 1 - exp(-softplus(d + shift) * scale * step) on [visible_density, d_opaque],
 * where d_opaque makes alpha 1 in float: a table lookup with linear interpolation replaces an
 * exp, a log and an exp per sample (test_field bounds the table's error). */
static void tabulate_alpha(const vf_field *f, field_render_grid *r)
{
    const double opaque_sigma = 17.0 / r->scale_step; /* exp(-17) < 2^-24 */
    const double d_opaque = (opaque_sigma > 20 ? opaque_sigma : log(expm1(opaque_sigma))) -
                            f->density_shift;
    r->alpha_per_density = (float)(FIELD_ALPHA_TABLE / (d_opaque - r->visible_density));
    for (int i = 0; i <= FIELD_ALPHA_TABLE; i++) {
        double x = r->visible_density + i / (double)r->alpha_per_density + f->density_shift;
        double softplus = x > 30 ? x : log1p(exp(x));
        r->alpha[i] = (float)-expm1(-softplus * r->scale_step);
    }
}

void field_render_setup_init(const vf_field *f, field_render_setup *setup)
{
    memset(setup, 0, sizeof *setup);
    for (int i = 0; i < f->grid_count; i++) {
        const field_grid *g = &f->grids[i];
        field_render_grid *r = &setup->grids[i];
        r->step = f->step_ratio * g->voxel;
        r->scale_step = f->density_scale * r->step;
        r->inv_voxel = 1.0f / g->voxel;
        r->visible_density = field_density_threshold(f, FIELD_VISIBLE_ALPHA, r->step);
        tabulate_alpha(f, r);
        r->empty = 0;
        for (int a = 0; a < 3; a++) {
            r->empty |= g->occ_lo[a] >= g->occ_hi[a];
            r->occ_lo[a] = g->lo[a] + (float)g->occ_lo[a] * g->voxel;
            r->occ_hi[a] = g->lo[a] + (float)g->occ_hi[a] * g->voxel;
        }
    }
}

typedef struct render_state {
    float trans;
    fast_f4 rgb; /* lanes 0..2 */
    float depth;
    int count;
} render_state;

/* One grid point: density, the 12 SH logits and padding, a 64-byte cache line. */
typedef float point_f16 __attribute__((vector_size(FIELD_CH * sizeof(float))));

static inline point_f16 load_point(const float *p)
{
    point_f16 v;
    memcpy(&v, p, sizeof v);
    return v;
}

/* Every channel of a sample at once: the trilinear blend of its cell's 8 corner points
 * (offsets and weights), summed as a tree (a chain of eight dependent FMAs was the march's
 * longest latency). */
static inline point_f16 trilinear(const float *v, const size_t offset[8], const float w[8])
{
    return ((w[0] * load_point(v + offset[0]) + w[1] * load_point(v + offset[1])) +
            (w[2] * load_point(v + offset[2]) + w[3] * load_point(v + offset[3]))) +
           ((w[4] * load_point(v + offset[4]) + w[5] * load_point(v + offset[5])) +
            (w[6] * load_point(v + offset[6]) + w[7] * load_point(v + offset[7])));
}

/* The colour of a sample from its blended point: each colour's SH logits dotted with the
 * view basis (`basis` holds (1, x, y, z) at every colour's lanes), sigmoid; lane 3 unused. */
static inline fast_f4 sample_colour(point_f16 point, point_f16 basis)
{
    const point_f16 p = point * basis;
    /* lane k of each: colour k's term of basis function b; lane 3 is 0 (basis lanes 0, 13..15) */
    const fast_f4 b0 = __builtin_shufflevector(p, p, 1, 5, 9, 13);
    const fast_f4 b1 = __builtin_shufflevector(p, p, 2, 6, 10, 14);
    const fast_f4 b2 = __builtin_shufflevector(p, p, 3, 7, 11, 15);
    const fast_f4 b3 = __builtin_shufflevector(p, p, 4, 8, 12, 0);
    return fast_sigmoid4((b0 + b1) + (b2 + b3));
}

/* March grid gi over [ta, tb), the lattice anchored at ta. Returns 1 when the ray ended. */
static int render_segment(const vf_field *f, const field_render_grid *rg, int gi,
                          const field_ray *ray, float ta, float tb, float jitter, float min_trans,
                          point_f16 basis, render_state *s)
{
    if (rg->empty)
        return 0;
    const field_grid *g = &f->grids[gi];
    field_ray clipped = *ray;
    clipped.tmin = ta;
    clipped.tmax = tb;
    float c0, c1;
    if (!field_ray_box(&clipped, rg->occ_lo, rg->occ_hi, &c0, &c1))
        return 0;
    const float step = rg->step;
    const float visible = rg->visible_density;
    /* one lattice point either side of the clipped range: their cells are tested anyway */
    const float end = field_min(tb, c1 + step);
    int k = (int)floorf((c0 - ta) / step - jitter);
    k = k < 0 ? 0 : k;

    float og[3], dg[3];
    for (int a = 0; a < 3; a++) {
        og[a] = (ray->origin[a] - g->lo[a]) * rg->inv_voxel;
        dg[a] = ray->dir[a] * rg->inv_voxel;
    }
    field_skip skip;
    field_skip_init(&skip, dg, step);
    const int ncx = g->cells[0], ncy = g->cells[1], ncz = g->cells[2];
    const size_t sy = (size_t)g->dim[0], sz = sy * (size_t)g->dim[1];
    const size_t cy = (size_t)ncx, cz = cy * (size_t)ncy;
    const size_t o1 = FIELD_CH, oy = sy * FIELD_CH, oz = sz * FIELD_CH;

    for (;;) {
        const float t = ta + ((float)k + jitter) * step;
        if (t >= end)
            return 0;
        const float ux = og[0] + t * dg[0], uy = og[1] + t * dg[1], uz = og[2] + t * dg[2];
        int cx = (int)ux, cyi = (int)uy, czi = (int)uz;
        cx = cx < 0 ? 0 : cx >= ncx ? ncx - 1 : cx;
        cyi = cyi < 0 ? 0 : cyi >= ncy ? ncy - 1 : cyi;
        czi = czi < 0 ? 0 : czi >= ncz ? ncz - 1 : czi;
        const int radius = g->empty_radius[(size_t)cx + cy * cyi + cz * czi];
        if (radius) {
            k += field_empty_skip(&skip, (const float[3]){ux, uy, uz},
                                  (const int[3]){cx, cyi, czi}, radius);
            continue;
        }
        k++;

        const float fx = field_clamp01(ux - (float)cx), fy = field_clamp01(uy - (float)cyi);
        const float fz = field_clamp01(uz - (float)czi);
        const size_t base = (size_t)cx + sy * cyi + sz * czi;
        const float *v = g->values + base * FIELD_CH;
        const float gx = 1 - fx, gy = 1 - fy, gz = 1 - fz;
        const float a00 = gx * gy, a10 = fx * gy, a01 = gx * fy, a11 = fx * fy;
        const float w[8] = {a00 * gz, a10 * gz, a01 * gz, a11 * gz,
                            a00 * fz, a10 * fz, a01 * fz, a11 * fz};
        const size_t corner[8] = {0, o1, oy, oy + o1, oz, oz + o1, oz + oy, oz + oy + o1};
        /* all channels at once: a corner's 16 floats are one vector load */
        const point_f16 point = trilinear(v, corner, w);
        const float d = point[FIELD_CH_DENSITY];
        if (d < visible)
            continue;
        const float alpha = field_render_alpha(rg, d);

        const float weight = s->trans * alpha;
        s->rgb += weight * sample_colour(point, basis);
        s->depth += weight * t;
        s->count++;
        s->trans *= 1.0f - alpha;
        if (s->trans < min_trans)
            return 1;
    }
}

void field_render_ray(const vf_field *f, const field_render_setup *setup, const field_ray *ray,
                      float jitter, float min_trans, field_march_result *out)
{
    render_state s = {.trans = 1.0f};
    const float x = ray->dir[0], y = ray->dir[1], z = ray->dir[2];
    const point_f16 basis = {0, 1, x, y, z, 1, x, y, z, 1, x, y, z, 0, 0, 0};
    const field_grid *inner = &f->grids[0];
    const field_render_grid *rg = setup->grids;
    float i0, i1;
    int hits_inner = field_ray_box(ray, inner->lo, inner->hi, &i0, &i1);
    if (f->grid_count == 1) {
        if (hits_inner)
            render_segment(f, &rg[0], 0, ray, i0, i1, jitter, min_trans, basis, &s);
    } else {
        const field_grid *outer = &f->grids[1];
        float a0, a1;
        if (field_ray_box(ray, outer->lo, outer->hi, &a0, &a1)) {
            /* as field_march: outer grid in front of the inner box, the inner box, behind */
            if (!hits_inner) {
                render_segment(f, &rg[1], 1, ray, a0, a1, jitter, min_trans, basis, &s);
            } else {
                int done = 0;
                if (a0 < i0)
                    done = render_segment(f, &rg[1], 1, ray, a0, i0, jitter, min_trans, basis, &s);
                if (!done)
                    done = render_segment(f, &rg[0], 0, ray, i0, i1, jitter, min_trans, basis, &s);
                if (!done && i1 < a1)
                    render_segment(f, &rg[1], 1, ray, i1, a1, jitter, min_trans, basis, &s);
            }
        }
    }
    for (int k = 0; k < 3; k++)
        out->rgb[k] = s.rgb[k] + s.trans * f->background[k];
    out->trans = s.trans;
    out->depth = s.depth;
    out->count = s.count;
    out->overflow = 0;
}
