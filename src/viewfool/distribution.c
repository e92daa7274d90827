/* The viewpoint box, the tanh squashing, the entropy of the squashed Gaussian and the mixture
 * weights and density. */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "viewfool_internal.h"

#define FIXED_HALF 1e-6 /* half-width of a parameter a search space keeps fixed */

static const double default_lo[VF_VIEW_DIM] = {-180, -30, 20, -0.5, -1, -0.5};
static const double default_hi[VF_VIEW_DIM] = {180, 30, 160, 0.5, 1, 0.5};

static const char *const param_names[VF_VIEW_DIM] = {"psi", "theta", "phi", "dx", "dy", "dz"};

const char *vf_view_param_name(int i) { return i >= 0 && i < VF_VIEW_DIM ? param_names[i] : "?"; }

void vf_view_bounds_default(vf_view_bounds *bounds)
{
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        bounds->lo[i] = default_lo[i];
        bounds->hi[i] = default_hi[i];
    }
}

void vf_view_ranges_paper(double range[VF_VIEW_DIM])
{
    for (int i = 0; i < VF_VIEW_DIM; i++)
        range[i] = default_hi[i] - default_lo[i];
}

static const char *const space_names[3] = {"both", "rotation", "translation"};

vf_status vf_view_space_parse(const char *name, vf_view_space *space)
{
    for (int s = 0; s < 3; s++)
        if (name && !strcmp(name, space_names[s])) {
            *space = (vf_view_space)s;
            return VF_OK;
        }
    return vf_fail(VF_EINPUT, "the search space must be rotation, translation or both, not '%s'",
                   name ? name : "");
}

const char *vf_view_space_name(vf_view_space space)
{
    return (unsigned)space < 3 ? space_names[space] : "?";
}

void vf_view_bounds_restrict(vf_view_bounds *bounds, vf_view_space space,
                             const double at[VF_VIEW_DIM])
{
    for (int i = 0; i < VF_VIEW_DIM; i++)
        if ((space == VF_SPACE_ROTATION && i >= 3) || (space == VF_SPACE_TRANSLATION && i < 3)) {
            double v = at ? clamp(at[i], bounds->lo[i], bounds->hi[i]) : view_centre(bounds, i);
            bounds->lo[i] = v - FIXED_HALF;
            bounds->hi[i] = v + FIXED_HALF;
        }
}

vf_status vf_view_bounds_check(const vf_view_bounds *bounds)
{
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        double lo = bounds->lo[i], hi = bounds->hi[i];
        if (!isfinite(lo) || !isfinite(hi) || !(lo < hi))
            return vf_fail(VF_EINPUT, "viewpoint bounds for %s are [%g, %g]: need lo < hi",
                           param_names[i], lo, hi);
    }
    return VF_OK;
}

static int parse_number(const char *text, double *out)
{
    char *end;
    *out = strtod(text, &end);
    return end != text && *end == '\0' && isfinite(*out);
}

