/* VF_ATTACK_PEPG: the reference code's optimizer (Sehnke et al.'s parameter-exploring policy
 * gradients as in estool, with ViewFool's settings), one Gaussian only.
 *
 * Each step evaluates k = 2n + 1 viewpoints: the mean mu itself (sample 0) and n antithetic
 * pairs u = mu +- sigma * eps_j. The k losses are replaced by centred ranks s in [-0.5, 0.5]
 * (lowest -0.5, highest +0.5), which makes the update blind to the loss scale; the mean's rank
 * s_0 is the baseline. Then
 *
 *     g_mu    = sum_j (s+_j - s-_j) sigma eps_j                     + lambda dH/dmu
 *     g_sigma = sum_j ((s+_j + s-_j) / 2 - s_0) sigma (eps_j^2 - 1) / (2n) + lambda dH/dsigma
 *
 * (the plain entropy gradient, on the rank scale). mu follows momentum SGD: velocity =
 * momentum * velocity + (1 - momentum) * g_mu, mu += lr * lr_decay^t * velocity. sigma moves
 * by sigma_lr * g_sigma with the change clipped to +-20% of sigma, is clipped to
 * [sigma_min, sigma_max] (the reference: [0, 0.15]), and then decays by sigma_decay where it
 * exceeds 0.01. The reference reports the best sample of the last step (the mean included) as
 * its v*: vf_attack_v_best. */
#include <stdlib.h>
#include <string.h>

#include "viewfool_internal.h"

typedef struct {
    double loss;
    int index;
} ranked;

static int compare_ranked(const void *pa, const void *pb)
{
    const ranked *a = pa, *b = pb;
    if (a->loss != b->loss)
        return a->loss < b->loss ? -1 : 1;
    return a->index - b->index; /* a total order, so qsort's result is deterministic */
}

/* shaped[i] = rank(losses[i]) / (n - 1) - 0.5, tied losses sharing their mean rank (so a flat
 * stretch of the loss gives no push in any direction). */
static vf_status centred_ranks(const double *losses, int n, double *shaped)
{
    ranked *order = malloc((size_t)n * sizeof *order);
    if (!order)
        return vf_fail(VF_EINTERNAL, "out of memory ranking %d losses", n);
    for (int i = 0; i < n; i++)
        order[i] = (ranked){losses[i], i};
    qsort(order, (size_t)n, sizeof *order, compare_ranked);
    for (int r = 0; r < n;) {
        int end = r + 1;
        while (end < n && order[end].loss == order[r].loss)
            end++;
        double rank = 0.5 * (r + end - 1);
        for (; r < end; r++)
            shaped[order[r].index] = rank / (n - 1) - 0.5;
    }
    free(order);
    return VF_OK;
}

/* views[0] = the mean, views[1..n] = mu + sigma eps, views[n+1..2n] = mu - sigma eps. */
static void pepg_sample(vf_attack_state *st, const vf_attack_config *cfg, int pairs,
                        double *eps, double *views)
{
    vf_rng *rng = &st->rng;
    vf_view_squash(&cfg->bounds, st->mu[0], views);
    for (int j = 0; j < pairs; j++) {
        double *e = eps + j * VF_VIEW_DIM, up[VF_VIEW_DIM], um[VF_VIEW_DIM];
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            e[i] = vf_rng_normal(rng);
            up[i] = st->mu[0][i] + st->sigma[0][i] * e[i];
            um[i] = st->mu[0][i] - st->sigma[0][i] * e[i];
        }
        vf_view_squash(&cfg->bounds, up, views + (1 + j) * VF_VIEW_DIM);
        vf_view_squash(&cfg->bounds, um, views + (1 + pairs + j) * VF_VIEW_DIM);
    }
}

