/* The plain-C half of vf/classifier.h: choosing the engine, preprocessing, softmax, top-k,
 * class names and label sets. The network itself runs in onnxruntime/classifier_ort.c (a
 * worker process) or classifier_dnn.cpp. */
#define _GNU_SOURCE /* strdup, strtok_r, strncasecmp */
#include "vf/classifier.h"

#include <ctype.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "classifier_dnn.h"
#include "classifier_ort.h"
#include "onnx_shape.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/resources.h"

/* Inputs per forward call in vf_classifier_classify_images. */
#define CLASSIFY_BATCH 16

static const float imagenet_mean[3] = {0.485f, 0.456f, 0.406f};
static const float imagenet_std[3] = {0.229f, 0.224f, 0.225f};

struct vf_classifier {
    vf_ort *ort; /* exactly one of ort and dnn is set */
    vf_dnn *dnn;
    int input_size;
    char engine[48];
    char path[VF_PATH_MAX];
};

/* ---- the engine ---- */

static const char *const engine_names[] = {"auto", "onnxruntime", "opencv"};
static int engine_chosen = -1; /* -1: not set; then $VF_ENGINE, else auto */

vf_status vf_engine_parse(const char *name, vf_engine *out)
{
    for (int e = 0; e < 3; e++)
        if (!strcasecmp(name, engine_names[e])) {
            *out = (vf_engine)e;
            return VF_OK;
        }
    if (!strcasecmp(name, "ort")) {
        *out = VF_ENGINE_ONNXRUNTIME;
        return VF_OK;
    }
    return vf_fail(VF_EINPUT, "unknown classifier engine '%s' (auto, onnxruntime or opencv)",
                   name);
}

vf_status vf_engine_check(vf_engine engine)
{
    return engine == VF_ENGINE_ONNXRUNTIME ? vf_ort_available() : VF_OK;
}

const char *vf_engine_name(vf_engine engine)
{
    return (unsigned)engine < 3 ? engine_names[engine] : "?";
}

void vf_classifier_set_engine(vf_engine engine) { engine_chosen = (int)engine; }

static vf_status default_engine(vf_engine *out)
{
    if (engine_chosen >= 0) {
        *out = (vf_engine)engine_chosen;
        return VF_OK;
    }
    const char *env = getenv("VF_ENGINE");
    if (!env || !*env) {
        *out = VF_ENGINE_AUTO;
        return VF_OK;
    }
    vf_status status = vf_engine_parse(env, out);
    if (status != VF_OK)
        vf_error_prefix("VF_ENGINE");
    return status;
}

/* ---- opening a model ---- */

/* S from the graph input [N,3,S,S] (or [N,S,S,3], then *nhwc is set); 0 when the file does
 * not say. */
static int input_size_from_graph(const char *path, int *nhwc)
{
    char *data;
    size_t size;
    *nhwc = 0;
    if (vf_read_file(path, &data, &size) != VF_OK)
        return 0;
    long long dims[4];
    int n = vf_onnx_input_dims((const unsigned char *)data, size, dims, 4);
    free(data);
    if (n != 4)
        return 0;
    *nhwc = dims[3] == 3 && dims[1] != 3;
    long long h = *nhwc ? dims[1] : dims[2], w = *nhwc ? dims[2] : dims[3];
    return h == w && h > 0 && h <= 4096 ? (int)h : 0;
}

/* S from a "_<digits>" part of the file name (mobilenet_v1_0.25_128_quant.onnx); 0 when none. */
static int input_size_from_name(const char *path)
{
    char name[VF_PATH_MAX];
    vf_path_basename(name, sizeof name, path, 1);
    int found = 0;
    for (const char *p = strchr(name, '_'); p; p = strchr(p + 1, '_')) {
        char *end;
        long value = strtol(p + 1, &end, 10);
        if (end > p + 1 && (*end == '_' || *end == '\0') && value >= 32 && value <= 1024)
            found = (int)value;
    }
    return found;
}

