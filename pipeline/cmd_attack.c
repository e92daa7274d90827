/* vfcapture attack: ViewFool against a real classifier on renders of the trained field.
 *
 * The flow: check the options, the model and the label set before anything heavy; load the
 * field and the training cameras; classify renders at the training poses (natural accuracy,
 * and the label proposal when no --label is given); choose the viewpoint box (the capture's
 * coverage for a real capture); optimize the distribution with a checkpoint a step in the
 * staging folder; measure v*, 100 samples, fluctuation and the random-search baseline; write
 * attack.json and the pictures, then commit the stage. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "attack_outputs.h"
#include "attack_ws.h"
#include "cli.h"
#include "vf/attack_eval.h"
#include "vf/classifier.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/view_coverage.h"
#include "vf/view_loss.h"
#include "vf/viewfool.h"

#define CHECKPOINT "checkpoint.json"
#define CHECKPOINT_FORMAT 1
#define LOW_ACCURACY 0.5   /* natural accuracy below this gets a warning */

static const char usage[] =
    "usage: vfcapture attack WS [--model NAME|PATH] [--label L1,L2,...]\n"
    "                       [--method nes|pepg|random] [--lambda X] [--samples K] [--steps N] [--components K]\n"
    "                       [--space rotation|translation|both] [--bounds name=lo:hi,...]\n"
    "                       [--seed S] [--resume] [--json]\n"
    "\n"
    "Find the viewpoints from which the classifier misreads the object (ViewFool, Dong et al.,\n"
    "NeurIPS 2022): learn a distribution p(v) over viewpoints v = (psi, theta, phi in degrees,\n"
    "dx, dy, dz in scene units) that maximizes the cross-entropy of the true label set on\n"
    "renders of the trained field, plus lambda times its entropy. Writes WS/attack/attack.json,\n"
    "v_star.png, samples.png, loss.png and fluctuation.png.\n"
    "\n"
    "options:\n"
    "  -m, --model NAME|PATH  ImageNet classifier (default " VF_DEFAULT_MODEL ")\n"
    "      --models-dir DIR   look for model names here first\n"
    "  -l, --label L1,L2,...  true label set: class indices or names; a view counts as correct\n"
    "                         when the top-1 is any of them (default: the majority top-1 of\n"
    "                         renders at the training poses)\n"
    "      --method M         nes (the paper's Eq. 7: natural-gradient NES with the entropy\n"
    "                         term, default), pepg (the reference code's optimizer) or\n"
    "                         random (the baseline: 100 uniform viewpoints)\n"
    "      --lambda X         entropy weight (default 0.01): larger keeps p*(v) wider, 0 lets\n"
    "                         it shrink to a point\n"
    "  -k, --samples K        viewpoints a step (default 50; pepg 51, the mean and 25 pairs)\n"
    "  -n, --steps N          optimization steps (default 100)\n"
    "      --components K     mixture of K Gaussians, 1..8 (nes only; default 1)\n"
    "      --space S          rotation (only the angles move), translation (only the\n"
    "                         offsets) or both (default); the fixed ones stay at the training\n"
    "                         view the classifier recognises best\n"
    "      --bounds B         per-parameter box, e.g. psi=-90:90,phi=100:160 (parameters psi,\n"
    "                         theta, phi, dx, dy, dz). Default: psi -180:180, theta -30:30,\n"
    "                         phi 20:160, dx -0.5:0.5, dy -1:1, dz -0.5:0.5; for a real capture\n"
    "                         (poses stage) the range its photos cover\n"
    "      --seed S           random seed (default 0): the same seed gives the same result\n"
    "      --resume           continue an interrupted attack from its last step\n" CLI_ENGINE_HELP CLI_COMMON_HELP;

enum {
    OPT_MODELS_DIR = CLI_OPT_FIRST_CUSTOM,
    OPT_METHOD,
    OPT_LAMBDA,
    OPT_COMPONENTS,
    OPT_SPACE,
    OPT_BOUNDS,
    OPT_SEED,
    OPT_RESUME,
};

