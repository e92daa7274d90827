/* The rendering ray marcher: vf__field_march's forward pass, lean.
 *
 * It visits the same lattice of samples as vf__field_march (t_k = t_start + (k + jitter) * step
 * from the grid box entry), so renders agree with what training optimized, but:
 *   - the ray is clipped to the box of occupied cells and starts at the first lattice point
 *     inside it;
 *   - empty space is jumped: a sample in an empty cell moves the march as far as the cell's
 *     empty-space radius allows (empty_space.c, field_lattice_skip);
 *   - four rays are marched in turn: each ray's march is a chain of dependent steps (position,
 *     cell, radius load, jump), and four independent chains keep the core busy (the fox's
 *     3-minute field: 12 jumps and 9 samples a pixel of a 224 view);
 *   - a sample blends all 16 channels of its 8 corner points as 16-lane float vectors, added
 *     as a tree, not as one long chain of dependent additions;
 *   - the next sample's radius and corner points are prefetched (field_prefetch_points): 224
 *     views of four real captures' fields 9-17% faster (A/B in one process, 2 threads);
 *   - with F16C or AVX-512 (FIELD_RENDER_HALF) it reads a copy of the grids in half
 *     precision (IEEE binary16, 11 significant bits): a point is 32 bytes, so a cell's 8
 *     corners take 4 to 8 cache lines, not 8, and twice the grid fits the caches. 224 views
 *     of four real captures' fields 4-10% sooner one at a time, 4-16% in batches (A/B in one
 *     process, 2 threads), 84-88 dB from the float render (worst view 75 dB, largest pixel
 *     difference 0.03); the same held-out PSNR and names. Without the instructions
 *     (VF_PORTABLE) converting in software made renders 60-80% slower: it reads the floats;
 *   - samples under FIELD_VISIBLE_ALPHA are skipped by a raw-density threshold;
 *   - opacity comes from a table of raw density, and the colour's three sigmoids are one
 *     four-lane vector operation (fast_math.h). */

#include <string.h>

#include "fast_math.h"
#include "field_internal.h"

#if FIELD_RENDER_HALF
#include <immintrin.h>
#endif

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

/* One grid point: density, the 12 SH logits and padding (FIELD_CH floats). */
typedef float point_floats __attribute__((vector_size(FIELD_CH * sizeof(float))));

#if FIELD_RENDER_HALF
/* The point at p from its FIELD_CH halves: one instruction with AVX-512, two with F16C. */
static inline point_floats load_point(const uint16_t *p)
{
#if defined(__AVX512F__)
    return (point_floats)_mm512_cvtph_ps(_mm256_loadu_si256((const __m256i *)p));
#else
    const __m256 lo = _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)p));
    const __m256 hi = _mm256_cvtph_ps(_mm_loadu_si128((const __m128i *)(p + 8)));
    point_floats v;
    memcpy(&v, &lo, sizeof lo);
    memcpy((char *)&v + sizeof lo, &hi, sizeof hi);
    return v;
#endif
}

/* The FIELD_CH floats at v as halves at h, rounded to nearest. Values beyond the halves'
 * range (65504) are clamped to it: an infinity would make NaN of a trilinear blend where a
 * float grid gives a number (model files hold values up to 1e8; trained ones stay far below). */
static inline void store_point_half(const float *v, uint16_t *h)
{
#if defined(__AVX512F__)
    const __m512 big = _mm512_set1_ps(65504.0f);
    const __m512 x = _mm512_max_ps(_mm512_min_ps(_mm512_loadu_ps(v), big), -big);
    const __m256i out = _mm512_cvtps_ph(x, _MM_FROUND_TO_NEAREST_INT);
    memcpy(h, &out, sizeof out);
#else
    const __m256 big = _mm256_set1_ps(65504.0f), small = _mm256_set1_ps(-65504.0f);
    const __m256 a = _mm256_max_ps(_mm256_min_ps(_mm256_loadu_ps(v), big), small);
    const __m256 b = _mm256_max_ps(_mm256_min_ps(_mm256_loadu_ps(v + 8), big), small);
    const __m128i lo = _mm256_cvtps_ph(a, _MM_FROUND_TO_NEAREST_INT);
    const __m128i hi = _mm256_cvtps_ph(b, _MM_FROUND_TO_NEAREST_INT);
    memcpy(h, &lo, sizeof lo);
    memcpy(h + 8, &hi, sizeof hi);
#endif
}

