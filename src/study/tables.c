/* The tables of a study (vf/study.h): read every workspace's attacks, group, write. */
#define _GNU_SOURCE /* open_memstream, vasprintf */
#include "vf/study.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/csv.h"
#include "vf/fsutil.h"
#include "vf/json.h"
#include "vf/plot.h"
#include "vf/workspace.h"

#define MAX_TRANSFER 16 /* target models of one attack */
#define MAX_ROWS 4096   /* attacks of a study */

/* One current attack of one object: what the tables average. */
typedef struct attack_row {
    char object[128], attack[128], model[128], method[16], space[16];
    double lambda; /* NAN for random search */
    double natural, v_star, samples, random_search, std[6];
    double real_natural, real_v_star, real_samples; /* NAN without `real` */
    int transfer_count;
    char transfer_model[MAX_TRANSFER][128];
    double transfer_samples[MAX_TRANSFER], transfer_v_star[MAX_TRANSFER];
} attack_row;

typedef struct study {
    const char *dir;
    attack_row *rows;
    int count, objects;
    json_t *failed; /* [{object, stage, error}] */
    json_t *costs;  /* [{object, stage, seconds}] */
} study;

/* ---- a table: a header and rows of text cells, written as CSV and as Markdown ---- */

typedef struct table {
    const char *name, *title;
    int cols, n, cap; /* n cells so far; a row is cols cells */
    const char *head[24];
    char **cells;
} table;

static void table_start(table *t, const char *name, const char *title, const char *const *head)
{
    memset(t, 0, sizeof *t);
    t->name = name, t->title = title;
    while (head[t->cols])
        t->head[t->cols] = head[t->cols], t->cols++;
}

/* Append one cell; rows fill left to right. */
static void cell(table *t, const char *fmt, ...)
{
    if (t->n == t->cap) {
        int cap = t->cap ? 2 * t->cap : 256;
        char **grown = realloc(t->cells, (size_t)cap * sizeof *grown);
        if (!grown)
            return; /* out of memory: the cell is dropped, the writers see a short row */
        t->cells = grown, t->cap = cap;
    }
    va_list ap;
    va_start(ap, fmt);
    char *text = NULL;
    if (vasprintf(&text, fmt, ap) < 0)
        text = NULL;
    va_end(ap);
    t->cells[t->n++] = text;
}

/* A percentage cell ("-" when not measured). */
static void pct(table *t, double x)
{
    if (isfinite(x))
        cell(t, "%.1f", 100 * x);
    else
        cell(t, "-");
}

static void table_free(table *t)
{
    for (int i = 0; i < t->n; i++)
        free(t->cells[i]);
    free(t->cells);
}

static const char *at(const table *t, int row, int col)
{
    int i = row * t->cols + col;
    return i < t->n && t->cells[i] ? t->cells[i] : "";
}

static void write_csv(FILE *f, const table *t)
{
    for (int c = 0; c < t->cols; c++)
        (c ? vf_csv_next : vf_csv_text)(f, t->head[c]);
    fputc('\n', f);
    for (int r = 0; r < t->n / t->cols; r++) {
        for (int c = 0; c < t->cols; c++)
            (c ? vf_csv_next : vf_csv_text)(f, at(t, r, c));
        fputc('\n', f);
    }
}

static void write_markdown(FILE *f, const table *t)
{
    fprintf(f, "## %s\n\n|", t->title);
    for (int c = 0; c < t->cols; c++)
        fprintf(f, " %s |", t->head[c]);
    fputs("\n|", f);
    for (int c = 0; c < t->cols; c++)
        fputs(" --- |", f);
    fputc('\n', f);
    for (int r = 0; r < t->n / t->cols; r++) {
        fputc('|', f);
        for (int c = 0; c < t->cols; c++)
            fprintf(f, " %s |", at(t, r, c));
        fputc('\n', f);
    }
    if (t->n == 0)
        fputs("| (none) |\n", f);
    fputc('\n', f);
}

