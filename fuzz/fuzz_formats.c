/* libFuzzer targets, one per file format vfcapture reads, all calling the real loaders: the
 * input bytes become the file (or, for a COLMAP text model, its three files) and the loader
 * must either accept it or refuse it with an error, never crash, hang or take the machine's
 * memory. Built with -DVF_FUZZ=ON under clang (see fuzz/README.md); VF_FUZZ_FORMAT picks the
 * format at compile time, so each target is its own program:
 *
 *   transforms     vf_dataset_load (NeRF transforms.json; a 4x4 image "a.png" exists beside it)
 *   colmap_text    vf_colmap_model_load (cameras.txt, images.txt, points3D.txt split at "\n@@\n")
 *   field_model    vf_field_load, then a 24x24 render of what loaded
 *   checkpoint     vf_field_trainer_resume on a trainer holding two fixed 8x8 views (the seed
 *                  is a checkpoint of those views: VF_FUZZ_MAKE_SEED=FILE writes one), then a
 *                  training step
 *   onnx           vf_onnx_input_dims (the ONNX shape walker)
 *   manifest       vf_workspace_open (WS/manifest.json)
 *   attack_json    vf_attack_file_load (WS/attack/attack.json)
 *   targets_json   vf_targets_file_target (WS/export/targets.json), targets 0 and 3
 *   camera         vf_calib_load_camera (the camera file)
 *   normalization  vf_normalization_load (WS/poses/normalization.json) */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "../src/classify/onnx_shape.h"
#include "vf/calib.h"
#include "vf/colmap_model.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/fsutil.h"
#include "vf/localize.h"
#include "vf/log.h"
#include "vf/targets.h"
#include "vf/workspace.h"

#ifndef VF_FUZZ_FORMAT
#error "compile with -DVF_FUZZ_FORMAT=\"name\""
#endif

static char dir[256]; /* this process's scratch folder */

static void make_checkpoint_seed(const char *path);

/* A set-up step of the harness itself failed (not the loader under test). */
static void die(const char *what)
{
    fprintf(stderr, "fuzz harness: %s: %s\n", what, vf_error_message());
    abort();
}

static void write_bytes(const char *name, const uint8_t *data, size_t size)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *fp = fopen(path, "wb");
    if (!fp)
        abort();
    if (size && fwrite(data, 1, size, fp) != size)
        abort();
    fclose(fp);
}

static const char *path_of(const char *name)
{
    static char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    return path;
}

static void remove_dir(void)
{
    vf_remove_tree(dir);
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    snprintf(dir, sizeof dir, "/tmp/vf-fuzz-XXXXXX");
    if (!mkdtemp(dir))
        abort();
    atexit(remove_dir);
    vf_log_set_quiet(1);
    vf_image img;
    if (vf_image_alloc(&img, 4, 4, 3) != VF_OK || vf_image_save(path_of("a.png"), &img) != VF_OK)
        abort();
    vf_image_free(&img);
    char sub[512];
    snprintf(sub, sizeof sub, "%s/attack", dir);
    vf_mkdirs(sub);
    snprintf(sub, sizeof sub, "%s/export", dir);
    vf_mkdirs(sub);
    const char *seed = getenv("VF_FUZZ_MAKE_SEED");
    if (seed && !strcmp(VF_FUZZ_FORMAT, "checkpoint"))
        make_checkpoint_seed(seed);
    return 0;
}

/* The COLMAP model: three files split at the first two "\n@@\n". */
static void colmap_text(const uint8_t *data, size_t size)
{
    static const char *const names[3] = {"cameras.txt", "images.txt", "points3D.txt"};
    const uint8_t *p = data, *end = data + size;
    for (int i = 0; i < 3; i++) {
        const uint8_t *cut = end;
        for (const uint8_t *q = p; i < 2 && q + 4 <= end; q++)
            if (!memcmp(q, "\n@@\n", 4)) {
                cut = q;
                break;
            }
        write_bytes(names[i], p, (size_t)(cut - p));
        p = cut + 4 <= end ? cut + 4 : end;
    }
    vf_colmap_model m;
    if (vf_colmap_model_load(dir, &m) == VF_OK)
        vf_colmap_model_free(&m);
}