/* Make the half copies of f's grids that are missing or stale. They are a cache of the values,
 * which is why a const field gets them; the lock keeps renders from several threads safe. */
static vf_status make_half_copies(const vf_field *cf)
{
    vf_field *f = (vf_field *)cf;
    vf_status status = VF_OK;
#pragma omp critical(vf_field_half)
    {
        for (int i = 0; i < f->grid_count && status == VF_OK; i++) {
            field_grid *g = &f->grids[i];
            if (g->half && !f->half_stale)
                continue;
            if (!g->half)
                g->half = vf__field_alloc(g->points * FIELD_CH * sizeof *g->half);
            if (!g->half) {
                status = vf_fail(VF_EINTERNAL, "out of memory for the render copy of a %dx%dx%d "
                                               "grid", g->dim[0], g->dim[1], g->dim[2]);
                continue;
            }
            const ptrdiff_t points = (ptrdiff_t)g->points;
#pragma omp parallel for schedule(static)
            for (ptrdiff_t p = 0; p < points; p++)
                store_point_half(g->values + p * FIELD_CH, g->half + p * FIELD_CH);
        }
        if (status == VF_OK)
            f->half_stale = 0;
    }
    return status;
}
#else
static inline point_floats load_point(const float *p)
{
    point_floats v;
    memcpy(&v, p, sizeof v);
    return v;
}
#endif

vf_status vf__field_render_setup_init(const vf_field *f, field_render_setup *setup)
{
    memset(setup, 0, sizeof *setup);
#if FIELD_RENDER_HALF
    vf_status status = make_half_copies(f);
    if (status != VF_OK)
        return status;
#endif
    for (int i = 0; i < f->grid_count; i++) {
        const field_grid *g = &f->grids[i];
        field_render_grid *r = &setup->grids[i];
        r->step = f->step_ratio * g->voxel;
        r->scale_step = f->density_scale * r->step;
        r->visible_density = vf__field_density_threshold(f, FIELD_VISIBLE_ALPHA, r->step);
        tabulate_alpha(f, r);
        r->empty = 0;
        for (int a = 0; a < 3; a++) {
            r->empty |= g->occ_lo[a] >= g->occ_hi[a];
            r->occ_lo[a] = g->lo[a] + (float)g->occ_lo[a] * g->voxel;
            r->occ_hi[a] = g->lo[a] + (float)g->occ_hi[a] * g->voxel;
        }
#if FIELD_RENDER_HALF
        r->values = g->half;
#else
        r->values = g->values;
#endif
    }
    return VF_OK;
}

typedef struct render_state {
    float trans;
    fast_f4 rgb; /* lanes 0..2 */
    float depth;
    int count;
} render_state;

/* Every channel of a sample at once: the trilinear blend of its cell's 8 corner points
 * (offsets and weights), summed as a tree (a chain of eight dependent FMAs was the march's
 * longest latency). */
static inline point_floats trilinear(const field_render_value *v, const size_t offset[8], const float w[8])
{
    return ((w[0] * load_point(v + offset[0]) + w[1] * load_point(v + offset[1])) +
            (w[2] * load_point(v + offset[2]) + w[3] * load_point(v + offset[3]))) +
           ((w[4] * load_point(v + offset[4]) + w[5] * load_point(v + offset[5])) +
            (w[6] * load_point(v + offset[6]) + w[7] * load_point(v + offset[7])));
}

/* The colour of a sample from its blended point: each colour's SH logits dotted with the
 * view basis (`basis` holds (1, x, y, z) at every colour's lanes), sigmoid; lane 3 unused. */
static inline fast_f4 sample_colour(point_floats point, point_floats basis)
{
    const point_floats p = point * basis;
    /* lane k of each: colour k's term of basis function b; lane 3 is 0 (basis lanes 0, 13..15) */
    const fast_f4 b0 = __builtin_shufflevector(p, p, 1, 5, 9, 13);
    const fast_f4 b1 = __builtin_shufflevector(p, p, 2, 6, 10, 14);
    const fast_f4 b2 = __builtin_shufflevector(p, p, 3, 7, 11, 15);
    const fast_f4 b3 = __builtin_shufflevector(p, p, 4, 8, 12, 0);
    return fast_sigmoid4((b0 + b1) + (b2 + b3));
}

