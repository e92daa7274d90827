/* vfcapture score: the physical attack success rate, from real frames of a re-capture.
 *
 * Every frame is checked for blur, localized against the workspace's sparse model, and kept
 * when its viewpoint lies within the tolerance box around v* (or an exported target); kept
 * frames are classified and the misclassified share is the physical ASR, with a 95% Wilson
 * interval. Localized frames outside the box are the natural-viewpoint control. Results go to
 * WS/score/score.json and frames.csv; `score --summary` tabulates several workspaces. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "frames_in.h"
#include "physical.h"
#include "vf/attack_file.h"
#include "vf/classifier.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/sharpness.h"
#include "vf/targets.h"
#include "vf/wilson.h"
#include "vf/workspace.h"

static const char usage[] =
    "usage: vfcapture score WS VIDEO|FOLDER|IMAGE... [options]\n"
    "       vfcapture score --summary WS... [--csv FILE]\n"
    "\n"
    "Measure the physical attack success rate from a re-capture of the object: each frame is\n"
    "localized (see 'vfcapture localize'), kept when its viewpoint is within the tolerance box\n"
    "around v* of WS/attack/attack.json (or an exported target), and classified; the ASR is\n"
    "misclassified / kept (true labels from attack.json) with a 95% Wilson interval. Localized\n"
    "frames outside the box give the accuracy at natural viewpoints. Frames rejected as blurry,\n"
    "not localized or out of tolerance are counted. Writes WS/score/score.json and frames.csv.\n"
    "With --summary: one table across workspaces (Markdown on stdout; CSV with --csv).\n"
    "\n"
    "options:\n"
    "      --tolerance R      box half-width, percent of each parameter's range (default 5)\n"
    "      --target N         centre on exported target N (WS/export/targets.json) instead of v*\n"
    "      --model M          classifier (default: the attack's model, else " VF_DEFAULT_MODEL ")\n"
    "      --blur-ratio R     frames sharper than R x the median are used (default 0.3)\n"
    "      --summary          tabulate the scores of the given workspaces\n"
    "      --csv FILE         with --summary: also write the table as CSV\n" PHYSICAL_LOCALIZE_HELP
        CLI_ENGINE_HELP CLI_COMMON_HELP;

enum { OPT_TOLERANCE = CLI_OPT_FIRST_CUSTOM, OPT_TARGET, OPT_MODEL, OPT_BLUR, OPT_SUMMARY, OPT_CSV };

typedef struct score_options {
    const char *workspace;
    char *const *inputs;
    int input_count;
    double tolerance;       /* share, 0.05 for 5% */
    int target;             /* -1: v* */
    const char *model;
    double blur_ratio;
    int summary;
    const char *csv;
    vf_localize_options loc;
    cli_flags flags;
} score_options;

/* Counts for one group of frames (kept near the target, or natural). */
typedef struct tally {
    int frames, misclassified;
    int class_count[VF_NUM_CLASSES];
} tally;

typedef struct score_run {
    const score_options *opt;
    vf_attack_file attack;
    vf_viewpoint center;
    char center_name[64];
    vf_localizer *loc;
    vf_classifier *cls;
    tally kept, natural;
    int total, blurry, not_localized, out_of_tolerance;
    double sharpness_threshold;
    int frame_count;            /* frames in the input (pass 1) */
    json_t *frames;
    double localize_seconds;
} score_run;

