/* vf/viewfool.h: the ViewFool optimizer (Dong et al., NeurIPS 2022), independent of any renderer.
 *
 * A viewpoint is six numbers in the order (psi, theta, phi, dx, dy, dz), the field order of
 * vf_viewpoint in vf/pose.h; a batch of n viewpoints is a row-major n x 6 array. The attack
 * learns a distribution over viewpoints inside a box [lo, hi]:
 *
 *     v = a * tanh(u) + b,   u ~ N(mu, diag(sigma^2)),   a = (hi - lo) / 2,  b = (hi + lo) / 2
 *
 * (or a mixture of K such Gaussians in u, GMVFool-style) and maximizes
 *
 *     J(mu, sigma) = E_p(v)[ L(v) ] + lambda * H(p(v))
 *
 * where L(v) is the classifier's cross-entropy on the render at v with the true label. The
 * caller supplies L as a batch callback (render k viewpoints, classify, return k losses), so
 * this module never touches images. Two optimizers:
 *
 *   VF_ATTACK_NES   the paper's Eq. 7 in (mu, sigma): the score-function (NES) gradient of
 *                   E[L] with a mean-loss baseline, preconditioned by the inverse Fisher
 *                   (natural gradient), plus the plain exact gradient of lambda * H; Adam
 *                   ascent on mu, sigma (and the mixture logits). The loss term's natural
 *                   gradient in sigma shrinks like sigma^3 while the entropy's grows like
 *                   lambda / sigma, so sigma settles where they balance, wider for larger
 *                   lambda: that balance is what keeps p*(v) a distribution. Formulas:
 *                   src/viewfool/nes.c.
 *   VF_ATTACK_PEPG  the reference code's optimizer: PEPG with the mean as sample 0 and
 *                   antithetic pairs, centred-rank fitness, momentum SGD on mu with a
 *                   decaying step, sigma clipped to 0.15 (src/viewfool/pepg.c).
 *
 * Two answers are reported for every method: v* = a * tanh(mu*) + b (the paper's definition,
 * vf_attack_v_star) and the best sample of the last step (the reference code's, vf_attack_v_best).
 *
 * The optimizer state is a plain struct (plus one heap array, the per-step history) that
 * serializes to JSON, so an interrupted attack resumes bit-exactly. Memory: the caller owns
 * every array it passes in and every vf_attack_state it initializes (free it with
 * vf_attack_state_free); JSON values returned are new references the caller must decref. */
#ifndef VF_VIEWFOOL_H
#define VF_VIEWFOOL_H

#include <jansson.h>
#include <stdint.h>

#include "vf/error.h"
#include "vf/pose.h"
#include "vf/rng.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_ATTACK_MAX_COMPONENTS 8 /* largest mixture K */
/* Per component: mu[6], sigma[6], one mixture logit. */
#define VF_ATTACK_COMPONENT_PARAMS (2 * VF_VIEW_DIM + 1)
#define VF_ATTACK_MAX_PARAMS (VF_ATTACK_MAX_COMPONENTS * VF_ATTACK_COMPONENT_PARAMS)

/* ---- viewpoint box and the tanh squashing ---- */

typedef struct vf_view_bounds {
    double lo[VF_VIEW_DIM], hi[VF_VIEW_DIM];
} vf_view_bounds;

/* The default box: psi [-180, 180], theta [-30, 30], phi [20, 160] (degrees), dx [-0.5, 0.5],
 * dy [-1, 1], dz [-0.5, 0.5] (scene units). */
void vf_view_bounds_default(vf_view_bounds *bounds);

/* VF_EINPUT unless every lo < hi and both are finite. */
vf_status vf_view_bounds_check(const vf_view_bounds *bounds);

/* "psi", "theta", "phi", "dx", "dy", "dz" for i = 0..5 ("?" otherwise). */
const char *vf_view_param_name(int i);

/* Replace the parameters named in text, "psi=-90:90,phi=100:160" (lo < hi, finite), leaving
 * the others as they are. VF_EINPUT naming the item that does not parse. */
vf_status vf_view_bounds_parse(const char *text, vf_view_bounds *bounds);

/* The paper's full range of each parameter, the widths of the default box: psi 360 deg,
 * theta 60, phi 140, dx 1, dy 2, dz 1. Camera fluctuation and the re-shoot tolerance are
 * percentages of these, not of a (narrowed) search box, so figures compare across objects. */
