/* The ViewFool optimizer on analytic objectives: entropy and its gradient against numerical
 * integration and finite differences, the search-gradient estimator against exact gradients,
 * convergence of NES+Adam and PEPG, the entropy's pull on sigma, the mixture on two modes,
 * reproducibility, exact resume from JSON, and the reporting helpers. */
#include <string.h>

#include "check.h"
#include "vf/viewfool.h"

/* ---- analytic objectives over t = (v - b) / a in [-1, 1]^6 ---- */

enum { OBJ_QUADRATIC, OBJ_FLAT, OBJ_LINEAR_PSI, OBJ_BIMODAL, OBJ_BOX_PSI, OBJ_FAIL, OBJ_NAN };

typedef struct {
    int kind;
    vf_view_bounds bounds;
    double t0[VF_VIEW_DIM], t1[VF_VIEW_DIM], width;
    double fooled_above; /* "fooled" when the loss exceeds this */
    int calls;
} objective;

/* High (1) on a box of yaws |t_psi| < 0.3, low (0) outside, with soft edges. */
static double box_loss(double t)
{
    return 1.0 / (1.0 + exp(-(0.3 - fabs(t)) / 0.03));
}

static double objective_value(const objective *o, const double t[VF_VIEW_DIM])
{
    double d0 = 0.0, d1 = 0.0;
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        d0 += (t[i] - o->t0[i]) * (t[i] - o->t0[i]);
        d1 += (t[i] - o->t1[i]) * (t[i] - o->t1[i]);
    }
    switch (o->kind) {
    case OBJ_QUADRATIC:
        return -d0;
    case OBJ_FLAT:
        return 2.5;
    case OBJ_LINEAR_PSI:
        return t[0];
    case OBJ_BIMODAL:
        return exp(-d0 / (o->width * o->width)) + exp(-d1 / (o->width * o->width));
    case OBJ_BOX_PSI:
        return box_loss(t[0]);
    default:
        return NAN;
    }
}

static vf_status objective_fn(const double *views, int n, double *losses, int *fooled, void *ctx)
{
    objective *o = ctx;
    o->calls++;
    if (o->kind == OBJ_FAIL)
        return vf_fail(VF_EINPUT, "renderer exploded");
    for (int j = 0; j < n; j++) {
        double t[VF_VIEW_DIM];
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            double a = 0.5 * (o->bounds.hi[i] - o->bounds.lo[i]);
            double b = 0.5 * (o->bounds.hi[i] + o->bounds.lo[i]);
            t[i] = (views[j * VF_VIEW_DIM + i] - b) / a;
        }
        losses[j] = objective_value(o, t);
        fooled[j] = losses[j] > o->fooled_above;
    }
    return VF_OK;
}

static objective make_objective(int kind)
{
    objective o = {.kind = kind, .width = 0.5, .fooled_above = -0.01};
    vf_view_bounds_default(&o.bounds);
    const double t0[VF_VIEW_DIM] = {0.5, -0.3, 0.4, 0.2, -0.6, 0.1};
    const double t1[VF_VIEW_DIM] = {-0.45, 0.35, -0.3, -0.25, 0.3, -0.2};
    memcpy(o.t0, t0, sizeof t0);
    memcpy(o.t1, t1, sizeof t1);
    return o;
}

/* The normalized position t of a viewpoint. */
static void view_to_t(const vf_view_bounds *b, const double v[VF_VIEW_DIM], double t[VF_VIEW_DIM])
{
    for (int i = 0; i < VF_VIEW_DIM; i++)
        t[i] = (2.0 * v[i] - b->hi[i] - b->lo[i]) / (b->hi[i] - b->lo[i]);
}

static double max_abs_diff(const double *x, const double *y, int n)
{
    double m = 0.0;
    for (int i = 0; i < n; i++)
        m = fmax(m, fabs(x[i] - y[i]));
    return m;
}

/* ---- numerical integration references ---- */

static double normal_pdf(double x)
{
    return exp(-0.5 * x * x) / sqrt(2.0 * M_PI);
}

/* Trapezoid over eps in [-12, 12] of phi(eps) * {log(1 - tanh^2 u), its u-derivative, times
 * eps}, u = mu + sigma eps, with log(1 - tanh^2 u) written as -2 log cosh u. */
static void trapezoid_log_jacobian(double mu, double sigma, double out[3])
{
    int n = 48000;
    double h = 24.0 / n;
    out[0] = out[1] = out[2] = 0.0;
    for (int q = 0; q <= n; q++) {
        double eps = -12.0 + q * h, u = mu + sigma * eps;
        double w = normal_pdf(eps) * h * (q == 0 || q == n ? 0.5 : 1.0);
        out[0] += w * -2.0 * log(cosh(u));
        out[1] += w * -2.0 * tanh(u);
        out[2] += w * -2.0 * tanh(u) * eps;
    }
}