/* Run the engine's forward pass. */
static vf_status engine_forward(vf_classifier *cls, const float *nchw, int n, float *logits)
{
    return cls->ort ? vf_ort_forward(cls->ort, nchw, n, cls->input_size, logits, VF_NUM_CLASSES)
                    : vf_dnn_forward(cls->dnn, nchw, n, cls->input_size, logits, VF_NUM_CLASSES);
}

vf_status vf_classifier_open(const char *model_path, vf_classifier **out)
{
    vf_engine engine = VF_ENGINE_AUTO;
    vf_status status = default_engine(&engine);
    return status == VF_OK ? vf_classifier_open_with(model_path, engine, out) : status;
}

vf_status vf_classifier_open_with(const char *model_path, vf_engine engine, vf_classifier **out)
{
    if (!vf_is_file(model_path))
        return vf_fail(VF_EINPUT, "model file %s does not exist", model_path);
    if (engine == VF_ENGINE_AUTO) /* onnxruntime when it is installed */
        engine = vf_ort_available() == VF_OK ? VF_ENGINE_ONNXRUNTIME : VF_ENGINE_OPENCV;
    vf_status status = VF_OK;
    vf_classifier *cls = calloc(1, sizeof *cls);
    if (!cls)
        return vf_fail(VF_EINTERNAL, "out of memory");
    snprintf(cls->path, sizeof cls->path, "%s", model_path);
    if (engine == VF_ENGINE_ONNXRUNTIME) {
        status = vf_ort_load(model_path, &cls->ort);
        if (status == VF_OK) {
            snprintf(cls->engine, sizeof cls->engine, "onnxruntime %s", vf_ort_version(cls->ort));
            cls->input_size = vf_ort_input_size(cls->ort);
        }
    } else {
        int nhwc;
        cls->input_size = input_size_from_graph(model_path, &nhwc);
        status = nhwc ? vf_fail(VF_EINPUT,
                                "model %s takes NHWC input [N,S,S,3]; the opencv engine runs NCHW "
                                "models only (use --engine onnxruntime)",
                                model_path)
                      : vf_dnn_load(model_path, &cls->dnn);
        snprintf(cls->engine, sizeof cls->engine, "opencv %s", vf_dnn_version());
    }
    if (status != VF_OK) {
        free(cls);
        return status;
    }
    if (!cls->input_size)
        cls->input_size = input_size_from_name(model_path);
    if (!cls->input_size) {
        cls->input_size = 224;
        vf_warn("model %s does not state its input size; assuming 224", model_path);
    }
    /* Probe with a zero image: it must run and give one score per ImageNet class. */
    size_t plane = (size_t)cls->input_size * (size_t)cls->input_size;
    float *zeros = calloc(3 * plane, sizeof(float));
    float *logits = malloc(VF_NUM_CLASSES * sizeof(float));
    status = zeros && logits ? engine_forward(cls, zeros, 1, logits)
                             : vf_fail(VF_EINTERNAL, "out of memory");
    free(zeros);
    free(logits);
    if (status != VF_OK) {
        if (status == VF_EINPUT)
            vf_error_prefix("model %s is not an ImageNet classifier", model_path);
        vf_classifier_close(cls);
        return status;
    }
    *out = cls;
    return VF_OK;
}

void vf_classifier_close(vf_classifier *cls)
{
    if (!cls)
        return;
    vf_ort_free(cls->ort);
    vf_dnn_free(cls->dnn);
    free(cls);
}

const char *vf_classifier_engine(const vf_classifier *cls) { return cls->engine; }

int vf_classifier_input_size(const vf_classifier *cls) { return cls->input_size; }

const char *vf_classifier_path(const vf_classifier *cls) { return cls->path; }

/* ---- preprocessing and running ---- */

