/* JSON for attack configs and states, so an interrupted attack resumes exactly.
 *
 * jansson writes reals with 17 significant digits, which reads back to the same double, so a
 * saved and restored state continues bit-identically. The RNG words are hex strings (JSON
 * numbers cannot hold 64-bit integers exactly); -inf losses (no step yet) are null. */
#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "viewfool_internal.h"
#include "vf/json.h"

#define STATE_FORMAT 2 /* 2: moments over (mu, sigma), not (mu, log sigma) */

/* ---- small converters ---- */

static json_t *real_or_null(double x) { return isfinite(x) ? vf_json_number(x) : json_null(); }

/* Read exactly n numbers from a JSON array (null reads as -inf); name is for messages. */
static vf_status array_to_doubles(const json_t *array, const char *name, double *x, int n)
{
    if (!json_is_array(array) || (int)json_array_size(array) != n)
        return vf_fail(VF_EINPUT, "attack: \"%s\" must be an array of %d numbers", name, n);
    for (int i = 0; i < n; i++) {
        const json_t *item = json_array_get(array, (size_t)i);
        if (json_is_null(item))
            x[i] = -INFINITY;
        else if (json_is_number(item))
            x[i] = json_number_value(item);
        else
            return vf_fail(VF_EINPUT, "attack: \"%s\"[%d] is not a number", name, i);
    }
    return VF_OK;
}

static vf_status json_to_doubles(const json_t *obj, const char *key, double *x, int n)
{
    return array_to_doubles(json_object_get(obj, key), key, x, n);
}

static vf_status json_to_number(const json_t *obj, const char *key, double *x)
{
    const json_t *item = json_object_get(obj, key);
    if (json_is_null(item)) {
        *x = -INFINITY;
        return VF_OK;
    }
    if (!json_is_number(item))
        return vf_fail(VF_EINPUT, "attack: \"%s\" must be a number", key);
    *x = json_number_value(item);
    return VF_OK;
}

static vf_status json_to_int(const json_t *obj, const char *key, int lo, int hi, int *x)
{
    const json_t *item = json_object_get(obj, key);
    if (!json_is_integer(item) || json_integer_value(item) < lo || json_integer_value(item) > hi)
        return vf_fail(VF_EINPUT, "attack: \"%s\" must be an integer in [%d, %d]", key, lo, hi);
    *x = (int)json_integer_value(item);
    return VF_OK;
}

static vf_status json_to_u64(const json_t *item, const char *key, int base, uint64_t *x)
{
    const char *text = json_string_value(item);
    char *end;
    if (!text || !*text || *text == '-')
        return vf_fail(VF_EINPUT, "attack: \"%s\" must be a string holding an unsigned integer",
                       key);
    *x = strtoull(text, &end, base);
    if (*end)
        return vf_fail(VF_EINPUT, "attack: \"%s\" is \"%s\", not an unsigned integer", key, text);
    return VF_OK;
}

/* ---- state ---- */

json_t *vf_attack_state_to_json(const vf_attack_state *st)
{
    int k = st->components, n_params = k * VF_ATTACK_COMPONENT_PARAMS;
    json_t *mu = json_array(), *sigma = json_array(), *rng = json_array(), *hist = json_array();
    for (int c = 0; c < k; c++) {
        json_array_append_new(mu, vf_json_doubles(st->mu[c], VF_VIEW_DIM));
        json_array_append_new(sigma, vf_json_doubles(st->sigma[c], VF_VIEW_DIM));
    }
    for (int i = 0; i < 4; i++) {
        char hex[17];
        snprintf(hex, sizeof hex, "%016" PRIx64, st->rng.s[i]);
        json_array_append_new(rng, json_string(hex));
    }
    for (int t = 0; t < st->step; t++) {
        const vf_attack_record *r = &st->history[t];
        double row[4] = {r->mean_loss, r->max_loss, r->fooled_rate, r->entropy};
        json_array_append_new(hist, vf_json_doubles(row, 4));
    }
    return json_pack("{s:i, s:i, s:i, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o}",
                     "format", STATE_FORMAT, "components", k, "step", st->step, "mu", mu,
                     "sigma", sigma, "logit", vf_json_doubles(st->logit, k), "moment1",
                     vf_json_doubles(st->moment1, n_params), "moment2",
                     vf_json_doubles(st->moment2, n_params), "rng", rng, "last_best_view",
                     vf_json_doubles(st->last_best_view, VF_VIEW_DIM), "last_best_loss",
                     real_or_null(st->last_best_loss), "best_view",
                     vf_json_doubles(st->best_view, VF_VIEW_DIM), "best_loss",
                     real_or_null(st->best_loss), "history", hist);
}

