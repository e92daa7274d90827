/* The score stage (vf/score.h): the physical attack success rate from re-captured frames. */
#define _GNU_SOURCE
#include "vf/score.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/attack_file.h"
#include "vf/export.h"
#include "vf/classifier.h"
#include "vf/csv.h"
#include "vf/field.h"
#include "vf/frames.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/object3d.h"
#include "vf/plot.h"
#include "vf/pose.h"
#include "vf/real.h"
#include "vf/resources.h"
#include "vf/sharpness.h"
#include "vf/stats.h"
#include "vf/targets.h"
#include "vf/wilson.h"

/* Counts for one group of frames (kept near the target, or natural). */
typedef struct tally {
    int frames, misclassified;
    int class_count[VF_NUM_CLASSES];
} tally;

/* sheet.png: every so many classified frames, the square the classifier saw, small */
#define SHEET_MAX 36
#define SHEET_SIDE 112

typedef struct score_run {
    const vf_score_options *opt;
    const char *root;
    char *const *inputs;
    int input_count;
    vf_attack_file attack;
    vf_viewpoint center;
    char center_name[64];
    vf_localizer *loc;
    vf_classifier *cls;
    tally kept, natural;
    int total, blurry, not_localized, out_of_tolerance;
    double sharpness_threshold;
    int frame_count; /* frames in the input (pass 1) */
    json_t *frames;
    double localize_seconds;
    int object_mode;  /* the field was trained in object mode (vf/train.h object_only) */
    vf_field *field;  /* then its silhouette cuts each frame out before classifying */
    int classified;               /* frames classified so far */
    vf_image sheet[SHEET_MAX];    /* what the classifier saw of some of them */
    char *caption[SHEET_MAX];
    int fooled[SHEET_MAX];
    int sheet_count;
} score_run;

