/* bench_attack: the ViewFool attack at the paper's full budget, Table 1 and Table 2 columns.
 *
 *   chair  NeRF-synthetic chair, label set {folding chair, rocking chair, barber chair,
 *          throne}, the default viewpoint box
 *   fox    instant-ngp fox (real photos), brought to the object frame (vf/normalize.h),
 *          label set {red fox, kit fox, Arctic fox, grey fox}, the box the photos cover
 *          (vf/view_coverage.h)
 *
 * For each scene: a radiance field (trained here for --train-seconds, default 180, or loaded
 * with --field FILE; --save FILE keeps it), the natural accuracy over the training views,
 * then each requested run with mobilenet_v2_1.0_224_quant:
 *   nes0    the paper's NES, lambda = 0 (plain score-function gradient, see vf/viewfool.h)
 *   nes     ViewFool: NES, lambda = 0.01 (natural gradient)
 *   pepg    the reference code's PEPG variant
 *   random  the random-search baseline (100 uniform viewpoints)
 * printing per run the ASR of R(v*), the ASR over 100 samples of p*(v) (Table 1), the
 * per-parameter std of those samples (Table 2) and wall times. k = 50 samples a step and 100
 * steps unless --samples / --steps say otherwise.
 *
 * A full run at the current render speed can take longer than one should hold the shared
 * machine, so --state FILE --segment S stops the optimization after S seconds, saves it, and
 * the next invocation with the same --state continues it (times add up across segments).
 * --no-fluctuation skips the camera-fluctuation curve (200 renders) for slow scenes.
 *
 * usage: bench_attack chair|fox [--field FILE] [--save FILE] [--train-seconds S]
 *                     [--run nes0|nes|pepg|random]... [--samples K] [--steps N] [--seed S]
 *                     [--state FILE --segment SECONDS] [--no-fluctuation] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/attack_eval.h"
#include "vf/classifier.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/log.h"
#include "vf/normalize.h"
#include "vf/resources.h"
#include "vf/view_coverage.h"
#include "vf/view_loss.h"
#include "vf/workspace.h"
#include "vf/viewfool.h"

typedef struct scene {
    const char *name, *transforms, *labels;
    int real; /* real photos: normalize, keep the background, limit the box to the photos */
} scene;

static const scene scenes[] = {
    {"chair", "data/nerf_synthetic/chair/transforms_train.json",
     "folding chair,rocking chair,barber chair,throne", 0},
    {"fox", "data/real_captures/instant_ngp_fox/transforms.json",
     "red fox,kit fox,Arctic fox,grey fox", 1},
};

static void die(const char *what)
{
    fprintf(stderr, "bench_attack: %s: %s\n", what, vf_error_message());
    exit(2);
}

/* The scene's cameras in the object frame (count x 16), and its dataset. */
static double *object_frame_poses(const scene *sc, vf_dataset *ds)
{
    char path[VF_PATH_MAX];
    if (vf_shared_path(sc->transforms, path, sizeof path) != VF_OK ||
        vf_dataset_load(path, ds) != VF_OK)
        die(sc->transforms);
    double *c2w = malloc((size_t)ds->count * 16 * sizeof *c2w);
    for (int i = 0; i < ds->count; i++)
        memcpy(c2w + 16 * i, ds->frames[i].c2w, 16 * sizeof *c2w);
    if (sc->real) {
        vf_normalization norm;
        if (vf_normalize_scene(c2w, ds->count, NULL, 0, &norm) != VF_OK)
            die("normalizing the fox poses");
        for (int i = 0; i < ds->count; i++)
            vf_similarity_apply_c2w(&norm.object_from_world, c2w + 16 * i, c2w + 16 * i);
    }
    return c2w;
}

