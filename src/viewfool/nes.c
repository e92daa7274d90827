/* VF_ATTACK_NES: the paper's search gradient (Eq. 7) with Adam, for one Gaussian or a mixture.
 *
 * Parameters per component c: mu_c (6), rho_c = log sigma_c (6), logit alpha_c; weights
 * pi = softmax(alpha). With samples u_j ~ p(u) and fitness F_j (the loss, see below) the
 * score-function ("log-likelihood trick") estimate of grad E[F] is
 *
 *     g = (1/k) sum_j (F_j - mean F) grad_theta log p(u_j)                        (Eq. 7)
 *
 * where, with z = (u - mu_c) / sigma_c and responsibilities r_c(u) = pi_c N_c(u) / p(u),
 *
 *     d log p / d mu_c    = r_c z / sigma_c
 *     d log p / d rho_c   = r_c (z^2 - 1)
 *     d log p / d alpha_c = r_c - pi_c.
 *
 * For one Gaussian r = 1 and z = eps_j, giving the familiar (1/k) sum (F_j - F_mean) eps_j /
 * sigma and (1/k) sum (F_j - F_mean)(eps_j^2 - 1) (the latter is sigma * d/dsigma). Subtracting
 * the batch mean is the variance-reducing baseline (it leaves the expectation unchanged up to
 * a 1/k bias). The natural gradient multiplies by the inverse Fisher information of the
 * Gaussian, diag(sigma^2) for mu and 1/2 for log sigma:
 *
 *     g_mu  = (1/k) sum_j (F_j - F_mean) sigma eps_j
 *     g_rho = (1/2k) sum_j (F_j - F_mean) (eps_j^2 - 1)
 *
 * (in sigma itself: (1/2k) sum_j (F_j - F_mean) sigma (eps_j^2 - 1)),
 *
 * applied per component for a mixture (ignoring the weights, an approximation) and not to the
 * logits. The entropy term: for K = 1 its exact gradient (vf_squashed_entropy, reparameterized,
 * chain-ruled to log sigma) is added times lambda with the same preconditioner; for K > 1 the
 * entropy has no closed form, so each sample's fitness carries lambda * (-log p(u_j) +
 * sum_i log(1 - tanh(u_ji)^2)), whose score-function gradient is that of lambda * H(p(v)).
 * Adam then ascends g on (mu, log sigma, alpha). Because Adam rescales each coordinate by its
 * running RMS, the natural-gradient factors mostly change how steps track sigma over time:
 * the mean's steps shrink with sigma^2. With lambda > 0 that helps on noisy losses; with
 * lambda = 0, where sigma keeps shrinking, it stalls the mean (see tests/test_viewfool.c). */
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
        s += log_sech2(u[i]);
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
        mixture_log_density(st, u, resp);
        vf_attack_weights(st, pi);
    }
    for (int c = 0; c < st->components; c++) {
        double r = resp[c];
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            /* for the sampled component z is eps exactly */
            double z = c == comp ? eps[i] : (u[i] - st->mu[c][i]) / st->sigma[c][i];
            grad[param_mu(c, i)] += weight * r * z / st->sigma[c][i];
            grad[param_log_sigma(c, i)] += weight * r * (z * z - 1.0);
        }
        if (st->components > 1)
            grad[param_logit(c)] += weight * (r - pi[c]);
    }
}

/* Multiply by the inverse Fisher of each component's Gaussian: sigma^2 for mu, 1/2 for
 * log sigma (the Fisher of log sigma is 2). */
static void natural_precondition(const vf_attack_state *st, double *grad)
{
    for (int c = 0; c < st->components; c++)
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            grad[param_mu(c, i)] *= st->sigma[c][i] * st->sigma[c][i];
            grad[param_log_sigma(c, i)] *= 0.5;
        }
}

/* Per-sample fitness for the score function; for K > 1 it carries the entropy term, and
 * *entropy gets H(p(v)) (exact for K = 1, Monte Carlo for K > 1). */
static void nes_fitness(const vf_attack_state *st, const vf_attack_config *cfg, const double *u,
                        const double *losses, int k, double *fitness, double *entropy)
{
    if (st->components == 1) {
        memcpy(fitness, losses, (size_t)k * sizeof *fitness);
        *entropy = vf_squashed_entropy(&cfg->bounds, st->mu[0], st->sigma[0], NULL, NULL);
        return;
    }
    /* h_j = -log p(u_j) + sum_i log(1 - tanh^2 u_ji): E[h] + sum_i log a_i = H(p(v)). */
    double h_sum = 0.0;
    for (int j = 0; j < k; j++) {
        const double *uj = u + j * VF_VIEW_DIM;
        double h = -mixture_log_density(st, uj, NULL) + sum_log_sech2(uj);
        h_sum += h;
        fitness[j] = losses[j] + cfg->lambda * h;
    }
    *entropy = h_sum / k + sum_log_half_range(&cfg->bounds);
}