/* mu or sigma: an array of K arrays of 6. */
static vf_status json_to_rows(const json_t *obj, const char *key, int k,
                              double rows[][VF_VIEW_DIM])
{
    const json_t *array = json_object_get(obj, key);
    if (!json_is_array(array) || (int)json_array_size(array) != k)
        return vf_fail(VF_EINPUT, "attack state: \"%s\" must hold %d rows", key, k);
    for (int c = 0; c < k; c++) {
        vf_status status = array_to_doubles(json_array_get(array, (size_t)c), key, rows[c],
                                            VF_VIEW_DIM);
        if (status != VF_OK)
            return status;
    }
    return VF_OK;
}

static vf_status json_to_history(const json_t *obj, vf_attack_state *st)
{
    const json_t *array = json_object_get(obj, "history");
    if (!json_is_array(array) || (int)json_array_size(array) != st->step)
        return vf_fail(VF_EINPUT, "attack state: \"history\" must hold one row per step (%d)",
                       st->step);
    int steps = st->step;
    st->step = 0;
    for (int t = 0; t < steps; t++) {
        double row[4];
        vf_status status = array_to_doubles(json_array_get(array, (size_t)t), "history", row, 4);
        vf_attack_record rec = {row[0], row[1], row[2], row[3]};
        if (status == VF_OK)
            status = vf__history_push(st, &rec);
        if (status != VF_OK)
            return status;
        st->step++;
    }
    return VF_OK;
}

static vf_status json_to_rng(const json_t *obj, vf_rng *rng)
{
    const json_t *array = json_object_get(obj, "rng");
    if (!json_is_array(array) || json_array_size(array) != 4)
        return vf_fail(VF_EINPUT, "attack state: \"rng\" must hold 4 hex strings");
    for (int i = 0; i < 4; i++) {
        vf_status status = json_to_u64(json_array_get(array, (size_t)i), "rng", 16, &rng->s[i]);
        if (status != VF_OK)
            return status;
    }
    return VF_OK;
}

static vf_status state_from_json(const json_t *json, vf_attack_state *st)
{
    int format = 0, k = 1, n_params;
    vf_status s;
    if (!json_is_object(json))
        return vf_fail(VF_EINPUT, "attack state: not a JSON object");
    if ((s = json_to_int(json, "format", STATE_FORMAT, STATE_FORMAT, &format)) ||
        (s = json_to_int(json, "components", 1, VF_ATTACK_MAX_COMPONENTS, &k)) ||
        (s = json_to_int(json, "step", 0, 1 << 30, &st->step)))
        return s;
    st->components = k;
    n_params = k * VF_ATTACK_COMPONENT_PARAMS;
    if ((s = json_to_rows(json, "mu", k, st->mu)) ||
        (s = json_to_rows(json, "sigma", k, st->sigma)) ||
        (s = json_to_doubles(json, "logit", st->logit, k)) ||
        (s = json_to_doubles(json, "moment1", st->moment1, n_params)) ||
        (s = json_to_doubles(json, "moment2", st->moment2, n_params)) ||
        (s = json_to_rng(json, &st->rng)) ||
        (s = json_to_doubles(json, "last_best_view", st->last_best_view, VF_VIEW_DIM)) ||
        (s = json_to_number(json, "last_best_loss", &st->last_best_loss)) ||
        (s = json_to_doubles(json, "best_view", st->best_view, VF_VIEW_DIM)) ||
        (s = json_to_number(json, "best_loss", &st->best_loss)) ||
        (s = json_to_history(json, st)))
        return s;
    for (int c = 0; c < k; c++)
        for (int i = 0; i < VF_VIEW_DIM; i++)
            if (!(st->sigma[c][i] > 0) || !isfinite(st->sigma[c][i]) || !isfinite(st->mu[c][i]))
                return vf_fail(VF_EINPUT, "attack state: mu and sigma must be finite, sigma > 0");
    return VF_OK;
}

vf_status vf_attack_state_from_json(const json_t *json, vf_attack_state *st)
{
    memset(st, 0, sizeof *st);
    vf_status status = state_from_json(json, st);
    if (status != VF_OK)
        vf_attack_state_free(st);
    return status;
}

/* ---- config ---- */

