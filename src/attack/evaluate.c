/* Measuring an attack's answer: v*, samples of p*(v), fluctuation, wrong classes
 * (vf/attack_eval.h). */
#include "vf/attack_eval.h"

#include <math.h>
#include <string.h>

#include "vf/classifier.h"
#include "vf/json.h"

/* Stream offsets so the evaluation never reuses the optimizer's random numbers. */
#define SAMPLE_STREAM 0x5a3c1e77d2b4f601ULL
#define FLUCT_STREAM 0x0f1e2d3c4b5a6978ULL

static double fooled_rate(const vf_view_prediction *pred, int n)
{
    int fooled = 0;
    for (int i = 0; i < n; i++)
        fooled += !pred[i].correct;
    return n ? (double)fooled / n : 0.0;
}

static void count_wrong_classes(vf_attack_eval *ev)
{
    int votes[VF_NUM_CLASSES] = {0};
    for (int i = 0; i < ev->sample_count; i++)
        if (!ev->sample_pred[i].correct)
            votes[ev->sample_pred[i].top_class]++;
    ev->wrong_count = 0;
    while (ev->wrong_count < VF_TOP_WRONG) {
        int best = 0;
        for (int c = 1; c < VF_NUM_CLASSES; c++)
            if (votes[c] > votes[best])
                best = c;
        if (votes[best] == 0)
            break;
        ev->wrong_class[ev->wrong_count] = best;
        ev->wrong_votes[ev->wrong_count++] = votes[best];
        votes[best] = 0;
    }
}

/* Everything after the samples and v* are in place. */
static vf_status measure(vf_view_loss *vl, const vf_view_bounds *bounds, uint64_t seed,
                         vf_attack_eval *ev)
{
    vf_status status = vf_view_loss_classify(vl, ev->v_star, 1, &ev->v_star_pred, NULL);
    if (status == VF_OK)
        status = vf_view_loss_classify(vl, ev->v_best, 1, &ev->v_best_pred, NULL);
    if (status == VF_OK)
        status = vf_view_loss_classify(vl, ev->samples, ev->sample_count, ev->sample_pred, NULL);
    if (status != VF_OK)
        return status;
    ev->asr_v_star = !ev->v_star_pred.correct;
    ev->asr_v_best = !ev->v_best_pred.correct;
    ev->asr_samples = fooled_rate(ev->sample_pred, ev->sample_count);
    vf_view_std(ev->samples, ev->sample_count, ev->sample_std);
    count_wrong_classes(ev);

    vf_rng rng;
    vf_rng_seed(&rng, seed ^ FLUCT_STREAM);
    double views[VF_FLUCT_SAMPLES * VF_VIEW_DIM];
    vf_view_prediction pred[VF_FLUCT_SAMPLES];
    for (int r = 1; r <= VF_FLUCT_LEVELS && status == VF_OK; r++) {
        vf_view_fluctuation(bounds, ev->v_star, r, &rng, VF_FLUCT_SAMPLES, views);
        status = vf_view_loss_classify(vl, views, VF_FLUCT_SAMPLES, pred, NULL);
        ev->fluct_asr[r - 1] = fooled_rate(pred, VF_FLUCT_SAMPLES);
    }
    return status;
}

vf_status vf_attack_eval_distribution(vf_view_loss *vl, const vf_attack_state *st,
                                      const vf_attack_config *cfg, uint64_t seed,
                                      vf_attack_eval *out)
{
    memset(out, 0, sizeof *out);
    vf_attack_v_star(st, cfg, out->v_star);
    vf_attack_v_best(st, out->v_best);
    vf_rng rng;
    vf_rng_seed(&rng, seed ^ SAMPLE_STREAM);
    out->sample_count = VF_EVAL_SAMPLES;
    vf_attack_sample_views(st, cfg, &rng, VF_EVAL_SAMPLES, out->samples);
    return measure(vl, &cfg->bounds, seed, out);
}

vf_status vf_attack_eval_random(vf_view_loss *vl, const vf_view_bounds *bounds, uint64_t seed,
                                vf_attack_eval *out)
{
    memset(out, 0, sizeof *out);
    vf_random_search_result rs;
    double losses[VF_EVAL_SAMPLES];
    vf_status status = vf_attack_random_search(bounds, VF_EVAL_SAMPLES, seed ^ SAMPLE_STREAM,
                                               vf_view_loss_fn, vl, out->samples, losses, &rs);
    if (status != VF_OK)
        return status;
    out->sample_count = VF_EVAL_SAMPLES;
    memcpy(out->v_star, rs.best_view, sizeof out->v_star);
    memcpy(out->v_best, rs.best_view, sizeof out->v_best);
    return measure(vl, bounds, seed, out);
}

json_t *vf_view_prediction_to_json(const vf_view_prediction *p)
{
    json_t *doc =
        json_pack("{s:i, s:s, s:o, s:o, s:b}", "class", p->top_class, "name",
                  p->untrusted ? "(untrusted: not rendered)" : vf_class_short_name(p->top_class),
                  "confidence", vf_json_number((double)p->top_prob), "label_probability",
                  vf_json_number((double)p->label_prob), "fooled", !p->correct);
    if (doc && !isnan(p->gap_deg)) {
        json_object_set_new(doc, "gap_deg", vf_json_number(p->gap_deg));
        json_object_set_new(doc, "trusted", json_boolean(!p->untrusted));
    }
    return doc;
}