vf_status vf_classifier_normalize(const vf_image *rgb, float *chw_out)
{
    if (rgb->channels != 3)
        return vf_fail(VF_EINPUT, "the classifier needs an RGB image, not %d channels",
                       rgb->channels);
    size_t plane = (size_t)rgb->width * (size_t)rgb->height;
    for (int c = 0; c < 3; c++) {
        float *dst = chw_out + c * plane;
        const float *src = rgb->data + c;
        for (size_t i = 0; i < plane; i++)
            dst[i] = (src[3 * i] - imagenet_mean[c]) / imagenet_std[c];
    }
    return VF_OK;
}

vf_status vf_classifier_preprocess(const vf_image *rgb, int size, float *chw_out)
{
    if (rgb->channels != 3)
        return vf_fail(VF_EINPUT, "the classifier needs an RGB image, not %d channels",
                       rgb->channels);
    /* Shorter side to round(S * 256 / 224); the longer side scaled and truncated as torchvision
     * does, so a 224 model sees a 256-pixel short side. */
    int shorter = (int)lround(size * 256.0 / 224.0);
    int w = rgb->width, h = rgb->height;
    int new_w = w <= h ? shorter : (int)((double)shorter * w / h);
    int new_h = w <= h ? (int)((double)shorter * h / w) : shorter;
    vf_image resized, crop;
    vf_status status = vf_image_resize(rgb, new_w, new_h, &resized);
    if (status != VF_OK)
        return status;
    status = vf_image_center_crop(&resized, size, size, &crop);
    vf_image_free(&resized);
    if (status != VF_OK)
        return status;
    status = vf_classifier_normalize(&crop, chw_out);
    vf_image_free(&crop);
    return status;
}

void vf_softmax(float *values, int n)
{
    float max = values[0];
    for (int i = 1; i < n; i++)
        max = values[i] > max ? values[i] : max;
    double sum = 0;
    for (int i = 0; i < n; i++) {
        values[i] = expf(values[i] - max);
        sum += values[i];
    }
    for (int i = 0; i < n; i++)
        values[i] = (float)(values[i] / sum);
}

vf_status vf_classifier_logits(vf_classifier *cls, const float *batch_nchw, int n,
                               float *logits_out)
{
    if (n <= 0)
        return vf_fail(VF_EINPUT, "nothing to classify (batch of %d)", n);
    vf_status status = engine_forward(cls, batch_nchw, n, logits_out);
    if (status != VF_OK)
        vf_error_prefix("model %s (%s)", cls->path, cls->engine);
    return status;
}

vf_status vf_classifier_forward(vf_classifier *cls, const float *batch_nchw, int n,
                                float *probs_out)
{
    vf_status status = vf_classifier_logits(cls, batch_nchw, n, probs_out);
    for (int i = 0; status == VF_OK && i < n; i++)
        vf_softmax(probs_out + (size_t)i * VF_NUM_CLASSES, VF_NUM_CLASSES);
    return status;
}

/* log sum_i exp(x[idx_i]) (all n when idx is NULL), in double around the largest term. */
static double log_sum_exp(const float *x, const int *idx, int n)
{
    double top = -INFINITY, sum = 0.0;
    for (int i = 0; i < n; i++)
        top = fmax(top, (double)x[idx ? idx[i] : i]);
    for (int i = 0; i < n; i++)
        sum += exp((double)x[idx ? idx[i] : i] - top);
    return top + log(sum);
}

double vf_label_set_cross_entropy(const float *logits, const int *labels, int count)
{
    return log_sum_exp(logits, NULL, VF_NUM_CLASSES) - log_sum_exp(logits, labels, count);
}

/* Preprocess images[0..n) into batch in parallel. Errors happen on worker threads, whose
 * error messages are their own, so the first one is carried back to the caller's thread. */
