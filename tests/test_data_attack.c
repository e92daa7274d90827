/* The ViewFool attack end to end on real data, with a reduced budget: a radiance field of the
 * NeRF-synthetic chair trained here for 40 s, mobilenet_v2_1.0_224_quant, the chair classes
 * ImageNet has. Asserts that the classifier recognises the chair at natural views, that the
 * attack's distribution fools it far more often than the random-search baseline over the same
 * box, and that v* is misclassified. Then the trust limit (vf_view_loss_set_trust) with half
 * the photos: views beyond it are not rendered and never fooled, the others are classified as
 * before, and an attack under the limit keeps its samples near the photos. About 2.5 minutes
 * on 2 cores. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/attack_eval.h"
#include "vf/classifier.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/view_coverage.h"
#include "vf/view_loss.h"
#include "vf/viewfool.h"

/* A step budget, not a time budget: under a busy ctest -j the field is then just as good,
 * only later (about 35 s alone on 2 cores). */
#define TRAIN_STEPS 700
#define NATURAL_EVERY 2 /* natural accuracy on every 2nd training view */

static const char chair_classes[] = "folding chair,rocking chair,barber chair,throne";

static double natural_accuracy(vf_view_loss *vl, const vf_dataset *ds)
{
    int n = 0;
    double *c2w = malloc(sizeof(double) * 16 * (size_t)ds->count);
    vf_view_prediction *pred = malloc(sizeof *pred * (size_t)ds->count);
    for (int i = 0; i < ds->count; i += NATURAL_EVERY)
        memcpy(c2w + 16 * n++, ds->frames[i].c2w, 16 * sizeof(double));
    CHECK(vf_view_loss_classify_poses(vl, c2w, n, pred) == VF_OK, "natural views: %s",
          vf_error_message());
    int correct = 0, votes;
    for (int i = 0; i < n; i++)
        correct += pred[i].correct;
    int majority = vf_majority_class(pred, n, &votes);
    printf("natural views: %d of %d in {%s}; most common top-1 '%s' (%d)\n", correct, n,
           chair_classes, vf_class_short_name(majority), votes);
    free(c2w);
    free(pred);
    return (double)correct / n;
}

/* The share of n views within limit_deg of the photos. */
static double share_within(const double *photos, int count, const double *views, int n,
                           double limit_deg)
{
    int inside = 0;
    for (int i = 0; i < n; i++)
        inside += vf_view_trust_of(photos, count, views + VF_VIEW_DIM * i).gap_deg <= limit_deg;
    return (double)inside / n;
}

/* The photos more than 60 degrees from v* (as if no one had filmed where the attack went)
 * and a 20 degree limit: the views beyond are
 * answered without a render, never fooled, with losses below every rendered one; the views
 * within are classified as without the limit; and the attack's samples move to the photos. */