static const char *const param_names[VF_VIEW_DIM] = {"psi", "theta", "phi", "dx", "dy", "dz"};

typedef struct attack_options {
    const char *workspace, *model, *models_dir, *label, *space, *bounds;
    const char *method; /* nes, pepg, random */
    double lambda;
    int lambda_set, samples, steps, components, resume;
    unsigned long long seed;
    cli_flags flags;
} attack_options;

/* Everything one run holds. */
typedef struct attack_run {
    const attack_options *opt;
    char model_path[VF_PATH_MAX];
    int labels[VF_MAX_LABELS], label_count, label_proposed;
    vf_workspace ws;
    vf_field *field;
    vf_classifier *cls;
    vf_view_loss *vl;
    double *c2w;
    int view_count, real_capture;
    double natural_accuracy;
    vf_attack_config cfg;
    int limited[VF_VIEW_DIM]; /* parameters narrowed to the capture's coverage */
    int has_natural_best;
    double natural_best[VF_VIEW_DIM]; /* the training view recognised most confidently */
    vf_stage stage;
    vf_progress progress;
    double seconds_natural, seconds_attack, seconds_eval, seconds_baseline;
    double attack_start, resumed_seconds; /* for the checkpoint's running time */
} attack_run;

static vf_status parse_double(const char *name, const char *text, double lo, double hi,
                              double *out)
{
    if (cli_parse_doubles(text, out, 1) != 1 || !(*out >= lo && *out <= hi))
        return vf_fail(VF_EINPUT, "--%s must be a number from %g to %g, not '%s'", name, lo, hi,
                       text);
    return VF_OK;
}

static vf_status parse_int(const char *name, const char *text, long lo, long hi, int *out)
{
    long v;
    if (cli_parse_int(text, lo, hi, &v) != 0)
        return vf_fail(VF_EINPUT, "--%s must be a whole number from %ld to %ld, not '%s'", name,
                       lo, hi, text);
    *out = (int)v;
    return VF_OK;
}

static vf_status parse_options(int argc, char **argv, attack_options *opt)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS,
        CLI_ENGINE_OPTION,
        {"model", required_argument, NULL, 'm'},
        {"models-dir", required_argument, NULL, OPT_MODELS_DIR},
        {"label", required_argument, NULL, 'l'},
        {"method", required_argument, NULL, OPT_METHOD},
        {"lambda", required_argument, NULL, OPT_LAMBDA},
        {"samples", required_argument, NULL, 'k'},
        {"steps", required_argument, NULL, 'n'},
        {"components", required_argument, NULL, OPT_COMPONENTS},
        {"space", required_argument, NULL, OPT_SPACE},
        {"bounds", required_argument, NULL, OPT_BOUNDS},
        {"seed", required_argument, NULL, OPT_SEED},
        {"resume", no_argument, NULL, OPT_RESUME},
        {0, 0, 0, 0},
    };
    int c;
    vf_status s = VF_OK;
    while (s == VF_OK &&
           (c = getopt_long(argc, argv, CLI_COMMON_SHORT "m:l:k:n:", longopts, NULL)) != -1) {
        if (cli_common_option(c, &opt->flags, "attack", usage))
            continue;
        char *end;
        switch (c) {
        case 'm': opt->model = optarg; break;
        case OPT_MODELS_DIR: opt->models_dir = optarg; break;
        case 'l': opt->label = optarg; break;
        case OPT_METHOD: opt->method = optarg; break;
        case OPT_LAMBDA:
            s = parse_double("lambda", optarg, 0, 1e6, &opt->lambda);
            opt->lambda_set = 1;
            break;
        case 'k': s = parse_int("samples", optarg, 2, 100000, &opt->samples); break;
        case 'n': s = parse_int("steps", optarg, 0, 100000, &opt->steps); break;
        case OPT_COMPONENTS:
            s = parse_int("components", optarg, 1, VF_ATTACK_MAX_COMPONENTS, &opt->components);
            break;
        case OPT_SPACE: opt->space = optarg; break;
        case OPT_BOUNDS: opt->bounds = optarg; break;
        case OPT_SEED:
            opt->seed = strtoull(optarg, &end, 10);
            if (end == optarg || *end || optarg[0] == '-')
                s = vf_fail(VF_EINPUT, "--seed must be a whole number >= 0, not '%s'", optarg);
            break;
        case OPT_RESUME: opt->resume = 1; break;
        default: break;
        }
    }
    if (s != VF_OK)
        return s;
    if (optind != argc - 1)
        return vf_fail(VF_EINPUT, "give one workspace folder (see 'vfcapture attack --help')");
    opt->workspace = argv[optind];
    if (strcmp(opt->method, "nes") && strcmp(opt->method, "pepg") && strcmp(opt->method, "random"))
        return vf_fail(VF_EINPUT, "--method must be nes, pepg or random, not '%s'", opt->method);
    vf_view_space space;
    if (vf_view_space_parse(opt->space, &space) != VF_OK)
        return vf_fail(VF_EINPUT, "--space must be rotation, translation or both, not '%s'",
                       opt->space);
    if (opt->components > 1 && strcmp(opt->method, "nes"))
        return vf_fail(VF_EINPUT, "--components needs --method nes");
    return VF_OK;
}

