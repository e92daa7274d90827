/* Sparse Adam over the grid points a batch touched.
 *
 * Every thread accumulates its rays' gradients in its own dense gradient array (no atomics)
 * and lists the points it touched. The update then visits only those points: each point is
 * updated once, by the lowest-numbered thread that touched it, which sums all the threads'
 * gradients for it. Points a batch did not touch keep their moments unchanged ("lazy" Adam). */
#include <math.h>
#include <omp.h>
#include <stdlib.h>
#include <string.h>

#include "trainer_internal.h"

static void free_sink(field_grad_sink *s)
{
    for (int g = 0; g < FIELD_MAX_GRIDS; g++) {
        free(s->grad[g]);
        free(s->touched[g]);
        free(s->list[g]);
    }
    memset(s, 0, sizeof *s);
}

void vf__field_adam_free(field_adam *adam)
{
    for (int g = 0; g < FIELD_MAX_GRIDS; g++) {
        free(adam->m[g]);
        free(adam->v[g]);
    }
    for (int i = 0; adam->sinks && i < adam->threads; i++)
        free_sink(&adam->sinks[i]);
    free(adam->sinks);
    memset(adam, 0, sizeof *adam);
}

vf_status vf__field_adam_alloc(field_adam *adam, const vf_field *f, int threads)
{
    vf__field_adam_free(adam);
    adam->beta1 = 0.9f;
    adam->beta2 = 0.99f;
    adam->eps = 1e-8f;
    adam->threads = threads;
    adam->sinks = calloc((size_t)threads, sizeof *adam->sinks);
    int ok = adam->sinks != NULL;
    for (int g = 0; ok && g < f->grid_count; g++) {
        size_t n = f->grids[g].points;
        ok &= (adam->m[g] = vf__field_alloc(n * FIELD_CH * sizeof(float))) != NULL;
        ok &= (adam->v[g] = vf__field_alloc(n * FIELD_CH * sizeof(float))) != NULL;
        for (int i = 0; ok && i < threads; i++) {
            field_grad_sink *s = &adam->sinks[i];
            ok &= (s->grad[g] = vf__field_alloc(n * FIELD_CH * sizeof(float))) != NULL;
            ok &= (s->touched[g] = vf__field_alloc(n)) != NULL;
            ok &= (s->list[g] = malloc(n * sizeof(uint32_t))) != NULL;
        }
    }
    if (!ok) {
        vf__field_adam_free(adam);
        return vf_fail(VF_EINTERNAL, "out of memory for the optimizer");
    }
    return VF_OK;
}

size_t vf__field_adam_touched(const field_adam *adam)
{
    size_t n = 0;
    for (int g = 0; g < FIELD_MAX_GRIDS; g++)
        for (int i = 0; i < adam->threads; i++)
            n += adam->sinks[i].count[g];
    return n;
}

/* Total-variation gradient at point i: the derivative of the mean over channels of
 * sum over the 3 forward neighbour differences squared, taken at i (its 6 edges). The
 * degree-1 harmonics get tv_view on top of tv_color. */
static void add_tv(const field_grid *g, size_t i, float tv_density, float tv_color, float tv_view,
                   float grad[FIELD_CH])
{
    const size_t stride[3] = {1, (size_t)g->dim[0], (size_t)g->dim[0] * g->dim[1]};
    int pos[3] = {(int)(i % (size_t)g->dim[0]), (int)(i / stride[1] % (size_t)g->dim[1]),
                  (int)(i / stride[2])};
    const float *p = g->values + i * FIELD_CH;
    float diff[FIELD_CH] = {0};
    for (int a = 0; a < 3; a++) {
        if (pos[a] > 0) {
            const float *n = p - stride[a] * FIELD_CH;
            for (int ch = 0; ch < FIELD_CH; ch++)
                diff[ch] += p[ch] - n[ch];
        }
        if (pos[a] < g->dim[a] - 1) {
            const float *n = p + stride[a] * FIELD_CH;
            for (int ch = 0; ch < FIELD_CH; ch++)
                diff[ch] += p[ch] - n[ch];
        }
    }
    grad[FIELD_CH_DENSITY] += 2.0f * tv_density * diff[FIELD_CH_DENSITY];
    for (int ch = FIELD_CH_SH; ch < FIELD_CH_USED; ch++) /* basis 0 is the constant */
        grad[ch] += 2.0f * (tv_color + ((ch - FIELD_CH_SH) % 4 ? tv_view : 0.0f)) * diff[ch];
}

