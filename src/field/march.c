/* Ray marching through the grids: forward compositing and its backward pass.
 *
 * Samples sit on a lattice t_k = t_start + (k + jitter) * step along the ray, so a ray gives
 * the same samples every time it is marched (the gradient check and determinism rely on
 * this). Samples in empty cells are jumped over as far as the cell's empty-space radius
 * allows (empty_space.c), to the next lattice point that may hold density. */
#include <string.h>

#include "field_internal.h"

int vf__field_ray_box(const field_ray *ray, const float lo[3], const float hi[3], float *t0,
                      float *t1)
{
    float enter = ray->tmin, leave = ray->tmax;
    for (int a = 0; a < 3; a++) {
        float o = ray->origin[a], d = ray->dir[a];
        if (fabsf(d) < 1e-12f) {
            if (o < lo[a] || o > hi[a])
                return 0;
            continue;
        }
        float inv = 1.0f / d;
        float ta = (lo[a] - o) * inv, tb = (hi[a] - o) * inv;
        if (ta > tb) {
            float swap = ta;
            ta = tb;
            tb = swap;
        }
        enter = field_max(enter, ta);
        leave = field_min(leave, tb);
    }
    *t0 = enter;
    *t1 = leave;
    return enter < leave;
}

static float grid_step(const vf_field *f, const field_grid *g)
{
    return f->step_ratio * g->voxel;
}

int vf__field_max_samples(const vf_field *f)
{
    double total = 4;
    for (int i = 0; i < f->grid_count; i++) {
        const field_grid *g = &f->grids[i];
        double dx = g->hi[0] - g->lo[0], dy = g->hi[1] - g->lo[1], dz = g->hi[2] - g->lo[2];
        total += sqrt(dx * dx + dy * dy + dz * dz) / grid_step(f, g) + 2;
    }
    return (int)total;
}

/* Running state of one ray's march across its segments. */
typedef struct march_state {
    float trans;
    float rgb[3];
    float depth;
    int count;
    int overflow;
    field_scratch *rec;
} march_state;

