/* WS/attack/attack.json, written and read (vf/attack_file.h). */
#include "vf/attack_file.h"
#include "vf/json.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ---- writing ---- */

static json_t *label_json(const vf_attack_outcome *o)
{
    json_t *idx = json_array(), *names = json_array();
    for (int i = 0; i < o->label_count; i++) {
        json_array_append_new(idx, json_integer(o->labels[i]));
        json_array_append_new(names, json_string(vf_class_short_name(o->labels[i])));
    }
    return json_pack("{s:o, s:o, s:b}", "indices", idx, "names", names, "proposed",
                     o->label_proposed);
}

static json_t *bounds_json(const vf_attack_outcome *o)
{
    json_t *limited = json_array();
    for (int i = 0; i < VF_VIEW_DIM; i++)
        if (o->limited && o->limited[i])
            json_array_append_new(limited, json_string(vf_view_param_name(i)));
    return json_pack("{s:o, s:o, s:o}", "lo", vf_json_doubles(o->cfg->bounds.lo, VF_VIEW_DIM),
                     "hi", vf_json_doubles(o->cfg->bounds.hi, VF_VIEW_DIM), "limited_to_capture",
                     limited);
}

/* The measured part: v*, the samples, fluctuation, the wrong classes. */
static json_t *eval_json(const vf_attack_eval *ev)
{
    json_t *samples = json_array(), *preds = json_array(), *wrong = json_array();
    for (int i = 0; i < ev->sample_count; i++) {
        json_array_append_new(samples,
                              vf_json_doubles(ev->samples + VF_VIEW_DIM * i, VF_VIEW_DIM));
        json_array_append_new(preds, vf_view_prediction_to_json(&ev->sample_pred[i]));
    }
    for (int i = 0; i < ev->wrong_count; i++)
        json_array_append_new(wrong, json_pack("{s:i, s:s, s:i}", "class", ev->wrong_class[i],
                                               "name", vf_class_short_name(ev->wrong_class[i]),
                                               "count", ev->wrong_votes[i]));
    double r[VF_FLUCT_LEVELS], range[VF_VIEW_DIM];
    for (int i = 0; i < VF_FLUCT_LEVELS; i++)
        r[i] = i + 1;
    vf_view_ranges_paper(range);
    return json_pack(
        "{s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:o, s:{s:o, s:o, s:i}, s:o}", "v_star",
        vf_json_doubles(ev->v_star, VF_VIEW_DIM), "v_star_prediction",
        vf_view_prediction_to_json(&ev->v_star_pred), "asr_v_star", vf_json_number(ev->asr_v_star),
        "v_best", vf_json_doubles(ev->v_best, VF_VIEW_DIM), "v_best_prediction",
        vf_view_prediction_to_json(&ev->v_best_pred), "asr_v_best", vf_json_number(ev->asr_v_best),
        "measure_ranges", vf_json_doubles(range, VF_VIEW_DIM), "samples", samples,
        "sample_predictions", preds, "asr_samples", vf_json_number(ev->asr_samples), "sample_std",
        vf_json_doubles(ev->sample_std, VF_VIEW_DIM), "fluctuation", "r_percent",
        vf_json_doubles(r, VF_FLUCT_LEVELS), "asr", vf_json_doubles(ev->fluct_asr, VF_FLUCT_LEVELS),
        "samples_per_level", VF_FLUCT_SAMPLES, "top_wrong_classes", wrong);
}