/* "psi=-90:90,phi=100:160" onto bounds; each named parameter replaced. */
static vf_status apply_bounds_text(const char *text, vf_view_bounds *b)
{
    char buf[1024];
    if (snprintf(buf, sizeof buf, "%s", text) >= (int)sizeof buf)
        return vf_fail(VF_EINPUT, "--bounds is too long");
    char *save = NULL;
    for (char *item = strtok_r(buf, ",", &save); item; item = strtok_r(NULL, ",", &save)) {
        char *eq = strchr(item, '=');
        int i = 0;
        while (eq && i < VF_VIEW_DIM &&
               (strlen(param_names[i]) != (size_t)(eq - item) ||
                strncmp(item, param_names[i], (size_t)(eq - item))))
            i++;
        double lo, hi;
        char *colon = eq ? strchr(eq + 1, ':') : NULL;
        if (!eq || i == VF_VIEW_DIM || !colon)
            return vf_fail(VF_EINPUT, "--bounds wants name=lo:hi with names psi, theta, phi, dx, "
                           "dy, dz, not '%s'", item);
        *colon = '\0';
        if (cli_parse_doubles(eq + 1, &lo, 1) != 1 || cli_parse_doubles(colon + 1, &hi, 1) != 1 ||
            !(lo < hi))
            return vf_fail(VF_EINPUT, "--bounds %s: give two numbers lo:hi with lo < hi",
                           param_names[i]);
        b->lo[i] = lo;
        b->hi[i] = hi;
    }
    return VF_OK;
}

/* Everything that can be checked without the workspace: fail fast on a typo. */
static vf_status check_inputs(attack_run *run)
{
    const attack_options *opt = run->opt;
    vf_view_bounds scratch;
    vf_view_bounds_default(&scratch);
    vf_status s = vf_find_model(opt->model, opt->models_dir, run->model_path,
                                sizeof run->model_path);
    if (s == VF_OK)
        s = vf_class_names_load();
    if (s == VF_OK && opt->label)
        s = vf_parse_label_set(opt->label, run->labels, VF_MAX_LABELS, &run->label_count);
    if (s == VF_OK && opt->bounds)
        s = apply_bounds_text(opt->bounds, &scratch);
    return s;
}

static const char *label_names(const attack_run *run, char *out, size_t size)
{
    size_t used = 0;
    out[0] = '\0';
    for (int i = 0; i < run->label_count && used < size; i++)
        used += (size_t)snprintf(out + used, size - used, "%s%s", i ? ", " : "",
                                 vf_class_short_name(run->labels[i]));
    return out;
}