/* March grid `gi` over ray parameters [ta, tb). Returns 1 when the ray terminated. */
static int march_segment(const vf_field *f, int gi, const field_ray *ray, float ta, float tb,
                         float jitter, float min_trans, const float basis[4], march_state *s)
{
    const field_grid *g = &f->grids[gi];
    const float step = grid_step(f, g);
    const float scale_step = f->density_scale * step, shift = f->density_shift;
    field_lattice lat;
    field_lattice_init(&lat, g, ray->origin, ray->dir, ta + jitter * step, step);
    const size_t sy = (size_t)g->dim[0], sz = sy * (size_t)g->dim[1];
    const size_t cy = (size_t)g->cells[0], cz = cy * (size_t)g->cells[1];
    /* Offsets of the 8 corners of a cell, in floats. */
    const size_t o1 = FIELD_CH, oy = sy * FIELD_CH, oz = sz * FIELD_CH;
    const int recording = s->rec != NULL;

    for (float k = 0;;) {
        float t = ta + (k + jitter) * step;
        if (t >= tb)
            return 0;
        int c[3];
        float u[3];
        for (int a = 0; a < 3; a++) {
            u[a] = lat.u0[a] + k * lat.du[a];
            int ci = (int)u[a];
            ci = ci < 0 ? 0 : ci >= g->cells[a] ? g->cells[a] - 1 : ci;
            c[a] = ci;
        }
        int radius = g->empty_radius[(size_t)c[0] + cy * c[1] + cz * c[2]];
        if (radius) { /* empty: jump as far as empty space reaches */
            k = field_lattice_skip(&lat, k, u, c, radius);
            continue;
        }
        k += 1.0f;
        field_prefetch_sample(g, &lat, k);

        float fx = field_clamp01(u[0] - (float)c[0]);
        float fy = field_clamp01(u[1] - (float)c[1]);
        float fz = field_clamp01(u[2] - (float)c[2]);
        size_t base = (size_t)c[0] + sy * c[1] + sz * c[2];
        const float *v = g->values + base * FIELD_CH;
        float w0 = (1 - fx) * (1 - fy) * (1 - fz), w1 = fx * (1 - fy) * (1 - fz);
        float w2 = (1 - fx) * fy * (1 - fz), w3 = fx * fy * (1 - fz);
        float w4 = (1 - fx) * (1 - fy) * fz, w5 = fx * (1 - fy) * fz;
        float w6 = (1 - fx) * fy * fz, w7 = fx * fy * fz;

        float d = w0 * v[0] + w1 * v[o1] + w2 * v[oy] + w3 * v[oy + o1] + w4 * v[oz] +
                  w5 * v[oz + o1] + w6 * v[oz + oy] + w7 * v[oz + oy + o1];
        float x = d + shift, ex = x > 20.0f ? 0.0f : expf(x);
        float softplus = x > 20.0f ? x : log1pf(ex);
        float alpha = 1.0f - expf(-softplus * scale_step);
        if (!recording && alpha < 1e-5f)
            continue; /* invisible: rendering skips its colour */

        float acc[FIELD_CH];
        for (int ch = 0; ch < FIELD_CH; ch++)
            acc[ch] = w0 * v[ch] + w1 * v[o1 + ch] + w2 * v[oy + ch] + w3 * v[oy + o1 + ch] +
                      w4 * v[oz + ch] + w5 * v[oz + o1 + ch] + w6 * v[oz + oy + ch] +
                      w7 * v[oz + oy + o1 + ch];
        float rgb[3];
        for (int k3 = 0; k3 < 3; k3++) {
            const float *sh = acc + FIELD_CH_SH + 4 * k3;
            rgb[k3] = field_sigmoid(sh[0] * basis[0] + sh[1] * basis[1] + sh[2] * basis[2] +
                                    sh[3] * basis[3]);
        }
        if (recording) {
            if (s->count >= s->rec->capacity) {
                s->overflow = 1;
                return 1;
            }
            field_sample *r = &s->rec->samples[s->count];
            r->base = (uint32_t)base;
            r->grid = (uint8_t)gi;
            r->frac[0] = fx;
            r->frac[1] = fy;
            r->frac[2] = fz;
            r->alpha = alpha;
            r->trans = s->trans;
            r->rgb[0] = rgb[0];
            r->rgb[1] = rgb[1];
            r->rgb[2] = rgb[2];
            /* d(softplus(x))/dx = sigmoid(x) = e^x / (1 + e^x) */
            r->dtau = scale_step * (x > 20.0f ? 1.0f : ex / (1.0f + ex));
            r->t = t;
        }
        s->count++;
        float w = s->trans * alpha;
        s->rgb[0] += w * rgb[0];
        s->rgb[1] += w * rgb[1];
        s->rgb[2] += w * rgb[2];
        s->depth += w * t;
        s->trans *= 1.0f - alpha;
        if (s->trans < min_trans)
            return 1;
    }
}

int vf__field_ray_segments(const vf_field *f, const field_ray *ray, field_segment out[3])
{
    int n = 0;
    float i0, i1, a0, a1;
    const int hits_inner = vf__field_ray_box(ray, f->grids[0].lo, f->grids[0].hi, &i0, &i1);
    if (f->grid_count == 1) {
        if (hits_inner)
            out[n++] = (field_segment){0, i0, i1};
    } else if (vf__field_ray_box(ray, f->grids[1].lo, f->grids[1].hi, &a0, &a1)) {
        if (!hits_inner) {
            out[n++] = (field_segment){1, a0, a1};
        } else {
            if (a0 < i0)
                out[n++] = (field_segment){1, a0, i0};
            out[n++] = (field_segment){0, i0, i1};
            if (i1 < a1)
                out[n++] = (field_segment){1, i1, a1};
        }
    }
    return n;
}

