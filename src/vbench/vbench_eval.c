/* Evaluating classifiers on a built viewpoint benchmark: top-1 accuracy per model, object and
 * split, counting a top-1 inside the object's label set as correct. */
#define _GNU_SOURCE
#include <stdlib.h>
#include <string.h>

#include <jansson.h>

#include "vf/classifier.h"
#include "vf/image.h"
#include "vf/log.h"
#include "vf/vbench.h"
#include "vf/workspace.h"

#define EVAL_CHUNK 16

typedef struct vbench_set {
    int object_count, image_count;
    char **object_names;
    int *label_count;                 /* per object */
    int (*labels)[VF_MAX_LABELS];        /* per object */
    char **files;                     /* per image, full paths */
    int *object;                      /* per image */
    vf_vbench_split *split;           /* per image */
} vbench_set;

static void set_free(vbench_set *s)
{
    for (int i = 0; i < s->image_count; i++)
        free(s->files[i]);
    free(s->files);
    free(s->object);
    free(s->split);
    free(s->label_count);
    free(s->labels);
    /* object_names are handed to the results */
    memset(s, 0, sizeof *s);
}

static vf_status read_objects(const json_t *objects, const char *index_path, vbench_set *s)
{
    s->object_count = (int)json_array_size(objects);
    s->object_names = calloc((size_t)s->object_count, sizeof *s->object_names);
    s->label_count = calloc((size_t)s->object_count, sizeof *s->label_count);
    s->labels = calloc((size_t)s->object_count, sizeof *s->labels);
    if (!s->object_names || !s->label_count || !s->labels)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int o = 0; o < s->object_count; o++) {
        const json_t *obj = json_array_get(objects, (size_t)o);
        const json_t *indices = json_object_get(json_object_get(obj, "label"), "indices");
        const char *name = json_string_value(json_object_get(obj, "name"));
        if (!name || !json_is_array(indices) || json_array_size(indices) == 0 ||
            json_array_size(indices) > VF_MAX_LABELS)
            return vf_fail(VF_EINPUT, "%s: object %d has no name or label indices", index_path, o);
        s->object_names[o] = strdup(name);
        s->label_count[o] = (int)json_array_size(indices);
        for (int k = 0; k < s->label_count[o]; k++)
            s->labels[o][k] = (int)json_integer_value(json_array_get(indices, (size_t)k));
    }
    return VF_OK;
}

static vf_status read_images(const json_t *images, const char *dir, const char *index_path,
                             vbench_set *s)
{
    s->image_count = (int)json_array_size(images);
    s->files = calloc((size_t)s->image_count, sizeof *s->files);
    s->object = calloc((size_t)s->image_count, sizeof *s->object);
    s->split = calloc((size_t)s->image_count, sizeof *s->split);
    if (!s->files || !s->object || !s->split)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; i < s->image_count; i++) {
        const json_t *img = json_array_get(images, (size_t)i);
        const char *file = json_string_value(json_object_get(img, "file"));
        const char *split = json_string_value(json_object_get(img, "split"));
        json_int_t object = json_integer_value(json_object_get(img, "object"));
        if (!file || !split || object < 0 || object >= s->object_count)
            return vf_fail(VF_EINPUT, "%s: image %d lacks a file, split or object", index_path, i);
        if (asprintf(&s->files[i], "%s/%s", dir, file) < 0)
            return vf_fail(VF_EINTERNAL, "out of memory");
        s->object[i] = (int)object;
        s->split[i] = strcmp(split, "natural") ? VF_VBENCH_ADVERSARIAL : VF_VBENCH_NATURAL;
    }
    return VF_OK;
}

static vf_status load_set(const char *dir, vbench_set *s)
{
    char path[VF_PATH_MAX];
    json_t *doc = NULL;
    vf_status status = vf_path_join(path, sizeof path, dir, "index.json");
    if (status == VF_OK && !vf_is_file(path))
        status = vf_fail(VF_EINPUT, "%s is not a benchmark set (no index.json): make one with "
                                    "'vfcapture benchmark build'", dir);
    if (status == VF_OK)
        status = vf_json_load(path, &doc);
    if (status == VF_OK)
        status = read_objects(json_object_get(doc, "objects"), path, s);
    if (status == VF_OK)
        status = read_images(json_object_get(doc, "images"), dir, path, s);
    if (status == VF_OK && (s->object_count == 0 || s->image_count == 0))
        status = vf_fail(VF_EINPUT, "%s lists no objects or no images", path);
    json_decref(doc);
    return status;
}