/* -integral p log p over the interval, with the exact density of v = a tanh(u) + b,
 * p(v) = N(atanh(t); mu, sigma^2) / (a (1 - t^2)), t = (v - b) / a; midpoint rule in t. */
static double numeric_entropy_1d(double mu, double sigma, double lo, double hi)
{
    int n = 400000;
    double a = 0.5 * (hi - lo), h = 2.0 / n, sum = 0.0;
    for (int q = 0; q < n; q++) {
        double t = -1.0 + (q + 0.5) * h;
        double p = normal_pdf((atanh(t) - mu) / sigma) / sigma / (a * (1.0 - t * t));
        if (p > 0)
            sum -= p * log(p) * a * h; /* dv = a dt */
    }
    return sum;
}

static void test_log_jacobian(void)
{
    const double cases[][2] = {{0, 0.1}, {0.7, 0.5}, {-1.3, 1.0}, {2.5, 2.0}, {0.3, 1e-3},
                               {-4, 0.3}, {0, 2.0}};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double mu = cases[c][0], sigma = cases[c][1], ref[3], d_mu, d_sigma;
        double value = vf_log_jacobian_mean(mu, sigma, &d_mu, &d_sigma);
        trapezoid_log_jacobian(mu, sigma, ref);
        CHECK(fabs(value - ref[0]) < 1e-7 && fabs(d_mu - ref[1]) < 1e-7 &&
                  fabs(d_sigma - ref[2]) < 1e-7,
              "mu %g sigma %g: quadrature (%.10f %.10f %.10f) vs trapezoid (%.10f %.10f %.10f)",
              mu, sigma, value, d_mu, d_sigma, ref[0], ref[1], ref[2]);
    }
}

static void test_entropy(void)
{
    vf_view_bounds b;
    vf_view_bounds_default(&b);
    /* moderate sigmas, where the density vanishes at the box's edges */
    double mu[VF_VIEW_DIM] = {0.0, 1.2, -0.5, 0.3, -2.0, 0.8};
    double sigma[VF_VIEW_DIM] = {0.3, 0.3, 0.8, 0.05, 0.5, 0.6};
    double numeric = 0.0;
    for (int i = 0; i < VF_VIEW_DIM; i++)
        numeric += numeric_entropy_1d(mu[i], sigma[i], b.lo[i], b.hi[i]);
    double h = vf_squashed_entropy(&b, mu, sigma, NULL, NULL);
    CHECK(fabs(h - numeric) < 1e-5, "entropy %.9f vs v-space integration %.9f", h, numeric);

    /* gradient against central finite differences, sigmas up to the clip's upper end */
    double mu2[VF_VIEW_DIM] = {0.3, -1.2, 0.8, 0.0, 2.0, -0.4};
    double sigma2[VF_VIEW_DIM] = {0.1, 0.5, 1.0, 1.7, 0.3, 2.0};
    double g_mu[VF_VIEW_DIM], g_sigma[VF_VIEW_DIM], step = 1e-5, worst = 0.0;
    vf_squashed_entropy(&b, mu2, sigma2, g_mu, g_sigma);
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        double p[VF_VIEW_DIM], m[VF_VIEW_DIM];
        memcpy(p, mu2, sizeof p);
        memcpy(m, mu2, sizeof m);
        p[i] += step;
        m[i] -= step;
        double fd_mu = (vf_squashed_entropy(&b, p, sigma2, NULL, NULL) -
                        vf_squashed_entropy(&b, m, sigma2, NULL, NULL)) / (2 * step);
        memcpy(p, sigma2, sizeof p);
        memcpy(m, sigma2, sizeof m);
        p[i] += step;
        m[i] -= step;
        double fd_sigma = (vf_squashed_entropy(&b, mu2, p, NULL, NULL) -
                           vf_squashed_entropy(&b, mu2, m, NULL, NULL)) / (2 * step);
        worst = fmax(worst, fmax(fabs(fd_mu - g_mu[i]), fabs(fd_sigma - g_sigma[i])));
    }
    CHECK(worst < 1e-6, "entropy gradient vs finite differences: worst error %g", worst);
}