void vf_view_ranges_paper(double range[VF_VIEW_DIM]);

/* Search spaces of the paper's Table 1: all six parameters, the rotation (psi, theta, phi) with
 * the offsets fixed, or the translation (dx, dy, dz) with the angles fixed. */
typedef enum { VF_SPACE_BOTH = 0, VF_SPACE_ROTATION = 1, VF_SPACE_TRANSLATION = 2 } vf_view_space;

/* "both", "rotation", "translation"; VF_EINPUT naming the choices otherwise. */
vf_status vf_view_space_parse(const char *name, vf_view_space *space);
const char *vf_view_space_name(vf_view_space space);

/* Fix the parameters outside the space (a box 2e-6 wide) at the values of `at`, clipped into
 * the box, or at the box's centre when `at` is NULL. Callers pass a natural viewpoint (the
 * training view the classifier recognises best): the centre of the default box looks
 * straight down (phi 90), where the translation space would start out misclassified. */
void vf_view_bounds_restrict(vf_view_bounds *bounds, vf_view_space space,
                             const double at[VF_VIEW_DIM]);

/* v = a * tanh(u) + b, one viewpoint. */
void vf_view_squash(const vf_view_bounds *bounds, const double u[VF_VIEW_DIM],
                    double v[VF_VIEW_DIM]);

/* ---- entropy of the squashed Gaussian ---- */

/* E[log(1 - tanh(u)^2)] for u ~ N(mu, sigma^2), the expected log-Jacobian of the squashing in
 * one dimension, by a 321-point trapezoid rule in eps (error ~1e-13 for sigma <= 2).
 * d_mu, d_sigma (may be NULL) receive its derivatives E[-2 tanh(u)] and E[-2 tanh(u) eps]
 * with u = mu + sigma * eps (reparameterization). Thread-safe. */
double vf_log_jacobian_mean(double mu, double sigma, double *d_mu, double *d_sigma);

/* Differential entropy of p(v) for one diagonal Gaussian in u squashed into the box:
 *     H = sum_i [ 0.5 log(2 pi e sigma_i^2) + log a_i + E log(1 - tanh(u_i)^2) ]
 * grad_mu and grad_sigma (6 each, may be NULL) receive dH/dmu and dH/dsigma. */
double vf_squashed_entropy(const vf_view_bounds *bounds, const double mu[VF_VIEW_DIM],
                           const double sigma[VF_VIEW_DIM], double grad_mu[VF_VIEW_DIM],
                           double grad_sigma[VF_VIEW_DIM]);

/* ---- configuration ---- */

typedef enum { VF_ATTACK_NES = 0, VF_ATTACK_PEPG = 1 } vf_attack_method;

typedef struct vf_attack_config {
    vf_view_bounds bounds;
    vf_attack_method method;
    int samples;    /* k, loss evaluations per step (PEPG: the mean and (k-1)/2 antithetic
                     * pairs, k odd) */
    int steps;      /* vf_attack_optimize stops when the state reaches this many steps */
    double lambda;  /* entropy weight */
    double lr;      /* step of mu: Adam (NES, in u units) or momentum SGD (PEPG) */
    uint64_t seed;  /* seeds the state's RNG at vf_attack_init */

    /* sigma (in u units): initial value and the range it is kept in */
    double sigma_init, sigma_min, sigma_max;
    double sigma_lr; /* NES: Adam step of sigma; PEPG: sigma step (each change clipped to
                      * +-20% of sigma) */

    /* NES only */
    int antithetic;       /* 1: samples come in mirrored pairs eps, -eps */
    int components;       /* K, mixture components in u (1 = the paper's single Gaussian) */
    double weight_lr;     /* K > 1: Adam step of the mixture logits (0 keeps weights equal) */
    double adam_beta1, adam_beta2;

    /* PEPG only */
    double momentum;    /* velocity = momentum * velocity + (1 - momentum) * gradient */
    double lr_decay;    /* lr at step t is lr * lr_decay^t */
    double sigma_decay; /* after each step, sigma > 0.01 is multiplied by this */
} vf_attack_config;