/* Write a text built with a memory stream to path, atomically. */
typedef struct text_out {
    char *data;
    size_t size;
    FILE *f;
} text_out;

static vf_status text_begin(text_out *o)
{
    memset(o, 0, sizeof *o);
    o->f = open_memstream(&o->data, &o->size);
    return o->f ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
}

static vf_status text_end(text_out *o, const char *dir, const char *name, vf_status status)
{
    char path[VF_PATH_MAX];
    fclose(o->f);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, dir, name);
    if (status == VF_OK)
        status = vf_write_file_atomic(path, o->data, o->size);
    free(o->data);
    return status;
}

static vf_status save_table(const table *t, const char *dir)
{
    text_out o;
    char name[64];
    vf_status s = text_begin(&o);
    if (s != VF_OK)
        return s;
    write_csv(o.f, t);
    snprintf(name, sizeof name, "%s.csv", t->name);
    return text_end(&o, dir, name, VF_OK);
}

/* ---- reading the workspaces ---- */

static double number(const json_t *o, const char *key)
{
    const json_t *v = json_object_get(o, key);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

static double side(const json_t *doc, const char *key, const char *which)
{
    return number(json_object_get(doc, key), which);
}

static void model_name(const char *path, char *out, size_t size)
{
    vf_path_basename(out, size, path ? path : "", 1);
}

static void add_failure(study *st, const char *object, const char *stage, const char *error)
{
    json_array_append_new(st->failed, json_pack("{s:s, s:s, s:s}", "object", object, "stage",
                                                stage, "error", error));
}

/* WS/transfer/NAME/transfer.json into the row (nothing when it has not run). */
static void read_transfer(const vf_workspace *ws, attack_row *row)
{
    char stage[160], path[VF_PATH_MAX];
    json_t *doc = NULL;
    snprintf(stage, sizeof stage, "transfer/%s", row->attack);
    if (vf_workspace_need(ws, stage) != VF_OK ||
        vf_workspace_path(ws, stage, "transfer.json", path, sizeof path) != VF_OK ||
        vf_json_load(path, &doc) != VF_OK)
        return;
    size_t i;
    json_t *m;
    json_array_foreach(json_object_get(doc, "models"), i, m) {
        if (row->transfer_count == MAX_TRANSFER)
            break;
        int k = row->transfer_count++;
        model_name(json_string_value(json_object_get(m, "model")), row->transfer_model[k],
                   sizeof row->transfer_model[k]);
        row->transfer_samples[k] = number(m, "asr_samples");
        row->transfer_v_star[k] = number(m, "asr_v_star");
    }
    json_decref(doc);
}

/* WS/real/NAME/real.json into the row (NAN when it has not run). */
static void read_real(const vf_workspace *ws, attack_row *row)
{
    char stage[160], path[VF_PATH_MAX];
    json_t *doc = NULL;
    row->real_natural = row->real_v_star = row->real_samples = NAN;
    snprintf(stage, sizeof stage, "real/%s", row->attack);
    if (vf_workspace_need(ws, stage) != VF_OK ||
        vf_workspace_path(ws, stage, "real.json", path, sizeof path) != VF_OK ||
        vf_json_load(path, &doc) != VF_OK)
        return;
    row->real_natural = side(doc, "natural_accuracy", "real");
    row->real_v_star = side(doc, "asr_v_star", "real");
    row->real_samples = side(doc, "asr_samples", "real");
    json_decref(doc);
}

static vf_status read_attack(study *st, const vf_workspace *ws, const char *object,
                             const char *stage)
{
    char path[VF_PATH_MAX], why[256];
    if (vf_workspace_is_stale(ws, stage, why, sizeof why)) {
        char text[512];
        snprintf(text, sizeof text, "stale (%s): not counted", why);
        add_failure(st, object, stage, text);
        return VF_OK;
    }
    if (st->count == MAX_ROWS)
        return vf_fail(VF_EINPUT, "%s: more than %d attacks in one study", st->dir, MAX_ROWS);
    json_t *doc = NULL;
    vf_status s = vf_workspace_path(ws, stage, "attack.json", path, sizeof path);
    if (s == VF_OK && vf_json_load(path, &doc) != VF_OK) {
        add_failure(st, object, stage, vf_error_message());
        return VF_OK;
    }
    attack_row *row = &st->rows[st->count++];
    memset(row, 0, sizeof *row);
    snprintf(row->object, sizeof row->object, "%s", object);
    snprintf(row->attack, sizeof row->attack, "%s", stage + strlen("attack/"));
    model_name(json_string_value(json_object_get(doc, "model")), row->model, sizeof row->model);
    snprintf(row->method, sizeof row->method, "%s",
             json_string_value(json_object_get(doc, "method")) ?: "?");
    snprintf(row->space, sizeof row->space, "%s",
             json_string_value(json_object_get(doc, "space")) ?: "?");
    row->lambda = strcmp(row->method, "random") ? number(json_object_get(doc, "config"), "lambda")
                                                : NAN;
    row->natural = number(doc, "natural_accuracy");
    row->v_star = number(doc, "asr_v_star");
    row->samples = number(doc, "asr_samples");
    row->random_search = number(json_object_get(doc, "random_search"), "asr_samples");
    for (int k = 0; k < 6; k++)
        row->std[k] = json_number_value(json_array_get(json_object_get(doc, "sample_std"), k));
    json_decref(doc);
    read_real(ws, row);
    read_transfer(ws, row);
    return s;
}

static int bench_file(const char *name)
{
    size_t n = strlen(name);
    return n > 10 && !strcmp(name + n - 10, ".bench.tsv");
}

/* The workflow's benchmark files in dir (STAGE.bench.tsv: seconds, h:m:s, max_rss in MB, ...)
 * as costs of `object`; returns how many there were. */
static int read_bench_costs(study *st, const char *dir, const char *object)
{
    char **names = NULL;
    int n = 0;
    if (!vf_is_dir(dir) || vf_list_folder(dir, bench_file, &names, &n) != VF_OK)
        return 0;
    for (int i = 0; i < n; i++) {
        char path[VF_PATH_MAX], *text = NULL, stage[128];
        size_t size;
        double seconds, rss;
        snprintf(stage, sizeof stage, "%.*s", (int)(strlen(names[i]) - 10), names[i]);
        if (vf_path_join(path, sizeof path, dir, names[i]) != VF_OK ||
            vf_read_file(path, &text, &size) != VF_OK)
            continue;
        const char *line = strchr(text, '\n'); /* past the header */
        if (line && sscanf(line + 1, "%lf %*s %lf", &seconds, &rss) == 2)
            json_array_append_new(st->costs,
                                  json_pack("{s:s, s:s, s:o, s:o}", "object", object, "stage",
                                            stage, "seconds", vf_json_number(seconds), "max_rss_mb",
                                            vf_json_number(rss)));
        free(text);
    }
    vf_free_names(names, n);
    return n;
}

/* What each job of the object cost: its benchmark files (STUDY/logs/OBJECT/), else the seconds
 * the manifest records (a stage's own time, without loading). */
static void read_costs(study *st, const vf_workspace *ws, const char *object)
{
    char dir[VF_PATH_MAX];
    if (snprintf(dir, sizeof dir, "%s/logs/%s", st->dir, object) < (int)sizeof dir &&
        read_bench_costs(st, dir, object) > 0)
        return;
    const char *stage;
    json_t *record;
    json_object_foreach(json_object_get(ws->manifest, "stages"), stage, record)
        json_array_append_new(st->costs,
                              json_pack("{s:s, s:s, s:o, s:n}", "object", object, "stage", stage,
                                        "seconds", vf_json_number(number(record, "seconds")),
                                        "max_rss_mb"));
}

static int folder_name(const char *name)
{
    return strcmp(name, "tables") && strcmp(name, "logs") && strcmp(name, "imagenet_v");
}

static vf_status read_object(study *st, const char *object)
{
    char root[VF_PATH_MAX], failed[VF_PATH_MAX], manifest[VF_PATH_MAX];
    vf_status s = vf_path_join(root, sizeof root, st->dir, object);
    if (s == VF_OK)
        s = vf_path_join(failed, sizeof failed, root, VF_STUDY_FAILED_FILE);
    if (s == VF_OK)
        s = vf_path_join(manifest, sizeof manifest, root, "manifest.json");
    if (s != VF_OK)
        return s;
    if (vf_is_file(failed)) {
        json_t *doc = NULL;
        if (vf_json_load(failed, &doc) == VF_OK)
            add_failure(st, object, json_string_value(json_object_get(doc, "stage")) ?: "?",
                        json_string_value(json_object_get(doc, "error")) ?: "?");
        else
            add_failure(st, object, "?", "unreadable failed.json");
        json_decref(doc);
        st->objects++;
        return VF_OK;
    }
    if (!vf_is_file(manifest))
        return VF_OK; /* not a workspace */
    vf_workspace ws;
    if (vf_workspace_open(root, 0, &ws) != VF_OK) {
        add_failure(st, object, "manifest", vf_error_message());
        st->objects++;
        return VF_OK;
    }
    st->objects++;
    const char *stages[256];
    int n = vf_workspace_stages_of(&ws, "attack", stages, 256);
    if (n == 0)
        add_failure(st, object, "attack", "no attack finished");
    for (int i = 0; i < n && s == VF_OK; i++)
        s = read_attack(st, &ws, object, stages[i]);
    read_costs(st, &ws, object);
    vf_workspace_close(&ws);
    return s;
}

/* ---- grouping: mean and 95% interval over objects ---- */

/* Student's t, two-sided 95%, for df = 1..30; the normal beyond. */
static double t95(int df)
{
    static const double t[] = {0,     12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365,
                               2.306, 2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131,
                               2.120, 2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069,
                               2.064, 2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
    return df < 1 ? NAN : df <= 30 ? t[df] : 1.96;
}

typedef struct mean_ci {
    double mean, half; /* half-width of the 95% interval; NAN for one object */
    int n;
} mean_ci;

static mean_ci mean_of(const double *x, int count)
{
    double sum = 0, sq = 0;
    int n = 0;
    for (int i = 0; i < count; i++)
        if (isfinite(x[i]))
            sum += x[i], n++;
    mean_ci m = {n ? sum / n : NAN, NAN, n};
    for (int i = 0; i < count; i++)
        if (isfinite(x[i]))
            sq += (x[i] - m.mean) * (x[i] - m.mean);
    if (n > 1)
        m.half = t95(n - 1) * sqrt(sq / (n - 1) / n);
    return m;
}

/* "87.3 ± 4.1" (percent), "87.3" for one object, "-" for none. */
static void pct_ci(table *t, mean_ci m)
{
    if (!isfinite(m.mean))
        cell(t, "-");
    else if (!isfinite(m.half))
        cell(t, "%.1f", 100 * m.mean);
    else
        cell(t, "%.1f ± %.1f", 100 * m.mean, 100 * m.half);
}

static void method_label(const attack_row *r, char *out, size_t size)
{
    if (isfinite(r->lambda))
        snprintf(out, size, "%s lambda %g", r->method, r->lambda);
    else
        snprintf(out, size, "%s", r->method);
}

/* A group of Table 1: the same space, method, lambda and classifier. Groups are listed in the
 * order they first appear. */
static int same_group(const attack_row *a, const attack_row *b)
{
    return !strcmp(a->space, b->space) && !strcmp(a->method, b->method) &&
           !strcmp(a->model, b->model) &&
           ((isnan(a->lambda) && isnan(b->lambda)) || a->lambda == b->lambda);
}

/* Whether rows[i] is its group's first. */
static int opens_group(const study *st, int i)
{
    for (int j = 0; j < i; j++)
        if (same_group(&st->rows[j], &st->rows[i]))
            return 0;
    return 1;
}

/* The values of one field over rows[i]'s group. */
static int group_values(const study *st, int i, size_t offset, double *out)
{
    int n = 0;
    for (int j = 0; j < st->count; j++)
        if (same_group(&st->rows[j], &st->rows[i]))
            out[n++] = *(const double *)((const char *)&st->rows[j] + offset);
    return n;
}

static mean_ci group_mean(const study *st, int i, size_t offset, double *scratch)
{
    return mean_of(scratch, group_values(st, i, offset, scratch));
}

/* ---- the paper's numbers (../shared/DESIGN.md, "The paper's numbers") ---- */

/* Table 1, ResNet-50 | ViT-B/16, R(p*) / R(v*) / Real(v*) (random search: R(p*) only). */
static const char *paper_table1(const attack_row *r)
{
    static const struct {
        const char *space, *method;
        double lambda;
        const char *text;
    } rows[] = {
        {"translation", "random", NAN, "38.08 \\| 26.01"},
        {"translation", "nes", 0, "54.27 / 60 / 44 \\| 46.30 / 55 / 31"},
        {"translation", "nes", 0.01, "55.24 / 67 / 46 \\| 43.10 / 59 / 32"},
        {"rotation", "random", NAN, "51.68 \\| 45.60"},
        {"rotation", "nes", 0, "89.62 / 94 / 84 \\| 83.07 / 87 / 78"},
        {"rotation", "nes", 0.01, "84.25 / 96 / 92 \\| 79.25 / 91 / 85"},
        {"both", "random", NAN, "53.98 \\| 47.52"},
        {"both", "nes", 0, "92.01 / 96 / 87 \\| 85.02 / 91 / 77"},
        {"both", "nes", 0.01, "88.79 / 98 / 91 \\| 82.14 / 92 / 88"},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++)
        if (!strcmp(rows[i].space, r->space) && !strcmp(rows[i].method, r->method) &&
            (isnan(rows[i].lambda) ? isnan(r->lambda) : rows[i].lambda == r->lambda))
            return rows[i].text;
    return "-";
}

/* Table 2 (ResNet-50, both): R(p*), R(v*), std psi, theta, phi, dx, dy, dz. */
static const char *paper_table2(double lambda)
{
    static const struct {
        double lambda;
        const char *text;
    } rows[] = {
        {0, "92.01, 96; 4.554, 1.681, 2.474, 0.031, 0.064, 0.029"},
        {1e-4, "90.69, 97; 6.797, 2.130, 3.385, 0.040, 0.077, 0.037"},
        {1e-3, "90.63, 98; 15.718, 3.366, 6.607, 0.062, 0.097, 0.060"},
        {0.01, "88.79, 98; 21.644, 3.397, 7.485, 0.065, 0.099, 0.060"},
        {0.1, "88.85, 98; 22.179, 3.552, 8.006, 0.066, 0.113, 0.063"},
        {1.0, "77.00, 92; 23.937, 4.193, 9.209, 0.071, 0.141, 0.069"},
    };
    for (size_t i = 0; i < sizeof rows / sizeof rows[0]; i++)
        if (fabs(rows[i].lambda - lambda) < 1e-12)
            return rows[i].text;
    return "-";
}

/* ---- the tables ---- */

static void make_table1(const study *st, table *t, double *scratch)
{
    static const char *head[] = {"space", "method", "classifier", "objects", "R(p*(v))", "R(v*)",
                                 "Real(v*)", "Real(p*(v))", "natural (field)",
                                 "natural (object)", "random search R(p)",
                                 "paper ResNet-50 \\| ViT-B/16", NULL};
    table_start(t, "table1",
                "Table 1: attack success rate (%), mean over objects ± 95% interval", head);
    for (int i = 0; i < st->count; i++) {
        if (!opens_group(st, i))
            continue;
        const attack_row *r = &st->rows[i];
        char method[64];
        method_label(r, method, sizeof method);
        cell(t, "%s", r->space), cell(t, "%s", method), cell(t, "%s", r->model);
        cell(t, "%d", group_values(st, i, offsetof(attack_row, samples), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, samples), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, v_star), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, real_v_star), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, real_samples), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, natural), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, real_natural), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, random_search), scratch));
        cell(t, "%s", paper_table1(r));
    }
}

