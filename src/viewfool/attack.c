/* Attack configuration, state life cycle and the step/run loop (the methods in nes.c, pepg.c). */
#include <stdlib.h>
#include <string.h>

#include "viewfool_internal.h"

void vf_attack_config_default(vf_attack_config *cfg, vf_attack_method method)
{
    memset(cfg, 0, sizeof *cfg);
    vf_view_bounds_default(&cfg->bounds);
    cfg->method = method;
    cfg->steps = 100;
    cfg->lambda = 0.01;
    cfg->lr = 0.1;
    cfg->seed = 0;
    cfg->sigma_init = 0.1;
    cfg->antithetic = 1;
    cfg->components = 1;
    cfg->weight_lr = 0.01;
    cfg->adam_beta1 = 0.9;
    cfg->adam_beta2 = 0.999;
    cfg->momentum = 0.9;
    cfg->lr_decay = 0.99;
    cfg->sigma_decay = 0.999;
    if (method == VF_ATTACK_PEPG) {
        cfg->samples = 51;
        cfg->sigma_min = 1e-6;
        cfg->sigma_max = 0.15;
        cfg->sigma_lr = 0.2;
    } else {
        cfg->samples = 50;
        cfg->sigma_min = 1e-3;
        cfg->sigma_max = 2.0;
        cfg->sigma_lr = 0.01;
    }
}

static int in_range(double x, double lo, double hi)
{
    return isfinite(x) && x >= lo && x <= hi;
}

vf_status vf_attack_config_check(const vf_attack_config *cfg)
{
    vf_status status = vf_view_bounds_check(&cfg->bounds);
    if (status != VF_OK)
        return status;
    if (cfg->method != VF_ATTACK_NES && cfg->method != VF_ATTACK_PEPG)
        return vf_fail(VF_EINPUT, "unknown attack method %d", (int)cfg->method);
    if (cfg->samples < 2 || cfg->samples > 1000000)
        return vf_fail(VF_EINPUT, "samples per step is %d: use 2 to 1000000", cfg->samples);
    if (cfg->method == VF_ATTACK_PEPG && (cfg->samples < 3 || cfg->samples % 2 == 0))
        return vf_fail(VF_EINPUT, "PEPG evaluates the mean and antithetic pairs: samples per "
                       "step (%d) must be odd and at least 3", cfg->samples);
    if (cfg->steps < 0)
        return vf_fail(VF_EINPUT, "steps is %d: use 0 or more", cfg->steps);
    if (!in_range(cfg->lambda, 0, 1e6))
        return vf_fail(VF_EINPUT, "lambda is %g: use a value >= 0", cfg->lambda);
    if (!(cfg->lr > 0) || !isfinite(cfg->lr))
        return vf_fail(VF_EINPUT, "learning rate is %g: use a value > 0", cfg->lr);
    if (!(cfg->sigma_min > 0) || !(cfg->sigma_min <= cfg->sigma_init) ||
        !(cfg->sigma_init <= cfg->sigma_max) || !isfinite(cfg->sigma_max))
        return vf_fail(VF_EINPUT, "sigma init %g must lie in [sigma min %g, sigma max %g], with "
                       "sigma min > 0", cfg->sigma_init, cfg->sigma_min, cfg->sigma_max);
    if (cfg->components < 1 || cfg->components > VF_ATTACK_MAX_COMPONENTS)
        return vf_fail(VF_EINPUT, "mixture components is %d: use 1 to %d", cfg->components,
                       VF_ATTACK_MAX_COMPONENTS);
    if (cfg->method == VF_ATTACK_PEPG && cfg->components != 1)
        return vf_fail(VF_EINPUT, "PEPG optimizes one Gaussian: use the NES method for a "
                       "mixture of %d components", cfg->components);
    if (!in_range(cfg->weight_lr, 0, 1e3))
        return vf_fail(VF_EINPUT, "mixture weight lr is %g: use a value >= 0", cfg->weight_lr);
    if (!in_range(cfg->adam_beta1, 0, 0.999999) || !in_range(cfg->adam_beta2, 0, 0.999999))
        return vf_fail(VF_EINPUT, "Adam betas %g, %g must lie in [0, 1)", cfg->adam_beta1,
                       cfg->adam_beta2);
    if (!in_range(cfg->sigma_lr, 0, 1e3))
        return vf_fail(VF_EINPUT, "sigma step %g must be >= 0", cfg->sigma_lr);
    if (!in_range(cfg->momentum, 0, 0.999999) || !in_range(cfg->lr_decay, 1e-6, 1) ||
        !in_range(cfg->sigma_decay, 1e-6, 1))
        return vf_fail(VF_EINPUT, "PEPG momentum %g must lie in [0, 1), lr decay %g and sigma "
                       "decay %g in (0, 1]", cfg->momentum, cfg->lr_decay, cfg->sigma_decay);
    return VF_OK;
}