/* sigma* maximizing the entropy of tanh(u), u ~ N(0, sigma^2): the root of dH/dsigma. */
static double max_entropy_sigma(void)
{
    double lo = 0.1, hi = 2.0;
    for (int it = 0; it < 60; it++) {
        double mid = 0.5 * (lo + hi), d_sigma;
        vf_log_jacobian_mean(0.0, mid, NULL, &d_sigma);
        if (1.0 / mid + d_sigma > 0)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

/* ---- the gradient estimator ---- */

static double expect_sech2(double mu, double sigma, int times_eps)
{
    double sum = 0.0, h = 24.0 / 24000;
    for (int q = 0; q <= 24000; q++) {
        double eps = -12.0 + q * h, s = 1.0 / cosh(mu + sigma * eps);
        sum += normal_pdf(eps) * h * s * s * (times_eps ? eps : 1.0);
    }
    return sum;
}

static double expect_tanh(double mu, double sigma)
{
    double sum = 0.0, h = 24.0 / 24000;
    for (int q = 0; q <= 24000; q++) {
        double eps = -12.0 + q * h;
        sum += normal_pdf(eps) * h * tanh(mu + sigma * eps);
    }
    return sum;
}

static void test_gradient_single(void)
{
    objective o = make_objective(OBJ_LINEAR_PSI);
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.samples = 200000;
    cfg.lambda = 0.0;
    vf_attack_state st;
    CHECK(vf_attack_init(&st, &cfg) == VF_OK, "init: %s", vf_error_message());
    double mu = 0.4, sigma = 0.6;
    st.mu[0][0] = mu;
    for (int i = 0; i < VF_VIEW_DIM; i++)
        st.sigma[0][i] = sigma;

    /* E[tanh(u_psi)]: d/dmu = E[sech^2 u], d/dsigma = E[sech^2(u) eps]; the natural gradient
     * scales them by sigma^2 and sigma^2 / 2. */
    double natural[VF_ATTACK_COMPONENT_PARAMS], with_entropy[VF_ATTACK_COMPONENT_PARAMS];
    vf_rng rng;
    vf_rng_seed(&rng, 11);
    CHECK(vf_attack_estimate_gradient(&st, &cfg, objective_fn, &o, &rng, natural) == VF_OK,
          "estimate: %s", vf_error_message());
    double s2 = sigma * sigma;
    CHECK_NEAR(natural[0], s2 * expect_sech2(mu, sigma, 0), 0.005);
    CHECK_NEAR(natural[VF_VIEW_DIM], 0.5 * s2 * expect_sech2(mu, sigma, 1), 0.005);
    for (int i = 1; i < VF_VIEW_DIM; i++) {
        CHECK_NEAR(natural[i], 0.0, 0.005);
        CHECK_NEAR(natural[VF_VIEW_DIM + i], 0.0, 0.005);
    }

    /* With lambda the exact entropy gradient is added as it is: no natural-gradient factor
     * (Eq. 7; scaling it too is what collapsed p*(v) to a point). */
    cfg.lambda = 0.25;
    vf_rng_seed(&rng, 11);
    vf_attack_estimate_gradient(&st, &cfg, objective_fn, &o, &rng, with_entropy);
    double h_mu[VF_VIEW_DIM], h_sigma[VF_VIEW_DIM], worst = 0.0;
    vf_squashed_entropy(&cfg.bounds, st.mu[0], st.sigma[0], h_mu, h_sigma);
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        worst = fmax(worst, fabs(with_entropy[i] - natural[i] - 0.25 * h_mu[i]));
        worst = fmax(worst, fabs(with_entropy[VF_VIEW_DIM + i] - natural[VF_VIEW_DIM + i] -
                                 0.25 * h_sigma[i]));
    }
    CHECK(worst < 1e-12, "entropy term = lambda * exact plain gradient (error %g)", worst);
    vf_attack_state_free(&st);
}

static void test_gradient_mixture(void)
{
    objective o = make_objective(OBJ_LINEAR_PSI);
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.samples = 400000;
    cfg.lambda = 0.0;
    cfg.components = 2;
    vf_attack_state st;
    CHECK(vf_attack_init(&st, &cfg) == VF_OK, "init: %s", vf_error_message());
    const double mu[2] = {-0.5, 0.8}, sigma[2] = {0.4, 0.3};
    for (int c = 0; c < 2; c++) {
        st.mu[c][0] = mu[c];
        st.sigma[c][0] = sigma[c];
    }
    st.logit[0] = 0.3;
    st.logit[1] = -0.2;
    double w[2], grad[2 * VF_ATTACK_COMPONENT_PARAMS];
    vf_attack_weights(&st, w);
    vf_rng rng;
    vf_rng_seed(&rng, 12);
    CHECK(vf_attack_estimate_gradient(&st, &cfg, objective_fn, &o, &rng, grad) == VF_OK,
          "estimate: %s", vf_error_message());

    /* E[L] = sum_c w_c E_c[tanh u]: d/dmu_c = w_c E_c[sech^2], d/dsigma_c = w_c E_c[sech^2
     * eps], d/dlogit_c = w_c (E_c[L] - E[L]); natural: times sigma_c^2 and sigma_c^2 / 2. */
    double e[2] = {expect_tanh(mu[0], sigma[0]), expect_tanh(mu[1], sigma[1])};
    double total = w[0] * e[0] + w[1] * e[1];
    for (int c = 0; c < 2; c++) {
        const double *g = grad + c * VF_ATTACK_COMPONENT_PARAMS;
        double s2 = sigma[c] * sigma[c];
        CHECK_NEAR(g[0], s2 * w[c] * expect_sech2(mu[c], sigma[c], 0), 0.003);
        CHECK_NEAR(g[VF_VIEW_DIM], 0.5 * s2 * w[c] * expect_sech2(mu[c], sigma[c], 1), 0.003);
        CHECK_NEAR(g[2 * VF_VIEW_DIM], w[c] * (e[c] - total), 0.01);
        CHECK_NEAR(g[3], 0.0, 0.01);
    }
    vf_attack_state_free(&st);
}

/* ---- optimization on analytic objectives ---- */

static void run_attack(vf_attack_config *cfg, objective *o, vf_attack_state *st)
{
    CHECK(vf_attack_init(st, cfg) == VF_OK, "init: %s", vf_error_message());
    CHECK(vf_attack_optimize(st, cfg, objective_fn, o, NULL, NULL) == VF_OK, "run: %s",
          vf_error_message());
    CHECK(st->step == cfg->steps, "ran %d of %d steps", st->step, cfg->steps);
}

/* The mean of many samples of p(v), as t = (v - b) / a. */
static void sample_mean_t(const vf_attack_state *st, const vf_attack_config *cfg,
                          double t[VF_VIEW_DIM])
{
    enum { N = 4000 };
    static double views[N * VF_VIEW_DIM];
    vf_rng rng;
    vf_rng_seed(&rng, 99);
    vf_attack_sample_views(st, cfg, &rng, N, views);
    double mean[VF_VIEW_DIM] = {0};
    for (int j = 0; j < N; j++)
        for (int i = 0; i < VF_VIEW_DIM; i++)
            mean[i] += views[j * VF_VIEW_DIM + i] / N;
    view_to_t(&cfg->bounds, mean, t);
}

static void test_nes_converges(void)
{
    objective o = make_objective(OBJ_QUADRATIC);
    vf_attack_config cfg;
    vf_attack_state st;
    double v[VF_VIEW_DIM], t[VF_VIEW_DIM];

    /* lambda > 0: sigma settles wide, so E[L] = -|E t - t0|^2 - var t is maximal where the
     * samples' mean lies on the maximum (v* = a tanh(mu*) + b sits a little further out). */
    static const double lambdas[2] = {0.001, 0.01};
    for (int l = 0; l < 2; l++) {
        vf_attack_config_default(&cfg, VF_ATTACK_NES);
        cfg.lambda = lambdas[l];
        run_attack(&cfg, &o, &st);
        sample_mean_t(&st, &cfg, t);
        double err = max_abs_diff(t, o.t0, VF_VIEW_DIM);
        CHECK(err < 0.05, "NES+Adam, lambda %g: the samples' mean within %g of the range's "
              "half-width from the maximum", lambdas[l], err);
        CHECK(st.history[st.step - 1].mean_loss > st.history[0].mean_loss + 0.3,
              "lambda %g: mean loss rose from %g to %g", lambdas[l], st.history[0].mean_loss,
              st.history[st.step - 1].mean_loss);
        vf_attack_state_free(&st);
    }

    /* lambda 0: sigma falls to its floor within ~10 steps (Adam moves it by sigma_lr whatever
     * the gradient's size), and the mean's natural-gradient steps, which scale with sigma^2,
     * then stall under Adam's memory of the early gradients: v* gets only part of the way
     * (measured: 0.31 from the maximum, from 0.6 at the start). */
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.lambda = 0.0;
    run_attack(&cfg, &o, &st);
    vf_attack_v_star(&st, &cfg, v);
    view_to_t(&cfg.bounds, v, t);
    double err = max_abs_diff(t, o.t0, VF_VIEW_DIM);
    CHECK(err < 0.4 && st.sigma[0][0] < 0.01, "lambda 0: v* off by %g (0.6 at the start), "
          "sigma %g", err, st.sigma[0][0]);
    vf_attack_state_free(&st);
}

static void test_pepg_converges(void)
{
    objective o = make_objective(OBJ_QUADRATIC);
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_PEPG);
    vf_attack_state st;
    double v[VF_VIEW_DIM], t[VF_VIEW_DIM];
    run_attack(&cfg, &o, &st);
    vf_attack_v_best(&st, v);
    view_to_t(&cfg.bounds, v, t);
    double err = max_abs_diff(t, o.t0, VF_VIEW_DIM);
    CHECK(err < 0.05, "PEPG: v_best (best sample of the last step) off by %g", err);
    CHECK(memcmp(v, st.last_best_view, sizeof v) == 0, "v_best is the last step's best");
    vf_attack_v_star(&st, &cfg, v);
    view_to_t(&cfg.bounds, v, t);
    err = max_abs_diff(t, o.t0, VF_VIEW_DIM);
    CHECK(err < 0.05, "PEPG: v* (the distribution's centre) off by %g", err);
    for (int i = 0; i < VF_VIEW_DIM; i++)
        CHECK(st.sigma[0][i] <= cfg.sigma_max, "PEPG keeps sigma under its clip");
    vf_attack_state_free(&st);
}