/* Defaults for a method: bounds as vf_view_bounds_default, 100 steps, seed 0, lambda 0.01 and
 *   NES:  k = 50, Adam (beta 0.9, 0.999) with step 0.1 on mu and 0.01 on sigma, sigma 0.1 in
 *         [1e-3, 2], antithetic sampling, K = 1 (mixture logits' Adam step 0.01);
 *   PEPG: the reference code's settings: k = 51 (the mean and 25 antithetic pairs), lr 0.1
 *         decaying 0.99 a step, momentum 0.9, sigma 0.1 in [1e-6, 0.15] (the reference clips
 *         at 0; a tiny floor keeps the score finite), sigma step 0.2, sigma decay 0.999.
 * The step sizes of NES were chosen by measurement (tests/test_viewfool.c, bench_attack). */
void vf_attack_config_default(vf_attack_config *cfg, vf_attack_method method);

/* VF_EINPUT with a one-line reason when a field is out of range (for example PEPG with K > 1,
 * an even PEPG k, sigma_min <= 0). */
vf_status vf_attack_config_check(const vf_attack_config *cfg);

/* Every field as a JSON object (a new reference); the seed as a decimal string. */
json_t *vf_attack_config_to_json(const vf_attack_config *cfg);

/* Read a config written by vf_attack_config_to_json. Missing keys keep the method's defaults;
 * VF_EINPUT when a present key has the wrong type or the result fails the check. */
vf_status vf_attack_config_from_json(const json_t *json, vf_attack_config *cfg);

/* ---- the loss callback ---- */

/* Evaluate n viewpoints (views: n x 6): write losses[i] = L(views[i]) (cross-entropy, to be
 * maximized) and, optionally, fooled[i] = 1 when the classifier's top-1 is not the true label.
 * fooled arrives zeroed; a callback that does not know may leave it. A non-finite loss is an
 * error. Return VF_OK or a vf_fail() status, which aborts the step unchanged. */
typedef vf_status (*vf_attack_loss_fn)(const double *views, int n, double *losses, int *fooled,
                                       void *ctx);

/* ---- optimizer state ---- */

/* One step's summary. entropy is H(p(v)) before the update (exact for K = 1, a Monte Carlo
 * estimate over the step's samples for K > 1). */
typedef struct vf_attack_record {
    double mean_loss, max_loss, fooled_rate, entropy;
} vf_attack_record;

typedef struct vf_attack_state {
    int components; /* K */
    double mu[VF_ATTACK_MAX_COMPONENTS][VF_VIEW_DIM];
    double sigma[VF_ATTACK_MAX_COMPONENTS][VF_VIEW_DIM];
    double logit[VF_ATTACK_MAX_COMPONENTS]; /* mixture weights are softmax(logit) */

    /* Optimizer memory over the parameter vector (per component: mu, sigma, logit).
     * NES: Adam's first and second moments. PEPG: moment1[0..5] is the velocity of mu. */
    double moment1[VF_ATTACK_MAX_PARAMS], moment2[VF_ATTACK_MAX_PARAMS];

    int step; /* steps taken */
    vf_rng rng;

    /* Best sample of the most recent step, and of all steps (loss -inf before any step). */
    double last_best_view[VF_VIEW_DIM], last_best_loss;
    double best_view[VF_VIEW_DIM], best_loss;

    /* One record per step taken; owned by the state (heap). */
    vf_attack_record *history;
    int history_cap;
} vf_attack_state;

/* Start an attack: mu = 0 (the box centre); for K > 1 component c instead starts in the middle
 * of the c-th of K equal yaw sectors (tanh(mu_psi) = (2c + 1) / K - 1, so K = 2 looks from
 * psi = -90 and +90); sigma = sigma_init; equal weights; zero moments; no history; RNG seeded
 * with cfg->seed. Free with vf_attack_state_free. VF_EINPUT if the config fails its check. */
vf_status vf_attack_init(vf_attack_state *st, const vf_attack_config *cfg);

/* Free the history; the struct may be initialized again. NULL is fine. */
void vf_attack_state_free(vf_attack_state *st);

/* Deep copy (dst is overwritten, not freed first). VF_EINTERNAL when out of memory. */
vf_status vf_attack_state_copy(vf_attack_state *dst, const vf_attack_state *src);

/* One optimization step: draw cfg->samples viewpoints from the state's RNG, call loss_fn once
 * with all of them, update the distribution, append a history record. On an error from
 * loss_fn (or a non-finite loss) the parameters, moments and history are left unchanged (the
 * RNG has advanced). */
vf_status vf_attack_step(vf_attack_state *st, const vf_attack_config *cfg,
                         vf_attack_loss_fn loss_fn, void *ctx);