vf_status vf_view_bounds_parse(const char *text, vf_view_bounds *bounds)
{
    char buf[1024];
    if (snprintf(buf, sizeof buf, "%s", text) >= (int)sizeof buf)
        return vf_fail(VF_EINPUT, "the bounds text is too long");
    char *save = NULL;
    for (char *item = strtok_r(buf, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(item, '=');
        char *colon = eq ? strchr(eq + 1, ':') : NULL;
        int i = 0;
        while (eq && i < VF_VIEW_DIM &&
               (strlen(param_names[i]) != (size_t)(eq - item) ||
                strncmp(item, param_names[i], (size_t)(eq - item))))
            i++;
        if (!eq || i == VF_VIEW_DIM || !colon)
            return vf_fail(VF_EINPUT,
                           "bounds want name=lo:hi with names psi, theta, phi, dx, "
                           "dy, dz, not '%s'",
                           item);
        *colon = '\0';
        double lo, hi;
        if (!parse_number(eq + 1, &lo) || !parse_number(colon + 1, &hi) || !(lo < hi))
            return vf_fail(VF_EINPUT, "bounds of %s: give two numbers lo:hi with lo < hi",
                           param_names[i]);
        bounds->lo[i] = lo;
        bounds->hi[i] = hi;
    }
    return VF_OK;
}

void vf_view_squash(const vf_view_bounds *bounds, const double u[VF_VIEW_DIM],
                    double v[VF_VIEW_DIM])
{
    for (int i = 0; i < VF_VIEW_DIM; i++)
        v[i] = view_half_range(bounds, i) * tanh(u[i]) + view_centre(bounds, i);
}

/* ---- quadrature for E[f(eps)], eps ~ N(0, 1) ----
 *
 * The trapezoid rule on [-10, 10] with step 1/16. For integrands analytic in a strip around the
 * real axis times the Gaussian density it converges geometrically, error ~ exp(-2 pi d / h):
 * log cosh(mu + sigma eps) and tanh have their nearest poles at Im eps = pi / (2 sigma), so
 * d >= 0.78 for sigma <= 2 and the error is below 1e-30, far under the truncation error
 * (the density beyond +-10 holds 1.5e-23 of the mass). Gauss-Hermite rules of similar size do
 * worse here because of the near-kink of log cosh at 0 when sigma is large. */

#define QUAD_STEP 0.0625
#define QUAD_HALF_WIDTH 10.0

static double quad_nodes[QUAD_POINTS], quad_weights[QUAD_POINTS];
static pthread_once_t quad_once = PTHREAD_ONCE_INIT;

static void quad_compute(void)
{
    double sum = 0.0;
    for (int q = 0; q < QUAD_POINTS; q++) {
        double eps = -QUAD_HALF_WIDTH + q * QUAD_STEP;
        double end = q == 0 || q == QUAD_POINTS - 1 ? 0.5 : 1.0;
        quad_nodes[q] = eps;
        quad_weights[q] = end * QUAD_STEP * exp(-0.5 * eps * eps) / sqrt(2.0 * M_PI);
        sum += quad_weights[q];
    }
    for (int q = 0; q < QUAD_POINTS; q++) /* exactly normalized */
        quad_weights[q] /= sum;
}

void vf__normal_quadrature(const double **nodes, const double **weights)
{
    pthread_once(&quad_once, quad_compute);
    *nodes = quad_nodes;
    *weights = quad_weights;
}

/* ---- entropy ---- */

double vf__log_sech2(double u)
{
    /* log(1 - tanh(u)^2) = -2 log cosh(u) = 2 (log 2 - |u| - log1p(exp(-2|u|))), stable for
     * any u (1 - tanh^2 underflows to 0 for |u| > 19 otherwise). */
    double x = fabs(u);
    return 2.0 * (M_LN2 - x - log1p(exp(-2.0 * x)));
}

double vf_log_jacobian_mean(double mu, double sigma, double *d_mu, double *d_sigma)
{
    const double *x, *w;
    vf__normal_quadrature(&x, &w);
    double value = 0.0, gm = 0.0, gs = 0.0;
    for (int q = 0; q < QUAD_POINTS; q++) {
        double u = mu + sigma * x[q];
        double slope = -2.0 * tanh(u); /* d/du log(1 - tanh(u)^2) */
        value += w[q] * vf__log_sech2(u);
        gm += w[q] * slope;
        gs += w[q] * slope * x[q];
    }
    if (d_mu)
        *d_mu = gm;
    if (d_sigma)
        *d_sigma = gs;
    return value;
}

double vf_squashed_entropy(const vf_view_bounds *bounds, const double mu[VF_VIEW_DIM],
                           const double sigma[VF_VIEW_DIM], double grad_mu[VF_VIEW_DIM],
                           double grad_sigma[VF_VIEW_DIM])
{
    /* Change of variables v = a tanh(u) + b: H(v) = H(u) + E log|dv/du|, and per dimension
     * log|dv/du| = log a + log(1 - tanh(u)^2). H(u) = 0.5 log(2 pi e sigma^2). */
    double h = 0.0;
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        double d_mu, d_sigma;
        double jac = vf_log_jacobian_mean(mu[i], sigma[i], &d_mu, &d_sigma);
        h += 0.5 * log(2.0 * M_PI * M_E * sigma[i] * sigma[i]) + log(view_half_range(bounds, i)) +
             jac;
        if (grad_mu)
            grad_mu[i] = d_mu;
        if (grad_sigma)
            grad_sigma[i] = 1.0 / sigma[i] + d_sigma;
    }
    return h;
}

/* ---- mixtures ---- */

void vf_attack_weights(const vf_attack_state *st, double *weights)
{
    double top = -INFINITY, sum = 0.0;
    for (int c = 0; c < st->components; c++)
        top = st->logit[c] > top ? st->logit[c] : top;
    for (int c = 0; c < st->components; c++)
        sum += weights[c] = exp(st->logit[c] - top);
    for (int c = 0; c < st->components; c++)
        weights[c] /= sum;
}

double vf__mixture_log_density(const vf_attack_state *st, const double u[VF_VIEW_DIM],
                               double *resp)
{
    double pi[VF_ATTACK_MAX_COMPONENTS], logp[VF_ATTACK_MAX_COMPONENTS], top = -INFINITY;
    vf_attack_weights(st, pi);
    for (int c = 0; c < st->components; c++) {
        double l = log(pi[c]);
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            double z = (u[i] - st->mu[c][i]) / st->sigma[c][i];
            l += -0.5 * z * z - log(st->sigma[c][i]) - 0.5 * log(2.0 * M_PI);
        }
        logp[c] = l;
        if (l > top)
            top = l;
    }
    /* log-sum-exp around the largest term */
    double sum = 0.0;
    for (int c = 0; c < st->components; c++)
        sum += exp(logp[c] - top);
    double log_density = top + log(sum);
    if (resp)
        for (int c = 0; c < st->components; c++)
            resp[c] = exp(logp[c] - log_density);
    return log_density;
}