static void test_entropy_widens(void)
{
    /* A flat loss: only the entropy acts, so the distribution should become the
     * maximum-entropy squashed Gaussian, mu = 0 and sigma = sigma*. */
    objective o = make_objective(OBJ_FLAT);
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.steps = 200; /* sigma moves about sigma_lr a step: 0.1 -> 0.87 takes ~80 */
    vf_attack_state st;
    run_attack(&cfg, &o, &st);
    double target = max_entropy_sigma(), worst_sigma = 0.0, worst_mu = 0.0;
    for (int i = 0; i < VF_VIEW_DIM; i++) {
        worst_sigma = fmax(worst_sigma, fabs(st.sigma[0][i] - target));
        worst_mu = fmax(worst_mu, fabs(st.mu[0][i]));
    }
    CHECK(target > 0.5 && target < 1.5, "sigma* = %g", target);
    CHECK(worst_sigma < 0.1 * target, "sigma grew from 0.1 to sigma* = %.3f (worst off %.3f)",
          target, worst_sigma);
    CHECK(worst_mu < 0.05, "mu stayed centred (worst %g)", worst_mu);
    CHECK(st.history[st.step - 1].entropy > st.history[0].entropy + 5.0,
          "entropy rose from %g to %g", st.history[0].entropy, st.history[st.step - 1].entropy);

    /* with lambda = 0 nothing drives sigma */
    cfg.lambda = 0.0;
    vf_attack_state_free(&st);
    run_attack(&cfg, &o, &st);
    CHECK_NEAR(st.sigma[0][2], cfg.sigma_init, 1e-9);
    vf_attack_state_free(&st);

    /* PEPG: tied losses give no rank signal, so a flat loss at lambda = 0 moves nothing but
     * sigma's decay, and lambda > 0 widens sigma up to its clip */
    vf_attack_config_default(&cfg, VF_ATTACK_PEPG);
    cfg.lambda = 0.0;
    run_attack(&cfg, &o, &st);
    CHECK(st.mu[0][0] == 0.0 &&
              fabs(st.sigma[0][0] - cfg.sigma_init * pow(cfg.sigma_decay, cfg.steps)) < 1e-12,
          "PEPG on a flat loss stays put (mu %g, sigma %g)", st.mu[0][0], st.sigma[0][0]);
    vf_attack_state_free(&st);
    cfg.lambda = 1.0;
    run_attack(&cfg, &o, &st);
    CHECK_NEAR(st.sigma[0][3], cfg.sigma_max * cfg.sigma_decay, 1e-12);
    vf_attack_state_free(&st);
}