static int in_label_set(const attack_run *run, int cls)
{
    for (int i = 0; i < run->label_count; i++)
        if (run->labels[i] == cls)
            return 1;
    return 0;
}

/* Renders at the training poses: propose the label when none was given, then the natural
 * accuracy. */
static vf_status natural_views(attack_run *run)
{
    double t0 = vf_now();
    vf_view_prediction *pred = malloc((size_t)run->view_count * sizeof *pred);
    if (!pred)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_info("classifying renders at the %d training poses...", run->view_count);
    vf_status s = vf_view_loss_classify_poses(run->vl, run->c2w, run->view_count, pred);
    if (s == VF_OK && run->label_count == 0) {
        int votes;
        run->labels[0] = vf_majority_class(pred, run->view_count, &votes);
        run->label_count = 1;
        run->label_proposed = 1;
        vf_info("no --label given: using '%s' (class %d), the top-1 of %d of the %d natural "
                "views; give --label to choose the set",
                vf_class_short_name(run->labels[0]), run->labels[0], votes, run->view_count);
    }
    if (s == VF_OK)
        s = vf_view_loss_set_labels(run->vl, run->labels, run->label_count);
    if (s == VF_OK) {
        int correct = 0;
        char names[512];
        int best = -1;
        for (int i = 0; i < run->view_count; i++) {
            int ok = in_label_set(run, pred[i].top_class);
            correct += ok;
            if (ok && (best < 0 || pred[i].top_prob > pred[best].top_prob))
                best = i;
        }
        if (best >= 0) {
            vf_viewpoint v;
            vf_c2w_to_viewpoint(run->c2w + 16 * best, &v);
            vf_viewpoint_to_array(&v, run->natural_best);
            run->has_natural_best = 1;
        }
        run->natural_accuracy = (double)correct / run->view_count;
        vf_info("natural accuracy: %.0f%% (%d of %d renders at the training poses are {%s})",
                100 * run->natural_accuracy, correct, run->view_count,
                label_names(run, names, sizeof names));
        if (run->natural_accuracy < LOW_ACCURACY)
            vf_warn("natural accuracy is only %.0f%%: the classifier already misreads most "
                    "natural views, so attack success rates say little; check the label set "
                    "(--label) and the field's quality",
                    100 * run->natural_accuracy);
    }
    free(pred);
    run->seconds_natural = vf_now() - t0;
    return s;
}

/* The search box: the default, or the capture's coverage; then the space; then --bounds. */
static vf_status choose_bounds(attack_run *run)
{
    vf_view_bounds *b = &run->cfg.bounds, def;
    vf_view_bounds_default(&def);
    *b = def;
    vf_status s = VF_OK;
    if (run->real_capture && (s = vf_view_coverage(run->c2w, run->view_count, b)) == VF_OK)
        for (int i = 0; i < VF_VIEW_DIM; i++) {
            run->limited[i] = 1;
            vf_info("real capture: %s limited to [%.3g, %.3g], the range its photos cover "
                    "(default [%.3g, %.3g])",
                    param_names[i], b->lo[i], b->hi[i], def.lo[i], def.hi[i]);
        }
    if (s == VF_OK && run->opt->bounds)
        s = apply_bounds_text(run->opt->bounds, b);
    return s == VF_OK ? vf_view_bounds_check(b) : s;
}

/* --space rotation|translation: the other parameters stay at the most recognisable natural
 * view (the box's centre when no view is recognised). */