static void make_table2(const study *st, table *t, double *scratch)
{
    static const char *head[] = {"classifier", "space", "lambda", "objects", "R(p*(v))", "R(v*)",
                                 "std psi", "std theta", "std phi", "std dx", "std dy", "std dz",
                                 "paper (ResNet-50, both)", NULL};
    table_start(t, "table2", "Table 2: the entropy weight lambda (nes), mean over objects", head);
    for (int i = 0; i < st->count; i++) {
        const attack_row *r = &st->rows[i];
        if (!isfinite(r->lambda) || !opens_group(st, i))
            continue;
        cell(t, "%s", r->model), cell(t, "%s", r->space), cell(t, "%g", r->lambda);
        cell(t, "%d", group_values(st, i, offsetof(attack_row, samples), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, samples), scratch));
        pct_ci(t, group_mean(st, i, offsetof(attack_row, v_star), scratch));
        for (int k = 0; k < 6; k++) {
            mean_ci m = group_mean(st, i, offsetof(attack_row, std) + (size_t)k * sizeof(double),
                                   scratch);
            cell(t, k < 3 ? "%.3f" : "%.4f", m.mean);
        }
        cell(t, "%s", paper_table2(r->lambda));
    }
}

/* Table 3: rows are attack settings (classifier, method, lambda, space), columns the models
 * the samples were carried to. */
