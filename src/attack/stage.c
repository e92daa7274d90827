/* The attack stage (vf/attack.h): the flow its header describes, one function a step. */
#define _GNU_SOURCE /* struct stat's st_mtim */
#include "vf/attack.h"

#include <ctype.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#include "attack_internal.h"
#include "vf/attack_file.h"
#include "vf/classifier.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/view_coverage.h"

#define CHECKPOINT "checkpoint.json"
#define CHECKPOINT_FORMAT 1
#define LOW_ACCURACY 0.5 /* natural accuracy below this gets a warning */

static const char *const search_names[3] = {"nes", "pepg", "random"};

vf_status vf_attack_search_parse(const char *name, vf_attack_search *out)
{
    for (int m = 0; m < 3; m++)
        if (name && !strcmp(name, search_names[m])) {
            *out = (vf_attack_search)m;
            return VF_OK;
        }
    return vf_fail(VF_EINPUT, "the method must be nes, pepg or random, not '%s'",
                   name ? name : "");
}

const char *vf_attack_search_name(vf_attack_search m)
{
    return (unsigned)m < 3 ? search_names[m] : "?";
}

void vf_attack_defaults(vf_attack_options *o)
{
    *o = (vf_attack_options){.model = VF_DEFAULT_MODEL,
                             .method = VF_SEARCH_NES,
                             .lambda = -1,
                             .steps = 100,
                             .components = 1,
                             .space = VF_SPACE_BOTH,
                             .trust_gap = VF_TRUST_GAP_DEG};
}

void vf_attack_default_name(const vf_attack_options *o, char *out, size_t size)
{
    char model[256], lambda[32] = "";
    vf_path_basename(model, sizeof model, o->model ? o->model : VF_DEFAULT_MODEL, 0);
    size_t len = strlen(model);
    if (len > 5 && !strcmp(model + len - 5, ".onnx"))
        model[len - 5] = '\0';
    for (char *c = model; *c; c++) /* a stage name's characters */
        *c = isalnum((unsigned char)*c) || *c == '.' || *c == '-' ? (char)tolower(*c) : '_';
    if (!isalnum((unsigned char)model[0]))
        model[0] = 'm';
    if (o->method != VF_SEARCH_RANDOM)
        snprintf(lambda, sizeof lambda, "-l%g", o->lambda >= 0 ? o->lambda : 0.01);
    int n = snprintf(out, size, "%s-%s%s-%s", model, vf_attack_search_name(o->method), lambda,
                     vf_view_space_name(o->space));
    if (o->components > 1 && n >= 0 && (size_t)n < size)
        snprintf(out + n, size - (size_t)n, "-k%d", o->components);
}

vf_status vf_attack_options_check(const vf_attack_options *o)
{
    if ((unsigned)o->method > VF_SEARCH_RANDOM)
        return vf_fail(VF_EINPUT, "unknown attack method %d", (int)o->method);
    if (o->components < 1 || o->components > VF_ATTACK_MAX_COMPONENTS)
        return vf_fail(VF_EINPUT, "the mixture needs 1 to %d components, not %d",
                       VF_ATTACK_MAX_COMPONENTS, o->components);
    if (o->components > 1 && o->method != VF_SEARCH_NES)
        return vf_fail(VF_EINPUT, "a mixture of components needs the nes method");
    if (!(o->trust_gap >= 0 && o->trust_gap <= 180))
        return vf_fail(VF_EINPUT, "the trust gap is 0 (off) to 180 degrees, not %g", o->trust_gap);
    char stage[160];
    snprintf(stage, sizeof stage, "attack/%s", o->name ? o->name : "x");
    if (o->name && vf_stage_name_check(stage) != VF_OK)
        return vf_fail(VF_EINPUT, "'%s' is not an attack name: use lower-case letters, digits, "
                                  "'_', '-' and '.'",
                       o->name);
    return VF_OK;
}