static vf_status restrict_space(attack_run *run)
{
    vf_view_space space;
    vf_status s = vf_view_space_parse(run->opt->space, &space);
    if (s != VF_OK || space == VF_SPACE_BOTH)
        return s;
    vf_view_bounds_restrict(&run->cfg.bounds, space,
                            run->has_natural_best ? run->natural_best : NULL);
    const vf_view_bounds *b = &run->cfg.bounds;
    int first = space == VF_SPACE_ROTATION ? 3 : 0;
    double fixed[3];
    for (int i = 0; i < 3; i++)
        fixed[i] = 0.5 * (b->lo[first + i] + b->hi[first + i]);
    vf_info("%s space: %s fixed at %.3g, %.3g, %.3g%s", run->opt->space,
            first ? "dx, dy, dz" : "psi, theta, phi", fixed[0], fixed[1], fixed[2],
            run->has_natural_best ? " (the training view recognised best)" : " (the box centre)");
    return vf_attack_config_check(&run->cfg);
}

static vf_status make_config(attack_run *run)
{
    const attack_options *opt = run->opt;
    int pepg = !strcmp(opt->method, "pepg");
    vf_view_bounds bounds = run->cfg.bounds;
    vf_attack_config_default(&run->cfg, pepg ? VF_ATTACK_PEPG : VF_ATTACK_NES);
    run->cfg.bounds = bounds;
    if (opt->samples)
        run->cfg.samples = opt->samples;
    run->cfg.steps = opt->steps;
    run->cfg.components = opt->components;
    run->cfg.seed = opt->seed;
    if (opt->lambda_set)
        run->cfg.lambda = opt->lambda;
    return vf_attack_config_check(&run->cfg);
}

/* What a checkpoint must match to be resumed. */
static json_t *setup_json(const attack_run *run)
{
    json_t *labels = json_array();
    for (int i = 0; i < run->label_count; i++)
        json_array_append_new(labels, json_integer(run->labels[i]));
    return json_pack("{s:s, s:o, s:o}", "model", run->model_path, "labels", labels, "config",
                     vf_attack_config_to_json(&run->cfg));
}

static vf_status save_checkpoint(const attack_run *run, const vf_attack_state *st)
{
    char path[VF_PATH_MAX];
    vf_status s = vf_path_join(path, sizeof path, run->stage.dir, CHECKPOINT);
    if (s != VF_OK)
        return s;
    json_t *doc = json_pack("{s:i, s:o, s:o, s:f}", "format", CHECKPOINT_FORMAT, "setup",
                            setup_json(run), "state", vf_attack_state_to_json(st), "seconds",
                            run->resumed_seconds + vf_now() - run->attack_start);
    s = vf_json_save(path, doc);
    json_decref(doc);
    return s;
}

/* --resume: continue from the staging folder's checkpoint when it matches this run. */
static vf_status load_checkpoint(attack_run *run, vf_attack_state *st)
{
    char path[VF_PATH_MAX];
    json_t *doc = NULL;
    vf_status s = vf_path_join(path, sizeof path, run->stage.dir, CHECKPOINT);
    if (s != VF_OK)
        return s;
    if (!vf_is_file(path)) {
        vf_info("--resume: no interrupted attack in %s; starting afresh", run->opt->workspace);
        return vf_attack_init(st, &run->cfg);
    }
    if ((s = vf_json_load(path, &doc)) != VF_OK)
        return s;
    json_t *setup = setup_json(run);
    if (!json_equal(setup, json_object_get(doc, "setup")))
        s = vf_fail(VF_EINPUT, "the interrupted attack in %s used other settings (model, "
                    "labels or options): run again with the same options, or without --resume",
                    run->opt->workspace);
    if (s == VF_OK)
        s = vf_attack_state_from_json(json_object_get(doc, "state"), st);
    if (s == VF_OK) {
        run->resumed_seconds = json_number_value(json_object_get(doc, "seconds"));
        vf_info("--resume: continuing the interrupted attack at step %d of %d", st->step,
                run->cfg.steps);
    }
    json_decref(setup);
    json_decref(doc);
    return s;
}

