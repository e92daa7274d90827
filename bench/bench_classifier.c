/* Classifier speed: forward() at batch 1 and 16, and preprocessing, on every core.
 *
 *   bench_classifier [MODEL]     (default mobilenet_v2_1.0_224_quant)
 *
 * Each figure is the median of several runs after a warm-up. */
#include <stdio.h>
#include <stdlib.h>

#include "vf/classifier.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/resources.h"

static int compare_doubles(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static double median(double *values, int n)
{
    qsort(values, (size_t)n, sizeof *values, compare_doubles);
    return n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

static int fail(const char *what)
{
    fprintf(stderr, "bench_classifier: %s: %s\n", what, vf_error_message());
    return 1;
}

/* Median seconds per image of forward() on a batch of n. */
static double time_forward(vf_classifier *cls, const float *input, int n, int runs)
{
    float *probs = malloc((size_t)n * VF_NUM_CLASSES * sizeof(float));
    double seconds[32];
    vf_classifier_forward(cls, input, n, probs); /* warm-up: first run allocates */
    vf_classifier_forward(cls, input, n, probs);
    for (int r = 0; r < runs; r++) {
        double start = vf_now();
        vf_classifier_forward(cls, input, n, probs);
        seconds[r] = (vf_now() - start) / n;
    }
    free(probs);
    return median(seconds, runs);
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
    return median(seconds, 15);
}

int main(int argc, char **argv)
{
    char model[VF_PATH_MAX], photo[VF_PATH_MAX];
    vf_classifier *cls;
    if (vf_find_model(argc > 1 ? argv[1] : NULL, NULL, model, sizeof model) != VF_OK ||
        vf_classifier_open(model, &cls) != VF_OK)
        return fail("model");
    int size = vf_classifier_input_size(cls);
    size_t plane = 3 * (size_t)size * (size_t)size;

    vf_image img, big;
    vf_shared_path("data/imagenet_samples/000_n01440764.jpg", photo, sizeof photo);
    if (vf_image_load_rgb(photo, (const float[3]){1, 1, 1}, &img) != VF_OK ||
        vf_image_resize(&img, 1920, 1440, &big) != VF_OK)
        return fail("image");
    float *batch = malloc(16 * plane * sizeof(float));
    for (int i = 0; i < 16; i++)
        vf_classifier_preprocess(&img, size, batch + i * plane);

    printf("model %s, input %dx%d\n", model, size, size);
    double b1 = time_forward(cls, batch, 1, 15);
    double b16 = time_forward(cls, batch, 16, 5);
    printf("forward batch  1: %6.1f images/s  %6.2f ms/image  (median of 15)\n", 1 / b1, 1e3 * b1);
    printf("forward batch 16: %6.1f images/s  %6.2f ms/image  (median of 5)\n", 1 / b16, 1e3 * b16);
    printf("preprocess %dx%d photo:  %6.2f ms/image\n", img.width, img.height,
           1e3 * time_preprocess(&img, size, batch));
    printf("preprocess %dx%d image: %6.2f ms/image\n", big.width, big.height,
           1e3 * time_preprocess(&big, size, batch));

    /* End to end: 16 large images preprocessed in parallel and classified. */
    vf_image many[16];
    float *probs = malloc(16 * VF_NUM_CLASSES * sizeof(float));
    for (int i = 0; i < 16; i++)
        many[i] = big;
    vf_classifier_classify_images(cls, many, 16, probs);
    double start = vf_now();
    vf_classifier_classify_images(cls, many, 16, probs);
    double each = (vf_now() - start) / 16;
    printf("classify_images, 16 x %dx%d: %6.1f images/s  %6.2f ms/image\n", big.width, big.height,
           1 / each, 1e3 * each);

    free(probs);
    free(batch);
    vf_image_free(&big);
    vf_image_free(&img);
    vf_classifier_close(cls);
    return 0;
}