static vf_status parse(int argc, char **argv, score_options *o)
{
    static const struct option longopts[] = {
        CLI_COMMON_OPTIONS, CLI_ENGINE_OPTION, PHYSICAL_LOCALIZE_OPTIONS,
        {"tolerance", required_argument, NULL, OPT_TOLERANCE},
        {"target", required_argument, NULL, OPT_TARGET},
        {"model", required_argument, NULL, OPT_MODEL},
        {"blur-ratio", required_argument, NULL, OPT_BLUR},
        {"summary", no_argument, NULL, OPT_SUMMARY},
        {"csv", required_argument, NULL, OPT_CSV},
        {0, 0, 0, 0}};
    *o = (score_options){.tolerance = 0.05, .target = -1, .blur_ratio = 0.3};
    vf_localize_defaults(&o->loc);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &o->flags, "score", usage))
            continue;
        double x;
        long n;
        int handled;
        vf_status status = physical_localize_option(c, optarg, &o->loc, &handled);
        if (status != VF_OK)
            return status;
        if (handled)
            continue;
        if (c == OPT_TOLERANCE) {
            if (cli_parse_doubles(optarg, &x, 1) != 1 || !(x > 0 && x <= 100))
                return vf_fail(VF_EINPUT, "--tolerance: give a percentage in (0, 100], e.g. 5");
            o->tolerance = x / 100;
        } else if (c == OPT_TARGET) {
            if (cli_parse_int(optarg, 0, 100000, &n))
                return vf_fail(VF_EINPUT, "--target: give a target number (0 is v*)");
            o->target = (int)n;
        } else if (c == OPT_MODEL) {
            o->model = optarg;
        } else if (c == OPT_BLUR) {
            if (cli_parse_doubles(optarg, &x, 1) != 1 || !(x >= 0 && x < 1))
                return vf_fail(VF_EINPUT, "--blur-ratio: give a share in [0, 1), e.g. 0.3");
            o->blur_ratio = x;
        } else if (c == OPT_SUMMARY) {
            o->summary = 1;
        } else if (c == OPT_CSV) {
            o->csv = optarg;
        }
    }
    if (o->summary) {
        if (optind >= argc)
            return vf_fail(VF_EINPUT, "--summary: give at least one workspace");
        o->inputs = argv + optind;
        o->input_count = argc - optind;
        return VF_OK;
    }
    if (argc - optind < 2)
        return vf_fail(VF_EINPUT, "give a workspace and the re-captured video(s) or folder(s) "
                                  "(see 'vfcapture score --help')");
    o->workspace = argv[optind];
    o->inputs = argv + optind + 1;
    o->input_count = argc - optind - 1;
    return VF_OK;
}

static vf_status open_classifier(score_run *run)
{
    const char *name = run->opt->model ? run->opt->model
                       : run->attack.model[0] ? run->attack.model
                                              : VF_DEFAULT_MODEL;
    char path[VF_PATH_MAX];
    vf_status status = vf_find_model(name, NULL, path, sizeof path);
    if (status == VF_OK)
        status = vf_class_names_load();
    if (status == VF_OK)
        status = vf_classifier_open(path, &run->cls);
    return status;
}

/* Pass 1: the sharpness every frame must reach, blur_ratio x the median. */
static vf_status measure_sharpness(score_run *run)
{
    frames_in in;
    vf_status status = frames_in_open(run->opt->inputs, run->opt->input_count, &in);
    if (status != VF_OK)
        return status;
    vf_rgb8 frame = {0};
    frame_info info;
    double *values = NULL;
    int n = 0, got;
    while ((status = frames_in_next(&in, &frame, &info, &got)) == VF_OK && got) {
        vf_frame_score s;
        double *grown = realloc(values, sizeof *values * (size_t)(n + 1));
        if (!grown) {
            status = vf_fail(VF_EINTERNAL, "out of memory");
            break;
        }
        values = grown;
        if ((status = vf_score_frame(&frame, &s)) != VF_OK)
            break;
        values[n++] = s.sharpness;
    }
    vf_rgb8_free(&frame);
    frames_in_close(&in);
    if (status == VF_OK && n == 0)
        status = vf_fail(VF_EINPUT, "no frames in the given input");
    if (status == VF_OK) {
        /* median by partial sort (n is at most a few thousand) */
        for (int i = 0; i <= n / 2; i++)
            for (int j = i + 1; j < n; j++)
                if (values[j] < values[i]) {
                    double t = values[i];
                    values[i] = values[j];
                    values[j] = t;
                }
        run->sharpness_threshold = run->opt->blur_ratio * values[n / 2];
        run->frame_count = n;
    }
    free(values);
    return status;
}