static vf_status after_step(const vf_attack_state *st, void *ctx)
{
    attack_run *run = ctx;
    const vf_attack_record *r = &st->history[st->step - 1];
    char note[96];
    snprintf(note, sizeof note, "loss %.3f  entropy %.2f  batch ASR %.0f%%", r->mean_loss,
             r->entropy, 100 * r->fooled_rate);
    vf_progress_update(&run->progress, (size_t)st->step, note);
    return save_checkpoint(run, st);
}

static vf_status optimize(attack_run *run, vf_attack_state *st)
{
    vf_status s = run->opt->resume ? load_checkpoint(run, st) : vf_attack_init(st, &run->cfg);
    if (s != VF_OK)
        return s;
    run->attack_start = vf_now();
    vf_progress_begin(&run->progress, "attack", (size_t)run->cfg.steps, "steps");
    s = vf_attack_run(st, &run->cfg, vf_view_loss_fn, run->vl, after_step, run);
    run->seconds_attack = run->resumed_seconds + vf_now() - run->attack_start;
    if (s == VF_OK)
        vf_progress_end(&run->progress);
    return s;
}

static json_t *doubles_json(const double *x, int n)
{
    json_t *a = json_array();
    for (int i = 0; i < n; i++)
        json_array_append_new(a, json_real(x[i]));
    return a;
}

static json_t *label_json(const attack_run *run)
{
    json_t *idx = json_array(), *names = json_array();
    for (int i = 0; i < run->label_count; i++) {
        json_array_append_new(idx, json_integer(run->labels[i]));
        json_array_append_new(names, json_string(vf_class_short_name(run->labels[i])));
    }
    return json_pack("{s:o, s:o, s:b}", "indices", idx, "names", names, "proposed",
                     run->label_proposed);
}

static json_t *result_json(const attack_run *run, const vf_attack_state *st,
                           const vf_attack_eval *ev, const vf_random_search_result *baseline)
{
    json_t *doc = vf_attack_eval_to_json(ev);
    json_t *limited = json_array();
    for (int i = 0; i < VF_VIEW_DIM; i++)
        if (run->limited[i])
            json_array_append_new(limited, json_string(param_names[i]));
    vf_camera cam = vf_view_loss_camera(run->vl);
    vf_view_loss_stats stats = vf_view_loss_get_stats(run->vl);
    double views = stats.views ? (double)stats.views : 1.0;
    json_object_set_new(doc, "model", json_string(run->model_path));
    json_object_set_new(doc, "engine", json_string(vf_classifier_engine(run->cls)));
    json_object_set_new(doc, "label", label_json(run));
    json_object_set_new(doc, "method", json_string(run->opt->method));
    json_object_set_new(doc, "space", json_string(run->opt->space));
    json_object_set_new(doc, "bounds",
                        json_pack("{s:o, s:o, s:o}", "lo",
                                  doubles_json(run->cfg.bounds.lo, VF_VIEW_DIM), "hi",
                                  doubles_json(run->cfg.bounds.hi, VF_VIEW_DIM),
                                  "limited_to_capture", limited));
    json_object_set_new(doc, "camera", attack_camera_json(&cam));
    json_object_set_new(doc, "natural_accuracy", json_real(run->natural_accuracy));
    json_object_set_new(doc, "natural_views", json_integer(run->view_count));
    json_object_set_new(doc, "config", vf_attack_config_to_json(&run->cfg));
    attack_json_add_distribution(doc, st, &run->cfg);
    if (baseline)
        json_object_set_new(doc, "random_search",
                            json_pack("{s:f, s:o, s:f, s:i}", "asr_samples", baseline->asr,
                                      "best_view", doubles_json(baseline->best_view, VF_VIEW_DIM),
                                      "best_loss", baseline->best_loss, "samples",
                                      VF_EVAL_SAMPLES));
    json_object_set_new(
        doc, "timings",
        json_pack("{s:f, s:f, s:f, s:f, s:i, s:f, s:f}", "natural_seconds", run->seconds_natural,
                  "attack_seconds", run->seconds_attack, "evaluation_seconds", run->seconds_eval,
                  "baseline_seconds", run->seconds_baseline, "views", (json_int_t)stats.views,
                  "render_ms_per_view", 1000 * stats.render_seconds / views,
                  "classify_ms_per_view", 1000 * stats.classify_seconds / views));
    return doc;
}