vf_status vf_attack_init(vf_attack_state *st, const vf_attack_config *cfg)
{
    memset(st, 0, sizeof *st);
    vf_status status = vf_attack_config_check(cfg);
    if (status != VF_OK)
        return status;
    vf_rng_seed(&st->rng, cfg->seed);
    st->components = cfg->components;
    for (int c = 0; c < st->components; c++) {
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            st->mu[c][i] = 0.0;
            st->sigma[c][i] = cfg->sigma_init;
        }
        /* Mixture components must start apart (identical ones get identical gradients and
         * never separate): component c looks from the middle of the c-th of K equal yaw
         * sectors, tanh(mu_psi) = (2c + 1) / K - 1. K = 1 starts at the box centre. */
        st->mu[c][0] = atanh((2.0 * c + 1.0) / st->components - 1.0);
    }
    st->last_best_loss = st->best_loss = -INFINITY;
    vf_attack_component_view(st, cfg, 0, st->last_best_view);
    memcpy(st->best_view, st->last_best_view, sizeof st->best_view);
    return VF_OK;
}

void vf_attack_state_free(vf_attack_state *st)
{
    if (!st)
        return;
    free(st->history);
    st->history = NULL;
    st->history_cap = 0;
}

vf_status vf_attack_state_copy(vf_attack_state *dst, const vf_attack_state *src)
{
    *dst = *src;
    dst->history = NULL;
    dst->history_cap = 0;
    if (src->step > 0) {
        dst->history = malloc((size_t)src->step * sizeof *dst->history);
        if (!dst->history)
            return vf_fail(VF_EINTERNAL, "out of memory copying the attack state");
        memcpy(dst->history, src->history, (size_t)src->step * sizeof *dst->history);
        dst->history_cap = src->step;
    }
    return VF_OK;
}

vf_status vf_attack_step(vf_attack_state *st, const vf_attack_config *cfg,
                         vf_attack_loss_fn loss_fn, void *ctx)
{
    vf_status status = vf_attack_config_check(cfg);
    if (status != VF_OK)
        return status;
    if (st->components != cfg->components)
        return vf_fail(VF_EINPUT, "the attack state has %d mixture components but the config "
                       "asks for %d", st->components, cfg->components);
    return cfg->method == VF_ATTACK_PEPG ? vf__pepg_step(st, cfg, loss_fn, ctx)
                                         : vf__nes_step(st, cfg, loss_fn, ctx);
}

vf_status vf_attack_optimize(vf_attack_state *st, const vf_attack_config *cfg,
                             vf_attack_loss_fn loss_fn, void *ctx, vf_attack_step_hook hook,
                             void *hook_ctx)
{
    while (st->step < cfg->steps) {
        vf_status status = vf_attack_step(st, cfg, loss_fn, ctx);
        if (status == VF_OK && hook)
            status = hook(st, hook_ctx);
        if (status != VF_OK)
            return status;
    }
    return VF_OK;
}

vf_status vf_attack_estimate_gradient(const vf_attack_state *st, const vf_attack_config *cfg,
                                      vf_attack_loss_fn loss_fn, void *ctx, vf_rng *rng,
                                      double *grad)
{
    vf_status status = vf_attack_config_check(cfg);
    if (status != VF_OK)
        return status;
    if (cfg->method != VF_ATTACK_NES || st->components != cfg->components)
        return vf_fail(VF_EINPUT, "gradient estimates need the NES method and a state with the "
                       "config's number of components");
    int k = cfg->samples;
    double *views = malloc((size_t)k * VF_VIEW_DIM * sizeof *views);
    double *losses = malloc((size_t)k * sizeof *losses);
    int *fooled = malloc((size_t)k * sizeof *fooled);
    double entropy;
    if (!views || !losses || !fooled)
        status = vf_fail(VF_EINTERNAL, "out of memory for %d attack samples", k);
    else
        status =
            vf__nes_gradient(st, cfg, loss_fn, ctx, rng, grad, views, losses, fooled, &entropy);
    free(views);
    free(losses);
    free(fooled);
    return status;
}

/* ---- helpers shared by the methods ---- */
