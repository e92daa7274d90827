/* bench_attack: the ViewFool attack at the paper's full budget: Tables 1 and 2 and Fig. 4.
 *
 *   chair  NeRF-synthetic chair, label set {folding chair, rocking chair, barber chair,
 *          throne}, the default viewpoint box
 *   fox    instant-ngp fox (real photos), brought to the object frame (vf/normalize.h),
 *          label set {red fox, kit fox, Arctic fox, grey fox}, the box the photos cover
 *          (vf/view_coverage.h)
 *
 * For the scene: a radiance field (trained here for --train-seconds, default 180, or loaded
 * with --field FILE; --save FILE keeps it), the natural accuracy over the training views
 * with mobilenet_v2_1.0_224_quant, then
 *
 *   --run R     one run in the "both" space: nes0 (NES, lambda 0), nes (ViewFool, lambda
 *               0.01), pepg (the reference code's optimizer) or random (random search)
 *   --table2    the paper's Table 2: NES at lambda 0, 1e-4, 1e-3, 1e-2, 1e-1 and 1
 *   --table1    the paper's Table 1: random search, lambda 0 and lambda 0.01 in each search
 *               space (translation, rotation, both)
 *   --fig4 PNG  the paper's Fig. 4: ASR under camera fluctuation around v*, lambda 0 and 0.01
 *
 * Every run prints the ASR of R(v*) (v* = a tanh(mu*) + b), of R(v_best) (the last step's best
 * sample), over 100 samples of p*(v), the per-parameter std of those samples and wall times.
 * Runs shared by the tables (same space and lambda) run once. k = 50 samples a step (pepg 51)
 * and 100 steps unless --samples / --steps say otherwise.
 *
 * usage: bench_attack chair|fox [--field FILE] [--save FILE] [--train-seconds S]
 *                     [--run nes0|nes|pepg|random]... [--table1] [--table2] [--fig4 PNG]
 *                     [--samples K] [--steps N] [--seed S] */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/attack_eval.h"
#include "vf/classifier.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/log.h"
#include "vf/normalize.h"
#include "vf/plot.h"
#include "vf/pose.h"
#include "vf/resources.h"
#include "vf/view_coverage.h"
#include "vf/view_loss.h"
#include "vf/workspace.h"
#include "vf/viewfool.h"