/* Classify one frame: the top class and whether it is outside the label set. */
static vf_status classify(score_run *run, const vf_rgb8 *frame, int *top, float *p)
{
    vf_image img = {0};
    float *probs = malloc(sizeof(float) * VF_NUM_CLASSES);
    vf_status status = probs ? vf_image_alloc(&img, frame->width, frame->height, 3)
                             : vf_fail(VF_EINTERNAL, "out of memory");
    if (status == VF_OK) {
        size_t n = (size_t)frame->width * frame->height * 3;
        for (size_t i = 0; i < n; i++)
            img.data[i] = frame->data[i] / 255.0f;
        status = vf_classifier_classify_images(run->cls, &img, 1, probs);
    }
    if (status == VF_OK)
        vf_topk(probs, 1, top, p);
    vf_image_free(&img);
    free(probs);
    return status;
}

static void count(tally *t, const vf_attack_file *a, int top)
{
    t->frames++;
    t->misclassified += !vf_attack_is_label(a, top);
    t->class_count[top]++;
}

/* One frame: blur check, localization, box, classification; its row in run->frames. */
static vf_status score_frame(score_run *run, const vf_rgb8 *frame, const frame_info *info)
{
    json_t *row = json_pack("{s:s}", "frame", info->name);
    json_array_append_new(run->frames, row);
    run->total++;
    vf_frame_score s;
    vf_status status = vf_score_frame(frame, &s);
    if (status != VF_OK)
        return status;
    json_object_set_new(row, "sharpness", json_real(s.sharpness));
    if (s.sharpness < run->sharpness_threshold) {
        run->blurry++;
        json_object_set_new(row, "status", json_string("blurry"));
        return VF_OK;
    }
    vf_localize_result r;
    if ((status = vf_localize_frame(run->loc, frame, &r)) != VF_OK)
        return status;
    run->localize_seconds += r.seconds;
    json_object_set_new(row, "inliers", json_integer(r.inliers));
    if (!r.localized) {
        run->not_localized++;
        json_object_set_new(row, "status", json_string("not localized"));
        json_object_set_new(row, "reason", json_string(r.reason));
        return VF_OK;
    }
    double worst;
    int inside = physical_within_box(&r.viewpoint, &run->center, run->attack.range,
                                     run->opt->tolerance, &worst);
    json_object_set_new(row, "viewpoint", physical_viewpoint_json(&r.viewpoint));
    json_object_set_new(row, "box_distance", json_real(worst));
    int top;
    float p;
    if ((status = classify(run, frame, &top, &p)) != VF_OK)
        return status;
    json_object_set_new(row, "class", json_integer(top));
    json_object_set_new(row, "class_name", json_string(vf_class_short_name(top)));
    json_object_set_new(row, "confidence", json_real(p));
    json_object_set_new(row, "fooled", json_boolean(!vf_attack_is_label(&run->attack, top)));
    if (inside) {
        count(&run->kept, &run->attack, top);
        json_object_set_new(row, "status", json_string("kept"));
    } else {
        run->out_of_tolerance++;
        count(&run->natural, &run->attack, top);
        json_object_set_new(row, "status", json_string("out of tolerance"));
    }
    return VF_OK;
}

static vf_status score_frames(score_run *run)
{
    frames_in in;
    vf_status status = frames_in_open(run->opt->inputs, run->opt->input_count, &in);
    if (status != VF_OK)
        return status;
    vf_rgb8 frame = {0};
    frame_info info;
    int got;
    vf_progress progress;
    vf_progress_begin(&progress, "scoring", (size_t)run->frame_count, "frames");
    while ((status = frames_in_next(&in, &frame, &info, &got)) == VF_OK && got) {
        if ((status = score_frame(run, &frame, &info)) != VF_OK) {
            vf_error_prefix("%s", info.name);
            break;
        }
        vf_progress_update(&progress, (size_t)run->total, NULL);
    }
    vf_progress_end(&progress);
    vf_rgb8_free(&frame);
    frames_in_close(&in);
    return status;
}