static vf_status preprocess_batch(const vf_image *images, int first, int n, int size,
                                  float *batch)
{
    size_t stride = 3 * (size_t)size * (size_t)size;
    vf_first_error error = {0};
#pragma omp parallel for schedule(dynamic)
    for (int i = 0; i < n; i++) {
        vf_status s = vf_classifier_preprocess(&images[i], size, batch + (size_t)i * stride);
        if (s != VF_OK)
            vf_error_prefix("image %d", first + i);
        vf_first_error_keep(&error, s);
    }
    return vf_first_error_raise(&error);
}

vf_status vf_classifier_classify_images(vf_classifier *cls, const vf_image *images, int n,
                                        float *probs_out)
{
    int size = cls->input_size;
    int batch_n = n < CLASSIFY_BATCH ? n : CLASSIFY_BATCH;
    float *batch = malloc((size_t)batch_n * 3 * (size_t)size * (size_t)size * sizeof(float));
    if (!batch)
        return vf_fail(VF_EINTERNAL, "out of memory for a batch of %d images", batch_n);
    vf_status status = VF_OK;
    for (int first = 0; first < n && status == VF_OK; first += batch_n) {
        int count = n - first < batch_n ? n - first : batch_n;
        status = preprocess_batch(images + first, first, count, size, batch);
        if (status == VF_OK)
            status = vf_classifier_forward(cls, batch, count,
                                           probs_out + (size_t)first * VF_NUM_CLASSES);
    }
    free(batch);
    return status;
}

void vf_topk(const float *probs, int k, int *idx, float *p)
{
    if (k <= 0)
        return;
    if (k > VF_NUM_CLASSES)
        k = VF_NUM_CLASSES;
    /* Insertion into a sorted list of the best k so far; ties keep the lower index first. */
    int filled = 0;
    for (int c = 0; c < VF_NUM_CLASSES; c++) {
        if (filled == k && probs[c] <= probs[idx[k - 1]])
            continue;
        int j = filled < k ? filled++ : k - 1;
        while (j > 0 && probs[idx[j - 1]] < probs[c]) {
            idx[j] = idx[j - 1];
            j--;
        }
        idx[j] = c;
    }
    for (int i = 0; p && i < k; i++)
        p[i] = probs[idx[i]];
}

/* ---- class names and label sets ---- */

static pthread_mutex_t names_lock = PTHREAD_MUTEX_INITIALIZER;
static int names_ready;
static char *full_names[VF_NUM_CLASSES];  /* lines of one buffer */
static char *short_names[VF_NUM_CLASSES]; /* a copy, cut at the first comma */

/* Split the file text into exactly VF_NUM_CLASSES lines; called with names_lock held. */
static vf_status read_names(void)
{
    char path[VF_PATH_MAX], *text;
    size_t size;
    vf_status status = vf_shared_path("models/imagenet_classes.txt", path, sizeof path);
    if (status == VF_OK)
        status = vf_read_file(path, &text, &size);
    if (status != VF_OK)
        return status;
    int count = 0;
    for (char *line = text, *next; *line && count <= VF_NUM_CLASSES; line = next) {
        next = line + strcspn(line, "\n");
        if (*next)
            *next++ = '\0';
        line[strcspn(line, "\r")] = '\0';
        if (count < VF_NUM_CLASSES)
            full_names[count] = line;
        count++;
    }
    char *copy = count == VF_NUM_CLASSES ? malloc(size + 1) : NULL;
    if (!copy) {
        free(text);
        return count != VF_NUM_CLASSES
                   ? vf_fail(VF_EINPUT, "%s has %d class names, expected %d", path, count,
                             VF_NUM_CLASSES)
                   : vf_fail(VF_EINTERNAL, "out of memory");
    }
    memcpy(copy, text, size + 1);
    for (int i = 0; i < VF_NUM_CLASSES; i++) {
        short_names[i] = copy + (full_names[i] - text);
        short_names[i][strcspn(short_names[i], ",")] = '\0';
    }
    names_ready = 1;
    return VF_OK;
}

