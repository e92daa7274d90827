/* Shared by the files of src/viewfool only: small helpers and the per-method step functions. */
#ifndef VF_VIEWFOOL_INTERNAL_H
#define VF_VIEWFOOL_INTERNAL_H

#include <math.h>

#include "vf/viewfool.h"

#define QUAD_POINTS 321 /* trapezoid nodes on [-10, 10] for expectations over N(0, 1) */
#define MU_LIMIT 10.0 /* |mu| clip: tanh(10) = 1 - 4e-9, nothing changes beyond */
#define LOGIT_LIMIT 10.0

static inline double view_half_range(const vf_view_bounds *b, int i)
{
    return 0.5 * (b->hi[i] - b->lo[i]);
}

static inline double view_centre(const vf_view_bounds *b, int i)
{
    return 0.5 * (b->hi[i] + b->lo[i]);
}

static inline double clamp(double x, double lo, double hi)
{
    return x < lo ? lo : x > hi ? hi : x;
}

/* Index of a component's parameters in the moment arrays and gradients. */
static inline int param_mu(int c, int i) { return c * VF_ATTACK_COMPONENT_PARAMS + i; }
static inline int param_sigma(int c, int i)
{
    return c * VF_ATTACK_COMPONENT_PARAMS + VF_VIEW_DIM + i;
}
static inline int param_logit(int c) { return c * VF_ATTACK_COMPONENT_PARAMS + 2 * VF_VIEW_DIM; }

/* Nodes and weights (QUAD_POINTS of each) for E[f(eps)], eps ~ N(0, 1). */
void vf__normal_quadrature(const double **nodes, const double **weights);

/* log(1 - tanh(u)^2), stable for large |u|. */
double vf__log_sech2(double u);

/* log of the mixture density of u (in u space) and, when resp is not NULL, the K
 * responsibilities r_c(u) = w_c N_c(u) / p(u). */
double vf__mixture_log_density(const vf_attack_state *st, const double u[VF_VIEW_DIM],
                               double *resp);

/* Call loss_fn for n views, check every loss is finite. fooled gets zeroed first. */
vf_status vf__evaluate_batch(vf_attack_loss_fn loss_fn, void *ctx, const double *views, int n,
                             double *losses, int *fooled);

/* Append a record to the history (grows it). VF_EINTERNAL when out of memory. */
vf_status vf__history_push(vf_attack_state *st, const vf_attack_record *rec);

/* Record the batch's best sample as the last step's best and, if better, the overall best. */
void vf__note_best(vf_attack_state *st, const double *views, const double *losses, int n);

/* Fill a record's loss statistics from a batch. */
void vf__batch_stats(const double *losses, const int *fooled, int n, vf_attack_record *rec);

vf_status vf__nes_step(vf_attack_state *st, const vf_attack_config *cfg, vf_attack_loss_fn loss_fn,
                       void *ctx);
vf_status vf__nes_gradient(const vf_attack_state *st, const vf_attack_config *cfg,
                           vf_attack_loss_fn loss_fn, void *ctx, vf_rng *rng, double *grad,
                           double *views, double *losses, int *fooled, double *entropy);
vf_status vf__pepg_step(vf_attack_state *st, const vf_attack_config *cfg,
                        vf_attack_loss_fn loss_fn, void *ctx);

#endif