static void make_table3(const study *st, table *t, double *scratch)
{
    static const char *head[] = {"attacked classifier", "method", "space", "model", "objects",
                                 "ASR p*(v)", "ASR v*", "paper p*(v) (ResNet-50 to MN-v2)",
                                 NULL};
    table_start(t, "table3", "Table 3: transfer of the adversarial viewpoints to other models",
                head);
    for (int i = 0; i < st->count; i++) {
        const attack_row *r = &st->rows[i];
        if (!opens_group(st, i))
            continue;
        char method[64];
        method_label(r, method, sizeof method);
        for (int k = 0; k < r->transfer_count; k++) {
            double *v = scratch, *s = scratch + MAX_ROWS;
            int n = 0;
            for (int j = 0; j < st->count; j++) {
                const attack_row *o = &st->rows[j];
                if (!same_group(o, r))
                    continue;
                for (int m = 0; m < o->transfer_count; m++)
                    if (!strcmp(o->transfer_model[m], r->transfer_model[k]))
                        s[n] = o->transfer_samples[m], v[n++] = o->transfer_v_star[m];
            }
            cell(t, "%s", r->model), cell(t, "%s", method), cell(t, "%s", r->space);
            cell(t, "%s", r->transfer_model[k]), cell(t, "%d", n);
            pct_ci(t, mean_of(s, n)), pct_ci(t, mean_of(v, n));
            /* the paper's MN-v2 column, ResNet-50's p*(v) at lambda 0 and 0.01 */
            int mn_v2 = strstr(r->transfer_model[k], "mobilenet_v2") != NULL;
            cell(t, "%s", !mn_v2 || !isfinite(r->lambda) ? "-"
                          : r->lambda == 0                ? "76.77"
                          : r->lambda == 0.01             ? "79.11"
                                                          : "-");
        }
    }
}