/* The touched points lie scattered over a grid of hundreds of megabytes, so the loops below
 * wait on memory, not arithmetic: each asks for the lines of the point PREFETCH entries ahead
 * in its list while it works on the current one (measured with the marcher's: train.c). */
#define PREFETCH 8

static FIELD_ALWAYS_INLINE void prefetch_gather(const field_adam *adam, const field_grid *grid,
                                                int g, size_t i, int use_tv)
{
    for (int s = 0; s < adam->threads; s++) {
        __builtin_prefetch(adam->sinks[s].touched[g] + i);
        __builtin_prefetch(adam->sinks[s].grad[g] + i * FIELD_CH);
    }
    const float *p = grid->values + i * FIELD_CH;
    __builtin_prefetch(p);
    if (use_tv) { /* its 6 neighbours, those inside the grid */
        const size_t row = (size_t)grid->dim[0], slice = row * (size_t)grid->dim[1];
        const size_t offset[3] = {1, row, slice};
        for (int a = 0; a < 3; a++) {
            if (i >= offset[a])
                __builtin_prefetch(p - offset[a] * FIELD_CH);
            if (i + offset[a] < grid->points)
                __builtin_prefetch(p + offset[a] * FIELD_CH);
        }
    }
}

static FIELD_ALWAYS_INLINE void prefetch_update(const field_adam *adam, const field_grid *grid,
                                                int g, size_t i)
{
    __builtin_prefetch(grid->values + i * FIELD_CH, 1);
    __builtin_prefetch(adam->m[g] + i * FIELD_CH, 1);
    __builtin_prefetch(adam->v[g] + i * FIELD_CH, 1);
}

/* Lowest thread whose sink touched point i of grid g. */
static int owner(const field_adam *adam, int g, size_t i)
{
    for (int s = 0; s < adam->threads; s++)
        if (adam->sinks[s].touched[g][i])
            return s;
    return -1;
}

static inline void adam_update(float *p, float *m, float *v, const float *grad,
                               const float step_size[FIELD_CH], float beta1, float beta2,
                               float eps_hat)
{
    for (int ch = 0; ch < FIELD_CH; ch++) {
        m[ch] = beta1 * m[ch] + (1.0f - beta1) * grad[ch];
        v[ch] = beta2 * v[ch] + (1.0f - beta2) * grad[ch] * grad[ch];
        p[ch] -= step_size[ch] * m[ch] / (__builtin_sqrtf(v[ch]) + eps_hat);
    }
}

