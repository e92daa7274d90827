/* Data test of the radiance-field trainer on real data: a short training on NeRF-synthetic
 * chair at 100x100 through the public API must render its 10 held-out test views far better
 * than a blank white image does (the background colour, which is most of every test view). */
#include "check.h"

#include <stdlib.h>
#include <string.h>

#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/image.h"
#include "vf/metrics.h"

enum { SIZE = 100 };
/* A step budget, not a time budget, so a busy machine (ctest -j) trains the same field, only
 * later. Measured on 2 shared cores: blank white 14.6 dB, 831 steps (30 s) 32.5 dB. */
#define TRAIN_STEPS 800
#define MIN_GAIN_DB 10.0
#define MIN_PSNR_DB 26.0

static const float white[3] = {1, 1, 1};

/* Load frame i of ds downscaled to SIZE x SIZE: camera into *cam, image (RGBA as stored)
 * into *img. */
static int load_small(const vf_dataset *ds, int i, vf_camera *cam, vf_image *img)
{
    vf_image full = {0};
    if (vf_image_load(ds->frames[i].image_path, &full) != VF_OK)
        return 0;
    vf_status st = vf_image_resize(&full, SIZE, SIZE, img);
    vf_image_free(&full);
    *cam = vf_camera_scaled(&ds->frames[i].camera, SIZE, SIZE);
    return st == VF_OK;
}

static vf_field *train_chair(void)
{
    vf_dataset ds;
    if (vf_dataset_load(vf_test_shared("data/nerf_synthetic/chair/transforms_train.json"), &ds) !=
        VF_OK) {
        CHECK(0, "loading chair training views: %s", vf_error_message());
        return NULL;
    }
    vf_field_train_options opt;
    vf_field_train_defaults(&opt);
    opt.seconds = 0;
    opt.steps = TRAIN_STEPS;
    opt.max_points = 64.0 * 64 * 64; /* 100x100 photos do not support a finer grid */
    opt.batch_rays = 4096;
    vf_field_trainer *t = NULL;
    CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "trainer: %s", vf_error_message());
    for (int i = 0; t && i < ds.count; i++) {
        vf_camera cam;
        vf_image img = {0};
        CHECK(load_small(&ds, i, &cam, &img), "view %d: %s", i, vf_error_message());
        CHECK(img.channels == 4, "chair views are RGBA, got %d channels", img.channels);
        CHECK(vf_field_trainer_add_view(t, &cam, ds.frames[i].c2w, &img) == VF_OK, "add view %d: %s",
              i, vf_error_message());
        vf_image_free(&img);
    }
    vf_dataset_free(&ds);
    vf_field *f = NULL;
    if (t && check_failed == 0 && vf_field_trainer_start(t) == VF_OK) {
        vf_field_train_status st = {0};
        while (vf_field_trainer_step(t, &st) == VF_OK && !st.done)
            ;
        CHECK(st.done, "training stopped early: %s", vf_error_message());
        printf("trained %d steps in %.1f s, training PSNR %.2f dB\n", st.step, st.elapsed, st.psnr);
        f = vf_field_trainer_take_field(t);
    }
    vf_field_trainer_free(t);
    return f;
}

/* Mean PSNR over the test views of the field's renders and of a blank white image. */
static void score_test_views(const vf_field *f, double *field_psnr, double *blank_psnr)
{
    vf_dataset ds;
    *field_psnr = *blank_psnr = 0;
    if (vf_dataset_load(vf_test_shared("data/nerf_synthetic/chair/transforms_test.json"), &ds) !=
        VF_OK) {
        CHECK(0, "loading chair test views: %s", vf_error_message());
        return;
    }
    CHECK(ds.count == 10, "chair has 10 test views, got %d", ds.count);
    vf_image blank = {0};
    if (vf_image_alloc(&blank, SIZE, SIZE, 3) != VF_OK)
        abort();
    for (size_t i = 0; i < (size_t)SIZE * SIZE * 3; i++)
        blank.data[i] = 1.0f;
    for (int i = 0; i < ds.count; i++) {
        vf_camera cam;
        vf_image small = {0}, truth = {0}, render = {0};
        CHECK(load_small(&ds, i, &cam, &small), "test view %d: %s", i, vf_error_message());
        CHECK(vf_image_to_rgb(&small, white, &truth) == VF_OK, "to rgb");
        CHECK(vf_field_render(f, &cam, ds.frames[i].c2w, &render) == VF_OK, "render %d: %s", i,
              vf_error_message());
        double p = vf_image_psnr(&render, &truth), b = vf_image_psnr(&blank, &truth);
        printf("  test view %d: field %.2f dB, blank %.2f dB\n", i, p, b);
        *field_psnr += p / ds.count;
        *blank_psnr += b / ds.count;
        vf_image_free(&small);
        vf_image_free(&truth);
        vf_image_free(&render);
    }
    vf_image_free(&blank);
    vf_dataset_free(&ds);
}

int main(void)
{
    vf_field *f = train_chair();
    CHECK(f != NULL, "no field trained");
    if (f) {
        double field_psnr, blank_psnr;
        score_test_views(f, &field_psnr, &blank_psnr);
        printf("chair %dx%d test PSNR: field %.2f dB, blank white %.2f dB\n", SIZE, SIZE,
               field_psnr, blank_psnr);
        CHECK(blank_psnr > 10 && blank_psnr < 25, "blank PSNR %.2f dB is implausible", blank_psnr);
        CHECK(field_psnr >= blank_psnr + MIN_GAIN_DB, "field %.2f dB not %.0f dB above blank %.2f dB",
              field_psnr, MIN_GAIN_DB, blank_psnr);
        CHECK(field_psnr >= MIN_PSNR_DB, "field %.2f dB below %.0f dB", field_psnr, MIN_PSNR_DB);
    }
    vf_field_free(f);
    return check_finish();
}