/* g_mu and g_sigma from the shaped fitness, plus the entropy terms. */
static void pepg_gradient(const vf_attack_state *st, const vf_attack_config *cfg, int pairs,
                          const double *eps, const double *shaped, double g_mu[VF_VIEW_DIM],
                          double g_sigma[VF_VIEW_DIM])
{
    const double *sigma = st->sigma[0], *plus = shaped + 1, *minus = shaped + 1 + pairs;
    double baseline = shaped[0];
    memset(g_mu, 0, VF_VIEW_DIM * sizeof *g_mu);
    memset(g_sigma, 0, VF_VIEW_DIM * sizeof *g_sigma);
    for (int j = 0; j < pairs; j++) {
        double diff = plus[j] - minus[j], avg = 0.5 * (plus[j] + minus[j]) - baseline;
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            double e = eps[j * VF_VIEW_DIM + i];
            g_mu[i] += diff * sigma[i] * e;
            g_sigma[i] += avg * sigma[i] * (e * e - 1.0) / (2.0 * pairs);
        }
    }
    if (cfg->lambda != 0.0) {
        double h_mu[VF_VIEW_DIM], h_sigma[VF_VIEW_DIM];
        vf_squashed_entropy(&cfg->bounds, st->mu[0], sigma, h_mu, h_sigma);
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            g_mu[i] += cfg->lambda * h_mu[i];
            g_sigma[i] += cfg->lambda * h_sigma[i];
        }
    }
}

static void pepg_update(vf_attack_state *st, const vf_attack_config *cfg,
                        const double g_mu[VF_VIEW_DIM], const double g_sigma[VF_VIEW_DIM])
{
    double lr = cfg->lr * pow(cfg->lr_decay, st->step);
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        double *velocity = &st->moment1[param_mu(0, i)];
        *velocity = cfg->momentum * *velocity + (1.0 - cfg->momentum) * g_mu[i];
        st->mu[0][i] = clamp(st->mu[0][i] + lr * *velocity, -MU_LIMIT, MU_LIMIT);
        double s = st->sigma[0][i];
        double change = clamp(cfg->sigma_lr * g_sigma[i], -0.2 * s, 0.2 * s);
        s = clamp(s + change, cfg->sigma_min, cfg->sigma_max);
        st->sigma[0][i] = s > 0.01 ? fmax(s * cfg->sigma_decay, cfg->sigma_min) : s;
    }
}

vf_status vf__pepg_step(vf_attack_state *st, const vf_attack_config *cfg,
                        vf_attack_loss_fn loss_fn, void *ctx)
{
    int pairs = (cfg->samples - 1) / 2, k = 2 * pairs + 1;
    double *eps = malloc((size_t)pairs * VF_VIEW_DIM * sizeof *eps);
    double *views = malloc((size_t)k * VF_VIEW_DIM * sizeof *views);
    double *losses = malloc((size_t)k * sizeof *losses);
    double *shaped = malloc((size_t)k * sizeof *shaped);
    int *fooled = malloc((size_t)k * sizeof *fooled);
    vf_status status;
    if (!eps || !views || !losses || !shaped || !fooled) {
        status = vf_fail(VF_EINTERNAL, "out of memory for %d attack samples", k);
        goto done;
    }
    pepg_sample(st, cfg, pairs, eps, views);
    if ((status = vf__evaluate_batch(loss_fn, ctx, views, k, losses, fooled)) != VF_OK)
        goto done;
    if ((status = centred_ranks(losses, k, shaped)) != VF_OK)
        goto done;

    vf_attack_record rec;
    vf__batch_stats(losses, fooled, k, &rec);
    rec.entropy = vf_squashed_entropy(&cfg->bounds, st->mu[0], st->sigma[0], NULL, NULL);
    if ((status = vf__history_push(st, &rec)) != VF_OK)
        goto done;
    vf__note_best(st, views, losses, k);

    double g_mu[VF_VIEW_DIM], g_sigma[VF_VIEW_DIM];
    pepg_gradient(st, cfg, pairs, eps, shaped, g_mu, g_sigma);
    pepg_update(st, cfg, g_mu, g_sigma);
    st->step++;
done:
    free(eps);
    free(views);
    free(losses);
    free(shaped);
    free(fooled);
    return status;
}