static void print_summary(const attack_run *run, const vf_attack_eval *ev,
                          const vf_random_search_result *baseline)
{
    char names[512];
    const double *v = ev->v_star;
    printf("label set {%s}%s; natural accuracy %.0f%% over %d training views\n",
           label_names(run, names, sizeof names), run->label_proposed ? " (proposed)" : "",
           100 * run->natural_accuracy, run->view_count);
    printf("v* = psi %.1f, theta %.1f, phi %.1f deg, dx %.3f, dy %.3f, dz %.3f: '%s' %.0f%% (%s)\n",
           v[0], v[1], v[2], v[3], v[4], v[5], vf_class_short_name(ev->v_star_pred.top_class),
           100.0 * ev->v_star_pred.top_prob, ev->asr_v_star > 0 ? "fooled" : "not fooled");
    if (strcmp(run->opt->method, "random"))
        printf("best sample of the last step: '%s' %.0f%% (%s)\n",
               vf_class_short_name(ev->v_best_pred.top_class), 100.0 * ev->v_best_pred.top_prob,
               ev->asr_v_best > 0 ? "fooled" : "not fooled");
    printf("ASR of R(v*): %.0f%%   ASR over %d samples of %s: %.0f%%", 100 * ev->asr_v_star,
           ev->sample_count, strcmp(run->opt->method, "random") ? "p*(v)" : "uniform viewpoints",
           100 * ev->asr_samples);
    if (baseline)
        printf("   (random search: %.0f%%)", 100 * baseline->asr);
    printf("\nstd of the samples: psi %.2f, theta %.2f, phi %.2f, dx %.3f, dy %.3f, dz %.3f\n",
           ev->sample_std[0], ev->sample_std[1], ev->sample_std[2], ev->sample_std[3],
           ev->sample_std[4], ev->sample_std[5]);
    printf("ASR under fluctuation r = 1..10%%:");
    for (int i = 0; i < VF_FLUCT_LEVELS; i++)
        printf(" %.0f", 100 * ev->fluct_asr[i]);
    printf("\ntop wrong classes:");
    for (int i = 0; i < ev->wrong_count; i++)
        printf("%s %s (%d)", i ? "," : "", vf_class_short_name(ev->wrong_class[i]),
               ev->wrong_votes[i]);
    printf("%s\nwritten: %s/attack/{attack.json, v_star.png, samples.png, %sfluctuation.png}\n",
           ev->wrong_count ? "" : " none", run->opt->workspace,
           strcmp(run->opt->method, "random") ? "loss.png, " : "");
}

