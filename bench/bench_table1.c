/* bench_table1: the paper's Table 1 protocol on the textured 3D models of data/models_3d,
 * with its real-image column.
 *
 * For each object (default: the five MobileNetV2 recognises at natural views, per that
 * folder's README): `vfcapture ingest MODEL.glb` (Blender renders the paper's capture),
 * `train`, then for each method (random search, NES at lambda 0, NES at lambda 0.01; all in the
 * "both" space) `attack` and `real`. It prints, per object and method and on average: natural
 * accuracy on the field's renders and on the object's, ASR of R(v*) and over 100 samples of
 * p*(v) on the field, the same on the object itself (Real(v*), Real(p*(v))), and wall time per
 * stage. Workspaces go to --out DIR (default bench_table1/) and are reused: a stage that has
 * finished there is not run again, so an interrupted benchmark continues.
 *
 * usage: bench_table1 [--objects NAME,...] [--out DIR] [--views N] [--train-minutes M]
 *                     [--steps N] [--fluctuation-samples N] [--natural-views N]
 *                     [--methods random,nes0,nes]
 * NAME is the part of the file name before "__" (water_bottle, bell_pepper, vase,
 * folding_chair, reflex_camera, ...). Without --train-minutes, `train` runs with the tool's
 * default budget for a 3D model (VF_TRAIN_MINUTES_MODEL). */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_shell.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/resources.h"

typedef struct object_spec {
    const char *name, *file, *labels; /* labels: the README's label set, class indices */
} object_spec;

static const object_spec known[] = {
    {"water_bottle", "water_bottle__WaterBottle.glb", "898"},
    {"bell_pepper", "bell_pepper__yellow_bell_pepper.glb", "945"},
    {"vase", "vase__GlassVaseFlowers_right.glb", "883"},
    {"folding_chair", "folding_chair__SheenChair.glb", "559,765,423,857"},
    {"reflex_camera", "reflex_camera__AntiqueCamera.glb", "759,732,872"},
    {"studio_couch", "studio_couch__sofa_03.glb", "831"},
    {"sports_car", "sports_car__ToyCar.glb", "817,751,511"},
    {"red_fox", "red_fox__Fox.glb", "277,278,279,280"},
};
#define RECOGNISED 5 /* the first five */

typedef struct method_spec {
    const char *name, *args;
} method_spec;

static const method_spec methods[] = {
    {"random", "--method random"},
    {"nes0", "--method nes --lambda 0"},
    {"nes", "--method nes --lambda 0.01"},
};
#define METHODS 3

typedef struct options {
    const char *objects, *out, *methods;
    int views, steps, fluct, natural;
    double train_minutes;
} options;

typedef struct row {
    double nat_field, nat_real, asr_vstar, asr_samples, real_vstar, real_samples;
    double attack_s, real_s;
    int ok;
} row;

static json_t *load(const char *ws, const char *file)
{
    char path[VF_PATH_MAX * 2];
    snprintf(path, sizeof path, "%s/%s", ws, file);
    return json_load_file(path, 0, NULL);
}