/* STUDY/imagenet_v/ATTACK/results.csv: the "all" rows (model,object,split,correct,total,top1). */
static void make_imagenet_v(const study *st, table *t)
{
    static const char *head[] = {"attack", "model", "natural top-1", "adversarial top-1",
                                 "images a split", NULL};
    table_start(t, "imagenet_v",
                "ImageNet-V: top-1 (%) on natural and on adversarial viewpoints (paper, 100 "
                "objects: ResNet-50 78.11 / 23.56, ViT-B 62.28 / 20.41, Swin-L 89.97 / 47.40)",
                head);
    char dir[VF_PATH_MAX];
    char **names = NULL;
    int n = 0;
    if (vf_path_join(dir, sizeof dir, st->dir, "imagenet_v") != VF_OK || !vf_is_dir(dir) ||
        vf_list_folder(dir, folder_name, &names, &n) != VF_OK)
        return;
    for (int a = 0; a < n; a++) {
        char path[VF_PATH_MAX], *text = NULL;
        size_t size;
        if (snprintf(path, sizeof path, "%s/%s/results.csv", dir, names[a]) >= (int)sizeof path ||
            vf_read_file(path, &text, &size) != VF_OK)
            continue;
        char *save = NULL, natural[64] = "";
        for (char *line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
            char model[256], object[256], split[32];
            int correct, total;
            double top1;
            if (sscanf(line, "%255[^,],%255[^,],%31[^,],%d,%d,%lf", model, object, split,
                       &correct, &total, &top1) != 6 ||
                strcmp(object, "all"))
                continue;
            if (!strcmp(split, "natural")) {
                snprintf(natural, sizeof natural, "%.1f", top1);
            } else {
                cell(t, "%s", names[a]), cell(t, "%s", model), cell(t, "%s", natural);
                cell(t, "%.1f", top1), cell(t, "%d", total);
            }
        }
        free(text);
    }
    vf_free_names(names, n);
}