static json_t *tally_json(const tally *t, const char *rate_name)
{
    double lo, hi;
    vf_wilson_interval(t->misclassified, t->frames, VF_Z95, &lo, &hi);
    json_t *classes = json_array();
    for (int c = 0; c < VF_NUM_CLASSES; c++)
        if (t->class_count[c])
            json_array_append_new(classes, json_pack("{s:i, s:s, s:i}", "class", c, "name",
                                                     vf_class_short_name(c), "frames",
                                                     t->class_count[c]));
    return json_pack("{s:i, s:i, s:f, s:[f,f], s:o}", "frames", t->frames, "misclassified",
                     t->misclassified, rate_name,
                     t->frames ? (double)t->misclassified / t->frames : 0.0, "interval95", lo,
                     hi, "predicted", classes);
}

static json_t *result_json(const score_run *run)
{
    const score_options *o = run->opt;
    return json_pack("{s:s, s:s, s:o, s:f, s:s, s:s, s:s, s:o, s:o, s:{s:i, s:i, s:i, s:i}, "
                     "s:i, s:f}",
                     "workspace", o->workspace, "center", run->center_name, "center_viewpoint",
                     physical_viewpoint_json(&run->center), "tolerance_percent",
                     100 * o->tolerance, "model", vf_classifier_path(run->cls), "engine",
                     vf_classifier_engine(run->cls), "label",
                     run->attack.label_text, "kept", tally_json(&run->kept, "asr"), "natural",
                     tally_json(&run->natural, "error_rate"), "rejected", "blurry", run->blurry,
                     "not_localized", run->not_localized, "out_of_tolerance",
                     run->out_of_tolerance, "total", run->total, "frames", run->total,
                     "localize_fps",
                     run->localize_seconds > 0
                         ? (run->total - run->blurry) / run->localize_seconds
                         : 0.0);
}

static vf_status write_frames_csv(const char *path, const json_t *frames)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    if (!f)
        return vf_fail(VF_EINTERNAL, "out of memory");
    fprintf(f, "frame,status,psi,theta,phi,dx,dy,dz,class,class_name,fooled\n");
    size_t i;
    json_t *row;
    json_array_foreach(frames, i, row) {
        json_t *v = json_object_get(row, "viewpoint");
        fprintf(f, "\"%s\",%s", json_string_value(json_object_get(row, "frame")),
                json_string_value(json_object_get(row, "status")));
        for (int k = 0; k < 6; k++)
            if (v)
                fprintf(f, ",%.6g", json_number_value(json_array_get(v, (size_t)k)));
            else
                fputc(',', f);
        json_t *cls = json_object_get(row, "class");
        if (cls)
            fprintf(f, ",%lld,\"%s\",%d\n", json_integer_value(cls),
                    json_string_value(json_object_get(row, "class_name")),
                    json_is_true(json_object_get(row, "fooled")));
        else
            fprintf(f, ",,,\n");
    }
    fclose(f);
    vf_status status = vf_write_file_atomic(path, text, size);
    free(text);
    return status;
}

static vf_status save_results(vf_workspace *ws, const score_run *run, json_t *result)
{
    vf_stage stage;
    char path[VF_PATH_MAX];
    vf_status status = vf_stage_begin(ws, "score", &stage);
    if (status != VF_OK)
        return status;
    json_t *doc = json_deep_copy(result);
    json_object_set(doc, "frames_detail", run->frames);
    if ((status = vf_path_join(path, sizeof path, stage.dir, "score.json")) == VF_OK)
        status = vf_json_save(path, doc);
    json_decref(doc);
    if (status == VF_OK && (status = vf_path_join(path, sizeof path, stage.dir, "frames.csv")) ==
                               VF_OK)
        status = write_frames_csv(path, run->frames);
    if (status == VF_OK)
        status = vf_stage_commit(&stage, json_pack("{s:f, s:s}", "tolerance_percent",
                                                   100 * run->opt->tolerance, "center",
                                                   run->center_name),
                                 json_deep_copy(result));
    else
        vf_stage_abort(&stage);
    return status;
}