void vf__field_adam_step(field_adam *adam, vf_field *f, const float lr[FIELD_CH], float tv_density,
                         float tv_color, float tv_view)
{
    vf__field_values_changed(f);
    adam->t++;
    const float bc1 = 1.0f - powf(adam->beta1, (float)adam->t);
    const float bc2 = 1.0f - powf(adam->beta2, (float)adam->t);
    /* Adam with bias correction folded into the step size and epsilon. */
    float step_size[FIELD_CH];
    for (int ch = 0; ch < FIELD_CH; ch++)
        step_size[ch] = lr[ch] * sqrtf(bc2) / bc1;
    const float eps_hat = adam->eps * sqrtf(bc2);
    const int use_tv = tv_density > 0 || tv_color > 0 || tv_view > 0;
    const int threads = adam->threads;

    /* One sink per training thread. The team here may be smaller than `threads` (OpenMP may
     * give fewer, e.g. with OMP_DYNAMIC), so each thread serves sinks me, me + team, ...: every
     * sink is applied whatever the team's size. The barriers sit outside those loops. */
#pragma omp parallel num_threads(threads)
    {
        const int me = omp_get_thread_num(), team = omp_get_num_threads();
        for (int g = 0; g < f->grid_count; g++) {
            field_grid *grid = &f->grids[g];
            /* 1. the owner of each point gathers its total gradient into its own sink */
            for (int o = me; o < threads; o += team) {
                field_grad_sink *mine = &adam->sinks[o];
                for (size_t k = 0; k < mine->count[g]; k++) {
                    if (k + PREFETCH < mine->count[g])
                        prefetch_gather(adam, grid, g, mine->list[g][k + PREFETCH], use_tv);
                    size_t i = mine->list[g][k];
                    if (owner(adam, g, i) != o)
                        continue;
                    float *total = mine->grad[g] + i * FIELD_CH;
                    for (int s = o + 1; s < threads; s++)
                        if (adam->sinks[s].touched[g][i]) {
                            const float *other = adam->sinks[s].grad[g] + i * FIELD_CH;
                            for (int ch = 0; ch < FIELD_CH; ch++)
                                total[ch] += other[ch];
                        }
                    if (use_tv)
                        add_tv(grid, i, tv_density, tv_color, tv_view, total);
                }
            }
#pragma omp barrier
            /* 2. update the points it owns */
            for (int o = me; o < threads; o += team) {
                field_grad_sink *mine = &adam->sinks[o];
                for (size_t k = 0; k < mine->count[g]; k++) {
                    if (k + PREFETCH < mine->count[g])
                        prefetch_update(adam, grid, g, mine->list[g][k + PREFETCH]);
                    size_t i = mine->list[g][k];
                    if (owner(adam, g, i) == o)
                        adam_update(grid->values + i * FIELD_CH, adam->m[g] + i * FIELD_CH,
                                    adam->v[g] + i * FIELD_CH, mine->grad[g] + i * FIELD_CH,
                                    step_size, adam->beta1, adam->beta2, eps_hat);
                }
            }
#pragma omp barrier
            /* 3. clear everything each sink touched */
            for (int o = me; o < threads; o += team) {
                field_grad_sink *mine = &adam->sinks[o];
                for (size_t k = 0; k < mine->count[g]; k++) {
                    size_t i = mine->list[g][k];
                    memset(mine->grad[g] + i * FIELD_CH, 0, FIELD_CH * sizeof(float));
                    mine->touched[g][i] = 0;
                }
                mine->count[g] = 0;
            }
        }
    }
}

/* ---- each photo's appearance: 6 floats a view, a dense Adam ---------------------------- */

vf_status vf__trainer_alloc_appearance(vf_field_trainer *t)
{
    if (!(t->opt.appearance > 0) || t->has_alpha || t->appearance)
        return VF_OK;
    const size_t n = 6 * (size_t)t->view_count;
    t->appearance = calloc(3 * n, sizeof *t->appearance);
    t->appearance_grad = calloc(n * (size_t)t->threads, sizeof *t->appearance_grad);
    if (!t->appearance || !t->appearance_grad)
        return vf_fail(VF_EINTERNAL, "out of memory");
    t->appearance_m = t->appearance + n;
    t->appearance_v = t->appearance + 2 * n;
    return VF_OK;
}

void vf__trainer_appearance_step(vf_field_trainer *t, float lr)
{
    const size_t n = 6 * (size_t)t->view_count;
    const float beta1 = t->adam.beta1, beta2 = t->adam.beta2; /* the field's */
    t->appearance_t++;
    const float c1 = 1.0f - powf(beta1, (float)t->appearance_t);
    const float c2 = 1.0f - powf(beta2, (float)t->appearance_t);
    double mean[6] = {0};
    for (size_t i = 0; i < n; i++) {
        double g = 0;
        for (int th = 0; th < t->threads; th++) {
            g += t->appearance_grad[(size_t)th * n + i];
            t->appearance_grad[(size_t)th * n + i] = 0;
        }
        float *m = &t->appearance_m[i], *v = &t->appearance_v[i];
        *m = beta1 * *m + (1 - beta1) * (float)g;
        *v = beta2 * *v + (1 - beta2) * (float)(g * g);
        t->appearance[i] -= lr * (*m / c1) / (sqrtf(*v / c2) + t->adam.eps);
        mean[i % 6] += t->appearance[i];
    }
    for (size_t i = 0; i < n; i++)
        t->appearance[i] -= (float)(mean[i % 6] / t->view_count);
}