static void make_objects(const study *st, table *t)
{
    static const char *head[] = {"object", "attack", "classifier", "method", "lambda", "space",
                                 "natural", "R(p*(v))", "R(v*)", "Real(v*)", "Real(p*(v))",
                                 "natural (object)", "random search R(p)", NULL};
    table_start(t, "objects", "Per object", head);
    for (int i = 0; i < st->count; i++) {
        const attack_row *r = &st->rows[i];
        cell(t, "%s", r->object), cell(t, "%s", r->attack), cell(t, "%s", r->model);
        cell(t, "%s", r->method);
        if (isfinite(r->lambda))
            cell(t, "%g", r->lambda);
        else
            cell(t, "-");
        cell(t, "%s", r->space);
        pct(t, r->natural), pct(t, r->samples), pct(t, r->v_star), pct(t, r->real_v_star);
        pct(t, r->real_samples), pct(t, r->real_natural), pct(t, r->random_search);
    }
}

static void make_list(table *t, const char *name, const char *title, const json_t *items,
                      const char *const *keys)
{
    table_start(t, name, title, keys);
    size_t i;
    json_t *item;
    json_array_foreach(items, i, item) {
        for (int k = 0; keys[k]; k++) {
            const json_t *v = json_object_get(item, keys[k]);
            if (json_is_number(v))
                cell(t, "%.1f", json_number_value(v));
            else
                cell(t, "%s", json_string_value(v) ?: "");
        }
    }
}