/* Everything one run holds. */
typedef struct attack_run {
    const vf_attack_options *opt;
    vf_workspace *ws;
    char stage_name[160]; /* attack/NAME */
    char model_path[VF_PATH_MAX];
    int labels[VF_MAX_LABELS], label_count, label_proposed;
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

/* Everything that can be checked without the workspace: fail fast on a typo. */
static vf_status check_inputs(attack_run *run)
{
    const vf_attack_options *opt = run->opt;
    vf_view_bounds scratch;
    vf_view_bounds_default(&scratch);
    vf_status s = vf_attack_options_check(opt);
    if (s == VF_OK)
        s = vf_find_model(opt->model, opt->models_dir, run->model_path, sizeof run->model_path);
    if (s == VF_OK)
        s = vf_class_names_load();
    if (s == VF_OK && opt->label)
        s = vf_parse_label_set(opt->label, run->labels, VF_MAX_LABELS, &run->label_count);
    if (s == VF_OK && opt->bounds)
        s = vf_view_bounds_parse(opt->bounds, &scratch);
    return s;
}

static vf_status load_cameras(attack_run *run)
{
    vf_dataset ds;
    vf_status s = vf_dataset_load_training(run->ws, &ds, &run->real_capture);
    if (s != VF_OK)
        return s;
    run->view_count = ds.count;
    run->c2w = vf_dataset_poses(&ds);
    vf_dataset_free(&ds);
    return run->c2w ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
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

/* Renders at the training poses: propose the label set when none was given, then the natural
 * accuracy and the most confidently recognised view. */
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
        vf_info("no label set given: using '%s' (class %d), the top-1 of %d of the %d natural "
                "views; give --label to choose the set",
                vf_class_short_name(run->labels[0]), run->labels[0], votes, run->view_count);
    }
    if (s == VF_OK)
        s = vf_view_loss_set_labels(run->vl, run->labels, run->label_count);
    if (s == VF_OK) {
        int correct = 0, best = -1;
        char names[512];
        for (int i = 0; i < run->view_count; i++) {
            int ok = vf_label_set_contains(run->labels, run->label_count, pred[i].top_class);
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

/* The search box: the default, or the capture's coverage; then the caller's bounds. */
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
                    vf_view_param_name(i), b->lo[i], b->hi[i], def.lo[i], def.hi[i]);
        }
    if (s == VF_OK && run->opt->bounds)
        s = vf_view_bounds_parse(run->opt->bounds, b);
    return s == VF_OK ? vf_view_bounds_check(b) : s;
}

static vf_status make_config(attack_run *run)
{
    const vf_attack_options *opt = run->opt;
    vf_view_bounds bounds = run->cfg.bounds;
    vf_attack_config_default(&run->cfg,
                             opt->method == VF_SEARCH_PEPG ? VF_ATTACK_PEPG : VF_ATTACK_NES);
    run->cfg.bounds = bounds;
    if (opt->samples)
        run->cfg.samples = opt->samples;
    run->cfg.steps = opt->steps;
    run->cfg.components = opt->components;
    run->cfg.seed = opt->seed;
    if (opt->lambda >= 0)
        run->cfg.lambda = opt->lambda;
    return vf_attack_config_check(&run->cfg);
}

/* Rotation or translation space: the other parameters stay at the most recognisable natural
 * view (the box's centre when no view is recognised). */
static vf_status restrict_space(attack_run *run)
{
    vf_view_space space = run->opt->space;
    if (space == VF_SPACE_BOTH)
        return VF_OK;
    vf_view_bounds_restrict(&run->cfg.bounds, space,
                            run->has_natural_best ? run->natural_best : NULL);
    const vf_view_bounds *b = &run->cfg.bounds;
    int first = space == VF_SPACE_ROTATION ? 3 : 0;
    double fixed[3];
    for (int i = 0; i < 3; i++)
        fixed[i] = 0.5 * (b->lo[first + i] + b->hi[first + i]);
    vf_info("%s space: %s fixed at %.3g, %.3g, %.3g%s", vf_view_space_name(space),
            first ? "dx, dy, dz" : "psi, theta, phi", fixed[0], fixed[1], fixed[2],
            run->has_natural_best ? " (the training view recognised best)" : " (the box centre)");
    return vf_attack_config_check(&run->cfg);
}

/* Which field the attack runs on: the train stage's file, by size and modification time (a
 * field trained again, e.g. in object mode, is another field). */
static json_t *field_identity(const attack_run *run)
{
    char path[VF_PATH_MAX];
    struct stat st;
    if (vf_workspace_path(run->ws, "train", VF_FIELD_FILE, path, sizeof path) != VF_OK ||
        stat(path, &st) != 0)
        return json_null();
    return json_pack("{s:I, s:I, s:I}", "size", (json_int_t)st.st_size, "mtime",
                     (json_int_t)st.st_mtim.tv_sec, "mtime_ns", (json_int_t)st.st_mtim.tv_nsec);
}

/* What a checkpoint must match to be resumed. */
static json_t *setup_json(const attack_run *run)
{
    json_t *labels = json_array();
    for (int i = 0; i < run->label_count; i++)
        json_array_append_new(labels, json_integer(run->labels[i]));
    return json_pack("{s:s, s:o, s:o, s:o, s:o}", "model", run->model_path, "labels", labels,
                     "trust_gap", vf_json_number(run->opt->trust_gap), "config",
                     vf_attack_config_to_json(&run->cfg), "field", field_identity(run));
}