static void check_trust(vf_view_loss *vl, const vf_dataset *ds, const double *v_star,
                        const double *samples, vf_attack_config cfg)
{
    double *photos = malloc(sizeof(double) * 16 * (size_t)ds->count);
    int count = 0;
    for (int i = 0; i < ds->count; i++)
        if (vf_view_trust_of(ds->frames[i].c2w, 1, v_star).angle_deg > 60)
            memcpy(photos + 16 * count++, ds->frames[i].c2w, 16 * sizeof(double));
    /* uniform views over the box, classified without the limit first */
    double views[VF_EVAL_SAMPLES * VF_VIEW_DIM];
    vf_view_prediction before[VF_EVAL_SAMPLES];
    vf_rng rng;
    vf_rng_seed(&rng, 5);
    for (int i = 0; i < VF_EVAL_SAMPLES * VF_VIEW_DIM; i++) {
        int k = i % VF_VIEW_DIM;
        views[i] = cfg.bounds.lo[k] + vf_rng_uniform(&rng) * (cfg.bounds.hi[k] - cfg.bounds.lo[k]);
    }
    CHECK(vf_view_loss_classify(vl, views, VF_EVAL_SAMPLES, before, NULL) == VF_OK, "%s",
          vf_error_message());
    const double limit = VF_TRUST_GAP_DEG;
    vf_view_loss_set_trust(vl, photos, count, limit);
    vf_view_prediction pred[VF_EVAL_SAMPLES];
    double loss[VF_EVAL_SAMPLES];
    CHECK(vf_view_loss_classify(vl, views, VF_EVAL_SAMPLES, pred, loss) == VF_OK, "%s",
          vf_error_message());
    int untrusted = 0, same = 0, rendered = 0;
    for (int i = 0; i < VF_EVAL_SAMPLES; i++) {
        double gap = vf_view_trust_of(photos, count, views + VF_VIEW_DIM * i).gap_deg;
        CHECK_NEAR(pred[i].gap_deg, gap, 1e-9);
        if (gap > limit) {
            untrusted++;
            CHECK(pred[i].untrusted && pred[i].correct && pred[i].top_class < 0 &&
                      fabs(loss[i] + (gap - limit) / limit) < 1e-9,
                  "sample %d, %.0f deg out: untrusted, not fooled, loss %g", i, gap, loss[i]);
        } else {
            rendered++;
            same += pred[i].top_class == before[i].top_class;
            CHECK(!pred[i].untrusted && loss[i] >= 0, "sample %d within: rendered", i);
        }
    }
    printf("trust: %d of %d photos; %d of %d uniform views beyond %.0f deg, %d of the %d within "
           "classified as without the limit\n",
           count, ds->count, untrusted, VF_EVAL_SAMPLES, limit, same, rendered);
    CHECK(untrusted > 0 && rendered > 0, "the photos leave views on both sides");
    CHECK(same == rendered, "a view within the limit renders and classifies as before");

    /* The same attack under the limit: its p*(v) near the photos. */
    vf_attack_state st;
    double drawn[VF_EVAL_SAMPLES * VF_VIEW_DIM];
    vf_rng_seed(&rng, 11);
    CHECK(vf_attack_init(&st, &cfg) == VF_OK &&
              vf_attack_optimize(&st, &cfg, vf_view_loss_fn, vl, NULL, NULL) == VF_OK,
          "attack under the limit: %s", vf_error_message());
    vf_attack_sample_views(&st, &cfg, &rng, VF_EVAL_SAMPLES, drawn);
    double off = share_within(photos, count, samples, VF_EVAL_SAMPLES, limit),
           on = share_within(photos, count, drawn, VF_EVAL_SAMPLES, limit);
    printf("trust: samples of p*(v) within %.0f deg of those photos: %.0f%% without the limit, "
           "%.0f%% under it\n",
           limit, 100 * off, 100 * on);
    CHECK(on >= off + 0.2, "the limit keeps p*(v) near the photos: %.0f%% -> %.0f%%", 100 * off,
          100 * on);
    vf_attack_state_free(&st);
    vf_view_loss_set_trust(vl, NULL, 0, 0);
    free(photos);
}