/* A ray being marched: its segments (vf__field_ray_segments), the one being marched and the
 * compositing so far. */
typedef struct ray_cursor {
    const field_ray *ray;
    float jitter;
    field_segment segments[3];
    int segment_count, segment, alive;
    render_state state;
    point_floats basis; /* (1, x, y, z) of the view direction at every colour's lanes */
    /* the segment being marched */
    const field_grid *g;
    const field_render_grid *rg;
    field_lattice lattice;
    float k, end;
    int cells[3];
    size_t cell_y, cell_z, point_y, point_z; /* strides in cells and in points */
} ray_cursor;

/* Set up the cursor's current segment, or the first later one with occupied cells on the ray;
 * the ray is done when none is left. Called a few times a ray: kept out of the hot loop. */
static __attribute__((noinline)) void cursor_start_segment(ray_cursor *c, const vf_field *f,
                                                           const field_render_setup *setup)
{
    for (; c->segment < c->segment_count; c->segment++) {
        const field_segment *sg = &c->segments[c->segment];
        const field_render_grid *rg = &setup->grids[sg->grid];
        if (rg->empty)
            continue;
        field_ray clipped = *c->ray;
        clipped.tmin = sg->ta;
        clipped.tmax = sg->tb;
        float c0, c1;
        if (!vf__field_ray_box(&clipped, rg->occ_lo, rg->occ_hi, &c0, &c1))
            continue;
        const field_grid *g = &f->grids[sg->grid];
        const float step = rg->step;
        c->g = g;
        c->rg = rg;
        /* one lattice point either side of the clipped range: their cells are tested anyway */
        c->end = field_min(sg->tb, c1 + step);
        c->k = field_max(floorf((c0 - sg->ta) / step - c->jitter), 0.0f);
        field_lattice_init(&c->lattice, g, c->ray->origin, c->ray->dir,
                           sg->ta + c->jitter * step, step);
        memcpy(c->cells, g->cells, sizeof c->cells);
        c->cell_y = (size_t)g->cells[0];
        c->cell_z = c->cell_y * (size_t)g->cells[1];
        c->point_y = (size_t)g->dim[0];
        c->point_z = c->point_y * (size_t)g->dim[1];
        return;
    }
    c->alive = 0;
}

static void cursor_init(ray_cursor *c, const vf_field *f, const field_render_setup *setup,
                        const field_ray *ray, float jitter)
{
    c->ray = ray;
    c->jitter = jitter;
    c->state = (render_state){.trans = 1.0f};
    const float x = ray->dir[0], y = ray->dir[1], z = ray->dir[2];
    c->basis = (point_floats){0, 1, x, y, z, 1, x, y, z, 1, x, y, z, 0, 0, 0};
    c->segment_count = vf__field_ray_segments(f, ray, c->segments);
    c->segment = 0;
    c->alive = 1;
    cursor_start_segment(c, f, setup);
}