static vf_field *train_field(const scene *sc, const vf_dataset *ds, const double *c2w,
                             double seconds)
{
    vf_field_train_options opt;
    vf_field_train_defaults(&opt);
    opt.seconds = seconds;
    opt.keep_background = sc->real;
    vf_field_trainer *t;
    if (vf_field_trainer_create(&opt, &t) != VF_OK)
        die("trainer");
    for (int i = 0; i < ds->count; i++) {
        vf_image img = {0};
        if (vf_image_load(ds->frames[i].image_path, &img) != VF_OK ||
            vf_field_trainer_add_view(t, &ds->frames[i].camera, c2w + 16 * i, &img) != VF_OK)
            die("adding a training view");
        vf_image_free(&img);
    }
    if (vf_field_trainer_start(t) != VF_OK)
        die("starting training");
    vf_field_train_status st;
    do
        if (vf_field_trainer_step(t, &st) != VF_OK)
            die("training");
    while (!st.done);
    printf("%s: field trained %.0f s, %d steps, train PSNR %.2f dB\n", sc->name, st.elapsed,
           st.step, st.psnr);
    vf_field *f = vf_field_trainer_take_field(t);
    vf_field_trainer_free(t);
    return f;
}

static void print_run(const char *scene, const char *run, const vf_attack_eval *ev,
                      double attack_s, double eval_s)
{
    printf("%-6s %-7s %8.0f%% %10.0f%%  ", scene, run, 100 * ev->asr_v_star,
           100 * ev->asr_samples);
    for (int i = 0; i < VF_VIEW_DIM; i++)
        printf(i < 3 ? "%7.2f" : "%7.3f", ev->sample_std[i]);
    printf("  %7.1f s %6.1f s  v*=(%.0f,%.0f,%.0f,%.2f,%.2f,%.2f) %s %.2f\n", attack_s, eval_s,
           ev->v_star[0], ev->v_star[1], ev->v_star[2], ev->v_star[3], ev->v_star[4],
           ev->v_star[5], vf_class_short_name(ev->v_star_pred.top_class),
           (double)ev->v_star_pred.top_prob);
    fflush(stdout);
}

static void note_step(const vf_attack_state *st, double seconds)
{
    const vf_attack_record *r = &st->history[st->step - 1];
    if (st->step % 10 == 0)
        fprintf(stderr, "  step %3d  loss %.3f  entropy %.2f  batch ASR %.0f%%  %.0f s\n",
                st->step, r->mean_loss, r->entropy, 100 * r->fooled_rate, seconds);
}

/* --state FILE: {"run", "seconds", "state"} of a run paused by --segment. */
static int load_paused(const char *path, const char *which, vf_attack_state *st, double *seconds)
{
    json_t *doc = NULL;
    if (!path || !vf_is_file(path) || vf_json_load(path, &doc) != VF_OK)
        return 0;
    const char *saved = json_string_value(json_object_get(doc, "run"));
    int ok = saved && !strcmp(saved, which) &&
             vf_attack_state_from_json(json_object_get(doc, "state"), st) == VF_OK;
    if (ok)
        *seconds = json_number_value(json_object_get(doc, "seconds"));
    json_decref(doc);
    return ok;
}

static void save_paused(const char *path, const char *which, const vf_attack_state *st,
                        double seconds)
{
    json_t *doc = json_pack("{s:s, s:f, s:o}", "run", which, "seconds", seconds, "state",
                            vf_attack_state_to_json(st));
    if (vf_json_save(path, doc) != VF_OK)
        die(path);
    json_decref(doc);
}

/* --no-fluctuation: only what Tables 1 and 2 need (v* and the 100 samples), for scenes whose
 * renders are slow. */
static void light_eval(vf_view_loss *vl, vf_attack_eval *ev)
{
    if (vf_view_loss_classify(vl, ev->v_star, 1, &ev->v_star_pred, NULL) != VF_OK ||
        vf_view_loss_classify(vl, ev->samples, ev->sample_count, ev->sample_pred, NULL) != VF_OK)
        die("evaluating");
    int fooled = 0;
    for (int i = 0; i < ev->sample_count; i++)
        fooled += !ev->sample_pred[i].correct;
    ev->asr_v_star = !ev->v_star_pred.correct;
    ev->asr_samples = (double)fooled / ev->sample_count;
    vf_view_std(ev->samples, ev->sample_count, ev->sample_std);
}

/* One run. With a state file and a segment limit, the optimization may stop early and
 * continue in the next invocation (so no single run holds the machine for long); the attack
 * time reported is the sum over the segments. */