/* Add lambda times the exact entropy gradient (K = 1), in (mu, log sigma) coordinates. */
static void add_entropy_gradient(const vf_attack_state *st, const vf_attack_config *cfg,
                                 double *grad)
{
    double g_mu[VF_VIEW_DIM], g_sigma[VF_VIEW_DIM];
    vf_squashed_entropy(&cfg->bounds, st->mu[0], st->sigma[0], g_mu, g_sigma);
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        double s = st->sigma[0][i];
        double d_mu = g_mu[i], d_rho = s * g_sigma[i]; /* dH/dlog sigma = sigma dH/dsigma */
        if (cfg->natural_gradient) {
            d_mu *= s * s;
            d_rho *= 0.5;
        }
        grad[param_mu(0, i)] += cfg->lambda * d_mu;
        grad[param_log_sigma(0, i)] += cfg->lambda * d_rho;
    }
}

vf_status nes_gradient(const vf_attack_state *st, const vf_attack_config *cfg,
                       vf_attack_loss_fn loss_fn, void *ctx, vf_rng *rng, double *grad,
                       double *views, double *losses, int *fooled, double *entropy)
{
    int k = cfg->samples, n_params = st->components * VF_ATTACK_COMPONENT_PARAMS;
    int *comp = malloc((size_t)k * sizeof *comp);
    double *eps = malloc((size_t)k * VF_VIEW_DIM * sizeof *eps);
    double *u = malloc((size_t)k * VF_VIEW_DIM * sizeof *u);
    double *fitness = malloc((size_t)k * sizeof *fitness);
    vf_status status = VF_OK;
    if (!comp || !eps || !u || !fitness) {
        status = vf_fail(VF_EINTERNAL, "out of memory for %d attack samples", k);
        goto done;
    }
    nes_sample(st, cfg, rng, k, comp, eps, u, views);
    if ((status = evaluate_batch(loss_fn, ctx, views, k, losses, fooled)) != VF_OK)
        goto done;

    nes_fitness(st, cfg, u, losses, k, fitness, entropy);
    double baseline = 0.0;
    for (int j = 0; j < k; j++)
        baseline += fitness[j] / k;
    memset(grad, 0, (size_t)n_params * sizeof *grad);
    for (int j = 0; j < k; j++)
        add_score(st, u + j * VF_VIEW_DIM, eps + j * VF_VIEW_DIM, comp[j],
                  (fitness[j] - baseline) / k, grad);
    if (cfg->natural_gradient)
        natural_precondition(st, grad);
    if (st->components == 1 && cfg->lambda != 0.0)
        add_entropy_gradient(st, cfg, grad);
done:
    free(comp);
    free(eps);
    free(u);
    free(fitness);
    return status;
}

/* Adam ascent on the parameter vector (the logits with their own, smaller step: Adam moves
 * every parameter by about lr a step whatever the gradient's size, so at the full lr a small
 * early lead would hand one component all the weight before the others reach their modes),
 * then the clips (|mu| <= 10, sigma in its range, |logit| <= 10). */
static void adam_update(vf_attack_state *st, const vf_attack_config *cfg, const double *grad)
{
    double t = st->step + 1;
    double fix1 = 1.0 - pow(cfg->adam_beta1, t), fix2 = 1.0 - pow(cfg->adam_beta2, t);
    double rho_lo = log(cfg->sigma_min), rho_hi = log(cfg->sigma_max);
    for (int c = 0; c < st->components; c++) {
        double theta[VF_ATTACK_COMPONENT_PARAMS];
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            theta[i] = st->mu[c][i];
            theta[VF_VIEW_DIM + i] = log(st->sigma[c][i]);
        }
        theta[2 * VF_VIEW_DIM] = st->logit[c];
        for (int p = 0; p < VF_ATTACK_COMPONENT_PARAMS; p++) {
            int idx = c * VF_ATTACK_COMPONENT_PARAMS + p;
            double g = grad[idx];
            st->moment1[idx] = cfg->adam_beta1 * st->moment1[idx] + (1.0 - cfg->adam_beta1) * g;
            st->moment2[idx] =
                cfg->adam_beta2 * st->moment2[idx] + (1.0 - cfg->adam_beta2) * g * g;
            double lr = p == 2 * VF_VIEW_DIM ? cfg->weight_lr : cfg->lr;
            theta[p] += lr * (st->moment1[idx] / fix1) / (sqrt(st->moment2[idx] / fix2) + 1e-8);
        }
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            st->mu[c][i] = clamp(theta[i], -MU_LIMIT, MU_LIMIT);
            st->sigma[c][i] = exp(clamp(theta[VF_VIEW_DIM + i], rho_lo, rho_hi));
        }
        st->logit[c] = st->components > 1 ? clamp(theta[2 * VF_VIEW_DIM], -LOGIT_LIMIT, LOGIT_LIMIT)
                                           : 0.0;
    }
}

vf_status nes_step(vf_attack_state *st, const vf_attack_config *cfg, vf_attack_loss_fn loss_fn,
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
    status = nes_gradient(st, cfg, loss_fn, ctx, &st->rng, grad, views, losses, fooled,
                          &rec.entropy);
    if (status != VF_OK)
        goto done;
    batch_stats(losses, fooled, k, &rec);
    if ((status = history_push(st, &rec)) != VF_OK)
        goto done;
    note_best(st, views, losses, k);
    adam_update(st, cfg, grad);
    st->step++;
done:
    free(views);
    free(losses);
    free(fooled);
    return status;
}