/* The expected NES ascent direction in sigma_psi for the box loss at mu = 0, by quadrature:
 * the loss term's natural gradient (sigma / 2) E[L (eps^2 - 1)] plus lambda dH/dsigma. */
static double box_sigma_drift(double sigma, double lambda)
{
    double sum = 0.0, h = 20.0 / 40000, d_jac;
    for (int q = 0; q <= 40000; q++) {
        double eps = -10.0 + q * h;
        sum += normal_pdf(eps) * h * box_loss(tanh(sigma * eps)) * (eps * eps - 1.0);
    }
    vf_log_jacobian_mean(0.0, sigma, NULL, &d_jac);
    return 0.5 * sigma * sum + lambda * (1.0 / sigma + d_jac);
}

/* The sigma where that drift vanishes (it is positive below, negative above). */
static double box_sigma_balance(double lambda)
{
    double lo = 1e-3, hi = 2.0;
    for (int it = 0; it < 60; it++) {
        double mid = 0.5 * (lo + hi);
        if (box_sigma_drift(mid, lambda) > 0)
            lo = mid;
        else
            hi = mid;
    }
    return 0.5 * (lo + hi);
}

/* The entropy term keeps p*(v) a distribution: on a loss that is high on a box of yaws, sigma
 * settles where the loss term and lambda dH/dsigma balance, stays there, and the balance
 * widens with lambda; at lambda = 0 sigma shrinks. */
