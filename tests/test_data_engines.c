/* The classifier engines on the graphs real exports contain: tests/onnx_ops.py builds small
 * random-weight classifiers with the ops OpenCV 4.6 refuses (Identity on weights, broadcast
 * Mul, Mod, LayerNorm, Gelu/Erf, Softmax, batched MatMul, a one-block ViT, an NHWC input, a
 * fixed batch of 1) and their logits computed in numpy. ONNX Runtime must load every one and
 * agree with numpy to 1e-4 relative, and each must run inside ViewFool attack steps on a
 * (briefly trained) chair field. Then the errors: an op no runtime knows, a file that is not a
 * model, and ONNX Runtime missing. */
#define _GNU_SOURCE /* setenv */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/classifier.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/view_loss.h"
#include "vf/viewfool.h"

static const char *graphs_dir;

static float *read_floats(const char *name, const char *suffix, size_t *count)
{
    char path[VF_PATH_MAX], *data;
    size_t size;
    snprintf(path, sizeof path, "%s/%s%s", graphs_dir, name, suffix);
    if (vf_read_file(path, &data, &size) != VF_OK)
        return NULL;
    *count = size / sizeof(float);
    return (float *)data;
}

static vf_classifier *open_graph(const char *name, vf_engine engine)
{
    char path[VF_PATH_MAX];
    snprintf(path, sizeof path, "%s/%s.onnx", graphs_dir, name);
    vf_classifier *cls = NULL;
    return vf_classifier_open_with(path, engine, &cls) == VF_OK ? cls : NULL;
}

/* max |a - b| / max |b| */
static double relative_error(const float *a, const float *b, size_t n)
{
    double diff = 0, scale = 0;
    for (size_t i = 0; i < n; i++) {
        diff = fmax(diff, fabs((double)a[i] - b[i]));
        scale = fmax(scale, fabs((double)b[i]));
    }
    return scale > 0 ? diff / scale : diff;
}

/* Each graph: ONNX Runtime loads it and reproduces numpy's logits; say what OpenCV does. */
static void test_graphs(void)
{
    char list[VF_PATH_MAX], *text;
    snprintf(list, sizeof list, "%s/models.txt", graphs_dir);
    if (vf_read_file(list, &text, NULL) != VF_OK) {
        CHECK(0, "no graphs: %s", vf_error_message());
        return;
    }
    int graphs = 0, opencv_loads = 0;
    char *save = NULL;
    for (char *line = strtok_r(text, "\n", &save); line; line = strtok_r(NULL, "\n", &save)) {
        char name[64], layout[8];
        int n, size;
        if (sscanf(line, "%63s %d %7s %d", name, &n, layout, &size) != 4)
            continue;
        graphs++;
        size_t inputs = 0, expected = 0;
        float *input = read_floats(name, ".input.bin", &inputs);
        float *want = read_floats(name, ".expected.bin", &expected);
        vf_classifier *cls = open_graph(name, VF_ENGINE_ONNXRUNTIME);
        CHECK(cls, "onnxruntime cannot load %s: %s", name, vf_error_message());
        CHECK(input && want && expected == (size_t)n * VF_NUM_CLASSES, "%s: reference files",
              name);
        if (cls && input && want) {
            CHECK(vf_classifier_input_size(cls) == size, "%s: input size %d, graph says %d", name,
                  vf_classifier_input_size(cls), size);
            /* The library takes NCHW; an NHWC model's reference input is turned back here. */
            float *nchw = malloc(inputs * sizeof(float));
            size_t plane = (size_t)size * size;
            for (int i = 0; i < n; i++)
                for (size_t p = 0; p < plane; p++)
                    for (int c = 0; c < 3; c++) {
                        size_t from = strcmp(layout, "nhwc") ? (i * 3 + c) * plane + p
                                                              : (i * plane + p) * 3 + c;
                        nchw[(i * 3 + c) * plane + p] = input[from];
                    }
            /* A fixed-batch model gets a batch of 3 copies, which the engine runs one by one. */
            int batch = n == 1 ? 3 : n;
            float *in = malloc((size_t)batch * 3 * plane * sizeof(float));
            for (int i = 0; i < batch; i++)
                memcpy(in + i * 3 * plane, nchw + (i % n) * 3 * plane, 3 * plane * sizeof(float));
            float *got = malloc((size_t)batch * VF_NUM_CLASSES * sizeof(float));
            vf_status s = vf_classifier_logits(cls, in, batch, got);
            CHECK(s == VF_OK, "%s: running: %s", name, vf_error_message());
            double worst = 0;
            for (int i = 0; s == VF_OK && i < batch; i++)
                worst = fmax(worst, relative_error(got + i * VF_NUM_CLASSES,
                                                   want + (i % n) * VF_NUM_CLASSES,
                                                   VF_NUM_CLASSES));
            CHECK(s == VF_OK && worst <= 1e-4, "%s: logits differ from numpy by %.2g relative",
                  name, worst);
            printf("%-18s onnxruntime: %.1e relative to numpy", name, worst);
            free(got);
            free(in);
            free(nchw);
        }
        vf_classifier_close(cls);
        vf_classifier *cv = open_graph(name, VF_ENGINE_OPENCV);
        printf("; opencv: %s\n", cv ? "loads" : vf_error_message());
        opencv_loads += cv != NULL;
        vf_classifier_close(cv);
        free(input);
        free(want);
    }
    free(text);
    CHECK(graphs == 9, "%d graphs listed", graphs);
    printf("opencv loads %d of %d graphs\n", opencv_loads, graphs);
}