void vf__field_march(const vf_field *f, const field_ray *ray, float jitter, float min_trans,
                     field_scratch *rec, field_march_result *out)
{
    march_state s = {.trans = 1.0f, .rec = rec};
    const float basis[4] = {1.0f, ray->dir[0], ray->dir[1], ray->dir[2]};
    field_segment seg[3];
    const int n = vf__field_ray_segments(f, ray, seg);
    for (int i = 0; i < n; i++)
        if (march_segment(f, seg[i].grid, ray, seg[i].ta, seg[i].tb, jitter, min_trans, basis, &s))
            break;
    for (int k = 0; k < 3; k++)
        out->rgb[k] = s.rgb[k] + s.trans * f->background[k];
    out->trans = s.trans;
    out->depth = s.depth;
    out->count = s.count;
    out->overflow = s.overflow;
}

/* Add the gradient of one sample's 16 channels to the 8 corners of its cell. */
static inline void scatter(const vf_field *f, field_grad_sink *sink, const field_sample *r,
                           const float grad[FIELD_CH])
{
    const field_grid *g = &f->grids[r->grid];
    const size_t sy = (size_t)g->dim[0], sz = sy * (size_t)g->dim[1];
    const size_t offset[8] = {0, 1, sy, sy + 1, sz, sz + 1, sz + sy, sz + sy + 1};
    const float fx = r->frac[0], fy = r->frac[1], fz = r->frac[2];
    const float weight[8] = {(1 - fx) * (1 - fy) * (1 - fz), fx * (1 - fy) * (1 - fz),
                             (1 - fx) * fy * (1 - fz),       fx * fy * (1 - fz),
                             (1 - fx) * (1 - fy) * fz,       fx * (1 - fy) * fz,
                             (1 - fx) * fy * fz,             fx * fy * fz};
    float *grad_base = sink->grad[r->grid];
    uint8_t *touched = sink->touched[r->grid];
    for (int corner = 0; corner < 8; corner++) {
        size_t i = r->base + offset[corner];
        if (!touched[i]) {
            touched[i] = 1;
            sink->list[r->grid][sink->count[r->grid]++] = (uint32_t)i;
        }
        float *dst = grad_base + i * FIELD_CH;
        const float w = weight[corner];
        for (int ch = 0; ch < FIELD_CH; ch++)
            dst[ch] += w * grad[ch];
    }
}

/* The distortion loss's running sums over the samples before the current one: the weight
 * and the weighted distance. For sample i (weight w, distance s, step ds),
 * dL/dw_i = 2 sum_j w_j |s - s_j| + 2/3 w ds, and the sum over j splits at i. */
typedef struct distortion_sums {
    float w_total, ws_total; /* over every sample */
    float w_before, ws_before;
} distortion_sums;

static inline float distortion_dw(distortion_sums *d, float w, float s, float ds)
{
    const float before = s * d->w_before - d->ws_before;
    const float after = (d->ws_total - d->ws_before - w * s) - s * (d->w_total - d->w_before - w);
    d->w_before += w;
    d->ws_before += w * s;
    return 2.0f * (before + after) + (2.0f / 3.0f) * w * ds;
}

static inline float sample_distance(const vf_field *f, const field_sample *r)
{
    return r->t / (float)f->camera_distance;
}

static inline float sample_step(const vf_field *f, const field_sample *r)
{
    return grid_step(f, &f->grids[r->grid]) / (float)f->camera_distance;
}

double vf__field_distortion_loss(const vf_field *f, const field_sample *samples, int count)
{
    double loss = 0;
    for (int i = 0; i < count; i++) {
        const double wi = samples[i].trans * samples[i].alpha, si = sample_distance(f, &samples[i]);
        for (int j = 0; j < count; j++)
            loss += wi * samples[j].trans * samples[j].alpha *
                    fabs(si - sample_distance(f, &samples[j]));
        loss += wi * wi * sample_step(f, &samples[i]) / 3.0;
    }
    return loss;
}