static void test_entropy_balance(void)
{
    objective o = make_objective(OBJ_BOX_PSI);
    static const double lambdas[] = {0.0, 0.001, 0.01, 0.1};
    double settled[4];
    for (int l = 0; l < 4; l++) {
        vf_attack_config cfg;
        vf_attack_config_default(&cfg, VF_ATTACK_NES);
        cfg.lambda = lambdas[l];
        cfg.steps = 300;
        cfg.seed = 21;
        vf_attack_state st;
        CHECK(vf_attack_init(&st, &cfg) == VF_OK, "init");
        double sum = 0, sum2 = 0;
        int n = 0;
        while (st.step < cfg.steps) {
            CHECK(vf_attack_step(&st, &cfg, objective_fn, &o) == VF_OK, "step: %s",
                  vf_error_message());
            if (st.step > 150) { /* settled by then: sigma moves ~sigma_lr a step */
                sum += st.sigma[0][0];
                sum2 += st.sigma[0][0] * st.sigma[0][0];
                n++;
            }
        }
        double mean = sum / n, spread = sqrt(fmax(sum2 / n - mean * mean, 0.0));
        settled[l] = mean;
        if (lambdas[l] == 0.0) {
            CHECK(st.sigma[0][0] < 0.2 * cfg.sigma_init,
                  "lambda 0: sigma shrinks (%.4f from %.2f)", st.sigma[0][0], cfg.sigma_init);
        } else {
            double predicted = box_sigma_balance(lambdas[l]);
            printf("lambda %g: sigma_psi settles at %.3f +- %.3f, predicted %.3f\n", lambdas[l],
                   mean, spread, predicted);
            CHECK(fabs(mean - predicted) < 0.15 * predicted,
                  "lambda %g: sigma settles at %.3f, the estimator's balance is %.3f",
                  lambdas[l], mean, predicted);
            CHECK(spread < 0.15 * predicted, "lambda %g: sigma stays there (spread %.3f)",
                  lambdas[l], spread);
        }
        vf_attack_state_free(&st);
    }
    for (int l = 1; l < 4; l++)
        CHECK(settled[l] > settled[l - 1], "wider with lambda: %g -> %.3f, %g -> %.3f",
              lambdas[l - 1], settled[l - 1], lambdas[l], settled[l]);
}

static void test_mixture_two_modes(void)
{
    objective o = make_objective(OBJ_BIMODAL);
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.components = 2;
    /* A small entropy weight: at 0.01 each component settles wider (about 0.3 in u) than the
     * modes themselves, and the sample counts near each mode below would mean little. */
    cfg.lambda = 1e-4;
    vf_attack_state st;
    run_attack(&cfg, &o, &st);
    double v[VF_VIEW_DIM], t[VF_VIEW_DIM], w[2];
    double err[2] = {1e9, 1e9}; /* distance of the nearest component to each mode */
    for (int c = 0; c < 2; c++) {
        vf_attack_component_view(&st, &cfg, c, v);
        view_to_t(&cfg.bounds, v, t);
        err[0] = fmin(err[0], max_abs_diff(t, o.t0, VF_VIEW_DIM));
        err[1] = fmin(err[1], max_abs_diff(t, o.t1, VF_VIEW_DIM));
    }
    vf_attack_weights(&st, w);
    CHECK(err[0] < 0.05 && err[1] < 0.05, "K = 2 finds both modes (off by %g and %g)", err[0],
          err[1]);
    CHECK(w[0] > 0.2 && w[1] > 0.2, "both components keep weight (%g, %g)", w[0], w[1]);
    CHECK(isfinite(st.history[st.step - 1].entropy), "Monte Carlo entropy is finite");

    /* samples of p*(v) come from both modes */
    vf_rng rng;
    vf_rng_seed(&rng, 5);
    double views[200 * VF_VIEW_DIM];
    vf_attack_sample_views(&st, &cfg, &rng, 200, views);
    int near[2] = {0, 0};
    for (int j = 0; j < 200; j++) {
        view_to_t(&cfg.bounds, views + j * VF_VIEW_DIM, t);
        near[0] += max_abs_diff(t, o.t0, VF_VIEW_DIM) < 0.2;
        near[1] += max_abs_diff(t, o.t1, VF_VIEW_DIM) < 0.2;
    }
    CHECK(near[0] > 40 && near[1] > 40, "samples near each mode: %d and %d of 200", near[0],
          near[1]);
    vf_attack_state_free(&st);
}

/* ---- reproducibility and resume ---- */

static void test_seeds(void)
{
    objective o = make_objective(OBJ_QUADRATIC);
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.steps = 20;
    cfg.seed = 7;
    vf_attack_state a, b, c;
    run_attack(&cfg, &o, &a);
    run_attack(&cfg, &o, &b);
    cfg.seed = 8;
    run_attack(&cfg, &o, &c);
    CHECK(memcmp(a.mu, b.mu, sizeof a.mu) == 0 && memcmp(a.sigma, b.sigma, sizeof a.sigma) == 0,
          "the same seed gives bit-identical results");
    CHECK(memcmp(a.mu, c.mu, sizeof a.mu) != 0, "a different seed gives different results");

    vf_attack_state copy;
    CHECK(vf_attack_state_copy(&copy, &a) == VF_OK, "copy");
    vf_attack_state_free(&a);
    CHECK(copy.step == b.step && copy.history != b.history &&
              memcmp(copy.history, b.history, (size_t)b.step * sizeof *b.history) == 0,
          "a copy owns its own, equal history");
    a = copy;
    vf_attack_state_free(&a);
    vf_attack_state_free(&b);
    vf_attack_state_free(&c);
}

/* Run cfg->steps straight, and again stopping after `split` steps, going through JSON text,
 * and continuing: everything must match bit for bit. */
