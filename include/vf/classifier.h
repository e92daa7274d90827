/* vf/classifier.h: ImageNet-1k classifiers and their class names.
 *
 * A vf_classifier is an ONNX model with one image input (RGB, ImageNet mean/std, float; NCHW
 * [N,3,S,S] or NHWC [N,S,S,3]) and output [N,1000] logits, run on the CPU on every core by one
 * of two engines:
 *
 *   onnxruntime  ONNX Runtime (the npm package onnxruntime-node, installed by scripts/setup.sh),
 *                run in a worker process of ours that the library talks to over a socket. It
 *                runs what torch.onnx.export writes: CNNs and transformers (ViT, Swin, ...).
 *   opencv       OpenCV 4.6's dnn module, in process; needs nothing more, but refuses many
 *                exports (Identity on weights, broadcast Mul, Mod, LayerNorm as Div ...).
 *
 * The default, "auto", is onnxruntime when it is installed, else opencv. The usual use is
 *
 *     vf_classifier *cls;
 *     vf_classifier_open(path, &cls);                     // path from vf_find_model()
 *     vf_classifier_classify_images(cls, images, n, probs); // probs: n * VF_NUM_CLASSES
 *     vf_topk(probs + i * VF_NUM_CLASSES, 5, idx, p);
 *     vf_classifier_close(cls);
 *
 * Threads: one vf_classifier may be used by one thread at a time (OpenCV's Net is not
 * re-entrant, and an onnxruntime worker answers one batch at a time); it parallelises
 * internally. Open one per thread to run several at once (each onnxruntime one is a process:
 * about 0.3 s to start for a MobileNet, 2 s for a ViT-B/16).
 * Everything else here (preprocess, top-k, class names once loaded) is thread-safe.
 *
 * Memory: the caller owns every buffer it passes in; a vf_classifier is freed with
 * vf_classifier_close(). Class names are loaded once into library-owned storage. */
#ifndef VF_CLASSIFIER_H
#define VF_CLASSIFIER_H

#include "vf/error.h"
#include "vf/image.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_NUM_CLASSES 1000
#define VF_MAX_LABELS 32 /* classes in one label set */

typedef struct vf_classifier vf_classifier;

typedef enum vf_engine {
    VF_ENGINE_AUTO,        /* onnxruntime when installed, else opencv */
    VF_ENGINE_ONNXRUNTIME,
    VF_ENGINE_OPENCV,
} vf_engine;

/* "auto", "onnxruntime" (or "ort"), "opencv"; VF_EINPUT naming the choices otherwise. */
vf_status vf_engine_parse(const char *name, vf_engine *out);

/* VF_OK when the engine can be used here; else VF_EINTERNAL saying what is missing and how to
 * install it (onnxruntime needs node and the npm package; opencv and auto always work). */
vf_status vf_engine_check(vf_engine engine);

/* The engine's name ("auto", "onnxruntime", "opencv"). */
const char *vf_engine_name(vf_engine engine);

/* The engine vf_classifier_open uses in this process (a command's --engine). Until set it is
 * $VF_ENGINE when that names one, else auto. */
void vf_classifier_set_engine(vf_engine engine);

/* Load the ONNX model at model_path with the process's engine, find its input size S (from
 * the graph, else from a "_128"-style number in the file name) and check with a zero input
 * that it gives 1000 outputs. VF_EINPUT "model PATH is not an ONNX classifier: ..." when it
 * cannot be used (with the engine's reason, which names the op it could not run). */
vf_status vf_classifier_open(const char *model_path, vf_classifier **out);

/* As vf_classifier_open with a given engine. VF_EINTERNAL when onnxruntime is asked for and is
 * not installed. */
vf_status vf_classifier_open_with(const char *model_path, vf_engine engine, vf_classifier **out);

/* The engine that runs it, with its version: "onnxruntime 1.30.0" or "opencv 4.6.0". Every
 * report that names a model names this too. */
const char *vf_classifier_engine(const vf_classifier *cls);

/* Free the model; NULL is fine. */
void vf_classifier_close(vf_classifier *cls);

/* The side S of the square input the model expects (128, 160, 192, 224, ...). */
int vf_classifier_input_size(const vf_classifier *cls);

/* The model file it was opened from. */
const char *vf_classifier_path(const vf_classifier *cls);

/* Standard ImageNet preprocessing of a 3-channel image for input size S: resize (filtered) so
 * the shorter side is round(S * 256 / 224), centre-crop S x S, subtract the ImageNet mean,
 * divide by the std, and write 3 * S * S floats in CHW order to chw_out. */
vf_status vf_classifier_preprocess(const vf_image *rgb, int size, float *chw_out);

/* Normalise an RGB image that already has the model's input size (a render of the S x S crop)
 * with the ImageNet mean/std, writing 3 * width * height floats in CHW order. */
vf_status vf_classifier_normalize(const vf_image *rgb, float *chw_out);

/* Run n preprocessed inputs (n * 3 * S * S floats, NCHW) and write the model's n *
 * VF_NUM_CLASSES logits to logits_out. */
vf_status vf_classifier_logits(vf_classifier *cls, const float *batch_nchw, int n,
                               float *logits_out);

/* The cross-entropy of a label set from one image's logits z, in double precision:
 *     -log sum_{y in set} softmax(z)_y = logsumexp(z) - logsumexp(z over the set),
 * finite and informative however confident the model is (no probability floor). */
double vf_label_set_cross_entropy(const float *logits, const int *labels, int count);

/* As vf_classifier_logits, then a softmax: n * VF_NUM_CLASSES probabilities in probs_out. */
vf_status vf_classifier_forward(vf_classifier *cls, const float *batch_nchw, int n,
                                float *probs_out);

/* Preprocess n RGB images (in parallel) and run them through the model in batches, writing
 * n * VF_NUM_CLASSES probabilities to probs_out. */
vf_status vf_classifier_classify_images(vf_classifier *cls, const vf_image *images, int n,
                                        float *probs_out);

/* In-place softmax of n logits. */
void vf_softmax(float *values, int n);

/* The k (1..VF_NUM_CLASSES) most probable classes of one probability vector, most probable
 * first: class indices in idx[k] and their probabilities in p[k] (p may be NULL). */
void vf_topk(const float *probs, int k, int *idx, float *p);

/* Load the 1000 class names from <shared>/models/imagenet_classes.txt. Loads once; later calls
 * return VF_OK at once. vf_class_name and vf_parse_label_set load on demand. */
vf_status vf_class_names_load(void);

/* The full name line of class i ("red fox, Vulpes vulpes"), or "?" when i is out of range or
 * the names cannot be loaded. */
const char *vf_class_name(int i);

/* The first synonym of class i ("red fox"), or "?" as above. */
const char *vf_class_short_name(int i);

/* Parse a label set: comma-separated class indices (0..999) and/or class names. A name
 * matches a class when it equals one of the class's synonyms, ignoring case and surrounding
 * spaces ("folding chair", "Vulpes vulpes"). Duplicates are dropped. Writes at most max
 * indices to labels and their number to *count. VF_EINPUT naming the label when it is out of
 * range, unknown, or ambiguous (a synonym of several classes, such as "crane": give the index). */
vf_status vf_parse_label_set(const char *text, int *labels, int max, int *count);

/* Whether class cls is one of the count labels: the top-1 is correct when it is. */
int vf_label_set_contains(const int *labels, int count, int cls);

#ifdef __cplusplus
}
#endif
#endif