static vf_status open_classifier(score_run *run)
{
    const char *name = run->opt->model        ? run->opt->model
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

/* Every frame of the inputs through fn, in order. The inputs are decoded twice, once for the
 * sharpness (the blur threshold is a share of the median over all frames) and once to score:
 * decoding again costs less than localizing the blurry frames the threshold then drops. */
typedef vf_status (*frame_fn)(score_run *run, const vf_rgb8 *frame, const vf_frame_info *info,
                              void *data);

static vf_status each_frame(score_run *run, frame_fn fn, void *data, vf_progress *progress)
{
    vf_frames in;
    vf_status status = vf_frames_open(run->inputs, run->input_count, &in);
    if (status != VF_OK)
        return status;
    vf_rgb8 frame = {0};
    vf_frame_info info;
    int got, n = 0;
    while ((status = vf_frames_next(&in, &frame, &info, &got)) == VF_OK && got) {
        if ((status = fn(run, &frame, &info, data)) != VF_OK) {
            vf_error_prefix("%s", info.name);
            break;
        }
        if (progress)
            vf_progress_update(progress, (size_t)++n, NULL);
    }
    vf_rgb8_free(&frame);
    vf_frames_close(&in);
    return status;
}

typedef struct sharpness_list {
    double *values;
    int n;
} sharpness_list;

static vf_status add_sharpness(score_run *run, const vf_rgb8 *frame, const vf_frame_info *info,
                               void *data)
{
    (void)run, (void)info;
    sharpness_list *list = data;
    vf_frame_score s;
    double *grown = realloc(list->values, sizeof *grown * (size_t)(list->n + 1));
    if (!grown)
        return vf_fail(VF_EINTERNAL, "out of memory");
    list->values = grown;
    vf_status status = vf_score_frame(frame, &s);
    if (status == VF_OK)
        list->values[list->n++] = s.sharpness;
    return status;
}

/* Pass 1: the sharpness every frame must reach, blur_ratio x the median. */
static vf_status measure_sharpness(score_run *run)
{
    sharpness_list list = {0};
    vf_status status = each_frame(run, add_sharpness, &list, NULL);
    if (status == VF_OK && list.n == 0)
        status = vf_fail(VF_EINPUT, "no frames in the given input");
    if (status == VF_OK) {
        vf_sort_doubles(list.values, list.n); /* the median, the upper middle one when even */
        run->sharpness_threshold =
            run->opt->blur_ratio * vf_sorted_quantile(list.values, list.n, 0.5);
        run->frame_count = list.n;
    }
    free(list.values);
    return status;
}

/* Object mode, as the train stage did it: the object is what its field (cut out of the scene,
 * vf_field_cut_object) shows, so a frame's mask is the field's silhouette at the frame's
 * localized pose: the attack and the measurement see the same object. */
static vf_status open_object_mode(score_run *run, const vf_workspace *ws)
{
    const json_t *params = json_object_get(vf_workspace_stage_record(ws, "train"), "params");
    if (!json_is_true(json_object_get(params, "object_only")))
        return VF_OK;
    vf_status status = vf_field_load_workspace(ws, &run->field);
    run->object_mode = status == VF_OK;
    if (run->object_mode)
        vf_info("object mode (as the field was trained): each frame is cut out by the field's "
                "silhouette at its pose and classified on white");
    return status;
}

/* Frames are cut by the field's silhouette rendered at most this many pixels long. */
#define SILHOUETTE_SIDE 480

/* The classifier's centre square of img (the crop vf_classifier_preprocess takes), small. */
static vf_status thumbnail(const vf_image *img, vf_image *out)
{
    int shorter = img->width < img->height ? img->width : img->height;
    int side = (int)lround(shorter * 224.0 / 256.0);
    vf_image square = {0};
    vf_status status = vf_image_center_crop(img, side, side, &square);
    if (status == VF_OK)
        status = vf_image_resize(&square, SHEET_SIDE, SHEET_SIDE, out);
    vf_image_free(&square);
    return status;
}

/* Classify one frame (in object mode its object cut out onto white, posed by c2w): the top
 * class; *coverage gets the object's share of the frame (1 outside object mode). thumb (may
 * be NULL) gets what the classifier saw, small. */
static vf_status classify(score_run *run, const vf_rgb8 *frame, const double c2w[16], int *top,
                          float *p, double *coverage, vf_image *thumb)
{
    vf_image img = {0};
    uint8_t *mask = NULL;
    float *probs = malloc(sizeof(float) * VF_NUM_CLASSES);
    vf_status status = probs ? vf_image_alloc(&img, frame->width, frame->height, 3)
                             : vf_fail(VF_EINTERNAL, "out of memory");
    vf_camera cam;
    if (status == VF_OK && run->object_mode &&
        (status = vf_localizer_camera(run->loc, frame->width, frame->height, &cam)) == VF_OK)
        status = vf_field_silhouette(run->field, &cam, c2w, SILHOUETTE_SIDE, &mask);
    if (status == VF_OK) {
        size_t n = (size_t)frame->width * frame->height, on = 0;
        for (size_t i = 0; i < n; i++) {
            int keep = !mask || mask[i];
            on += keep;
            for (int c = 0; c < 3; c++)
                img.data[3 * i + c] = keep ? frame->data[3 * i + c] / 255.0f : 1.0f;
        }
        *coverage = n ? (double)on / n : 0;
        status = vf_classifier_classify_images(run->cls, &img, 1, probs);
    }
    if (status == VF_OK && thumb)
        status = thumbnail(&img, thumb);
    free(mask);
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
static vf_status score_frame(score_run *run, const vf_rgb8 *frame, const vf_frame_info *info,
                             void *data)
{
    (void)data;
    json_t *row = json_pack("{s:s}", "frame", info->name);
    json_array_append_new(run->frames, row);
    run->total++;
    vf_frame_score s;
    vf_status status = vf_score_frame(frame, &s);
    if (status != VF_OK)
        return status;
    json_object_set_new(row, "sharpness", vf_json_number(s.sharpness));
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
    int inside = vf_viewpoint_within(&r.viewpoint, &run->center, run->attack.range,
                                     run->opt->tolerance, &worst);
    json_object_set_new(row, "viewpoint", vf_viewpoint_json(&r.viewpoint));
    json_object_set_new(row, "box_distance", vf_json_number(worst));
    int top;
    float p;
    double coverage;
    int stride = run->frame_count / SHEET_MAX + 1;
    vf_image *thumb = run->classified++ % stride == 0 && run->sheet_count < SHEET_MAX
                          ? &run->sheet[run->sheet_count]
                          : NULL;
    if ((status = classify(run, frame, r.c2w_object, &top, &p, &coverage, thumb)) != VF_OK)
        return status;
    if (thumb) {
        char caption[160];
        const char *tail = strrchr(info->name, '#'); /* a video's frame number */
        if (!tail)
            tail = (tail = strrchr(info->name, '/')) ? tail + 1 : info->name;
        snprintf(caption, sizeof caption, "%.40s %s\n%s %.0f%%", tail,
                 inside ? "on target" : "natural", vf_class_short_name(top), 100 * p);
        run->caption[run->sheet_count] = strdup(caption);
        run->fooled[run->sheet_count++] = !vf_attack_is_label(&run->attack, top);
    }
    if (run->object_mode)
        json_object_set_new(row, "object_coverage", vf_json_number(coverage));
    json_object_set_new(row, "class", json_integer(top));
    json_object_set_new(row, "class_name", json_string(vf_class_short_name(top)));
    json_object_set_new(row, "confidence", vf_json_number(p));
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

/* Pass 2: localize, select and classify. */
static vf_status score_frames(score_run *run)
{
    vf_progress progress;
    vf_progress_begin(&progress, "scoring", (size_t)run->frame_count, "frames");
    vf_status status = each_frame(run, score_frame, NULL, &progress);
    vf_progress_end(&progress);
    return status;
}

static json_t *tally_json(const tally *t, const char *rate_name)
{
    double lo, hi;
    vf_wilson_interval(t->misclassified, t->frames, VF_Z95, &lo, &hi);
    json_t *classes = json_array();
    for (int c = 0; c < VF_NUM_CLASSES; c++)
        if (t->class_count[c])
            json_array_append_new(classes,
                                  json_pack("{s:i, s:s, s:i}", "class", c, "name",
                                            vf_class_short_name(c), "frames", t->class_count[c]));
    /* No frame, no rate: null, never a 0% that reads like a measurement. */
    return json_pack("{s:i, s:i, s:o, s:[o,o], s:o}", "frames", t->frames, "misclassified",
                     t->misclassified, rate_name,
                     t->frames ? vf_json_number((double)t->misclassified / t->frames) : json_null(),
                     "interval95", vf_json_number(lo), vf_json_number(hi), "predicted", classes);
}

static json_t *result_json(const score_run *run)
{
    const vf_score_options *o = run->opt;
    return json_pack(
        "{s:s, s:s, s:o, s:o, s:s, s:s, s:s, s:o, s:o, s:{s:i, s:i, s:i, s:i}, "
        "s:i, s:o, s:s}",
        "workspace", run->root, "center", run->center_name, "center_viewpoint",
        vf_viewpoint_json(&run->center), "tolerance_percent", vf_json_number(100 * o->tolerance),
        "model", vf_classifier_path(run->cls), "engine", vf_classifier_engine(run->cls), "label",
        run->attack.label_text, "kept", tally_json(&run->kept, "asr"), "natural",
        tally_json(&run->natural, "error_rate"), "rejected", "blurry", run->blurry, "not_localized",
        run->not_localized, "out_of_tolerance", run->out_of_tolerance, "total", run->total,
        "frames", run->total, "localize_fps",
        vf_json_number(
            run->localize_seconds > 0 ? (run->total - run->blurry) / run->localize_seconds : 0.0),
        "mode", run->object_mode ? "object" : "scene");
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
    json_array_foreach(frames, i, row)
    {
        json_t *v = json_object_get(row, "viewpoint");
        vf_csv_text(f, json_string_value(json_object_get(row, "frame")));
        vf_csv_next(f, json_string_value(json_object_get(row, "status")));
        for (int k = 0; k < 6; k++)
            if (v)
                fprintf(f, ",%.6g", json_number_value(json_array_get(v, (size_t)k)));
            else
                fputc(',', f);
        json_t *cls = json_object_get(row, "class");
        if (cls) {
            fprintf(f, ",%lld", json_integer_value(cls));
            vf_csv_next(f, json_string_value(json_object_get(row, "class_name")));
            fprintf(f, ",%d\n", json_is_true(json_object_get(row, "fooled")));
        } else {
            fprintf(f, ",,,\n");
        }
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
    if (status == VF_OK &&
        (status = vf_path_join(path, sizeof path, stage.dir, "frames.csv")) == VF_OK)
        status = write_frames_csv(path, run->frames);
    if (status == VF_OK && run->sheet_count > 0 &&
        (status = vf_path_join(path, sizeof path, stage.dir, "sheet.png")) == VF_OK)
        status = vf_contact_sheet(path, run->sheet, (const char *const *)run->caption,
                                  run->fooled, run->sheet_count, 6);
    if (status == VF_OK)
        status = vf_stage_commit(&stage,
                                 json_pack("{s:o, s:s}", "tolerance_percent",
                                           vf_json_number(100 * run->opt->tolerance), "center",
                                           run->center_name),
                                 json_deep_copy(result));
    else
        vf_stage_abort(&stage);
    return status;
}

void vf_score_defaults(vf_score_options *o)
{
    *o = (vf_score_options){.tolerance = 0.05, .target = -1, .blur_ratio = 0.3};
    vf_localize_defaults(&o->loc);
}

vf_status vf_score_run(vf_workspace *ws, char *const *inputs, int input_count,
                       const vf_score_options *o, json_t **out)
{
    score_run run = {.opt = o,
                     .root = ws->root,
                     .inputs = inputs,
                     .input_count = input_count,
                     .frames = json_array()};
    *out = NULL;
    vf_status status = input_count > 0 ? VF_OK : vf_fail(VF_EINPUT, "no frames to score");
    if (status == VF_OK && !(o->tolerance > 0 && o->tolerance <= 1))
        status =
            vf_fail(VF_EINPUT, "the tolerance must be a share in (0, 1], not %g", o->tolerance);
    if (status == VF_OK)
        status = vf_attack_file_load_workspace(ws, vf_export_attack(ws), &run.attack);
    run.center = run.attack.v_star;
    snprintf(run.center_name, sizeof run.center_name, "v*");
    if (status == VF_OK && o->target >= 0) {
        status = vf_targets_workspace_target(ws->root, o->target, &run.center, NULL);
        snprintf(run.center_name, sizeof run.center_name, "target %d", o->target);
    }
    if (status == VF_OK)
        status = open_classifier(&run);
    if (status == VF_OK)
        status = vf_localizer_open(ws, &o->loc, &run.loc);
    if (status == VF_OK)
        status = open_object_mode(&run, ws);
    if (status == VF_OK)
        status = measure_sharpness(&run);
    if (status == VF_OK)
        status = score_frames(&run);
    if (status == VF_OK && run.kept.frames == 0) /* a failed measurement: nothing committed */
        status = vf_fail(VF_EINPUT,
                         "no measurement: none of the %d frames is within %g%% of %s (%d blurry, "
                         "%d not localized, %d out of tolerance); re-shoot nearer it ('vfcapture "
                         "reshoot') or widen --tolerance",
                         run.total, 100 * o->tolerance, run.center_name, run.blurry,
                         run.not_localized, run.out_of_tolerance);
    if (status == VF_OK) {
        *out = result_json(&run);
        status = save_results(ws, &run, *out);
        if (status != VF_OK) {
            json_decref(*out);
            *out = NULL;
        }
    }
    vf_localizer_close(run.loc);
    vf_field_free(run.field);
    vf_classifier_close(run.cls);
    vf_attack_file_free(&run.attack);
    json_decref(run.frames);
    for (int i = 0; i < run.sheet_count; i++) {
        vf_image_free(&run.sheet[i]);
        free(run.caption[i]);
    }
    return status;
}
/* ---- reading score.json ---- */

vf_status vf_score_load(const vf_workspace *ws, json_t **doc)
{
    *doc = NULL;
    char path[VF_PATH_MAX];
    double center[VF_VIEW_DIM];
    vf_status status = vf_workspace_need(ws, "score");
    if (status == VF_OK)
        status = vf_workspace_path(ws, "score", "score.json", path, sizeof path);
    if (status == VF_OK)
        status = vf_json_load(path, doc);
    if (status == VF_OK &&
        (!vf_json_read_doubles(json_object_get(*doc, "center_viewpoint"), center, VF_VIEW_DIM) ||
         !(json_number_value(json_object_get(*doc, "tolerance_percent")) > 0) ||
         !json_is_object(json_object_get(*doc, "kept")) ||
         !json_is_array(json_object_get(*doc, "frames_detail"))))
        status = vf_fail(VF_EINPUT, "%s is not what score writes (center_viewpoint, "
                                    "tolerance_percent, kept, frames_detail)",
                         path);
    if (status != VF_OK) {
        json_decref(*doc);
        *doc = NULL;
    }
    return status;
}

/* ---- the summary across workspaces ---- */

static double nan_to(double x) { return isnan(x) ? -1 : x; }

/* One workspace: the attack's rendered rates, the object's (a 3D model's `real`) and the
 * physical ones (`score`); at least one of the last two must be there. */
static vf_status summary_row(const char *root, json_t *rows)
{
    vf_attack_file a = {0};
    vf_real_rates real = {NAN, NAN, NAN};
    json_t *score = NULL;
    vf_workspace ws;
    int has_real = 0;
    vf_status status = vf_workspace_open(root, 0, &ws);
    if (status != VF_OK)
        return status;
    status = vf_attack_file_load_workspace(&ws, vf_export_attack(&ws), &a);
    if (status == VF_OK)
        status = vf_real_load_rates(&ws, a.stage, &real, &has_real);
    if (status == VF_OK && vf_workspace_has_stage(&ws, "score"))
        status = vf_score_load(&ws, &score);
    if (status == VF_OK && !score && !has_real)
        status = vf_fail(VF_EINPUT,
                         "%s has no score (run 'vfcapture score %s VIDEO') and no "
                         "real check (a 3D model: 'vfcapture real %s')",
                         root, root, root);
    vf_workspace_close(&ws);
    if (status == VF_OK) {
        char name[256];
        vf_path_basename(name, sizeof name, root, 0);
        json_t *kept = json_object_get(score, "kept");
        json_t *row =
            json_pack("{s:s, s:s, s:o, s:o, s:o, s:o, s:o, s:o}", "object", name, "label",
                      a.label_text, "natural_accuracy", vf_json_number(nan_to(a.natural_accuracy)),
                      "asr_v_star", vf_json_number(nan_to(a.asr_v_star)), "asr_samples",
                      vf_json_number(nan_to(a.asr_samples)), "real_natural_accuracy",
                      vf_json_number(nan_to(real.natural_accuracy)), "real_asr_v_star",
                      vf_json_number(nan_to(real.asr_v_star)), "real_asr_samples",
                      vf_json_number(nan_to(real.asr_samples)));
        if (json_integer_value(json_object_get(kept, "frames")) > 0)
            json_object_update_new(row,
                                   json_pack("{s:O, s:O, s:O, s:O}", "physical_asr",
                                             json_object_get(kept, "asr"), "interval95",
                                             json_object_get(kept, "interval95"), "misclassified",
                                             json_object_get(kept, "misclassified"), "frames_used",
                                             json_object_get(kept, "frames")));
        json_array_append_new(rows, row);
    }
    vf_attack_file_free(&a);
    json_decref(score);
    return status;
}

vf_status vf_score_summary(char *const *workspaces, int count, json_t **rows)
{
    *rows = json_array();
    vf_status status = VF_OK;
    for (int i = 0; status == VF_OK && i < count; i++)
        status = summary_row(workspaces[i], *rows);
    if (status != VF_OK) {
        json_decref(*rows);
        *rows = NULL;
    }
    return status;
}
