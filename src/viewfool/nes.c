/* VF_ATTACK_NES: the paper's search gradient (Eq. 7) with Adam, for one Gaussian or a mixture.
 *
 * Parameters per component c: mu_c (6), sigma_c (6), logit alpha_c; weights pi = softmax(alpha).
 * With samples u_j ~ p(u) and losses L_j the score-function ("log-likelihood trick") estimate
 * of grad E[L] is
 *
 *     g = (1/k) sum_j (L_j - mean L) grad_theta log p(u_j)
 *
 * where, with z = (u - mu_c) / sigma_c and responsibilities r_c(u) = pi_c N_c(u) / p(u),
 *
 *     d log p / d mu_c    = r_c z / sigma_c
 *     d log p / d sigma_c = r_c (z^2 - 1) / sigma_c
 *     d log p / d alpha_c = r_c - pi_c.
 *
 * Subtracting the batch mean is the variance-reducing baseline (it leaves the expectation
 * unchanged up to a 1/k bias). Eq. 7 preconditions this loss term by the inverse Fisher of
 * each component's Gaussian, sigma^2 for mu and sigma^2 / 2 for sigma (its Fisher is 2 /
 * sigma^2), so for one Gaussian (r = 1, z = eps_j)
 *
 *     g_mu    = (1/k) sum_j (L_j - mean L) sigma eps_j
 *     g_sigma = (1/k) sum_j (L_j - mean L) sigma (eps_j^2 - 1) / 2
 *
 * and adds lambda times the *plain* gradient of the entropy: for K = 1 the exact one
 * (vf_squashed_entropy: dH/dsigma is about 1 / sigma), for K > 1, where H has no closed form,
 * its score-function estimate (1/k) sum_j (h_j - mean h) grad log p(u_j) with h_j = -log p(u_j)
 * + sum_i log(1 - tanh^2 u_ji), whose expectation plus sum_i log a_i is H(p(v)). The
 * natural-gradient factors are not applied to the logits or to the entropy.
 *
 * Why this shape matters: near a maximum of L of curvature -c the loss term in sigma is about
 * -c sigma^3 / 2 (it shrinks with sigma) while lambda dH/dsigma is about lambda / sigma (it
 * grows), so sigma settles near (2 lambda / c)^(1/4): wider for larger lambda, collapsing only
 * at lambda = 0. Scaling the entropy by the Fisher too, or ascending log sigma, removes that
 * balance (the loss term wins by orders of magnitude and p*(v) collapses to a point; measured
 * on chair: std psi 0.4 deg at lambda 0.01).
 *
 * Adam then ascends g: mu with step cfg->lr, sigma with cfg->sigma_lr (sigma kept in
 * [sigma_min, sigma_max]), the logits with cfg->weight_lr. */
#include <stdlib.h>
#include <string.h>

#include "viewfool_internal.h"

/* Draw k samples: component comp[j], normal eps[j], u[j] = mu + sigma * eps, and views. */
static void nes_sample(const vf_attack_state *st, const vf_attack_config *cfg, vf_rng *rng,
                       int k, int *comp, double *eps, double *u, double *views)
{
    double weights[VF_ATTACK_MAX_COMPONENTS];
    vf_attack_weights(st, weights);
    for (int j = 0; j < k; j++) {
        double *e = eps + j * VF_VIEW_DIM;
        if (cfg->antithetic && j % 2 == 1) {
            comp[j] = comp[j - 1];
            for (int i = 0; i < VF_VIEW_DIM; i++)
                e[i] = -e[i - VF_VIEW_DIM];
        } else {
            int c = 0;
            if (st->components > 1) {
                double x = vf_rng_uniform(rng), cum = 0.0;
                for (c = 0; c < st->components - 1; c++) {
                    cum += weights[c];
                    if (x < cum)
                        break;
                }
            }
            comp[j] = c;
            for (int i = 0; i < VF_VIEW_DIM; i++)
                e[i] = vf_rng_normal(rng);
        }
        double *uj = u + j * VF_VIEW_DIM;
        for (int i = 0; i < VF_VIEW_DIM; i++)
            uj[i] = st->mu[comp[j]][i] + st->sigma[comp[j]][i] * e[i];
        vf_view_squash(&cfg->bounds, uj, views + j * VF_VIEW_DIM);
    }
}

static double sum_log_sech2(const double u[VF_VIEW_DIM])
{
    double s = 0.0;
    for (int i = 0; i < VF_VIEW_DIM; i++)
        s += vf__log_sech2(u[i]);
    return s;
}

