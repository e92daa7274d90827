/* vfcapture score: parse the options, run the score stage (vf/score.h) or its summary across
 * workspaces, print the result. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "physical.h"
#include "vf/csv.h"
#include "vf/resources.h"
#include "vf/score.h"

static const char usage[] =
    "usage: vfcapture score WS VIDEO|FOLDER|IMAGE... [options]\n"
    "       vfcapture score --summary WS... [--csv FILE]\n"
    "\n"
    "Measure the physical attack success rate from a re-capture of the object: each frame is\n"
    "localized (see 'vfcapture localize'), kept when its viewpoint is within the tolerance box\n"
    "around v* of the exported attack (WS/attack/NAME/attack.json, or an exported target), and\n"
    "classified; the ASR is misclassified / kept (true labels from attack.json) with a 95%\n"
    "Wilson interval. Localized\n"
    "frames outside the box give the accuracy at natural viewpoints. Frames rejected as blurry,\n"
    "not localized or out of tolerance are counted. Writes WS/score/score.json, frames.csv and\n"
    "sheet.png (what the classifier saw of frames spread over the video).\n"
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
    int summary;
    const char *csv;
    vf_score_options score;
    cli_flags flags;
} score_options;

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
    *o = (score_options){0};
    vf_score_defaults(&o->score);
    int c;
    while ((c = getopt_long(argc, argv, CLI_COMMON_SHORT, longopts, NULL)) != -1) {
        if (cli_common_option(c, &o->flags, "score", usage))
            continue;
        double x;
        long n;
        int handled;
        vf_status status = physical_localize_option(c, optarg, &o->score.loc, &handled);
        if (status != VF_OK)
            return status;
        if (handled)
            continue;
        if (c == OPT_TOLERANCE) {
            if (cli_number_above("--tolerance", optarg, 0, 100, &x) != VF_OK) /* percent */
                return VF_EINPUT;
            o->score.tolerance = x / 100;
        } else if (c == OPT_TARGET) {
            if (cli_count("--target", optarg, 0, 100000, &n) != VF_OK) /* 0 is v* */
                return VF_EINPUT;
            o->score.target = (int)n;
        } else if (c == OPT_MODEL) {
            o->score.model = optarg;
        } else if (c == OPT_BLUR) {
            if (cli_number("--blur-ratio", optarg, 0, 0.99, &x) != VF_OK)
                return VF_EINPUT;
            o->score.blur_ratio = x;
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

static void percent(FILE *f, double x)
{
    if (x < 0)
        fprintf(f, "n/a");
    else
        fprintf(f, "%.1f%%", 100 * x);
}

/* The rates of a row: rendered (field), then the object itself (a 3D model's `real`). */
static const char *const rate_keys[6] = {"natural_accuracy", "asr_v_star",
                                         "asr_samples",      "real_natural_accuracy",
                                         "real_asr_v_star",  "real_asr_samples"};

static void print_table(FILE *f, const json_t *rows, int csv)
{
    fputs(csv ? "object,label,natural_accuracy,asr_v_star,asr_samples,real_natural_accuracy,"
                "real_asr_v_star,real_asr_samples,physical_asr,interval_lo,interval_hi,"
                "misclassified,frames_used\n"
              : "| object | label | natural accuracy | ASR R(v*) | ASR R(p*(v)) | natural "
                "accuracy (object) | Real(v*) | Real(p*(v)) | physical ASR (95% interval) | "
                "frames used |\n|---|---|---|---|---|---|---|---|---|---|\n",
          f);
    size_t i;
    json_t *r;
    json_array_foreach(rows, i, r)
    {
        json_t *iv = json_object_get(r, "interval95");
        int physical = json_object_get(r, "physical_asr") != NULL;
        double asr = json_number_value(json_object_get(r, "physical_asr"));
        long long k = json_integer_value(json_object_get(r, "misclassified"));
        long long n = json_integer_value(json_object_get(r, "frames_used"));
        double lo = json_number_value(json_array_get(iv, 0));
        double hi = json_number_value(json_array_get(iv, 1));
        const char *object = json_string_value(json_object_get(r, "object"));
        const char *label = json_string_value(json_object_get(r, "label"));
        if (csv) {
            vf_csv_text(f, object);
            vf_csv_next(f, label);
        } else {
            fprintf(f, "| %s | %s |", object, label);
        }
        for (int j = 0; j < 6; j++) {
            double v = json_number_value(json_object_get(r, rate_keys[j]));
            if (csv && v >= 0)
                fprintf(f, ",%.4f", v);
            else if (csv)
                fputc(',', f);
            else {
                fputc(' ', f);
                percent(f, v);
                fprintf(f, " |");
            }
        }
        if (csv && physical)
            fprintf(f, ",%.4f,%.4f,%.4f,%lld,%lld\n", asr, lo, hi, k, n);
        else if (csv)
            fprintf(f, ",,,,,\n");
        else if (physical)
            fprintf(f, " %.1f%% (%.1f%% to %.1f%%), %lld/%lld | %lld |\n", 100 * asr, 100 * lo,
                    100 * hi, k, n, n);
        else
            fprintf(f, " n/a | n/a |\n");
    }
}

static vf_status summary(const score_options *o)
{
    json_t *rows = NULL;
    vf_status status = vf_score_summary(o->inputs, o->input_count, &rows);
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
    vf_workspace ws;
    if ((status = vf_workspace_open(o.workspace, 0, &ws)) == VF_OK) {
        status = vf_score_run(&ws, o.inputs, o.input_count, &o.score, &result);
        vf_workspace_close(&ws);
    }
    if (status != VF_OK)
        return cli_fail("score", status);
    if (o.flags.json)
        cli_print_json(result);
    else {
        print_result(result);
        json_decref(result);
    }
    return 0;
}