/* A small trainer over two fixed synthetic views; the checkpoint target resumes it. */
static vf_field_trainer *small_trainer(void)
{
    vf_field_train_options opt;
    vf_field_train_defaults(&opt);
    opt.seconds = 0, opt.steps = 8;          /* a step budget: the same seed every time */
    opt.batch_rays = 64, opt.levels = 1;      /* one tiny level, one thread */
    opt.max_points = 12 * 12 * 12, opt.threads = 1;
    vf_field_trainer *t;
    if (vf_field_trainer_create(&opt, &t) != VF_OK)
        die("trainer");
    vf_camera cam = {.width = 8, .height = 8, .fx = 10, .fy = 10, .cx = 4, .cy = 4};
    for (int k = 0; k < 2; k++) {
        vf_viewpoint v = {.psi = 40.0 * k, .phi = 120};
        double c2w[16];
        vf_viewpoint_to_c2w(&v, c2w);
        vf_image img;
        if (vf_image_alloc(&img, 8, 8, 3) != VF_OK)
            abort();
        for (int i = 0; i < 8 * 8 * 3; i++)
            img.data[i] = (float)((i * 7 + k * 3) % 11) / 10.0f;
        if (vf_field_trainer_add_view(t, &cam, c2w, &img) != VF_OK)
            die("view");
        vf_image_free(&img);
    }
    return t;
}

static void checkpoint(const uint8_t *data, size_t size)
{
    write_bytes("train.vfc", data, size);
    vf_field_trainer *t = small_trainer();
    vf_field_train_status st;
    if (vf_field_trainer_resume(t, path_of("train.vfc")) == VF_OK)
        vf_field_trainer_step(t, &st);
    vf_field_trainer_free(t);
}

/* VF_FUZZ_MAKE_SEED=FILE: write the checkpoint target's seed (two steps of small_trainer). */
static void make_checkpoint_seed(const char *path)
{
    vf_field_trainer *t = small_trainer();
    vf_field_train_status st;
    if (vf_field_trainer_start(t) != VF_OK || vf_field_trainer_step(t, &st) != VF_OK ||
        vf_field_trainer_step(t, &st) != VF_OK || vf_field_trainer_save_checkpoint(t, path) != VF_OK)
        die("seed");
    vf_field_trainer_free(t);
    exit(0);
}

static void field_model(const uint8_t *data, size_t size)
{
    write_bytes("model.vff", data, size);
    vf_field *f;
    if (vf_field_load(path_of("model.vff"), &f) != VF_OK)
        return;
    vf_camera cam = {.width = 24, .height = 24, .fx = 30, .fy = 30, .cx = 12, .cy = 12};
    vf_viewpoint v = {.psi = 30, .theta = 10, .phi = 60, .dx = 0.1, .dy = -0.2, .dz = 0.05};
    vf_image img = {0};
    vf_field_render_viewpoints(f, &cam, &v, 1, &img);
    vf_image_free(&img);
    vf_field_free(f);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    const char *format = VF_FUZZ_FORMAT;
    if (!strcmp(format, "transforms")) {
        write_bytes("transforms.json", data, size);
        vf_dataset ds;
        if (vf_dataset_load(path_of("transforms.json"), &ds) == VF_OK)
            vf_dataset_free(&ds);
    } else if (!strcmp(format, "colmap_text")) {
        colmap_text(data, size);
    } else if (!strcmp(format, "field_model")) {
        field_model(data, size);
    } else if (!strcmp(format, "checkpoint")) {
        checkpoint(data, size);
    } else if (!strcmp(format, "onnx")) {
        long long dims[8];
        vf_onnx_input_dims(data, size, dims, 8);
    } else if (!strcmp(format, "manifest")) {
        write_bytes("manifest.json", data, size);
        vf_workspace ws;
        if (vf_workspace_open(dir, 0, &ws) == VF_OK) {
            vf_workspace_has_stage(&ws, "attack");
            vf_workspace_close(&ws);
        }
    } else if (!strcmp(format, "attack_json")) {
        write_bytes("attack/attack.json", data, size);
        vf_attack_file a;
        if (vf_attack_file_load(path_of("attack/attack.json"), &a) == VF_OK)
            vf_attack_file_free(&a);
    } else if (!strcmp(format, "targets_json")) {
        write_bytes("export/targets.json", data, size);
        vf_viewpoint v;
        vf_targets_file_target(path_of("export/targets.json"), 0, &v);
        vf_targets_file_target(path_of("export/targets.json"), 3, &v);
    } else if (!strcmp(format, "camera")) {
        write_bytes("camera.json", data, size);
        vf_camera cam;
        vf_calib_load_camera(path_of("camera.json"), &cam);
    } else if (!strcmp(format, "normalization")) {
        write_bytes("normalization.json", data, size);
        vf_similarity a, b;
        vf_normalization_load(path_of("normalization.json"), &a, &b);
    } else {
        abort();
    }
    return 0;
}