static double get(const json_t *doc, const char *key, const char *sub)
{
    const json_t *v = json_object_get(doc, key);
    if (sub)
        v = json_object_get(v, sub);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

/* Seconds the manifest records for a finished stage, NAN when it has not run. */
static double stage_seconds(const char *ws, const char *stage)
{
    json_t *m = load(ws, "manifest.json");
    double s = get(json_object_get(json_object_get(m, "stages"), stage), "seconds", NULL);
    json_decref(m);
    return s;
}

static int wanted(const char *list, const char *name)
{
    if (!list)
        return -1;
    size_t n = strlen(name);
    for (const char *p = list; (p = strstr(p, name)) != NULL; p += n)
        if ((p == list || p[-1] == ',') && (p[n] == ',' || p[n] == '\0'))
            return 1;
    return 0;
}

static void method_row(const options *o, const object_spec *obj, const char *ws, int m, row *r)
{
    char saved[VF_PATH_MAX * 2];
    snprintf(saved, sizeof saved, "%s/table1_%s.json", ws, methods[m].name);
    if (!vf_is_file(saved)) {
        /* each method is its own attack of the workspace (attack/NAME), so all three stay */
        const char *name = methods[m].name;
        char real_file[160], attack_stage[160], real_stage[160];
        snprintf(real_file, sizeof real_file, "real/%s/real.json", name);
        snprintf(attack_stage, sizeof attack_stage, "attack/%s", name);
        snprintf(real_stage, sizeof real_stage, "real/%s", name);
        if (bench_run("'%s' attack '%s' --attack %s --label %s --space both %s --steps %d --quiet",
                      bench_tool(), ws, name, obj->labels, methods[m].args, o->steps) ||
            bench_run("'%s' real '%s' --attack %s --fluctuation-samples %d --natural-views %d "
                      "--quiet",
                      bench_tool(), ws, name, o->fluct, o->natural))
            return;
        json_t *real = load(ws, real_file);
        json_object_set_new(real, "attack_seconds", json_real(stage_seconds(ws, attack_stage)));
        json_object_set_new(real, "real_seconds", json_real(stage_seconds(ws, real_stage)));
        json_object_del(real, "views");
        json_dump_file(real, saved, JSON_INDENT(1));
        json_decref(real);
    }
    json_t *doc = json_load_file(saved, 0, NULL);
    *r = (row){.nat_field = get(doc, "natural_accuracy", "field"),
               .nat_real = get(doc, "natural_accuracy", "real"),
               .asr_vstar = get(doc, "asr_v_star", "field"),
               .asr_samples = get(doc, "asr_samples", "field"),
               .real_vstar = get(doc, "asr_v_star", "real"),
               .real_samples = get(doc, "asr_samples", "real"),
               .attack_s = get(doc, "attack_seconds", NULL),
               .real_s = get(doc, "real_seconds", NULL),
               .ok = doc != NULL};
    json_decref(doc);
}

/* ingest_s and train_s are NAN on the mean rows (they are per object, not per method): "-". */
static void print_row(const char *object, const char *method, const row *r, double ingest_s,
                      double train_s)
{
    char ingest[16] = "-", train[16] = "-";
    if (!isnan(ingest_s))
        snprintf(ingest, sizeof ingest, "%.0f", ingest_s);
    if (!isnan(train_s))
        snprintf(train, sizeof train, "%.0f", train_s);
    printf("%-14s %-7s %6.0f %6.0f   %6.0f %6.0f   %6.0f %6.0f   %6s %6s %6.0f %6.0f\n",
           object, method, 100 * r->nat_field, 100 * r->nat_real, 100 * r->asr_samples,
           100 * r->asr_vstar, 100 * r->real_samples, 100 * r->real_vstar, ingest, train,
           r->attack_s, r->real_s);
}

int main(int argc, char **argv)
{
    options o = {.out = "bench_table1", .views = 100, .steps = 100, .fluct = 20, .natural = 100,
                 .train_minutes = 0};
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) {
            fprintf(stderr, "usage: see the comment at the top of bench/bench_table1.c\n");
            return 1;
        }
        if (!strcmp(a, "--objects"))
            o.objects = v;
        else if (!strcmp(a, "--out"))
            o.out = v;
        else if (!strcmp(a, "--methods"))
            o.methods = v;
        else if (!strcmp(a, "--views"))
            o.views = atoi(v);
        else if (!strcmp(a, "--steps"))
            o.steps = atoi(v);
        else if (!strcmp(a, "--fluctuation-samples"))
            o.fluct = atoi(v);
        else if (!strcmp(a, "--natural-views"))
            o.natural = atoi(v);
        else if (!strcmp(a, "--train-minutes"))
            o.train_minutes = atof(v);
        else {
            fprintf(stderr, "bench_table1: unknown option %s\n", a);
            return 1;
        }
        i++;
    }
    vf_mkdirs(o.out);
    row sum[METHODS] = {{0}};
    int counted[METHODS] = {0};
    int n_objects = sizeof known / sizeof known[0];
    static row rows[sizeof known / sizeof known[0]][METHODS];
    double ingest_s[sizeof known / sizeof known[0]], train_s[sizeof known / sizeof known[0]];
    for (int k = 0; k < n_objects; k++) {
        const object_spec *obj = &known[k];
        if (o.objects ? !wanted(o.objects, obj->name) : k >= RECOGNISED)
            continue;
        char ws[VF_PATH_MAX], model[VF_PATH_MAX], rel[VF_PATH_MAX];
        snprintf(ws, sizeof ws, "%s/%s", o.out, obj->name);
        snprintf(rel, sizeof rel, "data/models_3d/%s", obj->file);
        if (vf_shared_path(rel, model, sizeof model) != VF_OK)
            continue;
        if (isnan(stage_seconds(ws, "ingest")) &&
            bench_run("'%s' ingest '%s' -o '%s' --views %d --quiet", bench_tool(), model, ws,
                      o.views))
            continue;
        char budget[64] = ""; /* none: the tool's default for a 3D model */
        if (o.train_minutes > 0)
            snprintf(budget, sizeof budget, "--minutes %g", o.train_minutes);
        if (isnan(stage_seconds(ws, "train")) &&
            bench_run("'%s' train '%s' %s --quiet", bench_tool(), ws, budget))
            continue;
        ingest_s[k] = stage_seconds(ws, "ingest");
        train_s[k] = stage_seconds(ws, "train");
        for (int m = 0; m < METHODS; m++) {
            if (o.methods && !wanted(o.methods, methods[m].name))
                continue;
            method_row(&o, obj, ws, m, &rows[k][m]);
            if (!rows[k][m].ok)
                continue;
            counted[m]++;
            row *s = &sum[m], *r = &rows[k][m];
            s->nat_field += r->nat_field;
            s->nat_real += r->nat_real;
            s->asr_samples += r->asr_samples;
            s->asr_vstar += r->asr_vstar;
            s->real_samples += r->real_samples;
            s->real_vstar += r->real_vstar;
            s->attack_s += r->attack_s;
            s->real_s += r->real_s;
        }
    }
    printf("\nTable 1 protocol on data/models_3d (MobileNetV2, 'both' space; percentages; "
           "seconds on this machine)\n");
    printf("%-14s %-7s %13s   %13s   %13s   %27s\n", "", "", "natural acc", "rendered ASR",
           "real ASR", "wall time (s)");
    printf("%-14s %-7s %6s %6s   %6s %6s   %6s %6s   %6s %6s %6s %6s\n", "object", "method",
           "field", "object", "p*(v)", "v*", "p*(v)", "v*", "ingest", "train", "attack", "real");
    for (int k = 0; k < n_objects; k++)
        for (int m = 0; m < METHODS; m++)
            if (rows[k][m].ok)
                print_row(known[k].name, methods[m].name, &rows[k][m], ingest_s[k], train_s[k]);
    for (int m = 0; m < METHODS; m++) {
        if (!counted[m])
            continue;
        row avg = sum[m];
        double n = counted[m];
        avg.nat_field /= n, avg.nat_real /= n, avg.asr_samples /= n, avg.asr_vstar /= n;
        avg.real_samples /= n, avg.real_vstar /= n, avg.attack_s /= n, avg.real_s /= n;
        char label[32];
        snprintf(label, sizeof label, "mean of %d", counted[m]);
        print_row(label, methods[m].name, &avg, NAN, NAN);
    }
    return 0;
}