static double sum_log_half_range(const vf_view_bounds *b)
{
    double s = 0.0;
    for (int i = 0; i < VF_VIEW_DIM; i++)
        s += log(view_half_range(b, i));
    return s;
}

/* Add weight * grad_theta log p(u) to grad (plain gradient, before any preconditioning). */
static void add_score(const vf_attack_state *st, const double u[VF_VIEW_DIM],
                      const double eps[VF_VIEW_DIM], int comp, double weight, double *grad)
{
    double resp[VF_ATTACK_MAX_COMPONENTS] = {1.0}, pi[VF_ATTACK_MAX_COMPONENTS] = {1.0};
    if (st->components > 1) {
        vf__mixture_log_density(st, u, resp);
        vf_attack_weights(st, pi);
    }
    for (int c = 0; c < st->components; c++) {
        double r = resp[c];
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            /* for the sampled component z is eps exactly */
            double z = c == comp ? eps[i] : (u[i] - st->mu[c][i]) / st->sigma[c][i];
            grad[param_mu(c, i)] += weight * r * z / st->sigma[c][i];
            grad[param_sigma(c, i)] += weight * r * (z * z - 1.0) / st->sigma[c][i];
        }
        if (st->components > 1)
            grad[param_logit(c)] += weight * (r - pi[c]);
    }
}

/* Multiply by the inverse Fisher of each component's Gaussian: sigma^2 for mu, sigma^2 / 2
 * for sigma. */
static void natural_precondition(const vf_attack_state *st, double *grad)
{
    for (int c = 0; c < st->components; c++)
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            double s2 = st->sigma[c][i] * st->sigma[c][i];
            grad[param_mu(c, i)] *= s2;
            grad[param_sigma(c, i)] *= 0.5 * s2;
        }
}

/* (1/k) sum_j (x_j - mean x) grad log p(u_j) into grad (zeroed first): the plain score-function
 * gradient of E[x]. */
static void score_gradient(const vf_attack_state *st, const double *u, const double *eps,
                           const int *comp, const double *x, int k, double *grad)
{
    double baseline = 0.0;
    for (int j = 0; j < k; j++)
        baseline += x[j] / k;
    memset(grad, 0, (size_t)st->components * VF_ATTACK_COMPONENT_PARAMS * sizeof *grad);
    for (int j = 0; j < k; j++)
        add_score(st, u + j * VF_VIEW_DIM, eps + j * VF_VIEW_DIM, comp[j], (x[j] - baseline) / k,
                  grad);
}

/* lambda times the plain entropy gradient into grad, and H(p(v)) into *entropy: exact for
 * K = 1, score-function and Monte Carlo over the step's samples for K > 1 (h: scratch, k). */
static void add_entropy_gradient(const vf_attack_state *st, const vf_attack_config *cfg,
                                 const double *u, const double *eps, const int *comp, int k,
                                 double *h, double *grad, double *entropy)
{
    if (st->components == 1) {
        double g_mu[VF_VIEW_DIM], g_sigma[VF_VIEW_DIM];
        *entropy = vf_squashed_entropy(&cfg->bounds, st->mu[0], st->sigma[0], g_mu, g_sigma);
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            grad[param_mu(0, i)] += cfg->lambda * g_mu[i];
            grad[param_sigma(0, i)] += cfg->lambda * g_sigma[i];
        }
        return;
    }
    double h_sum = 0.0, g_h[VF_ATTACK_MAX_PARAMS];
    for (int j = 0; j < k; j++) {
        const double *uj = u + j * VF_VIEW_DIM;
        h[j] = -vf__mixture_log_density(st, uj, NULL) + sum_log_sech2(uj);
        h_sum += h[j];
    }
    *entropy = h_sum / k + sum_log_half_range(&cfg->bounds);
    if (cfg->lambda == 0.0)
        return;
    score_gradient(st, u, eps, comp, h, k, g_h);
    for (int p = 0; p < st->components * VF_ATTACK_COMPONENT_PARAMS; p++)
        grad[p] += cfg->lambda * g_h[p];
}

