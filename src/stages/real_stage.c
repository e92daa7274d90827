/* The real check (vf/real.h): the attack's viewpoints seen on the object itself.
 *
 * Every camera is classified twice, on a render of the field and on Blender's render of the
 * model, with the same classifier camera, normalization and label set, so the two columns
 * differ only by what the field got wrong about the object. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "vf/attack_eval.h"
#include "vf/attack_file.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/metrics.h"
#include "vf/plot.h"
#include "vf/pose.h"
#include "vf/real.h"
#include "vf/resources.h"
#include "vf/rng.h"
#include "vf/view_loss.h"

#define SHEET_SAMPLES 11 /* v* and this many samples, field beside model, on the sheet */
#define SHEET_COLUMNS 6

enum { G_STAR, G_SAMPLES, G_FLUCT, G_NATURAL, G_COUNT };
static const char *const group_names[G_COUNT] = {"v_star", "samples", "fluctuation", "natural"};

typedef struct real_run {
    vf_workspace *ws;
    const vf_real_options *o;
    vf_object3d obj;
    vf_attack_file af;
    vf_field *field;
    vf_classifier *cls;
    vf_view_loss *vl;
    vf_camera cam;
    char classifier_path[VF_PATH_MAX];
    int n, first[G_COUNT + 1]; /* cameras of group g: first[g] .. first[g + 1] - 1 */
    double *c2w;               /* n x 16, the workspace's frame (the field's) */
    double *object_c2w;        /* the same cameras in the object's frame (Blender's) */
    double *views;             /* n x 6: the viewpoint of each camera */
    vf_view_prediction *field_pred, *real_pred;
    double *psnr;              /* field render against the object's render, dB */
    vf_image *images;          /* the model's renders */
    int images_loaded;
    vf_stage stage;
    char stage_name[160]; /* real/NAME */
    double seconds_render, seconds_classify;
} real_run;

void vf_real_defaults(vf_real_options *o)
{
    *o = (vf_real_options){.fluctuation_samples = VF_FLUCT_SAMPLES, .natural_views = 100};
}

static vf_status open_inputs(real_run *r)
{
    vf_status s = VF_OK;
    if (r->o->object)
        r->obj = *r->o->object;
    else
        s = vf_object3d_load(r->ws, &r->obj);
    if (s == VF_OK)
        s = vf_attack_file_load_workspace(r->ws, r->o->attack, &r->af);
    if (s == VF_OK) /* real/NAME of attack/NAME */
        snprintf(r->stage_name, sizeof r->stage_name, "real/%s", r->af.stage + 7);
    if (s == VF_OK)
        s = vf_field_load_workspace(r->ws, &r->field);
    const char *name = r->o->classifier       ? r->o->classifier
                       : r->af.model[0] != 0 ? r->af.model
                                              : VF_DEFAULT_MODEL;
    if (s == VF_OK)
        s = vf_find_model(name, r->o->models_dir, r->classifier_path, sizeof r->classifier_path);
    if (s == VF_OK)
        s = vf_classifier_open(r->classifier_path, &r->cls);
    if (s == VF_OK)
        s = vf_view_loss_create(r->field, r->cls, &r->vl);
    if (s == VF_OK)
        s = vf_view_loss_set_labels(r->vl, r->af.labels, r->af.label_count);
    if (s == VF_OK)
        r->cam = vf_view_loss_camera(r->vl);
    return s;
}