/* The distribution and the optimizer's history ("mu" ... "batch_asr_per_step"). */
static void add_distribution(json_t *doc, const vf_attack_state *st, const vf_attack_config *cfg)
{
    json_t *mu = json_array(), *sigma = json_array(), *views = json_array();
    json_t *loss = json_array(), *max_loss = json_array(), *entropy = json_array(),
           *asr = json_array();
    double w[VF_ATTACK_MAX_COMPONENTS];
    if (st) {
        vf_attack_weights(st, w);
        for (int c = 0; c < st->components; c++) {
            double v[VF_VIEW_DIM];
            vf_attack_component_view(st, cfg, c, v);
            json_array_append_new(mu, vf_json_doubles(st->mu[c], VF_VIEW_DIM));
            json_array_append_new(sigma, vf_json_doubles(st->sigma[c], VF_VIEW_DIM));
            json_array_append_new(views, vf_json_doubles(v, VF_VIEW_DIM));
        }
        for (int s = 0; s < st->step; s++) {
            json_array_append_new(loss, vf_json_number(st->history[s].mean_loss));
            json_array_append_new(max_loss, vf_json_number(st->history[s].max_loss));
            json_array_append_new(entropy, vf_json_number(st->history[s].entropy));
            json_array_append_new(asr, vf_json_number(st->history[s].fooled_rate));
        }
    }
    /* One component: mu and sigma are plain 6-vectors; a mixture: one row per component. */
    int single = st && st->components == 1;
    json_object_set_new(doc, "mu",
                        !st      ? json_null()
                        : single ? json_incref(json_array_get(mu, 0))
                                 : json_incref(mu));
    json_object_set_new(doc, "sigma",
                        !st      ? json_null()
                        : single ? json_incref(json_array_get(sigma, 0))
                                 : json_incref(sigma));
    json_object_set_new(doc, "weights", st ? vf_json_doubles(w, st->components) : json_null());
    json_object_set_new(doc, "v_components", views);
    json_object_set_new(doc, "loss_per_step", loss);
    json_object_set_new(doc, "max_loss_per_step", max_loss);
    json_object_set_new(doc, "entropy_per_step", entropy);
    json_object_set_new(doc, "batch_asr_per_step", asr);
    json_decref(mu);
    json_decref(sigma);
}

/* "trust": the limit, v*'s gap to the photos and the share of the samples within it. */
static json_t *trust_json(const vf_attack_outcome *o)
{
    const vf_attack_eval *ev = o->ev;
    int inside = 0;
    for (int i = 0; i < ev->sample_count; i++)
        inside += !ev->sample_pred[i].untrusted;
    return json_pack("{s:o, s:o, s:b, s:o}", "gap_limit_deg",
                     o->trust_gap > 0 ? vf_json_number(o->trust_gap) : json_null(),
                     "v_star_gap_deg", vf_json_number(ev->v_star_pred.gap_deg), "v_star_trusted",
                     !ev->v_star_pred.untrusted, "samples_trusted",
                     vf_json_number(ev->sample_count ? (double)inside / ev->sample_count : NAN));
}

json_t *vf_attack_file_json(const vf_attack_outcome *o)
{
    json_t *doc = eval_json(o->ev);
    json_object_set_new(doc, "trust", trust_json(o));
    const vf_camera *cam = &o->camera;
    double views = o->stats.views ? (double)o->stats.views : 1.0;
    json_object_set_new(doc, "model", json_string(o->model));
    json_object_set_new(doc, "engine", json_string(o->engine));
    json_object_set_new(doc, "label", label_json(o));
    json_object_set_new(doc, "method", json_string(o->method));
    json_object_set_new(doc, "space", json_string(o->space));
    json_object_set_new(doc, "bounds", bounds_json(o));
    json_object_set_new(doc, "camera", vf_camera_json(cam));
    json_object_set_new(doc, "natural_accuracy", vf_json_number(o->natural_accuracy));
    json_object_set_new(doc, "natural_views", json_integer(o->natural_views));
    json_object_set_new(doc, "config", vf_attack_config_to_json(o->cfg));
    add_distribution(doc, o->st, o->cfg);
    if (o->baseline)
        json_object_set_new(doc, "random_search",
                            json_pack("{s:o, s:o, s:o, s:i}", "asr_samples",
                                      vf_json_number(o->baseline->asr), "best_view",
                                      vf_json_doubles(o->baseline->best_view, VF_VIEW_DIM),
                                      "best_loss", vf_json_number(o->baseline->best_loss),
                                      "samples", VF_EVAL_SAMPLES));
    json_object_set_new(
        doc, "timings",
        json_pack(
            "{s:o, s:o, s:o, s:o, s:i, s:o, s:o}", "natural_seconds",
            vf_json_number(o->seconds_natural), "attack_seconds", vf_json_number(o->seconds_attack),
            "evaluation_seconds", vf_json_number(o->seconds_eval), "baseline_seconds",
            vf_json_number(o->seconds_baseline), "views", (json_int_t)o->stats.views,
            "render_ms_per_view", vf_json_number(1000 * o->stats.render_seconds / views),
            "classify_ms_per_view", vf_json_number(1000 * o->stats.classify_seconds / views)));
    return doc;
}