vf_status vf__nes_gradient(const vf_attack_state *st, const vf_attack_config *cfg,
                           vf_attack_loss_fn loss_fn, void *ctx, vf_rng *rng, double *grad,
                           double *views, double *losses, int *fooled, double *entropy)
{
    int k = cfg->samples;
    int *comp = malloc((size_t)k * sizeof *comp);
    double *eps = malloc((size_t)k * VF_VIEW_DIM * sizeof *eps);
    double *u = malloc((size_t)k * VF_VIEW_DIM * sizeof *u);
    double *h = malloc((size_t)k * sizeof *h);
    vf_status status = VF_OK;
    if (!comp || !eps || !u || !h) {
        status = vf_fail(VF_EINTERNAL, "out of memory for %d attack samples", k);
        goto done;
    }
    nes_sample(st, cfg, rng, k, comp, eps, u, views);
    if ((status = vf__evaluate_batch(loss_fn, ctx, views, k, losses, fooled)) != VF_OK)
        goto done;
    score_gradient(st, u, eps, comp, losses, k, grad);
    natural_precondition(st, grad);
    add_entropy_gradient(st, cfg, u, eps, comp, k, h, grad, entropy);
done:
    free(comp);
    free(eps);
    free(u);
    free(h);
    return status;
}

/* Adam ascent on the parameter vector, each kind of parameter with its own step: mu by lr,
 * sigma by sigma_lr, the logits by weight_lr (Adam moves every parameter by about its step
 * whatever the gradient's size, so at the full lr a small early lead would hand one component
 * all the weight before the others reach their modes). Then the clips: |mu| <= 10, sigma in
 * its range, |logit| <= 10. */
static void adam_update(vf_attack_state *st, const vf_attack_config *cfg, const double *grad)
{
    double t = st->step + 1;
    double fix1 = 1.0 - pow(cfg->adam_beta1, t), fix2 = 1.0 - pow(cfg->adam_beta2, t);
    for (int c = 0; c < st->components; c++) {
        double theta[VF_ATTACK_COMPONENT_PARAMS];
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            theta[i] = st->mu[c][i];
            theta[VF_VIEW_DIM + i] = st->sigma[c][i];
        }
        theta[2 * VF_VIEW_DIM] = st->logit[c];
        for (int p = 0; p < VF_ATTACK_COMPONENT_PARAMS; p++) {
            int idx = c * VF_ATTACK_COMPONENT_PARAMS + p;
            double g = grad[idx];
            st->moment1[idx] = cfg->adam_beta1 * st->moment1[idx] + (1.0 - cfg->adam_beta1) * g;
            st->moment2[idx] =
                cfg->adam_beta2 * st->moment2[idx] + (1.0 - cfg->adam_beta2) * g * g;
            double lr = p < VF_VIEW_DIM ? cfg->lr : p < 2 * VF_VIEW_DIM ? cfg->sigma_lr
                                                                         : cfg->weight_lr;
            theta[p] += lr * (st->moment1[idx] / fix1) / (sqrt(st->moment2[idx] / fix2) + 1e-8);
        }
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            st->mu[c][i] = clamp(theta[i], -MU_LIMIT, MU_LIMIT);
            st->sigma[c][i] = clamp(theta[VF_VIEW_DIM + i], cfg->sigma_min, cfg->sigma_max);
        }
        st->logit[c] = st->components > 1 ? clamp(theta[2 * VF_VIEW_DIM], -LOGIT_LIMIT, LOGIT_LIMIT)
                                           : 0.0;
    }
}

vf_status vf__nes_step(vf_attack_state *st, const vf_attack_config *cfg, vf_attack_loss_fn loss_fn,
                       void *ctx)
{
    int k = cfg->samples;
    double grad[VF_ATTACK_MAX_PARAMS];
    double *views = malloc((size_t)k * VF_VIEW_DIM * sizeof *views);
    double *losses = malloc((size_t)k * sizeof *losses);
    int *fooled = malloc((size_t)k * sizeof *fooled);
    vf_attack_record rec;
    vf_status status;
    if (!views || !losses || !fooled) {
        status = vf_fail(VF_EINTERNAL, "out of memory for %d attack samples", k);
        goto done;
    }
    status = vf__nes_gradient(st, cfg, loss_fn, ctx, &st->rng, grad, views, losses, fooled,
                              &rec.entropy);
    if (status != VF_OK)
        goto done;
    vf__batch_stats(losses, fooled, k, &rec);
    if ((status = vf__history_push(st, &rec)) != VF_OK)
        goto done;
    vf__note_best(st, views, losses, k);
    adam_update(st, cfg, grad);
    st->step++;
done:
    free(views);
    free(losses);
    free(fooled);
    return status;
}