/* One step of a live cursor: a jump over empty space, or a sample. */
static inline void cursor_step(ray_cursor *c, const vf_field *f, const field_render_setup *setup,
                               float min_trans)
{
    const float k = c->k, step = c->rg->step;
    const float t = c->segments[c->segment].ta + (k + c->jitter) * step;
    if (t >= c->end) {
        c->segment++;
        cursor_start_segment(c, f, setup);
        return;
    }
    const field_grid *g = c->g;
    const field_lattice *lat = &c->lattice;
    const float ux = lat->u0[0] + k * lat->du[0], uy = lat->u0[1] + k * lat->du[1];
    const float uz = lat->u0[2] + k * lat->du[2];
    int cx = (int)ux, cy = (int)uy, cz = (int)uz;
    cx = cx < 0 ? 0 : cx >= c->cells[0] ? c->cells[0] - 1 : cx;
    cy = cy < 0 ? 0 : cy >= c->cells[1] ? c->cells[1] - 1 : cy;
    cz = cz < 0 ? 0 : cz >= c->cells[2] ? c->cells[2] - 1 : cz;
    const int radius = g->empty_radius[(size_t)cx + c->cell_y * cy + c->cell_z * cz];
    if (radius) {
        c->k = field_lattice_skip(lat, k, (const float[3]){ux, uy, uz}, (const int[3]){cx, cy, cz},
                                  radius);
        return;
    }
    c->k = k + 1.0f;
    field_prefetch_points(g, lat, c->k, c->rg->values, FIELD_CH * sizeof *c->rg->values);

    const float fx = field_clamp01(ux - (float)cx), fy = field_clamp01(uy - (float)cy);
    const float fz = field_clamp01(uz - (float)cz);
    const size_t base = (size_t)cx + c->point_y * cy + c->point_z * cz;
    const field_render_value *v = c->rg->values + base * FIELD_CH;
    const float gx = 1 - fx, gy = 1 - fy, gz = 1 - fz;
    const float a00 = gx * gy, a10 = fx * gy, a01 = gx * fy, a11 = fx * fy;
    const float w[8] = {a00 * gz, a10 * gz, a01 * gz, a11 * gz,
                        a00 * fz, a10 * fz, a01 * fz, a11 * fz};
    const size_t o1 = FIELD_CH, oy = c->point_y * FIELD_CH, oz = c->point_z * FIELD_CH;
    const size_t corner[8] = {0, o1, oy, oy + o1, oz, oz + o1, oz + oy, oz + oy + o1};
    /* all channels at once: a corner is one load (and conversion) of 16 values */
    const point_floats point = trilinear(v, corner, w);
    const float d = point[FIELD_CH_DENSITY];
    if (d < c->rg->visible_density)
        return;
    const float alpha = field_render_alpha(c->rg, d);

    render_state *s = &c->state;
    const float weight = s->trans * alpha;
    s->rgb += weight * sample_colour(point, c->basis);
    s->depth += weight * t;
    s->count++;
    s->trans *= 1.0f - alpha;
    if (s->trans < min_trans)
        c->alive = 0;
}

/* A ray stopped below min_trans lies on a surface, and what is left of its light comes from
 * behind it, not from the background: its colour and depth so far are renormalized over the
 * opacity met (as if the rest came from the same surface) and it is reported opaque. */
static void cursor_finish(const ray_cursor *c, const vf_field *f, float min_trans,
                          field_march_result *out)
{
    const render_state *s = &c->state;
    const int stopped = s->trans < min_trans;
    const float scale = stopped ? 1.0f / (1.0f - s->trans) : 1.0f;
    for (int k = 0; k < 3; k++)
        out->rgb[k] = stopped ? s->rgb[k] * scale : s->rgb[k] + s->trans * f->background[k];
    out->trans = stopped ? 0.0f : s->trans;
    out->depth = s->depth * scale;
    out->count = s->count;
    out->overflow = 0;
}

enum { LANES = 4 }; /* rays marched in turn: 2 were 12% faster than 1, 4 another 5%, 8 slower
                      (8 again with the half copy: -1 to +4%, nothing measurable) */

void vf__field_render_rays(const vf_field *f, const field_render_setup *setup,
                           const field_ray *rays, int n, float jitter, float min_trans,
                           field_march_result *out)
{
    int first = 0;
    for (; first + LANES <= n; first += LANES) {
        ray_cursor c[LANES];
        for (int j = 0; j < LANES; j++)
            cursor_init(&c[j], f, setup, &rays[first + j], jitter);
        /* in turn while all are live (straight-line code the compiler interleaves), then
         * whatever is left one by one */
        for (;;) {
            int all_alive = 1;
            for (int j = 0; j < LANES; j++)
                all_alive &= c[j].alive;
            if (!all_alive)
                break;
            for (int j = 0; j < LANES; j++)
                cursor_step(&c[j], f, setup, min_trans);
        }
        for (int j = 0; j < LANES; j++) {
            while (c[j].alive)
                cursor_step(&c[j], f, setup, min_trans);
            cursor_finish(&c[j], f, min_trans, &out[first + j]);
        }
    }
    for (; first < n; first++) {
        ray_cursor c;
        cursor_init(&c, f, setup, &rays[first], jitter);
        while (c.alive)
            cursor_step(&c, f, setup, min_trans);
        cursor_finish(&c, f, min_trans, &out[first]);
    }
}