static void run(const char *scene_name, const char *which, vf_view_loss *vl,
                const vf_view_bounds *bounds, int samples, int steps, uint64_t seed,
                const char *state_path, double segment, int fluctuation)
{
    vf_attack_eval ev;
    double t0 = vf_now(), before = 0;
    if (!strcmp(which, "random") && !fluctuation) {
        vf_random_search_result rs;
        memset(&ev, 0, sizeof ev);
        ev.sample_count = VF_EVAL_SAMPLES;
        if (vf_attack_random_search(bounds, VF_EVAL_SAMPLES, seed, vf_view_loss_fn, vl,
                                    ev.samples, NULL, &rs) != VF_OK)
            die("random search");
        memcpy(ev.v_star, rs.best_view, sizeof ev.v_star);
        light_eval(vl, &ev);
        print_run(scene_name, which, &ev, 0, vf_now() - t0);
        return;
    }
    if (!strcmp(which, "random")) {
        if (vf_attack_eval_random(vl, bounds, seed, &ev) != VF_OK)
            die("random search");
        print_run(scene_name, which, &ev, 0, vf_now() - t0);
        return;
    }
    int pepg = !strcmp(which, "pepg");
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, pepg ? VF_ATTACK_PEPG : VF_ATTACK_NES);
    cfg.bounds = *bounds;
    cfg.samples = samples;
    cfg.steps = steps;
    cfg.seed = seed;
    if (!strcmp(which, "nes0")) {
        cfg.lambda = 0;
        cfg.natural_gradient = 0;
    } else if (strcmp(which, "nes") && !pepg) {
        fprintf(stderr, "bench_attack: unknown run %s\n", which);
        exit(1);
    }
    vf_attack_state st;
    if (!load_paused(state_path, which, &st, &before) && vf_attack_init(&st, &cfg) != VF_OK)
        die(which);
    if (st.step > 0)
        fprintf(stderr, "  %s: continuing at step %d (%.0f s so far)\n", which, st.step, before);
    while (st.step < cfg.steps && !(segment > 0 && vf_now() - t0 > segment)) {
        if (vf_attack_step(&st, &cfg, vf_view_loss_fn, vl) != VF_OK)
            die(which);
        note_step(&st, before + vf_now() - t0);
    }
    double attack_s = before + vf_now() - t0;
    if (st.step < cfg.steps) {
        save_paused(state_path, which, &st, attack_s);
        printf("%-6s %-7s paused at step %d of %d after %.0f s; run again with --state %s\n",
               scene_name, which, st.step, cfg.steps, attack_s, state_path);
        vf_attack_state_free(&st);
        return;
    }
    double t1 = vf_now();
    if (fluctuation && vf_attack_eval_distribution(vl, &st, &cfg, seed, &ev) != VF_OK)
        die("evaluating");
    if (!fluctuation) {
        vf_rng rng;
        memset(&ev, 0, sizeof ev);
        vf_rng_seed(&rng, seed);
        ev.sample_count = VF_EVAL_SAMPLES;
        vf_attack_best_view(&st, &cfg, ev.v_star);
        vf_attack_sample_views(&st, &cfg, &rng, VF_EVAL_SAMPLES, ev.samples);
        light_eval(vl, &ev);
    }
    print_run(scene_name, which, &ev, attack_s, vf_now() - t1);
    vf_attack_state_free(&st);
}

