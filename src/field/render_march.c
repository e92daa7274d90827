/* The rendering ray marcher: field_march's forward pass, lean.
 *
 * It visits the same lattice of samples as field_march (t_k = t_start + (k + jitter) * step
 * from the grid box entry), so renders agree with what training optimized, but:
 *   - the ray is clipped to the box of occupied cells and starts at the first lattice point
 *     inside it;
 *   - empty space is jumped: a sample in an empty cell moves the march as far as the cell's
 *     empty-space radius allows (empty_space.c);
 *   - a sample's density is tested against a precomputed raw-density threshold before any
 *     transcendental function is evaluated, and samples under FIELD_VISIBLE_ALPHA are skipped;
 *   - exp/log are inlined polynomials (fast_math.h). */

#include "fast_math.h"
#include "field_internal.h"


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
    float rgb[3];
    float depth;
    int count;
} render_state;

static inline float clamp01(float x)
{
    return x < 0.0f ? 0.0f : x > 1.0f ? 1.0f : x;
}

/* March grid gi over [ta, tb), the lattice anchored at ta. Returns 1 when the ray ended. */
static int render_segment(const vf_field *f, const field_render_grid *rg, int gi,
                          const field_ray *ray, float ta, float tb, float jitter, float min_trans,
                          const float basis[4], render_state *s)
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
    const float step = rg->step, scale_step = rg->scale_step, shift = f->density_shift;
    const float visible = rg->visible_density;
    /* one lattice point either side of the clipped range: their cells are tested anyway */
    const float end = fminf(tb, c1 + step);
    int k = (int)floorf((c0 - ta) / step - jitter);
    k = k < 0 ? 0 : k;

    float og[3], dg[3], fastest = 0;
    for (int a = 0; a < 3; a++) {
        og[a] = (ray->origin[a] - g->lo[a]) * rg->inv_voxel;
        dg[a] = ray->dir[a] * rg->inv_voxel;
        fastest = fabsf(dg[a]) > fastest ? fabsf(dg[a]) : fastest;
    }
    const float samples_per_cell = 1.0f / (fastest * step);
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
            k += field_empty_jump(radius, samples_per_cell);
            continue;
        }
        k++;

        const float fx = clamp01(ux - (float)cx), fy = clamp01(uy - (float)cyi);
        const float fz = clamp01(uz - (float)czi);
        const size_t base = (size_t)cx + sy * cyi + sz * czi;
        const float *v = g->values + base * FIELD_CH;
        const float w0 = (1 - fx) * (1 - fy) * (1 - fz), w1 = fx * (1 - fy) * (1 - fz);
        const float w2 = (1 - fx) * fy * (1 - fz), w3 = fx * fy * (1 - fz);
        const float w4 = (1 - fx) * (1 - fy) * fz, w5 = fx * (1 - fy) * fz;
        const float w6 = (1 - fx) * fy * fz, w7 = fx * fy * fz;
        const float d = w0 * v[0] + w1 * v[o1] + w2 * v[oy] + w3 * v[oy + o1] + w4 * v[oz] +
                        w5 * v[oz + o1] + w6 * v[oz + oy] + w7 * v[oz + oy + o1];
        if (d < visible)
            continue;
        const float alpha = 1.0f - fast_exp(-fast_softplus(d + shift) * scale_step);

        float acc[FIELD_CH];
        for (int ch = 0; ch < FIELD_CH; ch++)
            acc[ch] = w0 * v[ch] + w1 * v[o1 + ch] + w2 * v[oy + ch] + w3 * v[oy + o1 + ch] +
                      w4 * v[oz + ch] + w5 * v[oz + o1 + ch] + w6 * v[oz + oy + ch] +
                      w7 * v[oz + oy + o1 + ch];
        const float weight = s->trans * alpha;
        for (int c = 0; c < 3; c++) {
            const float *sh = acc + FIELD_CH_SH + 4 * c;
            s->rgb[c] += weight * fast_sigmoid(sh[0] * basis[0] + sh[1] * basis[1] +
                                               sh[2] * basis[2] + sh[3] * basis[3]);
        }
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
    const float basis[4] = {1.0f, ray->dir[0], ray->dir[1], ray->dir[2]};
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