/* table1.png: R(p*(v)) of each Table 1 row, a point each (the plot module draws lines). */
static vf_status chart(const study *st, const char *dir, double *scratch)
{
    double x[256], y[256], vs[256];
    int n = 0;
    for (int i = 0; i < st->count && n < 256; i++)
        if (opens_group(st, i)) {
            x[n] = n + 1;
            y[n] = 100 * group_mean(st, i, offsetof(attack_row, samples), scratch).mean;
            vs[n] = 100 * group_mean(st, i, offsetof(attack_row, v_star), scratch).mean;
            n++;
        }
    if (n == 0)
        return VF_OK;
    char path[VF_PATH_MAX];
    vf_plot_series series[2] = {{"R(p*(v))", x, y, n}, {"R(v*)", x, vs, n}};
    vf_plot_axes axes = {"Table 1 rows (in tables.md order): mean ASR over objects",
                         "row of Table 1", "ASR (%)", 0, 100};
    vf_status s = vf_path_join(path, sizeof path, dir, "table1.png");
    return s == VF_OK ? vf_plot_lines(path, &axes, series, 2) : s;
}

static vf_status write_all(study *st, json_t **result)
{
    char dir[VF_PATH_MAX];
    static const char *failed_keys[] = {"object", "stage", "error", NULL};
    static const char *cost_keys[] = {"object", "stage", "seconds", "max_rss_mb", NULL};
    double *scratch = malloc(2 * MAX_ROWS * sizeof *scratch);
    table tables[7];
    int count = 0;
    vf_status s = scratch ? vf_path_join(dir, sizeof dir, st->dir, "tables")
                          : vf_fail(VF_EINTERNAL, "out of memory");
    if (s == VF_OK)
        s = vf_mkdirs(dir);
    if (s == VF_OK) {
        make_table1(st, &tables[count++], scratch);
        make_table2(st, &tables[count++], scratch);
        make_table3(st, &tables[count++], scratch);
        make_imagenet_v(st, &tables[count++]);
        make_objects(st, &tables[count++]);
        make_list(&tables[count++], "failed", "Failed objects and stale attacks", st->failed,
                  failed_keys);
        make_list(&tables[count++], "costs", "What each job cost: wall seconds and peak memory (MB)",
                  st->costs, cost_keys);
    }
    text_out md;
    if (s == VF_OK && (s = text_begin(&md)) == VF_OK) {
        fprintf(md.f, "# Study %s: %d objects, %d attacks, %zu failed or stale\n\n", st->dir,
                st->objects, st->count, json_array_size(st->failed));
        fputs("ASR = attack success rate: the share of renders whose top-1 is outside the "
              "object's label set. R(.) on the radiance field, Real(.) on the 3D model itself "
              "(vfcapture real). The paper's numbers (Dong et al., NeurIPS 2022) are over 100 "
              "objects with ResNet-50 and ViT-B/16.\n\n",
              md.f);
        for (int i = 0; i < count; i++)
            write_markdown(md.f, &tables[i]);
        s = text_end(&md, dir, "tables.md", s);
    }
    for (int i = 0; i < count && s == VF_OK; i++)
        s = save_table(&tables[i], dir);
    if (s == VF_OK)
        s = chart(st, dir, scratch);
    if (s == VF_OK && result)
        *result = json_pack("{s:i, s:i, s:O, s:s}", "objects", st->objects, "attacks", st->count,
                            "failed", st->failed, "tables", dir);
    for (int i = 0; i < count; i++)
        table_free(&tables[i]);
    free(scratch);
    return s;
}