/* The cameras: v*, the samples, the fluctuation boxes, natural training views. */
static vf_status make_cameras(real_run *r)
{
    vf_dataset ds = {0};
    vf_status s = vf_dataset_load_training(r->ws, &ds, NULL);
    if (s != VF_OK)
        return s;
    int natural = r->o->natural_views < ds.count ? r->o->natural_views : ds.count;
    int fluct = VF_FLUCT_LEVELS * r->o->fluctuation_samples;
    int counts[G_COUNT] = {1, r->af.sample_count, fluct, natural};
    r->first[0] = 0;
    for (int g = 0; g < G_COUNT; g++)
        r->first[g + 1] = r->first[g] + counts[g];
    r->n = r->first[G_COUNT];
    r->c2w = malloc((size_t)r->n * 16 * sizeof *r->c2w);
    r->object_c2w = malloc((size_t)r->n * 16 * sizeof *r->object_c2w);
    r->views = malloc((size_t)r->n * 6 * sizeof *r->views);
    r->field_pred = calloc((size_t)r->n, sizeof *r->field_pred);
    r->real_pred = calloc((size_t)r->n, sizeof *r->real_pred);
    r->psnr = calloc((size_t)r->n, sizeof *r->psnr);
    r->images = calloc((size_t)r->n, sizeof *r->images);
    if (!r->c2w || !r->object_c2w || !r->views || !r->field_pred || !r->real_pred || !r->psnr ||
        !r->images) {
        vf_dataset_free(&ds);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
    vf_viewpoint_to_array(&r->af.v_star, r->views);
    memcpy(r->views + 6 * r->first[G_SAMPLES], r->af.samples,
           (size_t)r->af.sample_count * 6 * sizeof(double));
    vf_view_bounds box;
    memcpy(box.lo, r->af.lo, sizeof box.lo);
    memcpy(box.hi, r->af.hi, sizeof box.hi);
    vf_rng rng;
    vf_rng_seed(&rng, r->o->seed);
    for (int level = 0; level < VF_FLUCT_LEVELS; level++)
        vf_view_fluctuation(&box, r->views, level + 1, &rng, r->o->fluctuation_samples,
                            r->views + 6 * (r->first[G_FLUCT] + level * r->o->fluctuation_samples));
    for (int i = 0; i < r->first[G_NATURAL]; i++) {
        vf_viewpoint v = vf_viewpoint_from_array(r->views + 6 * i);
        vf_viewpoint_to_c2w(&v, r->c2w + 16 * i);
    }
    for (int i = 0; i < natural; i++) {
        int k = r->first[G_NATURAL] + i;
        memcpy(r->c2w + 16 * k, ds.frames[(long)i * ds.count / natural].c2w, 16 * sizeof(double));
        vf_viewpoint v;
        vf_c2w_to_viewpoint(r->c2w + 16 * k, &v);
        vf_viewpoint_to_array(&v, r->views + 6 * k);
    }
    vf_similarity to_object = r->o->to_object ? *r->o->to_object : vf_similarity_identity();
    for (int i = 0; i < r->n; i++)
        vf_similarity_apply_c2w(&to_object, r->c2w + 16 * i, r->object_c2w + 16 * i);
    vf_dataset_free(&ds);
    return VF_OK;
}

/* A staging folder left by an interrupted run keeps its renders only when they were made for
 * the same model, camera and cameras. */
static vf_status prepare_renders(real_run *r, char *dir, size_t size)
{
    json_t *poses = json_array();
    for (int i = 0; i < 16 * r->n; i++)
        json_array_append_new(poses, vf_json_number(r->object_c2w[i]));
    json_t *request = json_pack("{s:s, s:s, s:i, s:i, s:o, s:o, s:o, s:o, s:i, s:o}", "model",
                                r->obj.model, "scene", r->obj.scene, "width", r->cam.width,
                                "height", r->cam.height, "fx", vf_json_number(r->cam.fx), "fy",
                                vf_json_number(r->cam.fy), "cx", vf_json_number(r->cam.cx), "cy",
                                vf_json_number(r->cam.cy), "samples", r->obj.samples, "c2w", poses);
    static const char *const renders[] = {"renders", NULL};
    vf_status s = vf_path_join(dir, size, r->stage.dir, "renders");
    return s == VF_OK ? vf_stage_keep_if_same(r->stage.dir, request, renders) : s;
}

/* How closely the field reproduces the object at each camera. */
static vf_status compare_renders(real_run *r)
{
    vf_image field[16] = {{0}};
    vf_status s = VF_OK;
    for (int first = 0; s == VF_OK && first < r->n; first += 16) {
        int m = r->n - first < 16 ? r->n - first : 16;
        s = vf_field_render_batch(r->field, &r->cam, r->c2w + 16 * first, m, field);
        for (int i = 0; s == VF_OK && i < m; i++)
            r->psnr[first + i] = vf_image_psnr(&field[i], &r->images[first + i]);
    }
    for (int i = 0; i < 16; i++)
        vf_image_free(&field[i]);
    return s;
}

static vf_status classify_both(real_run *r)
{
    char dir[VF_PATH_MAX];
    double t0 = vf_now();
    vf_status s = vf_view_loss_classify_poses(r->vl, r->c2w, r->n, r->field_pred);
    if (s == VF_OK)
        s = prepare_renders(r, dir, sizeof dir);
    double t1 = vf_now();
    if (s == VF_OK)
        s = vf_object3d_render_images(&r->obj, &r->cam, r->object_c2w, r->n, dir, "view_",
                                      "rendering the object", r->images);
    r->images_loaded = s == VF_OK;
    double t2 = vf_now();
    if (s == VF_OK)
        s = vf_view_loss_classify_images(r->vl, r->images, r->n, r->real_pred);
    if (s == VF_OK)
        s = compare_renders(r);
    r->seconds_render = t2 - t1;
    r->seconds_classify = (t1 - t0) + (vf_now() - t2);
    return s;
}

/* The share of group g's cameras that fool the classifier. */
static double fooled_rate(const vf_view_prediction *pred, int first, int count)
{
    int fooled = 0;
    for (int i = 0; i < count; i++)
        fooled += !pred[first + i].correct;
    return count ? (double)fooled / count : NAN;
}

static double agreement(const real_run *r, int first, int count)
{
    int same = 0;
    for (int i = 0; i < count; i++)
        same += r->field_pred[first + i].top_class == r->real_pred[first + i].top_class;
    return count ? (double)same / count : NAN;
}

static double mean_psnr(const real_run *r, int first, int count)
{
    double sum = 0;
    for (int i = 0; i < count; i++)
        sum += r->psnr[first + i];
    return count ? sum / count : NAN;
}

static json_t *pair_json(double field, double real)
{
    return json_pack("{s:o, s:o}", "field", vf_json_number(field), "real", vf_json_number(real));
}

static json_t *result_json(const real_run *r)
{
    int fl = r->o->fluctuation_samples;
    json_t *levels = json_array(), *field_curve = json_array(), *real_curve = json_array();
    for (int level = 0; level < VF_FLUCT_LEVELS; level++) {
        int first = r->first[G_FLUCT] + level * fl;
        json_array_append_new(levels, vf_json_number(level + 1));
        json_array_append_new(field_curve, vf_json_number(fooled_rate(r->field_pred, first, fl)));
        json_array_append_new(real_curve, vf_json_number(fooled_rate(r->real_pred, first, fl)));
    }
    json_t *views = json_array();
    for (int g = 0; g < G_COUNT; g++)
        for (int i = r->first[g]; i < r->first[g + 1]; i++) {
            json_t *v = json_array();
            for (int k = 0; k < 6; k++)
                json_array_append_new(v, vf_json_number(r->views[6 * i + k]));
            json_array_append_new(
                views, json_pack("{s:s, s:i, s:o, s:o, s:o, s:o}", "group", group_names[g], "index",
                                 i - r->first[g], "view", v, "psnr", vf_json_number(r->psnr[i]),
                                 "field", vf_view_prediction_to_json(&r->field_pred[i]), "real",
                                 vf_view_prediction_to_json(&r->real_pred[i])));
        }
    int ns = r->af.sample_count, nn = r->first[G_COUNT] - r->first[G_NATURAL];
    return json_pack(
        "{s:s, s:s, s:s, s:{s:[o,o,o], s:o}, s:s, s:o, s:o, s:o, s:i, s:o, s:{s:o, s:o, s:o, s:i}, "
        "s:i, s:o, s:o, s:{s:o, s:o, s:o, s:o}, s:{s:o, s:o}, s:o}",
        "object", r->obj.model, "classifier", r->classifier_path, "engine",
        vf_classifier_engine(r->cls), "transform", "center",
        vf_json_number(r->obj.transform.center[0]), vf_json_number(r->obj.transform.center[1]),
        vf_json_number(r->obj.transform.center[2]), "scale", vf_json_number(r->obj.transform.scale),
        "label", r->af.label_text, "asr_v_star",
        pair_json(fooled_rate(r->field_pred, 0, 1), fooled_rate(r->real_pred, 0, 1)), "asr_samples",
        pair_json(fooled_rate(r->field_pred, r->first[G_SAMPLES], ns),
                  fooled_rate(r->real_pred, r->first[G_SAMPLES], ns)),
        "natural_accuracy",
        pair_json(1 - fooled_rate(r->field_pred, r->first[G_NATURAL], nn),
                  1 - fooled_rate(r->real_pred, r->first[G_NATURAL], nn)),
        "natural_views", nn, "attack",
        json_pack("{s:o, s:o, s:o}", "asr_v_star", vf_json_number(r->af.asr_v_star),
                  "asr_samples", vf_json_number(r->af.asr_samples), "natural_accuracy",
                  vf_json_number(r->af.natural_accuracy)),
        "fluctuation", "r_percent", levels, "field", field_curve, "real", real_curve,
        "samples_per_level", fl, "samples", ns, "agreement", vf_json_number(agreement(r, 0, r->n)),
        "agreement_natural", vf_json_number(agreement(r, r->first[G_NATURAL], nn)), "psnr",
        "v_star", vf_json_number(r->psnr[0]), "samples",
        vf_json_number(mean_psnr(r, r->first[G_SAMPLES], ns)), "fluctuation",
        vf_json_number(mean_psnr(r, r->first[G_FLUCT], r->first[G_NATURAL] - r->first[G_FLUCT])),
        "natural", vf_json_number(mean_psnr(r, r->first[G_NATURAL], nn)), "seconds",
        "render_object", vf_json_number(r->seconds_render), "field_and_classifier",
        vf_json_number(r->seconds_classify), "views", views);
}

/* field | model, for v* and the first samples, captions red when fooled. */
static vf_status save_sheet(const real_run *r, const char *path)
{
    int pairs = 1 + (r->af.sample_count < SHEET_SAMPLES ? r->af.sample_count : SHEET_SAMPLES);
    vf_image tiles[2 * (1 + SHEET_SAMPLES)] = {{0}};
    char text[2 * (1 + SHEET_SAMPLES)][128];
    const char *captions[2 * (1 + SHEET_SAMPLES)];
    int mark[2 * (1 + SHEET_SAMPLES)];
    vf_status s = VF_OK;
    for (int p = 0; s == VF_OK && p < pairs; p++) {
        int i = p == 0 ? 0 : r->first[G_SAMPLES] + p - 1;
        const vf_view_prediction *fp = &r->field_pred[i], *rp = &r->real_pred[i];
        s = vf_view_loss_render(r->vl, r->views + 6 * i, &tiles[2 * p]);
        if (s == VF_OK)
            s = vf_image_alloc(&tiles[2 * p + 1], r->images[i].width, r->images[i].height, 3);
        if (s != VF_OK)
            break;
        memcpy(tiles[2 * p + 1].data, r->images[i].data,
               (size_t)r->images[i].width * r->images[i].height * 3 * sizeof(float));
        char name[32];
        if (p == 0)
            snprintf(name, sizeof name, "v*");
        else
            snprintf(name, sizeof name, "sample %d", p);
        snprintf(text[2 * p], sizeof text[0], "%s field\n%.24s %.2f", name,
                 vf_class_short_name(fp->top_class), fp->top_prob);
        snprintf(text[2 * p + 1], sizeof text[0], "%s object\n%.24s %.2f", name,
                 vf_class_short_name(rp->top_class), rp->top_prob);
        captions[2 * p] = text[2 * p];
        captions[2 * p + 1] = text[2 * p + 1];
        mark[2 * p] = !fp->correct;
        mark[2 * p + 1] = !rp->correct;
    }
    if (s == VF_OK)
        s = vf_contact_sheet(path, tiles, captions, mark, 2 * pairs, SHEET_COLUMNS);
    for (int t = 0; t < 2 * pairs; t++)
        vf_image_free(&tiles[t]);
    return s;
}

static vf_status save_curve(const real_run *r, const char *path)
{
    int fl = r->o->fluctuation_samples;
    double x[VF_FLUCT_LEVELS], field[VF_FLUCT_LEVELS], real[VF_FLUCT_LEVELS];
    for (int level = 0; level < VF_FLUCT_LEVELS; level++) {
        int first = r->first[G_FLUCT] + level * fl;
        x[level] = level + 1;
        field[level] = 100 * fooled_rate(r->field_pred, first, fl);
        real[level] = 100 * fooled_rate(r->real_pred, first, fl);
    }
    vf_plot_series series[2] = {{"rendered (field)", x, field, VF_FLUCT_LEVELS},
                                {"real (the model itself)", x, real, VF_FLUCT_LEVELS}};
    vf_plot_axes axes = {"Attack success under camera fluctuation around v*",
                         "fluctuation r (% of each parameter's range)", "ASR (%)", 0, 100};
    return vf_plot_lines(path, &axes, series, 2);
}

static vf_status save_outputs(const real_run *r, json_t *doc)
{
    char path[VF_PATH_MAX];
    vf_status s = vf_path_join(path, sizeof path, r->stage.dir, VF_REAL_FILE);
    if (s == VF_OK)
        s = vf_json_save(path, doc);
    if (s == VF_OK && (s = vf_path_join(path, sizeof path, r->stage.dir, "sheet.png")) == VF_OK)
        s = save_sheet(r, path);
    if (s == VF_OK &&
        (s = vf_path_join(path, sizeof path, r->stage.dir, "fluctuation.png")) == VF_OK)
        s = save_curve(r, path);
    return s;
}

static void release(real_run *r)
{
    for (int i = 0; r->images_loaded && i < r->n; i++)
        vf_image_free(&r->images[i]);
    free(r->images);
    free(r->c2w);
    free(r->object_c2w);
    free(r->views);
    free(r->field_pred);
    free(r->real_pred);
    free(r->psnr);
    vf_view_loss_free(r->vl);
    vf_classifier_close(r->cls);
    vf_field_free(r->field);
    vf_attack_file_free(&r->af);
}

vf_status vf_real_run(vf_workspace *ws, const vf_real_options *o, json_t **result)
{
    real_run r = {.ws = ws, .o = o};
    vf_status s = open_inputs(&r);
    if (s == VF_OK)
        s = make_cameras(&r);
    int staged = 0;
    if (s == VF_OK && (s = vf_stage_resume(ws, r.stage_name, &r.stage)) == VF_OK)
        staged = 1;
    if (s == VF_OK) {
        vf_info("checking %d cameras on the field and on %s", r.n, r.obj.model);
        s = classify_both(&r);
    }
    json_t *doc = s == VF_OK ? result_json(&r) : NULL;
    if (s == VF_OK)
        s = doc ? save_outputs(&r, doc) : vf_fail(VF_EINTERNAL, "out of memory");
    if (s == VF_OK) {
        json_t *sum = json_pack("{s:O, s:O, s:O, s:O, s:i}", "asr_v_star",
                                json_object_get(doc, "asr_v_star"), "asr_samples",
                                json_object_get(doc, "asr_samples"), "natural_accuracy",
                                json_object_get(doc, "natural_accuracy"), "agreement",
                                json_object_get(doc, "agreement"), "cameras", r.n);
        json_t *params = json_pack("{s:s, s:s, s:i, s:i, s:I}", "attack", r.af.stage + 7,
                                   "classifier", r.classifier_path,
                                   "fluctuation_samples", o->fluctuation_samples,
                                   "natural_views", o->natural_views, "seed",
                                   (json_int_t)o->seed);
        s = vf_stage_commit(&r.stage, params, sum);
        if (s == VF_OK && result)
            *result = json_incref(doc);
    } else if (staged && s == VF_EINPUT) {
        vf_stage_abort(&r.stage); /* nothing worth keeping for a retry */
    }
    json_decref(doc);
    release(&r);
    return s;
}

vf_status vf_real_load_rates(const vf_workspace *ws, const char *attack, vf_real_rates *out,
                             int *found)
{
    char path[VF_PATH_MAX], stage[160];
    json_t *doc = NULL;
    *found = 0;
    snprintf(stage, sizeof stage, "real/%s", strncmp(attack, "attack/", 7) ? attack : attack + 7);
    if (!vf_workspace_has_stage(ws, stage))
        return VF_OK;
    vf_status s = vf_workspace_need(ws, stage);
    if (s == VF_OK)
        s = vf_workspace_path(ws, stage, VF_REAL_FILE, path, sizeof path);
    if (s == VF_OK)
        s = vf_json_load(path, &doc);
    if (s != VF_OK)
        return s;
    const char *keys[3] = {"natural_accuracy", "asr_v_star", "asr_samples"};
    double *dst[3] = {&out->natural_accuracy, &out->asr_v_star, &out->asr_samples};
    for (int i = 0; i < 3 && s == VF_OK; i++) {
        const json_t *x = json_object_get(json_object_get(doc, keys[i]), "real");
        if (!json_is_number(x))
            s = vf_fail(VF_EINPUT, "%s: no \"%s\" of the object (\"real\")", path, keys[i]);
        else
            *dst[i] = json_number_value(x);
    }
    json_decref(doc);
    *found = s == VF_OK;
    return s;
}