/* ---- reading ---- */

int vf_json_read_view(const json_t *arr, double out[6])
{
    if (!vf_json_read_doubles(arr, out, 6))
        return 0;
    for (int i = 0; i < 6; i++)
        if (!(fabs(out[i]) <= (i < 3 ? 720.0 : 400.0)))
            return 0;
    return 1;
}

static double number_or_nan(const json_t *doc, const char *key)
{
    const json_t *x = json_object_get(doc, key);
    return json_is_number(x) ? json_number_value(x) : NAN;
}

static void read_prediction(const json_t *p, vf_sample_prediction *out)
{
    const json_t *cls = json_object_get(p, "class");
    out->cls = json_is_integer(cls) ? (int)json_integer_value(cls) : -1;
    const char *name = json_string_value(json_object_get(p, "name"));
    snprintf(out->name, sizeof out->name, "%s", name ? name : "?");
    out->confidence = number_or_nan(p, "confidence");
    out->fooled = json_is_true(json_object_get(p, "fooled"));
}

static vf_status read_labels(const json_t *doc, const char *path, vf_attack_file *a)
{
    json_t *label = json_object_get(doc, "label");
    const json_t *indices = json_object_get(label, "indices"),
                 *names = json_object_get(label, "names");
    size_t n = json_array_size(indices);
    if (n == 0 || n > VF_MAX_LABELS)
        return vf_fail(VF_EINPUT, "%s: \"label\" needs \"indices\" (1 to %d class numbers)", path,
                       VF_MAX_LABELS);
    size_t used = 0;
    for (size_t i = 0; i < n; i++) {
        const json_t *index = json_array_get(indices, i);
        if (!json_is_integer(index) || json_integer_value(index) < 0 ||
            json_integer_value(index) >= VF_NUM_CLASSES)
            return vf_fail(VF_EINPUT, "%s: \"label\" indices must be class numbers 0 to %d", path,
                           VF_NUM_CLASSES - 1);
        a->labels[i] = (int)json_integer_value(index);
        const char *name = json_string_value(json_array_get(names, i));
        if (name && used < sizeof a->label_text)
            used += (size_t)snprintf(a->label_text + used, sizeof a->label_text - used, "%s%s",
                                     used ? ", " : "", name);
    }
    a->label_count = (int)n;
    a->label = json_incref(label);
    return VF_OK;
}

/* The classifier's camera the attack rendered with (optional: older files have none). */
static vf_status read_camera(const json_t *doc, const char *path, vf_attack_file *a)
{
    const json_t *c = json_object_get(doc, "camera");
    if (!c)
        return VF_OK;
    char where[VF_PATH_MAX + 16];
    snprintf(where, sizeof where, "%s: \"camera\"", path);
    vf_status status = vf_camera_from_json(c, where, &a->camera);
    a->has_camera = status == VF_OK;
    return status;
}

/* "measure_ranges", or the paper's full ranges for files written before it existed. */
static vf_status read_ranges(const json_t *doc, const char *path, vf_attack_file *a)
{
    const json_t *r = json_object_get(doc, "measure_ranges");
    if (!r) {
        vf_view_ranges_paper(a->range);
        return VF_OK;
    }
    if (!vf_json_read_view(r, a->range))
        return vf_fail(VF_EINPUT, "%s: \"measure_ranges\" must be 6 numbers", path);
    for (int i = 0; i < 6; i++)
        if (!(a->range[i] > 0))
            return vf_fail(VF_EINPUT, "%s: \"measure_ranges\" must be positive", path);
    return VF_OK;
}

static vf_status read_samples(const json_t *doc, const char *path, vf_attack_file *a)
{
    const json_t *samples = json_object_get(doc, "samples");
    const json_t *preds = json_object_get(doc, "sample_predictions");
    size_t n = json_array_size(samples);
    a->samples = malloc(sizeof(double) * 6 * (n + 1));
    if (!a->samples)
        return vf_fail(VF_EINTERNAL, "out of memory reading %s", path);
    for (size_t i = 0; i < n; i++)
        if (!vf_json_read_view(json_array_get(samples, i), a->samples + 6 * i))
            return vf_fail(VF_EINPUT, "%s: samples[%zu] is not 6 numbers", path, i);
    a->sample_count = (int)n;
    if (n > 0 && json_array_size(preds) == n) {
        a->predictions = calloc(n, sizeof *a->predictions);
        if (!a->predictions)
            return vf_fail(VF_EINTERNAL, "out of memory reading %s", path);
        for (size_t i = 0; i < n; i++)
            read_prediction(json_array_get(preds, i), &a->predictions[i]);
    }
    return VF_OK;
}