/* Object, then attack name: the tables do not depend on the order the jobs finished in. */
static int by_object_and_attack(const void *a, const void *b)
{
    const attack_row *x = a, *y = b;
    int c = strcmp(x->object, y->object);
    return c ? c : strcmp(x->attack, y->attack);
}

vf_status vf_study_tables(const char *study_dir, json_t **result)
{
    if (result)
        *result = NULL;
    study st = {.dir = study_dir, .failed = json_array(), .costs = json_array()};
    char **names = NULL;
    int n = 0;
    st.rows = malloc(MAX_ROWS * sizeof *st.rows);
    vf_status s = st.rows ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    if (s == VF_OK && !vf_is_dir(study_dir))
        s = vf_fail(VF_EINPUT, "%s does not exist", study_dir);
    if (s == VF_OK)
        s = vf_list_folder(study_dir, folder_name, &names, &n);
    for (int i = 0; i < n && s == VF_OK; i++)
        s = read_object(&st, names[i]);
    char logs[VF_PATH_MAX]; /* the jobs over all objects (ImageNet-V) */
    if (s == VF_OK && vf_path_join(logs, sizeof logs, study_dir, "logs") == VF_OK)
        read_bench_costs(&st, logs, "(all)");
    if (s == VF_OK && st.objects == 0)
        s = vf_fail(VF_EINPUT, "%s holds no workspace: is it a study's folder (its 'out')?",
                    study_dir);
    if (s == VF_OK)
        qsort(st.rows, (size_t)st.count, sizeof *st.rows, by_object_and_attack);
    if (s == VF_OK)
        s = write_all(&st, result);
    vf_free_names(names, n);
    free(st.rows);
    json_decref(st.failed);
    json_decref(st.costs);
    return s;
}