vf_status vf_class_names_load(void)
{
    pthread_mutex_lock(&names_lock);
    vf_status status = names_ready ? VF_OK : read_names();
    pthread_mutex_unlock(&names_lock);
    return status;
}

const char *vf_class_name(int i)
{
    if (i < 0 || i >= VF_NUM_CLASSES || vf_class_names_load() != VF_OK)
        return "?";
    return full_names[i];
}

const char *vf_class_short_name(int i)
{
    if (i < 0 || i >= VF_NUM_CLASSES || vf_class_names_load() != VF_OK)
        return "?";
    return short_names[i];
}

/* Does one of the comma-separated synonyms in `names` equal word[0..len), ignoring case? */
static int has_synonym(const char *names, const char *word, size_t len)
{
    while (*names) {
        names += strspn(names, " ");
        size_t n = strcspn(names, ",");
        size_t trimmed = n;
        while (trimmed > 0 && names[trimmed - 1] == ' ')
            trimmed--;
        if (trimmed == len && strncasecmp(names, word, len) == 0)
            return 1;
        names += n + (names[n] == ',');
    }
    return 0;
}

/* The class index a label (index or name, already trimmed) stands for. */
static vf_status lookup_label(const char *label, int *index)
{
    char *end;
    long value = strtol(label, &end, 10);
    if (end != label && *end == '\0') {
        if (value < 0 || value >= VF_NUM_CLASSES)
            return vf_fail(VF_EINPUT, "label %s is out of range (class indices are 0..%d)", label,
                           VF_NUM_CLASSES - 1);
        *index = (int)value;
        return VF_OK;
    }
    int found = -1;
    for (int c = 0; c < VF_NUM_CLASSES; c++) {
        if (!has_synonym(full_names[c], label, strlen(label)))
            continue;
        if (found >= 0)
            return vf_fail(VF_EINPUT,
                           "label '%s' is ambiguous: classes %d (%s) and %d (%s); give the index",
                           label, found, full_names[found], c, full_names[c]);
        found = c;
    }
    if (found < 0)
        return vf_fail(VF_EINPUT,
                       "unknown class '%s' (names are listed in models/imagenet_classes.txt)",
                       label);
    *index = found;
    return VF_OK;
}

/* Strip leading and trailing whitespace in place. */
static char *trim(char *s)
{
    while (isspace((unsigned char)*s))
        s++;
    size_t n = strlen(s);
    while (n > 0 && isspace((unsigned char)s[n - 1]))
        s[--n] = '\0';
    return s;
}

vf_status vf_parse_label_set(const char *text, int *labels, int max, int *count)
{
    vf_status status = vf_class_names_load();
    if (status != VF_OK)
        return status;
    char *copy = strdup(text), *save = NULL;
    if (!copy)
        return vf_fail(VF_EINTERNAL, "out of memory");
    int n = 0;
    for (char *tok = strtok_r(copy, ",", &save); tok && status == VF_OK;
         tok = strtok_r(NULL, ",", &save)) {
        char *label = trim(tok);
        int index = -1, duplicate = 0;
        if (!*label)
            continue;
        status = lookup_label(label, &index);
        for (int i = 0; status == VF_OK && i < n; i++)
            duplicate |= labels[i] == index;
        if (status != VF_OK || duplicate)
            continue;
        if (n == max)
            status = vf_fail(VF_EINPUT, "too many labels in '%s' (at most %d)", text, max);
        else
            labels[n++] = index;
    }
    free(copy);
    if (status == VF_OK && n == 0)
        status = vf_fail(VF_EINPUT, "no class labels in '%s'", text);
    if (status == VF_OK)
        *count = n;
    return status;
}

int vf_label_set_contains(const int *labels, int count, int cls)
{
    for (int i = 0; i < count; i++)
        if (labels[i] == cls)
            return 1;
    return 0;
}