typedef struct scene {
    const char *name, *transforms, *labels;
    int real; /* real photos: normalize, limit the box to the photos (their surroundings are
                 modelled by default) */
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

/* One measured run: a method, a search space and lambda. */
typedef struct result {
    const char *method; /* nes, pepg, random */
    vf_view_space space;
    double lambda;
    vf_attack_eval ev;
    double attack_s, eval_s;
} result;

#define MAX_RESULTS 32

typedef struct bench {
    const char *scene;
    vf_view_loss *vl;
    vf_view_bounds box; /* the scene's box for the "both" space */
    double natural[VF_VIEW_DIM]; /* the training view recognised best: where a space's fixed
                                  * parameters stay */
    int samples, steps;
    uint64_t seed;
    result results[MAX_RESULTS];
    int count;
} bench;

static const double table2_lambdas[] = {0, 1e-4, 1e-3, 1e-2, 1e-1, 1};

static void print_header(void)
{
    printf("%-6s %-6s %-11s %7s %9s %9s %10s  %7s%7s%7s%7s%7s%7s  %8s %7s\n", "scene", "method",
           "space", "lambda", "ASR R(v*)", "R(v_best)", "R(p*(v))", "psi", "theta", "phi", "dx",
           "dy", "dz", "attack", "eval");
}

static void print_result(const char *scene, const result *r)
{
    const vf_attack_eval *ev = &r->ev;
    printf("%-6s %-6s %-11s %7g %8.0f%% %8.0f%% %9.0f%%  ", scene, r->method,
           vf_view_space_name(r->space), r->lambda, 100 * ev->asr_v_star, 100 * ev->asr_v_best,
           100 * ev->asr_samples);
    for (int i = 0; i < VF_VIEW_DIM; i++)
        printf(i < 3 ? "%7.2f" : "%7.3f", ev->sample_std[i]);
    printf("  %7.1fs %6.1fs  v*=(%.0f,%.0f,%.0f,%.2f,%.2f,%.2f) %s %.2f\n", r->attack_s,
           r->eval_s, ev->v_star[0], ev->v_star[1], ev->v_star[2], ev->v_star[3], ev->v_star[4],
           ev->v_star[5], vf_class_short_name(ev->v_star_pred.top_class),
           (double)ev->v_star_pred.top_prob);
    fflush(stdout);
}

static vf_status note_step(const vf_attack_state *st, void *ctx)
{
    const vf_attack_record *r = &st->history[st->step - 1];
    if (st->step % 20 == 0)
        fprintf(stderr, "  step %3d  loss %.3f  entropy %.2f  batch ASR %.0f%%  sigma_psi %.3f  %.0f s\n",
                st->step, r->mean_loss, r->entropy, 100 * r->fooled_rate, st->sigma[0][0],
                vf_now() - *(const double *)ctx);
    return VF_OK;
}

/* The run of (method, space, lambda), measured once and remembered. */
static const result *measure(bench *b, const char *method, vf_view_space space, double lambda)
{
    for (int i = 0; i < b->count; i++) {
        const result *r = &b->results[i];
        if (!strcmp(r->method, method) && r->space == space &&
            (r->lambda == lambda || !strcmp(method, "random")))
            return r;
    }
    if (b->count == MAX_RESULTS) {
        fprintf(stderr, "bench_attack: too many runs\n");
        exit(1);
    }
    result *r = &b->results[b->count++];
    *r = (result){.method = method, .space = space, .lambda = lambda};
    vf_view_bounds box = b->box;
    vf_view_bounds_restrict(&box, space, b->natural);
    double t0 = vf_now();
    if (!strcmp(method, "random")) {
        r->lambda = 0;
        if (vf_attack_eval_random(b->vl, &box, b->seed, &r->ev) != VF_OK)
            die("random search");
        r->eval_s = vf_now() - t0;
        print_result(b->scene, r);
        return r;
    }
    vf_attack_config cfg;
    vf_attack_config_default(&cfg, !strcmp(method, "pepg") ? VF_ATTACK_PEPG : VF_ATTACK_NES);
    cfg.bounds = box;
    if (b->samples)
        cfg.samples = b->samples + (cfg.method == VF_ATTACK_PEPG && b->samples % 2 == 0);
    cfg.steps = b->steps;
    cfg.seed = b->seed;
    cfg.lambda = lambda;
    vf_attack_state st;
    if (vf_attack_init(&st, &cfg) != VF_OK ||
        vf_attack_optimize(&st, &cfg, vf_view_loss_fn, b->vl, note_step, &t0) != VF_OK)
        die(method);
    r->attack_s = vf_now() - t0;
    double t1 = vf_now();
    if (vf_attack_eval_distribution(b->vl, &st, &cfg, b->seed, &r->ev) != VF_OK)
        die("evaluating");
    r->eval_s = vf_now() - t1;
    vf_attack_state_free(&st);
    print_result(b->scene, r);
    return r;
}

static void table2(bench *b)
{
    int n = (int)(sizeof table2_lambdas / sizeof table2_lambdas[0]);
    const result *rows[8];
    for (int i = 0; i < n; i++)
        rows[i] = measure(b, "nes", VF_SPACE_BOTH, table2_lambdas[i]);
    printf("\nTable 2 (%s, NES, both space): the entropy weight lambda\n", b->scene);
    printf("| lambda | ASR R(p*(v)) | ASR R(v*) | std psi | theta | phi | dx | dy | dz |\n"
           "|---|---|---|---|---|---|---|---|---|\n");
    for (int i = 0; i < n; i++) {
        const vf_attack_eval *ev = &rows[i]->ev;
        printf("| %g | %.0f%% | %.0f%% | %.2f | %.2f | %.2f | %.3f | %.3f | %.3f |\n",
               table2_lambdas[i], 100 * ev->asr_samples, 100 * ev->asr_v_star, ev->sample_std[0],
               ev->sample_std[1], ev->sample_std[2], ev->sample_std[3], ev->sample_std[4],
               ev->sample_std[5]);
    }
    printf("\n");
}

static void table1(bench *b)
{
    static const vf_view_space spaces[3] = {VF_SPACE_TRANSLATION, VF_SPACE_ROTATION,
                                            VF_SPACE_BOTH};
    const result *rows[3][3];
    for (int s = 0; s < 3; s++) {
        rows[s][0] = measure(b, "random", spaces[s], 0);
        rows[s][1] = measure(b, "nes", spaces[s], 0);
        rows[s][2] = measure(b, "nes", spaces[s], 0.01);
    }
    printf("\nTable 1 (%s): ASR R(v*) / ASR R(p*(v)) (random search: best of 100 / all 100)\n",
           b->scene);
    printf("| space | random search | ViewFool lambda 0 | ViewFool lambda 0.01 |\n"
           "|---|---|---|---|\n");
    for (int s = 0; s < 3; s++) {
        printf("| %s |", vf_view_space_name(spaces[s]));
        for (int m = 0; m < 3; m++)
            printf(" %.0f%% / %.0f%% |", 100 * rows[s][m]->ev.asr_v_star,
                   100 * rows[s][m]->ev.asr_samples);
        printf("\n");
    }
    printf("\n");
}

static void fig4(bench *b, const char *path)
{
    const result *runs[2] = {measure(b, "nes", VF_SPACE_BOTH, 0),
                             measure(b, "nes", VF_SPACE_BOTH, 0.01)};
    static const char *names[2] = {"ViewFool, lambda = 0", "ViewFool, lambda = 0.01"};
    double r[VF_FLUCT_LEVELS], asr[2][VF_FLUCT_LEVELS];
    vf_plot_series series[2];
    printf("\nFig. 4 (%s): ASR (%%) under camera fluctuation r%% of the full ranges around v*\n",
           b->scene);
    printf("| r %% |");
    for (int i = 0; i < VF_FLUCT_LEVELS; i++)
        printf(" %d |", i + 1);
    printf("\n|---|");
    for (int i = 0; i < VF_FLUCT_LEVELS; i++)
        printf("---|");
    printf("\n");
    for (int k = 0; k < 2; k++) {
        printf("| %s |", names[k]);
        for (int i = 0; i < VF_FLUCT_LEVELS; i++) {
            r[i] = i + 1;
            asr[k][i] = 100 * runs[k]->ev.fluct_asr[i];
            printf(" %.0f |", asr[k][i]);
        }
        printf("\n");
        series[k] = (vf_plot_series){names[k], r, asr[k], VF_FLUCT_LEVELS};
    }
    char title[96];
    snprintf(title, sizeof title, "Camera fluctuation around v* (%s)", b->scene);
    vf_plot_axes axes = {title, "r (% of each parameter's full range)", "attack success rate (%)",
                         0, 100};
    if (vf_plot_lines(path, &axes, series, 2) != VF_OK)
        die(path);
    printf("written: %s\n\n", path);
}

int main(int argc, char **argv)
{
    const scene *sc = NULL;
    const char *field_path = NULL, *save_path = NULL, *runs[8], *fig4_path = NULL;
    int run_count = 0, want_table1 = 0, want_table2 = 0;
    double train_seconds = 180;
    bench b = {.steps = 100, .seed = 1};
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
        else if (!strcmp(a, "--table1"))
            want_table1 = 1;
        else if (!strcmp(a, "--table2"))
            want_table2 = 1;
        else if (!strcmp(a, "--fig4") && next)
            fig4_path = argv[++i];
        else if (!strcmp(a, "--samples") && next)
            b.samples = atoi(argv[++i]);
        else if (!strcmp(a, "--steps") && next)
            b.steps = atoi(argv[++i]);
        else if (!strcmp(a, "--seed") && next)
            b.seed = strtoull(argv[++i], NULL, 10);
        else
            sc = NULL, i = argc;
    }
    if (!sc) {
        fprintf(stderr, "usage: bench_attack chair|fox [--field FILE] [--save FILE] "
                        "[--train-seconds S] [--run nes0|nes|pepg|random]... [--table1] "
                        "[--table2] [--fig4 PNG] [--samples K] [--steps N] [--seed S]\n");
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
    int labels[VF_MAX_LABELS], label_count;
    if (vf_find_model(VF_DEFAULT_MODEL, NULL, model, sizeof model) != VF_OK ||
        vf_classifier_open(model, &cls) != VF_OK ||
        vf_view_loss_create(field, cls, &b.vl) != VF_OK)
        die("classifier");
    if (vf_parse_label_set(sc->labels, labels, VF_MAX_LABELS, &label_count) != VF_OK ||
        vf_view_loss_set_labels(b.vl, labels, label_count) != VF_OK)
        die("labels");
    b.scene = sc->name;

    vf_view_bounds_default(&b.box);
    if (sc->real && vf_view_coverage(c2w, ds.count, &b.box) != VF_OK)
        die("coverage");
    vf_view_prediction *natural = malloc((size_t)ds.count * sizeof *natural);
    double t0 = vf_now();
    if (vf_view_loss_classify_poses(b.vl, c2w, ds.count, natural) != VF_OK)
        die("natural views");
    int correct = 0, best = 0;
    for (int i = 0; i < ds.count; i++) {
        correct += natural[i].correct;
        if (natural[i].label_prob > natural[best].label_prob)
            best = i;
    }
    vf_viewpoint best_view;
    vf_c2w_to_viewpoint(c2w + 16 * best, &best_view);
    vf_viewpoint_to_array(&best_view, b.natural);
    vf_view_loss_stats s0 = vf_view_loss_get_stats(b.vl);
    printf("%s: natural accuracy %.0f%% over %d training views (label set: %s); %.1f ms render "
           "+ %.1f ms classify per view (%.1f s)\n",
           sc->name, 100.0 * correct / ds.count, ds.count, sc->labels,
           1000 * s0.render_seconds / s0.views, 1000 * s0.classify_seconds / s0.views,
           vf_now() - t0);
    printf("box: ");
    for (int i = 0; i < VF_VIEW_DIM; i++)
        printf("[%.4g, %.4g] ", b.box.lo[i], b.box.hi[i]);
    printf("\nfixed parameters of a search space: those of training view %d (label set %.0f%%): "
           "psi %.1f, theta %.1f, phi %.1f, dx %.3f, dy %.3f, dz %.3f",
           best, 100.0 * natural[best].label_prob, b.natural[0], b.natural[1], b.natural[2],
           b.natural[3], b.natural[4], b.natural[5]);
    printf("\nk = %d samples a step (pepg: the mean and pairs), %d steps, seed %llu\n",
           b.samples ? b.samples : 50, b.steps, (unsigned long long)b.seed);
    print_header();
    for (int r = 0; r < run_count; r++) {
        const char *w = runs[r];
        if (!strcmp(w, "nes0"))
            measure(&b, "nes", VF_SPACE_BOTH, 0);
        else if (!strcmp(w, "nes") || !strcmp(w, "pepg"))
            measure(&b, w, VF_SPACE_BOTH, 0.01);
        else if (!strcmp(w, "random"))
            measure(&b, "random", VF_SPACE_BOTH, 0);
        else {
            fprintf(stderr, "bench_attack: unknown run %s\n", w);
            return 1;
        }
    }
    if (want_table2)
        table2(&b);
    if (want_table1)
        table1(&b);
    if (fig4_path)
        fig4(&b, fig4_path);
    vf_view_loss_stats s1 = vf_view_loss_get_stats(b.vl);
    printf("%s: %ld views in all, %.1f ms render + %.1f ms classify per view\n", sc->name,
           s1.views, 1000 * s1.render_seconds / s1.views, 1000 * s1.classify_seconds / s1.views);

    free(natural);
    free(c2w);
    vf_dataset_free(&ds);
    vf_view_loss_free(b.vl);
    vf_classifier_close(cls);
    vf_field_free(field);
    return 0;
}