/* Called after every step of vf_attack_optimize (for progress and checkpoints); a non-OK return
 * stops the run with that status. */
typedef vf_status (*vf_attack_step_hook)(const vf_attack_state *st, void *hook_ctx);

/* Step until st->step == cfg->steps (a resumed state continues where it stopped). hook may be
 * NULL. */
vf_status vf_attack_optimize(vf_attack_state *st, const vf_attack_config *cfg,
                             vf_attack_loss_fn loss_fn, void *ctx, vf_attack_step_hook hook,
                             void *hook_ctx);

/* The NES ascent direction at the current state, estimated from cfg->samples samples drawn
 * from rng (not the state's): what vf_attack_step feeds to Adam, the natural gradient of the
 * loss term plus lambda times the plain entropy gradient. grad gets components * 13 numbers
 * laid out per component as d/dmu[6], d/dsigma[6], d/dlogit. For tests and diagnostics; NES
 * only (VF_EINPUT for PEPG). */
vf_status vf_attack_estimate_gradient(const vf_attack_state *st, const vf_attack_config *cfg,
                                      vf_attack_loss_fn loss_fn, void *ctx, vf_rng *rng,
                                      double *grad);

/* The state as JSON (a new reference): parameters, moments, step, RNG words (hex strings),
 * best samples and history. Doubles are written with 17 significant digits, so reading it
 * back gives bit-identical numbers. */
json_t *vf_attack_state_to_json(const vf_attack_state *st);

/* Rebuild a state from vf_attack_state_to_json output into *st (which the caller then frees
 * with vf_attack_state_free). VF_EINPUT with the offending key when malformed. */
vf_status vf_attack_state_from_json(const json_t *json, vf_attack_state *st);

/* ---- results and reports ---- */

/* Mixture weights softmax(logit), K numbers. */
void vf_attack_weights(const vf_attack_state *st, double *weights);

/* a * tanh(mu_c) + b for component c (the distribution's centre in viewpoint space). */
void vf_attack_component_view(const vf_attack_state *st, const vf_attack_config *cfg, int c,
                              double v[VF_VIEW_DIM]);

/* v* = a * tanh(mu*) + b of the heaviest component: the paper's answer, for every method. */
void vf_attack_v_star(const vf_attack_state *st, const vf_attack_config *cfg,
                      double v[VF_VIEW_DIM]);

/* The best sample of the last step (the reference code's answer; the centre before any step). */
void vf_attack_v_best(const vf_attack_state *st, double v[VF_VIEW_DIM]);

/* n viewpoints drawn from the learned p*(v) with the caller's rng (the state is unchanged),
 * written to views (n x 6). */
void vf_attack_sample_views(const vf_attack_state *st, const vf_attack_config *cfg,
                            vf_rng *rng, int n, double *views);

/* Per-parameter standard deviation (divisor n - 1; 0 when n < 2) of n viewpoints. */
void vf_view_std(const double *views, int n, double std[VF_VIEW_DIM]);

/* "Camera fluctuation": n viewpoints uniform in the box centre +- (r_percent / 100) * range
 * per parameter (range: vf_view_ranges_paper, so r means the same in every workspace),
 * clipped to the default box joined with `search` (the attack's box), written to views. */
void vf_view_fluctuation(const vf_view_bounds *search, const double centre[VF_VIEW_DIM],
                         double r_percent, vf_rng *rng, int n, double *views);

/* Call loss_fn on n viewpoints in one batch. losses (n, may be NULL) gets the losses; *asr
 * (may be NULL) the fraction flagged fooled. Allocates its own scratch. */
vf_status vf_attack_evaluate(vf_attack_loss_fn loss_fn, void *ctx, const double *views, int n,
                             double *losses, double *asr);

typedef struct vf_random_search_result {
    double best_view[VF_VIEW_DIM]; /* the sample with the highest loss */
    double best_loss;
    double asr; /* fraction of the samples flagged fooled */
} vf_random_search_result;

/* The random-search baseline: n viewpoints uniform in the box (seeded), evaluated in one
 * batch. views (n x 6) and losses (n) may be NULL; when given they receive every sample. */
vf_status vf_attack_random_search(const vf_view_bounds *bounds, int n, uint64_t seed,
                                  vf_attack_loss_fn loss_fn, void *ctx, double *views,
                                  double *losses, vf_random_search_result *result);

#ifdef __cplusplus
}
#endif
#endif