/* Optimize (unless random), measure, baseline, write the files and commit. */
static vf_status attack_and_report(attack_run *run)
{
    int random = !strcmp(run->opt->method, "random");
    vf_attack_state st = {0};
    vf_attack_eval *ev = malloc(sizeof *ev);
    vf_random_search_result baseline;
    vf_status s = ev ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    if (s == VF_OK)
        s = run->opt->resume ? vf_stage_resume(&run->ws, "attack", &run->stage)
                             : vf_stage_begin(&run->ws, "attack", &run->stage);
    if (s == VF_OK && !random)
        s = optimize(run, &st);
    double t0 = vf_now();
    if (s == VF_OK) {
        vf_info("measuring v*, %d samples and camera fluctuation...", VF_EVAL_SAMPLES);
        s = random ? vf_attack_eval_random(run->vl, &run->cfg.bounds, run->cfg.seed, ev)
                   : vf_attack_eval_distribution(run->vl, &st, &run->cfg, run->cfg.seed, ev);
    }
    run->seconds_eval = vf_now() - t0;
    t0 = vf_now();
    if (s == VF_OK && !random) {
        vf_info("random-search baseline (%d uniform viewpoints)...", VF_EVAL_SAMPLES);
        s = vf_attack_random_search(&run->cfg.bounds, VF_EVAL_SAMPLES, run->cfg.seed,
                                    vf_view_loss_fn, run->vl, NULL, NULL, &baseline);
    }
    run->seconds_baseline = vf_now() - t0;
    if (s == VF_OK)
        s = attack_write_pictures(run->stage.dir, run->vl, random ? NULL : &st, ev);
    json_t *doc = NULL;
    char path[VF_PATH_MAX];
    if (s == VF_OK) {
        doc = result_json(run, random ? NULL : &st, ev, random ? NULL : &baseline);
        s = vf_path_join(path, sizeof path, run->stage.dir, "attack.json");
    }
    if (s == VF_OK)
        s = vf_json_save(path, doc);
    if (s == VF_OK) {
        json_t *params = json_pack("{s:s, s:s, s:O, s:O}", "method", run->opt->method, "space",
                                   run->opt->space, "config", json_object_get(doc, "config"),
                                   "label", json_object_get(doc, "label"));
        json_t *summary = json_pack("{s:f, s:f, s:f}", "natural_accuracy", run->natural_accuracy,
                                    "asr_v_star", ev->asr_v_star, "asr_samples", ev->asr_samples);
        s = vf_stage_commit(&run->stage, params, summary);
    }
    /* the checkpoint goes once the stage is in place (a failed commit keeps it for --resume) */
    if (s == VF_OK && vf_workspace_path(&run->ws, "attack", CHECKPOINT, path, sizeof path) == VF_OK)
        remove(path);
    if (s == VF_OK) {
        if (run->opt->flags.json)
            cli_print_json(json_incref(doc));
        else
            print_summary(run, ev, random ? NULL : &baseline);
    }
    json_decref(doc);
    vf_attack_state_free(&st);
    free(ev);
    return s;
}

static vf_status run_attack(attack_run *run)
{
    vf_status s = check_inputs(run);
    if (s != VF_OK)
        return s;
    if ((s = attack_ws_open(run->opt->workspace, &run->ws, &run->field)) != VF_OK)
        return s;
    s = attack_ws_training_poses(&run->ws, &run->c2w, &run->view_count, &run->real_capture);
    if (s == VF_OK)
        s = choose_bounds(run);
    if (s == VF_OK)
        s = make_config(run);
    if (s == VF_OK)
        s = vf_classifier_open(run->model_path, &run->cls);
    if (s == VF_OK) {
        vf_info("model %s (input %dx%d, %s)", run->model_path, vf_classifier_input_size(run->cls),
                vf_classifier_input_size(run->cls), vf_classifier_engine(run->cls));
        s = vf_view_loss_create(run->field, run->cls, &run->vl);
    }
    if (s == VF_OK)
        s = natural_views(run);
    if (s == VF_OK)
        s = restrict_space(run);
    if (s == VF_OK)
        s = attack_and_report(run);
    /* A failure after the stage began leaves its staging folder (and checkpoint) for
     * --resume; the next run without --resume clears it. */
    vf_view_loss_free(run->vl);
    vf_classifier_close(run->cls);
    vf_field_free(run->field);
    free(run->c2w);
    vf_workspace_close(&run->ws);
    return s;
}

int cmd_attack(int argc, char **argv)
{
    attack_options opt = {.model = VF_DEFAULT_MODEL, .method = "nes", .space = "both",
                          .steps = 100, .components = 1};
    attack_run run = {.opt = &opt};
    vf_status status = parse_options(argc, argv, &opt);
    if (status == VF_OK)
        status = run_attack(&run);
    return status == VF_OK ? 0 : cli_fail("attack", status);
}