int main(void)
{
    vf_log_set_quiet(1);
    vf_dataset ds;
    char model[VF_PATH_MAX];
    if (vf_dataset_load(vf_test_shared("data/nerf_synthetic/chair/transforms_train.json"), &ds) !=
            VF_OK ||
        vf_find_model(VF_DEFAULT_MODEL, NULL, model, sizeof model) != VF_OK) {
        CHECK(0, "chair data or model missing: %s", vf_error_message());
        return check_finish();
    }
    vf_field *field = vf_test_train_field(&ds, 0, TRAIN_STEPS, 96.0 * 96.0 * 96.0);
    vf_classifier *cls = NULL;
    vf_view_loss *vl = NULL;
    int labels[VF_MAX_LABELS], label_count = 0;
    CHECK(field && vf_classifier_open(model, &cls) == VF_OK &&
              vf_view_loss_create(field, cls, &vl) == VF_OK &&
              vf_parse_label_set(chair_classes, labels, VF_MAX_LABELS, &label_count) == VF_OK &&
              vf_view_loss_set_labels(vl, labels, label_count) == VF_OK,
          "setting up: %s", vf_error_message());
    if (!vl)
        return check_finish();

    /* The field must look like a chair to the classifier, or nothing below means anything. */
    double natural = natural_accuracy(vl, &ds);
    CHECK(natural >= 0.4, "natural accuracy %.0f%% is below 40%%", 100 * natural);

    /* A reduced ViewFool budget against the random-search baseline on the same box. */
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, VF_ATTACK_NES);
    cfg.samples = 16;
    cfg.steps = 20;
    cfg.seed = 3;
    vf_attack_state st;
    double t0 = vf_now();
    CHECK(vf_attack_init(&st, &cfg) == VF_OK &&
              vf_attack_optimize(&st, &cfg, vf_view_loss_fn, vl, NULL, NULL) == VF_OK,
          "attack: %s", vf_error_message());
    double attack_s = vf_now() - t0;

    double v_star[VF_VIEW_DIM], samples[VF_EVAL_SAMPLES * VF_VIEW_DIM];
    vf_view_prediction star, pred[VF_EVAL_SAMPLES];
    vf_rng rng;
    vf_rng_seed(&rng, 11);
    vf_attack_v_star(&st, &cfg, v_star);
    vf_attack_sample_views(&st, &cfg, &rng, VF_EVAL_SAMPLES, samples);
    CHECK(vf_view_loss_classify(vl, v_star, 1, &star, NULL) == VF_OK &&
              vf_view_loss_classify(vl, samples, VF_EVAL_SAMPLES, pred, NULL) == VF_OK,
          "evaluating: %s", vf_error_message());
    int fooled = 0;
    for (int i = 0; i < VF_EVAL_SAMPLES; i++)
        fooled += !pred[i].correct;
    double asr = (double)fooled / VF_EVAL_SAMPLES;

    vf_random_search_result random;
    CHECK(vf_attack_random_search(&cfg.bounds, VF_EVAL_SAMPLES, 11, vf_view_loss_fn, vl, NULL, NULL,
                                  &random) == VF_OK,
          "random search: %s", vf_error_message());
    printf("ViewFool (k=%d, %d steps, %.0f s): ASR of p*(v) %.0f%%, v* (%.0f, %.0f, %.0f, %.2f, "
           "%.2f, %.2f) seen as '%s' %.0f%%; random search ASR %.0f%%\n",
           cfg.samples, cfg.steps, attack_s, 100 * asr, v_star[0], v_star[1], v_star[2], v_star[3],
           v_star[4], v_star[5], vf_class_short_name(star.top_class), 100.0 * star.top_prob,
           100 * random.asr);
    CHECK(asr >= random.asr + 0.15,
          "attack ASR %.0f%% does not beat random search %.0f%% by "
          "15 points",
          100 * asr, 100 * random.asr);
    CHECK(!star.correct, "v* is classified as '%s', inside the label set",
          vf_class_short_name(star.top_class));
    /* The optimizer really moved the distribution from where it started (the box centre, a
     * view from straight above that already fools the classifier, so the mean loss itself
     * need not rise while the entropy term widens p*(v)). */
    double moved = 0;
    for (int i = 0; i < VF_VIEW_DIM; i++)
        moved = fmax(moved, fabs(v_star[i] - 0.5 * (cfg.bounds.lo[i] + cfg.bounds.hi[i])) /
                                (cfg.bounds.hi[i] - cfg.bounds.lo[i]));
    CHECK(moved > 0.02, "v* moved %.1f%% of a range from the start", 100 * moved);
    check_trust(vl, &ds, v_star, samples, cfg);

    vf_attack_state_free(&st);
    vf_view_loss_free(vl);
    vf_classifier_close(cls);
    vf_field_free(field);
    vf_dataset_free(&ds);
    return check_finish();
}