double vf__field_depth_loss(const vf_field *f, const field_sample *samples, int count,
                            float target)
{
    double loss = 0;
    for (int i = 0; i < count; i++) {
        const double e = sample_distance(f, &samples[i]) - target;
        loss += samples[i].trans * samples[i].alpha * e * e;
    }
    return loss;
}

void vf__field_backward(const vf_field *f, const field_ray *ray, const field_scratch *rec,
                        const field_march_result *res, const float dl_drgb[3],
                        field_ray_losses losses, field_grad_sink *sink)
{
    const float basis[4] = {1.0f, ray->dir[0], ray->dir[1], ray->dir[2]};
    const float *g = dl_drgb;
    /* With C the full colour and P_i the colour composited up to and including sample i,
     * dC/dtau_i = T_{i+1} c_i - (C - P_i) where tau_i = sigma_i * step (alpha = 1 - e^-tau).
     * The loss `opaque` T_end (T_end the transmittance left for the background, whose
     * derivative is -T_end) enters C - P_i like the background's colour term T_end bg.
     * Any loss of the weights w_k = T_k alpha_k has the same form: with g_k = dL/dw_k,
     * dL/dtau_i = T_{i+1} g_i - sum_{k>i} w_k g_k; the distortion loss adds its g_k to the
     * colour's, which takes two passes over the samples for sum_k w_k g_k; the depth loss's
     * g_k is depth (s_k - target)^2. */
    const float lambda = losses.distortion, depth = losses.depth, target = losses.depth_target;
    distortion_sums dist = {0};
    float g_total =
        g[0] * res->rgb[0] + g[1] * res->rgb[1] + g[2] * res->rgb[2] + losses.opaque * res->trans;
    for (int i = 0; depth > 0 && i < res->count; i++) {
        const field_sample *r = &rec->samples[i];
        const float e = sample_distance(f, r) - target;
        g_total += r->trans * r->alpha * depth * e * e;
    }
    if (lambda > 0) {
        for (int i = 0; i < res->count; i++) {
            const field_sample *r = &rec->samples[i];
            dist.w_total += r->trans * r->alpha;
            dist.ws_total += r->trans * r->alpha * sample_distance(f, r);
        }
        distortion_sums pass = dist;
        for (int i = 0; i < res->count; i++) {
            const field_sample *r = &rec->samples[i];
            const float w = r->trans * r->alpha;
            const float dw = distortion_dw(&pass, w, sample_distance(f, r), sample_step(f, r));
            g_total += lambda * w * dw;
        }
    }
    float g_prefix = 0;
    for (int i = 0; i < res->count; i++) {
        const field_sample *r = &rec->samples[i];
        float w = r->trans * r->alpha;
        float g_c = g[0] * r->rgb[0] + g[1] * r->rgb[1] + g[2] * r->rgb[2];
        float g_w = lambda > 0
                        ? g_c + lambda * distortion_dw(&dist, w, sample_distance(f, r),
                                                       sample_step(f, r))
                        : g_c;
        if (depth > 0) {
            const float e = sample_distance(f, r) - target;
            g_w += depth * e * e;
        }
        g_prefix += w * g_w;
        float trans_next = r->trans * (1.0f - r->alpha);
        float dl_dtau = trans_next * g_w - (g_total - g_prefix);
        float grad[FIELD_CH] = {0};
        grad[FIELD_CH_DENSITY] = dl_dtau * r->dtau;
        for (int k = 0; k < 3; k++) {
            float dl_dlogit = w * g[k] * r->rgb[k] * (1.0f - r->rgb[k]);
            for (int b = 0; b < 4; b++)
                grad[FIELD_CH_SH + 4 * k + b] = dl_dlogit * basis[b];
        }
        scatter(f, sink, r, grad);
    }
}