static void check_resume(vf_attack_config *cfg, objective *o, int split, const char *what)
{
    vf_attack_state straight, first, resumed;
    run_attack(cfg, o, &straight);

    int steps = cfg->steps;
    cfg->steps = split;
    run_attack(cfg, o, &first);
    cfg->steps = steps;
    json_t *saved = vf_attack_state_to_json(&first);
    char *text = saved ? json_dumps(saved, JSON_COMPACT) : NULL;
    json_t *loaded = text ? json_loads(text, 0, NULL) : NULL;
    CHECK(loaded != NULL, "%s: state JSON round trip", what);
    CHECK(vf_attack_state_from_json(loaded, &resumed) == VF_OK, "%s: from JSON: %s", what,
          vf_error_message());
    CHECK(vf_attack_optimize(&resumed, cfg, objective_fn, o, NULL, NULL) == VF_OK, "%s: resume",
          what);

    CHECK(memcmp(straight.mu, resumed.mu, sizeof straight.mu) == 0 &&
              memcmp(straight.sigma, resumed.sigma, sizeof straight.sigma) == 0 &&
              memcmp(straight.logit, resumed.logit, sizeof straight.logit) == 0 &&
              memcmp(straight.moment1, resumed.moment1, sizeof straight.moment1) == 0 &&
              memcmp(straight.moment2, resumed.moment2, sizeof straight.moment2) == 0 &&
              memcmp(&straight.rng, &resumed.rng, sizeof straight.rng) == 0,
          "%s: a resumed run ends bit-identical to an uninterrupted one", what);
    CHECK(resumed.step == straight.step &&
              memcmp(straight.history, resumed.history,
                     (size_t)straight.step * sizeof *straight.history) == 0 &&
              memcmp(straight.best_view, resumed.best_view, sizeof straight.best_view) == 0,
          "%s: same history and best sample", what);
    free(text);
    json_decref(saved);
    json_decref(loaded);
    vf_attack_state_free(&straight);
    vf_attack_state_free(&first);
    vf_attack_state_free(&resumed);
}

static void test_resume(void)
{
    objective quad = make_objective(OBJ_QUADRATIC), bimodal = make_objective(OBJ_BIMODAL);
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.steps = 30;
    cfg.seed = 3;
    check_resume(&cfg, &quad, 13, "NES");
    check_resume(&cfg, &quad, 0, "NES from step 0");
    cfg.components = 3;
    check_resume(&cfg, &bimodal, 17, "NES mixture");
    vf_attack_config_default(&cfg, VF_ATTACK_PEPG);
    cfg.steps = 30;
    check_resume(&cfg, &quad, 11, "PEPG");

    /* malformed states are refused with a message */
    vf_attack_state st;
    json_t *bad = json_pack("{s:i}", "format", 2);
    CHECK(vf_attack_state_from_json(bad, &st) == VF_EINPUT, "incomplete state refused");
    CHECK(strstr(vf_error_message(), "components") != NULL, "message: %s", vf_error_message());
    json_decref(bad);
}

/* ---- configuration ---- */

static void test_config(void)
{
    vf_attack_config cfg, back;
    vf_attack_config_default(&cfg, VF_ATTACK_PEPG);
    cfg.seed = UINT64_MAX - 5;
    cfg.bounds.lo[2] = 10;
    cfg.samples = 65;
    json_t *json = vf_attack_config_to_json(&cfg);
    CHECK(json && vf_attack_config_from_json(json, &back) == VF_OK, "config round trip: %s",
          vf_error_message());
    CHECK(memcmp(&cfg, &back, sizeof cfg) == 0, "config survives JSON unchanged");
    json_decref(json);

    json = json_pack("{s:s, s:i}", "method", "nes", "steps", 7);
    CHECK(vf_attack_config_from_json(json, &back) == VF_OK && back.steps == 7 &&
              back.lambda == 0.01 && back.method == VF_ATTACK_NES,
          "missing keys keep the defaults");
    json_decref(json);
    json = json_pack("{s:s}", "lr", "fast");
    CHECK(vf_attack_config_from_json(json, &back) == VF_EINPUT, "a string lr is refused");
    json_decref(json);

    vf_attack_config_default(&cfg, VF_ATTACK_PEPG);
    cfg.components = 2;
    CHECK(vf_attack_config_check(&cfg) == VF_EINPUT, "PEPG with a mixture is refused");
    cfg.components = 1;
    cfg.samples = 50;
    CHECK(vf_attack_config_check(&cfg) == VF_EINPUT, "PEPG with even k is refused");
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.bounds.lo[1] = cfg.bounds.hi[1];
    CHECK(vf_attack_config_check(&cfg) == VF_EINPUT && strstr(vf_error_message(), "theta"),
          "empty theta range refused: %s", vf_error_message());
}