static vf_status score(const score_options *o, json_t **out)
{
    vf_workspace ws;
    char path[VF_PATH_MAX];
    score_run run = {.opt = o, .frames = json_array()};
    vf_status status = vf_workspace_open(o->workspace, 0, &ws);
    if (status != VF_OK) {
        json_decref(run.frames);
        return status;
    }
    if ((status = vf_workspace_path(&ws, "attack", "attack.json", path, sizeof path)) == VF_OK &&
        !vf_is_file(path))
        status = vf_fail(VF_EINPUT, "%s does not exist: run 'vfcapture attack' first", path);
    if (status == VF_OK)
        status = vf_attack_file_load(path, &run.attack);
    run.center = run.attack.v_star;
    snprintf(run.center_name, sizeof run.center_name, "v*");
    if (status == VF_OK && o->target >= 0) {
        status = physical_load_target(o->workspace, o->target, &run.center, NULL);
        snprintf(run.center_name, sizeof run.center_name, "target %d", o->target);
    }
    if (status == VF_OK)
        status = open_classifier(&run);
    if (status == VF_OK)
        status = vf_localizer_open(o->workspace, &o->loc, &run.loc);
    if (status == VF_OK)
        status = measure_sharpness(&run);
    if (status == VF_OK)
        status = score_frames(&run);
    if (status == VF_OK) {
        *out = result_json(&run);
        status = save_results(&ws, &run, *out);
        if (status != VF_OK)
            json_decref(*out);
    }
    vf_localizer_close(run.loc);
    vf_classifier_close(run.cls);
    vf_attack_file_free(&run.attack);
    json_decref(run.frames);
    vf_workspace_close(&ws);
    return status;
}

static void print_tally(const char *what, const json_t *t, const char *rate)
{
    json_t *iv = json_object_get(t, "interval95");
    long long n = json_integer_value(json_object_get(t, "frames"));
    if (n == 0) {
        printf("%s: no frames\n", what);
        return;
    }
    printf("%s: %lld of %lld frames misclassified, %s %.1f%% (95%% interval %.1f%% to %.1f%%)",
           what, json_integer_value(json_object_get(t, "misclassified")), n, rate,
           100 * json_number_value(json_object_get(t, rate)),
           100 * json_number_value(json_array_get(iv, 0)),
           100 * json_number_value(json_array_get(iv, 1)));
    printf("\n  predicted:");
    size_t i;
    json_t *c;
    json_array_foreach(json_object_get(t, "predicted"), i, c)
        printf(" %s (%lld)", json_string_value(json_object_get(c, "name")),
               json_integer_value(json_object_get(c, "frames")));
    printf("\n");
}

static void print_result(const json_t *r)
{
    json_t *rej = json_object_get(r, "rejected");
    printf("frames within %.1f%% of %s: ", json_number_value(json_object_get(r, "tolerance_percent")),
           json_string_value(json_object_get(r, "center")));
    print_tally("physical attack", json_object_get(r, "kept"), "asr");
    print_tally("natural viewpoints", json_object_get(r, "natural"), "error_rate");
    printf("rejected: %lld blurry, %lld not localized, %lld out of tolerance (of %lld frames)\n",
           json_integer_value(json_object_get(rej, "blurry")),
           json_integer_value(json_object_get(rej, "not_localized")),
           json_integer_value(json_object_get(rej, "out_of_tolerance")),
           json_integer_value(json_object_get(rej, "total")));
}

/* ---- --summary ---- */

static double nan_to(double x)
{
    return isnan(x) ? -1 : x;
}

static vf_status summary_row(const char *ws, json_t *rows)
{
    char path[VF_PATH_MAX];
    vf_attack_file a;
    json_t *score;
    vf_status status = vf_path_join(path, sizeof path, ws, "attack/attack.json");
    if (status == VF_OK)
        status = vf_attack_file_load(path, &a);
    if (status != VF_OK)
        return status;
    vf_attack_file_free(&a);
    if ((status = vf_path_join(path, sizeof path, ws, "score/score.json")) == VF_OK &&
        !vf_is_file(path))
        status = vf_fail(VF_EINPUT, "%s does not exist: run 'vfcapture score %s VIDEO' first",
                         path, ws);
    if (status == VF_OK)
        status = vf_json_load(path, &score);
    if (status != VF_OK)
        return status;
    char name[256];
    vf_path_basename(name, sizeof name, ws, 0);
    json_t *kept = json_object_get(score, "kept");
    json_array_append_new(
        rows, json_pack("{s:s, s:s, s:f, s:f, s:f, s:O, s:O, s:O, s:O}", "object", name, "label",
                        a.label_text, "natural_accuracy", nan_to(a.natural_accuracy), "asr_v_star",
                        nan_to(a.asr_v_star), "asr_samples", nan_to(a.asr_samples),
                        "physical_asr", json_object_get(kept, "asr"), "interval95",
                        json_object_get(kept, "interval95"), "misclassified",
                        json_object_get(kept, "misclassified"), "frames_used",
                        json_object_get(kept, "frames")));
    json_decref(score);
    return VF_OK;
}