int main(int argc, char **argv)
{
    const scene *sc = NULL;
    const char *field_path = NULL, *save_path = NULL, *runs[8], *state_path = NULL;
    double segment = 0;
    int fluctuation = 1;
    int run_count = 0, samples = 50, steps = 100;
    double train_seconds = 180;
    uint64_t seed = 1;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *next = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "chair") || !strcmp(a, "fox"))
            sc = &scenes[!strcmp(a, "fox")];
        else if (!strcmp(a, "--field") && next)
            field_path = argv[++i];
        else if (!strcmp(a, "--save") && next)
            save_path = argv[++i];
        else if (!strcmp(a, "--train-seconds") && next)
            train_seconds = atof(argv[++i]);
        else if (!strcmp(a, "--run") && next && run_count < 8)
            runs[run_count++] = argv[++i];
        else if (!strcmp(a, "--samples") && next)
            samples = atoi(argv[++i]);
        else if (!strcmp(a, "--steps") && next)
            steps = atoi(argv[++i]);
        else if (!strcmp(a, "--state") && next)
            state_path = argv[++i];
        else if (!strcmp(a, "--segment") && next)
            segment = atof(argv[++i]);
        else if (!strcmp(a, "--no-fluctuation"))
            fluctuation = 0;
        else if (!strcmp(a, "--seed") && next)
            seed = strtoull(argv[++i], NULL, 10);
        else
            sc = NULL, i = argc;
    }
    if (!sc || (segment > 0 && !state_path)) {
        fprintf(stderr, "usage: bench_attack chair|fox [--field FILE] [--save FILE] "
                        "[--train-seconds S] [--run nes0|nes|pepg|random]... [--samples K] "
                        "[--steps N] [--seed S] [--state FILE --segment SECONDS] "
                        "[--no-fluctuation]\n");
        return 1;
    }
    vf_log_set_quiet(1);
    vf_dataset ds;
    double *c2w = object_frame_poses(sc, &ds);
    vf_field *field = NULL;
    if (field_path) {
        if (vf_field_load(field_path, &field) != VF_OK)
            die(field_path);
    } else {
        field = train_field(sc, &ds, c2w, train_seconds);
    }
    if (save_path && vf_field_save(field, save_path) != VF_OK)
        die(save_path);

    char model[VF_PATH_MAX];
    vf_classifier *cls;
    vf_view_loss *vl;
    int labels[VF_MAX_LABELS], label_count;
    if (vf_find_model(VF_DEFAULT_MODEL, NULL, model, sizeof model) != VF_OK ||
        vf_classifier_open(model, &cls) != VF_OK || vf_view_loss_create(field, cls, &vl) != VF_OK)
        die("classifier");
    if (vf_parse_label_set(sc->labels, labels, VF_MAX_LABELS, &label_count) != VF_OK ||
        vf_view_loss_set_labels(vl, labels, label_count) != VF_OK)
        die("labels");

    vf_view_bounds bounds;
    vf_view_bounds_default(&bounds);
    if (sc->real && vf_view_coverage(c2w, ds.count, &bounds) != VF_OK)
        die("coverage");
    vf_view_prediction *natural = malloc((size_t)ds.count * sizeof *natural);
    double t0 = vf_now();
    if (vf_view_loss_classify_poses(vl, c2w, ds.count, natural) != VF_OK)
        die("natural views");
    int correct = 0;
    for (int i = 0; i < ds.count; i++)
        correct += natural[i].correct;
    vf_view_loss_stats s0 = vf_view_loss_get_stats(vl);
    printf("%s: natural accuracy %.0f%% over %d training views (label set: %s); %.1f ms render "
           "+ %.1f ms classify per view (%.1f s)\n",
           sc->name, 100.0 * correct / ds.count, ds.count, sc->labels,
           1000 * s0.render_seconds / s0.views, 1000 * s0.classify_seconds / s0.views,
           vf_now() - t0);
    printf("box: ");
    for (int i = 0; i < VF_VIEW_DIM; i++)
        printf("[%.4g, %.4g] ", bounds.lo[i], bounds.hi[i]);
    printf("\nk = %d samples a step, %d steps\n", samples, steps);
    printf("%-6s %-7s %9s %11s  %7s%7s%7s%7s%7s%7s  %9s %8s\n", "scene", "run", "ASR R(v*)",
           "ASR p*(v)", "psi", "theta", "phi", "dx", "dy", "dz", "attack", "eval");
    for (int r = 0; r < run_count; r++)
        run(sc->name, runs[r], vl, &bounds, samples, steps, seed, state_path, segment,
            fluctuation);
    vf_view_loss_stats s1 = vf_view_loss_get_stats(vl);
    printf("%s: %ld views in all, %.1f ms render + %.1f ms classify per view\n", sc->name,
           s1.views, 1000 * s1.render_seconds / s1.views, 1000 * s1.classify_seconds / s1.views);

    free(natural);
    free(c2w);
    vf_dataset_free(&ds);
    vf_view_loss_free(vl);
    vf_classifier_close(cls);
    vf_field_free(field);
    return 0;
}