json_t *vf_attack_config_to_json(const vf_attack_config *cfg)
{
    char seed[24];
    snprintf(seed, sizeof seed, "%" PRIu64, cfg->seed);
    json_t *bounds = json_pack("{s:o, s:o}", "lo", vf_json_doubles(cfg->bounds.lo, VF_VIEW_DIM),
                               "hi", vf_json_doubles(cfg->bounds.hi, VF_VIEW_DIM));
    json_t *json = json_pack(
        "{s:s, s:o, s:i, s:i, s:o, s:o, s:s, s:o, s:o, s:o}", "method",
        cfg->method == VF_ATTACK_PEPG ? "pepg" : "nes", "bounds", bounds, "samples", cfg->samples,
        "steps", cfg->steps, "lambda", vf_json_number(cfg->lambda), "lr", vf_json_number(cfg->lr),
        "seed", seed, "sigma_init", vf_json_number(cfg->sigma_init), "sigma_min",
        vf_json_number(cfg->sigma_min), "sigma_max", vf_json_number(cfg->sigma_max));
    json_t *more =
        json_pack("{s:o, s:b, s:i, s:o, s:o, s:o, s:o, s:o, s:o}", "sigma_decay",
                  vf_json_number(cfg->sigma_decay), "antithetic", cfg->antithetic, "components",
                  cfg->components, "weight_lr", vf_json_number(cfg->weight_lr), "adam_beta1",
                  vf_json_number(cfg->adam_beta1), "adam_beta2", vf_json_number(cfg->adam_beta2),
                  "momentum", vf_json_number(cfg->momentum), "lr_decay",
                  vf_json_number(cfg->lr_decay), "sigma_lr", vf_json_number(cfg->sigma_lr));
    json_object_update(json, more);
    json_decref(more);
    return json;
}

static vf_status config_real(const json_t *json, const char *key, double *x)
{
    if (!json_object_get(json, key))
        return VF_OK;
    return json_to_number(json, key, x);
}

static vf_status config_int(const json_t *json, const char *key, int *x)
{
    const json_t *item = json_object_get(json, key);
    if (!item)
        return VF_OK;
    if (json_is_boolean(item)) {
        *x = json_is_true(item);
        return VF_OK;
    }
    return json_to_int(json, key, -(1 << 30), 1 << 30, x);
}

static vf_status config_method(const json_t *json, vf_attack_config *cfg)
{
    const json_t *item = json_object_get(json, "method");
    const char *name = item ? json_string_value(item) : "nes";
    if (name && !strcmp(name, "nes"))
        vf_attack_config_default(cfg, VF_ATTACK_NES);
    else if (name && !strcmp(name, "pepg"))
        vf_attack_config_default(cfg, VF_ATTACK_PEPG);
    else
        return vf_fail(VF_EINPUT, "attack: \"method\" must be \"nes\" or \"pepg\"");
    return VF_OK;
}

vf_status vf_attack_config_from_json(const json_t *json, vf_attack_config *cfg)
{
    vf_status s;
    if (!json_is_object(json))
        return vf_fail(VF_EINPUT, "attack config: not a JSON object");
    if ((s = config_method(json, cfg)))
        return s;
    const json_t *bounds = json_object_get(json, "bounds");
    if (bounds && ((s = json_to_doubles(bounds, "lo", cfg->bounds.lo, VF_VIEW_DIM)) ||
                   (s = json_to_doubles(bounds, "hi", cfg->bounds.hi, VF_VIEW_DIM))))
        return s;
    const json_t *seed = json_object_get(json, "seed");
    if (seed && (s = json_to_u64(seed, "seed", 10, &cfg->seed)))
        return s;
    if ((s = config_int(json, "samples", &cfg->samples)) ||
        (s = config_int(json, "steps", &cfg->steps)) ||
        (s = config_real(json, "lambda", &cfg->lambda)) ||
        (s = config_real(json, "lr", &cfg->lr)) ||
        (s = config_real(json, "sigma_init", &cfg->sigma_init)) ||
        (s = config_real(json, "sigma_min", &cfg->sigma_min)) ||
        (s = config_real(json, "sigma_max", &cfg->sigma_max)) ||
        (s = config_real(json, "sigma_decay", &cfg->sigma_decay)) ||
        (s = config_int(json, "antithetic", &cfg->antithetic)) ||
        (s = config_int(json, "components", &cfg->components)) ||
        (s = config_real(json, "weight_lr", &cfg->weight_lr)) ||
        (s = config_real(json, "adam_beta1", &cfg->adam_beta1)) ||
        (s = config_real(json, "adam_beta2", &cfg->adam_beta2)) ||
        (s = config_real(json, "momentum", &cfg->momentum)) ||
        (s = config_real(json, "lr_decay", &cfg->lr_decay)) ||
        (s = config_real(json, "sigma_lr", &cfg->sigma_lr)))
        return s;
    return vf_attack_config_check(cfg);
}