static int is_correct(const vbench_set *s, int image, int top1)
{
    int o = s->object[image];
    return vf_label_set_contains(s->labels[o], s->label_count[o], top1);
}

/* Rows of one model: objects x splits, then the all-objects row of each split. */
static vf_vbench_row *model_row(vf_vbench_results *r, int model, int object, vf_vbench_split split)
{
    int per_model = (r->object_count + 1) * 2;
    int o = object < 0 ? r->object_count : object;
    return &r->rows[model * per_model + o * 2 + (int)split];
}

static vf_status eval_model(const vbench_set *s, int model, vf_vbench_results *r,
                            vf_progress *progress, size_t *done)
{
    vf_classifier *cls;
    vf_status status = vf_classifier_open(r->models[model], &cls);
    if (status != VF_OK)
        return status;
    r->engines[model] = strdup(vf_classifier_engine(cls));
    static const float white[3] = {1, 1, 1};
    float *probs = malloc((size_t)EVAL_CHUNK * VF_NUM_CLASSES * sizeof *probs);
    if (!probs)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    for (int first = 0; first < s->image_count && status == VF_OK; first += EVAL_CHUNK) {
        int n = s->image_count - first < EVAL_CHUNK ? s->image_count - first : EVAL_CHUNK;
        vf_image images[EVAL_CHUNK] = {{0}};
        for (int i = 0; i < n && status == VF_OK; i++)
            status = vf_image_load_rgb(s->files[first + i], white, &images[i]);
        if (status == VF_OK)
            status = vf_classifier_classify_images(cls, images, n, probs);
        for (int i = 0; i < n && status == VF_OK; i++) {
            int top1;
            vf_topk(probs + (size_t)i * VF_NUM_CLASSES, 1, &top1, NULL);
            int image = first + i, right = is_correct(s, image, top1);
            vf_vbench_row *row = model_row(r, model, s->object[image], s->split[image]);
            vf_vbench_row *all = model_row(r, model, -1, s->split[image]);
            row->correct += right;
            all->correct += right;
            row->total++;
            all->total++;
        }
        for (int i = 0; i < n; i++)
            vf_image_free(&images[i]);
        *done += (size_t)n;
        vf_progress_update(progress, *done, NULL);
    }
    free(probs);
    vf_classifier_close(cls);
    return status;
}

vf_status vf_vbench_eval(const char *dir, const char *const *model_paths, int model_count,
                         vf_vbench_results *out)
{
    memset(out, 0, sizeof *out);
    vbench_set set = {0};
    vf_status status = load_set(dir, &set);
    out->object_count = set.object_count;
    out->objects = set.object_names;
    if (status != VF_OK) {
        set_free(&set);
        vf_vbench_results_free(out);
        return status;
    }
    out->model_count = model_count;
    out->models = calloc((size_t)model_count, sizeof *out->models);
    out->engines = calloc((size_t)model_count, sizeof *out->engines);
    out->row_count = model_count * (set.object_count + 1) * 2;
    out->rows = calloc((size_t)out->row_count, sizeof *out->rows);
    if (!out->models || !out->engines || !out->rows)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    for (int m = 0; m < model_count && status == VF_OK; m++) {
        out->models[m] = strdup(model_paths[m]);
        for (int o = -1; o < set.object_count; o++)
            for (int split = 0; split < 2; split++) {
                vf_vbench_row *row = model_row(out, m, o, (vf_vbench_split)split);
                row->model = m;
                row->object = o;
                row->split = (vf_vbench_split)split;
            }
    }
    vf_progress progress;
    size_t done = 0;
    vf_progress_begin(&progress, "classifying", (size_t)model_count * set.image_count, "images");
    for (int m = 0; m < model_count && status == VF_OK; m++)
        status = eval_model(&set, m, out, &progress, &done);
    if (status == VF_OK)
        vf_progress_end(&progress);
    set_free(&set);
    if (status != VF_OK)
        vf_vbench_results_free(out);
    return status;
}

void vf_vbench_results_free(vf_vbench_results *r)
{
    for (int i = 0; r->models && i < r->model_count; i++)
        free(r->models[i]);
    for (int i = 0; r->engines && i < r->model_count; i++)
        free(r->engines[i]);
    free(r->engines);
    for (int i = 0; r->objects && i < r->object_count; i++)
        free(r->objects[i]);
    free(r->models);
    free(r->objects);
    free(r->rows);
    memset(r, 0, sizeof *r);
}