/* mu and sigma: one 6-vector each (a single Gaussian), a row a component (a mixture), or
 * null (random search). sigma must be positive and not huge: it is sampled from. */
static vf_status read_distribution(const json_t *doc, const char *path, vf_attack_file *a)
{
    const json_t *mu = json_object_get(doc, "mu"), *sigma = json_object_get(doc, "sigma");
    const json_t *weights = json_object_get(doc, "weights");
    if (!json_is_array(mu) && !json_is_array(sigma))
        return VF_OK;
    int mixture = json_is_array(json_array_get(mu, 0));
    int k = mixture ? (int)json_array_size(mu) : 1;
    int ok = k >= 1 && k <= VF_ATTACK_MAX_COMPONENTS &&
             (!mixture || json_array_size(sigma) == (size_t)k);
    double total = 0;
    for (int c = 0; c < k && ok; c++) {
        ok = vf_json_read_doubles(mixture ? json_array_get(mu, (size_t)c) : mu, a->mu[c],
                                  VF_VIEW_DIM) &&
             vf_json_read_doubles(mixture ? json_array_get(sigma, (size_t)c) : sigma, a->sigma[c],
                                  VF_VIEW_DIM);
        for (int i = 0; i < VF_VIEW_DIM && ok; i++)
            ok = fabs(a->mu[c][i]) < 1e3 && a->sigma[c][i] > 0 && a->sigma[c][i] < 1e3;
        const json_t *w = json_array_get(weights, (size_t)c);
        a->weight[c] = json_is_number(w) ? json_number_value(w) : 1.0 / k;
        ok = ok && a->weight[c] >= 0 && isfinite(a->weight[c]);
        total += a->weight[c];
    }
    if (!ok || !(total > 0))
        return vf_fail(VF_EINPUT,
                       "%s: \"mu\", \"sigma\" and \"weights\" do not describe a "
                       "distribution",
                       path);
    a->components = k;
    return VF_OK;
}

vf_status vf_attack_file_load(const char *path, vf_attack_file *out)
{
    memset(out, 0, sizeof *out);
    json_t *doc;
    vf_status status = vf_json_load(path, &doc);
    if (status != VF_OK)
        return status;
    double v[6];
    const json_t *bounds = json_object_get(doc, "bounds");
    if (!vf_json_read_view(json_object_get(doc, "v_star"), v))
        status = vf_fail(VF_EINPUT,
                         "%s: \"v_star\" must be 6 numbers (psi, theta, phi, dx, dy, "
                         "dz)",
                         path);
    else if (!vf_json_read_view(json_object_get(bounds, "lo"), out->lo) ||
             !vf_json_read_view(json_object_get(bounds, "hi"), out->hi))
        status =
            vf_fail(VF_EINPUT, "%s: \"bounds\" needs \"lo\" and \"hi\", 6 numbers each", path);
    for (int i = 0; status == VF_OK && i < 6; i++)
        if (!(out->hi[i] > out->lo[i]))
            status = vf_fail(VF_EINPUT, "%s: bounds hi[%d] must exceed lo[%d]", path, i, i);
    if (status == VF_OK)
        status = read_ranges(doc, path, out);
    if (status == VF_OK)
        status = read_labels(doc, path, out);
    if (status == VF_OK)
        status = read_samples(doc, path, out);
    if (status == VF_OK)
        status = read_distribution(doc, path, out);
    if (status == VF_OK) {
        out->v_star = vf_viewpoint_from_array(v);
        const char *model = json_string_value(json_object_get(doc, "model"));
        const char *method = json_string_value(json_object_get(doc, "method"));
        snprintf(out->model, sizeof out->model, "%s", model ? model : "");
        snprintf(out->method, sizeof out->method, "%s", method ? method : "");
        out->v_star_prediction.cls = -1;
        if (json_is_object(json_object_get(doc, "v_star_prediction")))
            read_prediction(json_object_get(doc, "v_star_prediction"), &out->v_star_prediction);
        out->natural_accuracy = number_or_nan(doc, "natural_accuracy");
        out->asr_v_star = number_or_nan(doc, "asr_v_star");
        out->asr_samples = number_or_nan(doc, "asr_samples");
        double limit = number_or_nan(json_object_get(doc, "trust"), "gap_limit_deg");
        out->trust_gap = limit > 0 && limit <= 180 ? limit : 0;
        status = read_camera(doc, path, out);
    }
    json_decref(doc);
    if (status != VF_OK)
        vf_attack_file_free(out);
    return status;
}