static vf_status save_checkpoint(const attack_run *run, const vf_attack_state *st)
{
    char path[VF_PATH_MAX];
    vf_status s = vf_path_join(path, sizeof path, run->stage.dir, CHECKPOINT);
    if (s != VF_OK)
        return s;
    json_t *doc = json_pack("{s:i, s:o, s:o, s:o}", "format", CHECKPOINT_FORMAT, "setup",
                            setup_json(run), "state", vf_attack_state_to_json(st), "seconds",
                            vf_json_number(run->resumed_seconds + vf_now() - run->attack_start));
    s = vf_json_save(path, doc);
    json_decref(doc);
    return s;
}

/* Continue from the staging folder's checkpoint when there is one and it matches this run. */
static vf_status load_checkpoint(attack_run *run, vf_attack_state *st)
{
    char path[VF_PATH_MAX];
    json_t *doc = NULL;
    vf_status s = vf_path_join(path, sizeof path, run->stage.dir, CHECKPOINT);
    if (s != VF_OK)
        return s;
    if (run->opt->restart || !vf_is_file(path))
        return vf_attack_init(st, &run->cfg);
    if ((s = vf_json_load(path, &doc)) != VF_OK)
        return s;
    json_t *setup = setup_json(run), *before = json_object_get(doc, "setup");
    if (!json_equal(json_object_get(setup, "field"), json_object_get(before, "field"))) {
        /* the field was trained again since: the checkpoint's search is of another field */
        vf_info("the interrupted attack in %s ran on an earlier field: starting over",
                run->ws->root);
        json_decref(setup);
        json_decref(doc);
        return vf_attack_init(st, &run->cfg);
    }
    if (!json_equal(setup, before))
        s = vf_fail(VF_EINPUT,
                    "the interrupted attack in %s used other settings (model, labels or "
                    "options): give the same to continue it, or --restart",
                    run->ws->root);
    if (s == VF_OK)
        s = vf_attack_state_from_json(json_object_get(doc, "state"), st);
    if (s == VF_OK) {
        run->resumed_seconds = json_number_value(json_object_get(doc, "seconds"));
        vf_info("continuing the interrupted attack at step %d of %d (--restart to start over)",
                st->step, run->cfg.steps);
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
    vf_status s = load_checkpoint(run, st);
    if (s != VF_OK)
        return s;
    run->attack_start = vf_now();
    vf_progress_begin(&run->progress, "attack", (size_t)run->cfg.steps, "steps");
    s = vf_attack_optimize(st, &run->cfg, vf_view_loss_fn, run->vl, after_step, run);
    run->seconds_attack = run->resumed_seconds + vf_now() - run->attack_start;
    if (s == VF_OK)
        vf_progress_end(&run->progress);
    return s;
}

static json_t *result_json(const attack_run *run, const vf_attack_state *st,
                           const vf_attack_eval *ev, const vf_random_search_result *baseline)
{
    vf_attack_outcome o = {.model = run->model_path,
                           .engine = vf_classifier_engine(run->cls),
                           .method = vf_attack_search_name(run->opt->method),
                           .space = vf_view_space_name(run->opt->space),
                           .labels = run->labels,
                           .label_count = run->label_count,
                           .label_proposed = run->label_proposed,
                           .cfg = &run->cfg,
                           .limited = run->limited,
                           .camera = vf_view_loss_camera(run->vl),
                           .natural_accuracy = run->natural_accuracy,
                           .natural_views = run->view_count,
                           .st = st,
                           .ev = ev,
                           .baseline = baseline,
                           .seconds_natural = run->seconds_natural,
                           .seconds_attack = run->seconds_attack,
                           .seconds_eval = run->seconds_eval,
                           .seconds_baseline = run->seconds_baseline,
                           .stats = vf_view_loss_get_stats(run->vl),
                           .trust_gap = run->opt->trust_gap};
    return vf_attack_file_json(&o);
}

/* Optimize (unless random), measure, baseline, write the files and commit. */
static vf_status attack_and_report(attack_run *run, json_t **result)
{
    int random = run->opt->method == VF_SEARCH_RANDOM;
    vf_attack_state st = {0};
    vf_attack_eval *ev = malloc(sizeof *ev);
    vf_random_search_result baseline;
    vf_status s = ev ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    if (s == VF_OK)
        s = run->opt->restart ? vf_stage_begin(run->ws, run->stage_name, &run->stage)
                              : vf_stage_resume(run->ws, run->stage_name, &run->stage);
    if (s == VF_OK && !random)
        s = optimize(run, &st);
    double t0 = vf_now();
    if (s == VF_OK) {
        vf_info("measuring v*, %d samples and camera fluctuation...", VF_EVAL_SAMPLES);
        s = random ? vf_attack_eval_random(run->vl, &run->cfg.bounds, run->cfg.seed, ev)
                   : vf_attack_eval_distribution(run->vl, &st, &run->cfg, run->cfg.seed, ev);
    }
    run->seconds_eval = vf_now() - t0;
    if (s == VF_OK && ev->v_star_pred.untrusted)
        vf_warn("v* lies %.0f degrees from the nearest photo, beyond the %.0f the field can "
                "vouch for: it is not counted as adversarial; film more views around the object "
                "or widen --trust-gap",
                ev->v_star_pred.gap_deg, run->opt->trust_gap);
    t0 = vf_now();
    if (s == VF_OK && !random) {
        vf_info("random-search baseline (%d uniform viewpoints)...", VF_EVAL_SAMPLES);
        s = vf_attack_random_search(&run->cfg.bounds, VF_EVAL_SAMPLES, run->cfg.seed,
                                    vf_view_loss_fn, run->vl, NULL, NULL, &baseline);
    }
    run->seconds_baseline = vf_now() - t0;
    if (s == VF_OK)
        s = vf__attack_write_pictures(run->stage.dir, run->vl, random ? NULL : &st, ev);
    json_t *doc = NULL;
    char path[VF_PATH_MAX];
    if (s == VF_OK) {
        doc = result_json(run, random ? NULL : &st, ev, random ? NULL : &baseline);
        s = vf_path_join(path, sizeof path, run->stage.dir, VF_ATTACK_FILE);
    }
    if (s == VF_OK)
        s = vf_json_save(path, doc);
    if (s == VF_OK) {
        json_t *params =
            json_pack("{s:s, s:s, s:s, s:O, s:O}", "name", run->stage_name + 7, "method",
                      vf_attack_search_name(run->opt->method),
                      "space", vf_view_space_name(run->opt->space), "config",
                      json_object_get(doc, "config"), "label", json_object_get(doc, "label"));
        json_t *summary =
            json_pack("{s:o, s:o, s:o}", "natural_accuracy", vf_json_number(run->natural_accuracy),
                      "asr_v_star", vf_json_number(ev->asr_v_star), "asr_samples",
                      vf_json_number(ev->asr_samples));
        s = vf_stage_commit(&run->stage, params, summary);
    }
    /* the checkpoint goes once the stage is in place (a failed commit keeps it for resume) */
    if (s == VF_OK &&
        vf_workspace_path(run->ws, run->stage_name, CHECKPOINT, path, sizeof path) == VF_OK)
        remove(path);
    if (s == VF_OK && result)
        *result = json_incref(doc);
    json_decref(doc);
    vf_attack_state_free(&st);
    free(ev);
    return s;
}

vf_status vf_attack_run(vf_workspace *ws, const vf_attack_options *o, json_t **result)
{
    attack_run run = {.opt = o, .ws = ws};
    if (result)
        *result = NULL;
    vf_status s = check_inputs(&run);
    if (s == VF_OK) {
        char name[128];
        if (o->name)
            snprintf(name, sizeof name, "%s", o->name);
        else
            vf_attack_default_name(o, name, sizeof name);
        snprintf(run.stage_name, sizeof run.stage_name, "attack/%s", name);
        s = vf_field_load_workspace(ws, &run.field);
        if (s == VF_OK)
            vf_info("attack %s, kept in %s/%s/", name, ws->root, run.stage_name);
    }
    if (s == VF_OK)
        s = load_cameras(&run);
    if (s == VF_OK)
        s = choose_bounds(&run);
    if (s == VF_OK)
        s = make_config(&run);
    if (s == VF_OK)
        s = vf_classifier_open(run.model_path, &run.cls);
    if (s == VF_OK) {
        vf_info("model %s (input %dx%d, %s)", run.model_path, vf_classifier_input_size(run.cls),
                vf_classifier_input_size(run.cls), vf_classifier_engine(run.cls));
        s = vf_view_loss_create(run.field, run.cls, &run.vl);
    }
    if (s == VF_OK)
        s = natural_views(&run);
    if (s == VF_OK) {
        vf_view_loss_set_trust(run.vl, run.c2w, run.view_count, o->trust_gap);
        s = restrict_space(&run);
    }
    if (s == VF_OK)
        s = attack_and_report(&run, result);
    /* A failure after the stage began leaves its staging folder (and checkpoint) for the
     * next run (see the header's life cycle). */
    vf_view_loss_free(run.vl);
    vf_classifier_close(run.cls);
    vf_field_free(run.field);
    free(run.c2w);
    return s;
}