/* Two NES steps of the attack on one field with the given graph as the classifier. */
static void attack_steps(const vf_field *field, const char *name)
{
    vf_classifier *cls = open_graph(name, VF_ENGINE_ONNXRUNTIME);
    vf_view_loss *vl = NULL;
    int label = 559; /* folding chair */
    CHECK(cls && vf_view_loss_create(field, cls, &vl) == VF_OK &&
              vf_view_loss_set_labels(vl, &label, 1) == VF_OK,
          "%s: setting up: %s", name, vf_error_message());
    if (vl) {
        vf_attack_config cfg;
        vf_attack_config_default(&cfg, VF_ATTACK_NES);
        cfg.samples = 4;
        cfg.steps = 2;
        vf_attack_state state;
        vf_status s = vf_attack_init(&state, &cfg);
        double mu0 = s == VF_OK ? state.mu[0][0] : 0;
        for (int step = 0; step < 2 && s == VF_OK; step++)
            s = vf_attack_step(&state, &cfg, vf_view_loss_fn, vl);
        CHECK(s == VF_OK, "%s: attack steps: %s", name, vf_error_message());
        CHECK(s == VF_OK && state.step == 2 && isfinite(state.history[1].mean_loss) &&
                  state.mu[0][0] != mu0,
              "%s: the steps did not move the distribution", name);
        vf_view_loss_stats stats = vf_view_loss_get_stats(vl);
        CHECK(stats.views >= 8, "%s: %d views classified", name, (int)stats.views);
        vf_attack_state_free(&state);
    }
    vf_view_loss_free(vl);
    vf_classifier_close(cls);
}

/* Every graph serves as the attack's classifier: renders of a (briefly trained) chair field at
 * the graph's input size, batched through the worker, losses back into NES. */
static void test_attack_steps(void)
{
    vf_dataset ds;
    if (vf_dataset_load(vf_test_shared("data/nerf_synthetic/chair/transforms_train.json"), &ds) !=
        VF_OK) {
        CHECK(0, "chair: %s", vf_error_message());
        return;
    }
    vf_field *field = vf_test_train_field(&ds, 8, 60, 32.0 * 32.0 * 32.0);
    vf_dataset_free(&ds);
    static const char *const names[] = {"identity_weights", "broadcast_mul", "mod",
                                        "layernorm", "gelu_erf", "softmax_matmul",
                                        "tiny_vit", "nhwc", "fixed_batch"};
    for (int i = 0; field && i < 9; i++)
        attack_steps(field, names[i]);
    printf("2 attack steps with each of the 9 graphs\n");
    vf_field_free(field);
}

static void test_errors(void)
{
    /* An op from an unknown domain: the error names it. */
    char path[VF_PATH_MAX];
    snprintf(path, sizeof path, "%s/unknown_op.onnx", graphs_dir);
    vf_classifier *cls = NULL;
    vf_status s = vf_classifier_open_with(path, VF_ENGINE_ONNXRUNTIME, &cls);
    CHECK(s == VF_EINPUT && strstr(vf_error_message(), "VfNoSuchOp"),
          "unknown op: status %d, '%s'", s, vf_error_message());
    CHECK(!strchr(vf_error_message(), '\n'), "the error is one line: %s", vf_error_message());

    /* Not a model at all. */
    snprintf(path, sizeof path, "%s/models.txt", graphs_dir);
    s = vf_classifier_open_with(path, VF_ENGINE_ONNXRUNTIME, &cls);
    CHECK(s == VF_EINPUT && strstr(vf_error_message(), "not an ONNX classifier"),
          "text file: status %d, '%s'", s, vf_error_message());

    /* ONNX Runtime not installed: asked for, a clear internal error; auto falls back. */
    const char *before = getenv("VF_ONNXRUNTIME_DIR");
    char *saved = before ? strdup(before) : NULL;
    setenv("VF_ONNXRUNTIME_DIR", "/nonexistent/ort", 1);
    snprintf(path, sizeof path, "%s/gelu_erf.onnx", graphs_dir);
    s = vf_classifier_open_with(path, VF_ENGINE_ONNXRUNTIME, &cls);
    CHECK(s == VF_EINTERNAL && strstr(vf_error_message(), "setup.sh"),
          "missing runtime: status %d, '%s'", s, vf_error_message());
    s = vf_classifier_open_with(path, VF_ENGINE_AUTO, &cls);
    CHECK(s == VF_OK && !strncmp(vf_classifier_engine(cls), "opencv", 6),
          "auto without the runtime: %s", s == VF_OK ? vf_classifier_engine(cls) : vf_error_message());
    if (s == VF_OK)
        vf_classifier_close(cls);
    if (saved)
        setenv("VF_ONNXRUNTIME_DIR", saved, 1);
    else
        unsetenv("VF_ONNXRUNTIME_DIR");
    free(saved);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    vf_log_set_quiet(1);
    if (vf_engine_check(VF_ENGINE_ONNXRUNTIME) != VF_OK) {
        CHECK(0, "%s", vf_error_message());
        return check_finish();
    }
    graphs_dir = vf_test_tmpdir();
    const char *python = vf_is_file("/usr/bin/python3") ? "/usr/bin/python3" : "python3";
    int rc = vf_test_system("%s %s/tests/onnx_ops.py %s", python, getenv("VF_SOURCE_DIR"),
                            graphs_dir);
    CHECK(rc == 0, "tests/onnx_ops.py failed (%d): python3-onnx installed?", rc);
    if (rc != 0)
        return check_finish();
    CHECK_CASE(test_graphs);
    CHECK_CASE(test_errors);
    CHECK_CASE(test_attack_steps);
    return check_finish();
}
