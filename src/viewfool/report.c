/* What the attack reports: v*, samples of p*(v), their spread, camera fluctuation boxes, batch
 * evaluation with the success rate, and the random-search baseline. */
#include <stdlib.h>
#include <string.h>

#include "viewfool_internal.h"

void vf_attack_component_view(const vf_attack_state *st, const vf_attack_config *cfg, int c,
                              double v[VF_VIEW_DIM])
{
    vf_view_squash(&cfg->bounds, st->mu[c], v);
}

void vf_attack_v_star(const vf_attack_state *st, const vf_attack_config *cfg,
                      double v[VF_VIEW_DIM])
{
    double w[VF_ATTACK_MAX_COMPONENTS];
    vf_attack_weights(st, w);
    int heaviest = 0;
    for (int c = 1; c < st->components; c++)
        if (w[c] > w[heaviest])
            heaviest = c;
    vf_attack_component_view(st, cfg, heaviest, v);
}

void vf_attack_v_best(const vf_attack_state *st, double v[VF_VIEW_DIM])
{
    memcpy(v, st->last_best_view, VF_VIEW_DIM * sizeof *v);
}

void vf_attack_sample_views(const vf_attack_state *st, const vf_attack_config *cfg,
                            vf_rng *rng, int n, double *views)
{
    double w[VF_ATTACK_MAX_COMPONENTS];
    vf_attack_weights(st, w);
    for (int j = 0; j < n; j++) {
        int c = 0;
        if (st->components > 1) {
            double x = vf_rng_uniform(rng), cum = 0.0;
            for (c = 0; c < st->components - 1; c++) {
                cum += w[c];
                if (x < cum)
                    break;
            }
        }
        double u[VF_VIEW_DIM];
        for (int i = 0; i < VF_VIEW_DIM; i++)
            u[i] = st->mu[c][i] + st->sigma[c][i] * vf_rng_normal(rng);
        vf_view_squash(&cfg->bounds, u, views + j * VF_VIEW_DIM);
    }
}

void vf_view_std(const double *views, int n, double std[VF_VIEW_DIM])
{
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        double mean = 0.0, ss = 0.0;
        for (int j = 0; j < n; j++)
            mean += views[j * VF_VIEW_DIM + i] / n;
        for (int j = 0; j < n; j++) {
            double d = views[j * VF_VIEW_DIM + i] - mean;
            ss += d * d;
        }
        std[i] = n > 1 ? sqrt(ss / (n - 1)) : 0.0;
    }
}

void vf_view_fluctuation(const vf_view_bounds *search, const double centre[VF_VIEW_DIM],
                         double r_percent, vf_rng *rng, int n, double *views)
{
    double range[VF_VIEW_DIM];
    vf_view_bounds clip;
    vf_view_ranges_paper(range);
    vf_view_bounds_default(&clip);
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        clip.lo[i] = fmin(clip.lo[i], search->lo[i]);
        clip.hi[i] = fmax(clip.hi[i], search->hi[i]);
    }
    for (int j = 0; j < n; j++)
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            double half = r_percent / 100.0 * range[i];
            double v = centre[i] + half * (2.0 * vf_rng_uniform(rng) - 1.0);
            views[j * VF_VIEW_DIM + i] = clamp(v, clip.lo[i], clip.hi[i]);
        }
}

vf_status vf_attack_evaluate(vf_attack_loss_fn loss_fn, void *ctx, const double *views, int n,
                             double *losses, double *asr)
{
    if (n <= 0)
        return vf_fail(VF_EINPUT, "nothing to evaluate (%d viewpoints)", n);
    double *own = losses ? NULL : malloc((size_t)n * sizeof *own);
    int *fooled = malloc((size_t)n * sizeof *fooled);
    vf_status status;
    if ((!losses && !own) || !fooled) {
        status = vf_fail(VF_EINTERNAL, "out of memory evaluating %d viewpoints", n);
    } else {
        vf_attack_record rec;
        status = vf__evaluate_batch(loss_fn, ctx, views, n, losses ? losses : own, fooled);
        if (status == VF_OK && asr) {
            vf__batch_stats(losses ? losses : own, fooled, n, &rec);
            *asr = rec.fooled_rate;
        }
    }
    free(own);
    free(fooled);
    return status;
}

vf_status vf_attack_random_search(const vf_view_bounds *bounds, int n, uint64_t seed,
                                  vf_attack_loss_fn loss_fn, void *ctx, double *views,
                                  double *losses, vf_random_search_result *result)
{
    vf_status status = vf_view_bounds_check(bounds);
    if (status != VF_OK)
        return status;
    if (n <= 0)
        return vf_fail(VF_EINPUT, "random search needs at least one sample, not %d", n);
    double *own_views = views ? NULL : malloc((size_t)n * VF_VIEW_DIM * sizeof *own_views);
    double *own_losses = losses ? NULL : malloc((size_t)n * sizeof *own_losses);
    double *v = views ? views : own_views, *l = losses ? losses : own_losses;
    if (!v || !l) {
        status = vf_fail(VF_EINTERNAL, "out of memory for %d random viewpoints", n);
        goto done;
    }
    vf_rng rng;
    vf_rng_seed(&rng, seed);
    for (int j = 0; j < n * VF_VIEW_DIM; j++) {
        int i = j % VF_VIEW_DIM;
        v[j] = bounds->lo[i] + (bounds->hi[i] - bounds->lo[i]) * vf_rng_uniform(&rng);
    }
    if ((status = vf_attack_evaluate(loss_fn, ctx, v, n, l, &result->asr)) != VF_OK)
        goto done;
    int best = 0;
    for (int j = 1; j < n; j++)
        if (l[j] > l[best])
            best = j;
    result->best_loss = l[best];
    memcpy(result->best_view, v + best * VF_VIEW_DIM, sizeof result->best_view);
done:
    free(own_views);
    free(own_losses);
    return status;
}
