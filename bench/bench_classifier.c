/* Classifier speed: forward() at batch 1 and 16 for each engine and each model, side by side in
 * one run, then preprocessing.
 *
 *   bench_classifier [--models-dir DIR] [MODEL ...]
 *
 * MODEL is a name or path; without any, every model vf_model_list finds (DIR, $VF_MODELS_DIR,
 * the per-user folder, the shared one). Each figure is the median of several runs after two
 * warm-up runs, capped at about 10 s of running per figure, so a ViT-B/16 gets fewer runs than a
 * MobileNet. A model an engine cannot load gets that engine's one-line reason.
 *
 * When NAME.input.bin and NAME.expected.bin lie beside NAME.onnx (bench/torchvision_models.py
 * writes PyTorch's logits there), the last column is max |logits - PyTorch's| / max |PyTorch's|. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/classifier.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/stats.h"

#define MAX_MODELS 64

/* Median seconds per image of forward() on a batch of n (at most `runs` runs, ~10 s); 0 when it
 * fails. */
static double time_forward(vf_classifier *cls, const float *input, int n, int runs)
{
    float *probs = malloc((size_t)n * VF_NUM_CLASSES * sizeof(float));
    double seconds[32], start = vf_now();
    int done = 0;
    /* warm-up: the first runs allocate */
    int ok = vf_classifier_forward(cls, input, n, probs) == VF_OK &&
             vf_classifier_forward(cls, input, n, probs) == VF_OK;
    double budget = 10.0 + (vf_now() - start);
    for (start = vf_now(); ok && done < runs && (done < 3 || vf_now() - start < budget); done++) {
        double t = vf_now();
        ok = vf_classifier_forward(cls, input, n, probs) == VF_OK;
        seconds[done] = (vf_now() - t) / n;
    }
    free(probs);
    return ok ? vf_median(seconds, done) : 0;
}

/* Median seconds of one vf_classifier_preprocess() call on img. */
static double time_preprocess(const vf_image *img, int size, float *out)
{
    double seconds[15];
    vf_classifier_preprocess(img, size, out);
    for (int r = 0; r < 15; r++) {
        double start = vf_now();
        vf_classifier_preprocess(img, size, out);
        seconds[r] = vf_now() - start;
    }
    return vf_median(seconds, 15);
}

/* Read a float32 file beside the model (NAME.onnx -> NAME<suffix>); NULL when absent. */
static float *read_beside(const char *model, const char *suffix, size_t *count)
{
    char path[VF_PATH_MAX], *data;
    size_t size, len = strlen(model);
    snprintf(path, sizeof path, "%.*s%s", (int)(len > 5 ? len - 5 : len), model, suffix);
    if (!vf_is_file(path) || vf_read_file(path, &data, &size) != VF_OK)
        return NULL;
    *count = size / sizeof(float);
    return (float *)data;
}

/* The relative error against the reference logits beside the model, or -1 when there are none
 * (or they do not fit the model). */
static double reference_error(vf_classifier *cls, const char *model)
{
    size_t inputs = 0, outputs = 0;
    float *input = read_beside(model, ".input.bin", &inputs);
    float *want = read_beside(model, ".expected.bin", &outputs);
    int size = vf_classifier_input_size(cls), n = (int)(outputs / VF_NUM_CLASSES);
    double error = -1;
    float *got = n > 0 ? malloc(outputs * sizeof(float)) : NULL;
    if (input && want && got && inputs == (size_t)n * 3 * size * size &&
        vf_classifier_logits(cls, input, n, got) == VF_OK) {
        double diff = 0, scale = 0;
        for (size_t i = 0; i < outputs; i++) {
            diff = fmax(diff, fabs((double)got[i] - want[i]));
            scale = fmax(scale, fabs((double)want[i]));
        }
        error = scale > 0 ? diff / scale : diff;
    }
    free(got);
    free(input);
    free(want);
    return error;
}

/* One row: model, engine, input, load time, ms/img at batch 1 and 16. */
static void bench_model(const char *path, vf_engine engine, const vf_image *photo)
{
    char name[128];
    vf_path_basename(name, sizeof name, path, 1);
    vf_classifier *cls;
    double start = vf_now();
    if (vf_classifier_open_with(path, engine, &cls) != VF_OK) {
        printf("%-34s %-18s fails: %.150s\n", name, vf_engine_name(engine), vf_error_message());
        fflush(stdout);
        return;
    }
    double load = vf_now() - start;
    int size = vf_classifier_input_size(cls);
    size_t plane = 3 * (size_t)size * (size_t)size;
    float *batch = malloc(16 * plane * sizeof(float));
    for (int i = 0; i < 16; i++)
        vf_classifier_preprocess(photo, size, batch + i * plane);
    double b1 = time_forward(cls, batch, 1, 15);
    double b16 = time_forward(cls, batch, 16, 5);
    double error = reference_error(cls, path);
    char vs[32] = "-";
    if (error >= 0)
        snprintf(vs, sizeof vs, "%.1e", error);
    printf("%-34s %-18s %5d %8.2f %10.2f %10.2f %10s\n", name, vf_classifier_engine(cls), size,
           load, 1e3 * b1, 1e3 * b16, vs);
    fflush(stdout);
    free(batch);
    vf_classifier_close(cls);
}

int main(int argc, char **argv)
{
    const char *models_dir = NULL;
    static char paths[MAX_MODELS][VF_PATH_MAX];
    int count = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--models-dir") && i + 1 < argc) {
            models_dir = argv[++i];
        } else if (count < MAX_MODELS) {
            if (vf_find_model(argv[i], models_dir, paths[count], VF_PATH_MAX) != VF_OK) {
                fprintf(stderr, "bench_classifier: %s\n", vf_error_message());
                return 1;
            }
            count++;
        }
    }
    if (count == 0)
        count = vf_model_list(models_dir, paths, MAX_MODELS);
    count = count < MAX_MODELS ? count : MAX_MODELS;

    vf_image img, big;
    char photo[VF_PATH_MAX];
    vf_shared_path("data/imagenet_samples/000_n01440764.jpg", photo, sizeof photo);
    if (vf_image_load_rgb(photo, (const float[3]){1, 1, 1}, &img) != VF_OK ||
        vf_image_resize(&img, 1920, 1440, &big) != VF_OK) {
        fprintf(stderr, "bench_classifier: %s\n", vf_error_message());
        return 1;
    }
    int ort = vf_engine_check(VF_ENGINE_ONNXRUNTIME) == VF_OK;
    if (!ort)
        printf("(onnxruntime: %s)\n", vf_error_message());
    printf("%-34s %-18s %5s %8s %10s %10s %10s\n", "model", "engine", "input", "load s",
           "ms/img b1", "ms/img b16", "vs torch");
    for (int m = 0; m < count; m++) {
        bench_model(paths[m], VF_ENGINE_OPENCV, &img);
        if (ort)
            bench_model(paths[m], VF_ENGINE_ONNXRUNTIME, &img);
    }

    size_t plane = 3 * 224 * 224;
    float *out = malloc(plane * sizeof(float));
    printf("\npreprocess %dx%d photo to 224:  %6.2f ms/image\n", img.width, img.height,
           1e3 * time_preprocess(&img, 224, out));
    printf("preprocess %dx%d image to 224: %6.2f ms/image\n", big.width, big.height,
           1e3 * time_preprocess(&big, 224, out));
    free(out);
    vf_image_free(&big);
    vf_image_free(&img);
    return 0;
}