static void test_callback_errors(void)
{
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    vf_attack_state st;
    CHECK(vf_attack_init(&st, &cfg) == VF_OK, "init");
    double mu_before[VF_VIEW_DIM];
    memcpy(mu_before, st.mu[0], sizeof mu_before);

    objective fail = make_objective(OBJ_FAIL), nan = make_objective(OBJ_NAN);
    CHECK(vf_attack_step(&st, &cfg, objective_fn, &fail) == VF_EINPUT &&
              strstr(vf_error_message(), "exploded"),
          "the callback's error comes back: %s", vf_error_message());
    CHECK(vf_attack_step(&st, &cfg, objective_fn, &nan) == VF_EINTERNAL &&
              strstr(vf_error_message(), "nan"),
          "a NaN loss is an error: %s", vf_error_message());
    CHECK(st.step == 0 && memcmp(mu_before, st.mu[0], sizeof mu_before) == 0,
          "failed steps change nothing");
    vf_attack_state_free(&st);
}

/* ---- reporting helpers ---- */

static void test_reports(void)
{
    vf_view_bounds b;
    vf_view_bounds_default(&b);
    vf_rng rng;
    vf_rng_seed(&rng, 9);

    /* camera fluctuation: inside the box, within r% of the range, clipped at the edge */
    double centre[VF_VIEW_DIM] = {170, 0, 90, 0, 0.9, -0.5}, views[20 * VF_VIEW_DIM];
    vf_view_fluctuation(&b, centre, 10, &rng, 20, views);
    int inside = 1, clipped = 0;
    for (int j = 0; j < 20; j++)
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            double x = views[j * VF_VIEW_DIM + i], half = 0.1 * (b.hi[i] - b.lo[i]);
            inside &= x >= b.lo[i] && x <= b.hi[i] && fabs(x - centre[i]) <= half + 1e-12;
            clipped += x == b.hi[0] && i == 0;
        }
    CHECK(inside, "fluctuation samples stay in the box and within +-10%% of the range");
    CHECK(clipped > 0, "samples past psi = 180 are clipped to it (%d)", clipped);

    /* std of known values */
    double two[2 * VF_VIEW_DIM] = {0, 0, 0, 0, 0, 0, 2, 4, 6, 8, 10, 12}, std[VF_VIEW_DIM];
    vf_view_std(two, 2, std);
    CHECK_NEAR(std[0], sqrt(2.0), 1e-12);
    CHECK_NEAR(std[5], 6.0 * sqrt(2.0), 1e-12);

    /* samples of a narrow p*(v): std about a sigma sech^2(mu) (delta method) */
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    vf_attack_state st;
    vf_attack_init(&st, &cfg);
    st.mu[0][0] = 0.5;
    st.sigma[0][0] = 0.01;
    double samples[2000 * VF_VIEW_DIM];
    vf_attack_sample_views(&st, &cfg, &rng, 2000, samples);
    vf_view_std(samples, 2000, std);
    double sech = 1.0 / cosh(0.5), expected = 180.0 * 0.01 * sech * sech;
    CHECK(fabs(std[0] / expected - 1.0) < 0.06, "psi std %g, expected about %g", std[0], expected);
    vf_attack_v_star(&st, &cfg, centre);
    CHECK_NEAR(centre[0], 180.0 * tanh(0.5), 1e-9);
    CHECK_NEAR(centre[2], 90.0, 1e-12);
    vf_attack_state_free(&st);

    /* random search: the best sample and the fooled fraction */
    objective o = make_objective(OBJ_QUADRATIC);
    o.fooled_above = -1.0;
    double rs_views[100 * VF_VIEW_DIM], rs_losses[100];
    vf_random_search_result res;
    CHECK(vf_attack_random_search(&b, 100, 4, objective_fn, &o, rs_views, rs_losses, &res) ==
              VF_OK,
          "random search: %s", vf_error_message());
    int fooled = 0, best_ok = 1, in_box = 1;
    for (int j = 0; j < 100; j++) {
        fooled += rs_losses[j] > -1.0;
        best_ok &= rs_losses[j] <= res.best_loss;
        for (int i = 0; i < VF_VIEW_DIM; i++)
            in_box &= rs_views[j * VF_VIEW_DIM + i] >= b.lo[i] &&
                      rs_views[j * VF_VIEW_DIM + i] <= b.hi[i];
    }
    CHECK(in_box && best_ok, "random samples in the box, best is the maximum");
    CHECK_NEAR(res.asr, fooled / 100.0, 1e-12);
    vf_random_search_result again;
    vf_attack_random_search(&b, 100, 4, objective_fn, &o, NULL, NULL, &again);
    CHECK(memcmp(&res, &again, sizeof res) == 0, "random search is reproducible");
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_log_jacobian);
    CHECK_CASE(test_entropy);
    CHECK_CASE(test_gradient_single);
    CHECK_CASE(test_gradient_mixture);
    CHECK_CASE(test_nes_converges);
    CHECK_CASE(test_pepg_converges);
    CHECK_CASE(test_entropy_widens);
    CHECK_CASE(test_entropy_balance);
    CHECK_CASE(test_mixture_two_modes);
    CHECK_CASE(test_seeds);
    CHECK_CASE(test_resume);
    CHECK_CASE(test_config);
    CHECK_CASE(test_callback_errors);
    CHECK_CASE(test_reports);
    return check_finish();
}