static void percent(FILE *f, double x)
{
    if (x < 0)
        fprintf(f, "n/a");
    else
        fprintf(f, "%.1f%%", 100 * x);
}

static void print_table(FILE *f, const json_t *rows, int csv)
{
    fputs(csv ? "object,label,natural_accuracy,asr_v_star,asr_samples,physical_asr,"
                     "interval_lo,interval_hi,misclassified,frames_used\n"
                   : "| object | label | natural accuracy | ASR R(v*) | ASR R(p*(v)) | physical "
                     "ASR (95% interval) | frames used |\n|---|---|---|---|---|---|---|\n",
          f);
    size_t i;
    json_t *r;
    json_array_foreach(rows, i, r) {
        double v[3] = {json_number_value(json_object_get(r, "natural_accuracy")),
                       json_number_value(json_object_get(r, "asr_v_star")),
                       json_number_value(json_object_get(r, "asr_samples"))};
        json_t *iv = json_object_get(r, "interval95");
        double asr = json_number_value(json_object_get(r, "physical_asr"));
        long long k = json_integer_value(json_object_get(r, "misclassified"));
        long long n = json_integer_value(json_object_get(r, "frames_used"));
        const char *obj = json_string_value(json_object_get(r, "object"));
        const char *label = json_string_value(json_object_get(r, "label"));
        if (csv) {
            fprintf(f, "\"%s\",\"%s\"", obj, label);
            for (int j = 0; j < 3; j++)
                fprintf(f, ",%.4f", v[j]);
            fprintf(f, ",%.4f,%.4f,%.4f,%lld,%lld\n", asr,
                    json_number_value(json_array_get(iv, 0)),
                    json_number_value(json_array_get(iv, 1)), k, n);
            continue;
        }
        fprintf(f, "| %s | %s |", obj, label);
        for (int j = 0; j < 3; j++) {
            fputc(' ', f);
            percent(f, v[j]);
            fprintf(f, " |");
        }
        fprintf(f, " %.1f%% (%.1f%% to %.1f%%), %lld/%lld | %lld |\n", 100 * asr,
                100 * json_number_value(json_array_get(iv, 0)),
                100 * json_number_value(json_array_get(iv, 1)), k, n, n);
    }
}

static vf_status summary(const score_options *o)
{
    json_t *rows = json_array();
    vf_status status = VF_OK;
    for (int i = 0; status == VF_OK && i < o->input_count; i++)
        status = summary_row(o->inputs[i], rows);
    if (status == VF_OK && o->csv) {
        char *text = NULL;
        size_t size = 0;
        FILE *f = open_memstream(&text, &size);
        if (!f) {
            status = vf_fail(VF_EINTERNAL, "out of memory");
        } else {
            print_table(f, rows, 1);
            fclose(f);
            status = vf_write_file_atomic(o->csv, text, size);
            free(text);
        }
    }
    if (status == VF_OK) {
        if (o->flags.json)
            cli_print_json(json_pack("{s:O}", "rows", rows));
        else
            print_table(stdout, rows, 0);
    }
    json_decref(rows);
    return status;
}

int cmd_score(int argc, char **argv)
{
    score_options o;
    vf_status status = parse(argc, argv, &o);
    if (status == VF_OK && o.summary)
        status = summary(&o);
    if (status != VF_OK || o.summary)
        return status == VF_OK ? 0 : cli_fail("score", status);
    json_t *result = NULL;
    if ((status = score(&o, &result)) != VF_OK)
        return cli_fail("score", status);
    if (o.flags.json)
        cli_print_json(result);
    else {
        print_result(result);
        json_decref(result);
    }
    return 0;
}