/* "a, b, c" of the workspace's attack names. */
static void list_attacks(const char *const *stages, int n, char *out, size_t size)
{
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < n && used < size; i++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", i ? ", " : "", stages[i] + 7);
}

vf_status vf_attack_choose(const vf_workspace *ws, const char *name, char *stage, size_t size)
{
    const char *stages[64];
    char names[1024];
    int n = vf_workspace_stages_of(ws, "attack", stages, 64);
    list_attacks(stages, n, names, sizeof names);
    if (name && name[0]) {
        if ((size_t)snprintf(stage, size, "attack/%s", name) >= size)
            return vf_fail(VF_EINPUT, "attack name too long: %s", name);
        if (!vf_workspace_has_stage(ws, stage) && n > 0)
            return vf_fail(VF_EINPUT, "%s has no attack '%s' (it has %s)", ws->root, name, names);
    } else if (n == 1) {
        snprintf(stage, size, "%s", stages[0]);
    } else if (n > 1) {
        return vf_fail(VF_EINPUT, "%s has %d attacks (%s): choose one with --attack NAME",
                       ws->root, n, names);
    } else {
        return vf_fail(VF_EINPUT, "%s has no attack yet: run 'vfcapture attack %s' first",
                       ws->root, ws->root);
    }
    return vf_workspace_need(ws, stage);
}

vf_status vf_attack_file_load_workspace(const vf_workspace *ws, const char *name,
                                        vf_attack_file *out)
{
    char path[VF_PATH_MAX], stage[128];
    memset(out, 0, sizeof *out);
    vf_status s = vf_attack_choose(ws, name, stage, sizeof stage);
    if (s == VF_OK)
        s = vf_workspace_path(ws, stage, VF_ATTACK_FILE, path, sizeof path);
    if (s == VF_OK)
        s = vf_attack_file_load(path, out);
    if (s == VF_OK)
        snprintf(out->stage, sizeof out->stage, "%s", stage);
    return s;
}

void vf_attack_file_free(vf_attack_file *a)
{
    free(a->samples);
    free(a->predictions);
    json_decref(a->label);
    a->samples = NULL;
    a->predictions = NULL;
    a->label = NULL;
    a->sample_count = 0;
}

int vf_attack_is_label(const vf_attack_file *a, int cls)
{
    return vf_label_set_contains(a->labels, a->label_count, cls);
}

vf_status vf_attack_file_sample(const vf_attack_file *a, vf_rng *rng, int n, double *views)
{
    if (a->components < 1)
        return vf_fail(VF_EINPUT, "the attack has no distribution to sample (random search "
                                  "keeps none): run it with --method nes or pepg");
    vf_attack_state st = {.components = a->components};
    vf_attack_config cfg = {0}; /* the sampler reads only the bounds */
    memcpy(cfg.bounds.lo, a->lo, sizeof a->lo);
    memcpy(cfg.bounds.hi, a->hi, sizeof a->hi);
    double total = 0;
    for (int c = 0; c < a->components; c++)
        total += a->weight[c];
    for (int c = 0; c < a->components; c++) {
        memcpy(st.mu[c], a->mu[c], sizeof st.mu[c]);
        memcpy(st.sigma[c], a->sigma[c], sizeof st.sigma[c]);
        st.logit[c] = log(a->weight[c] / total + 1e-300); /* softmax(logit) = the weights */
    }
    vf_attack_sample_views(&st, &cfg, rng, n, views);
    return VF_OK;
}
