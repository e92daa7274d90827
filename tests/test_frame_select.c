/* Sharpness scores, duplicate thumbnails and the frame selection rules, on synthetic frames
 * and scores whose right answers are known. */
#include <stdlib.h>
#include <string.h>

#include "check.h"
#include "vf/frame_select.h"
#include "vf/sharpness.h"

/* A w x h frame of random blocks (block pixels wide), reproducible from seed. */
static vf_rgb8 textured(int w, int h, int block, unsigned seed)
{
    vf_rgb8 img = {0, 0, NULL};
    vf_rgb8_resize_buffer(&img, w, h);
    int bw = (w + block - 1) / block;
    unsigned char *cells = malloc((size_t)bw * ((h + block - 1) / block));
    srand(seed);
    for (int i = 0; i < bw * ((h + block - 1) / block); i++)
        cells[i] = (unsigned char)(rand() % 256);
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++)
            for (int c = 0; c < 3; c++)
                img.data[((size_t)y * w + x) * 3 + c] = cells[(y / block) * bw + x / block];
    free(cells);
    return img;
}

/* A horizontal box blur of radius r (motion blur). */
static vf_rgb8 blurred(const vf_rgb8 *src, int r)
{
    vf_rgb8 out = {0, 0, NULL};
    vf_rgb8_resize_buffer(&out, src->width, src->height);
    for (int y = 0; y < src->height; y++)
        for (int x = 0; x < src->width; x++)
            for (int c = 0; c < 3; c++) {
                int sum = 0, n = 0;
                for (int k = -r; k <= r; k++)
                    if (x + k >= 0 && x + k < src->width) {
                        sum += src->data[((size_t)y * src->width + x + k) * 3 + c];
                        n++;
                    }
                out.data[((size_t)y * src->width + x) * 3 + c] = (unsigned char)(sum / n);
            }
    return out;
}

static void test_sharpness(void)
{
    vf_rgb8 sharp = textured(320, 240, 4, 1), soft = blurred(&sharp, 6);
    vf_rgb8 flat = {0, 0, NULL};
    vf_rgb8_resize_buffer(&flat, 320, 240);
    memset(flat.data, 128, (size_t)320 * 240 * 3);
    vf_frame_score a, b, f;
    CHECK(vf_score_frame(&sharp, &a) == VF_OK && vf_score_frame(&soft, &b) == VF_OK &&
              vf_score_frame(&flat, &f) == VF_OK,
          "scoring works");
    CHECK(b.sharpness < 0.3 * a.sharpness, "blurred %.1f well below sharp %.1f", b.sharpness,
          a.sharpness);
    CHECK_NEAR(f.sharpness, 0, 1e-9);
    CHECK_NEAR(vf_thumb_difference(&a, &a), 0, 1e-12);
    /* Sensor noise on a still scene keeps the thumbnail (it averages 10x10 pixels). */
    vf_rgb8 noisy = textured(320, 240, 4, 1);
    for (size_t i = 0; i < (size_t)320 * 240 * 3; i++) {
        int v = noisy.data[i] + rand() % 9 - 4;
        noisy.data[i] = (unsigned char)(v < 0 ? 0 : v > 255 ? 255 : v);
    }
    vf_frame_score nz;
    CHECK(vf_score_frame(&noisy, &nz) == VF_OK, "noisy frame");
    CHECK(vf_thumb_difference(&a, &nz) < 1.5, "noise keeps a still frame a duplicate (%.2f)",
          vf_thumb_difference(&a, &nz));
    vf_rgb8_free(&noisy);
    CHECK(vf_thumb_difference(&a, &f) > 20, "different frames differ (%.2f)",
          vf_thumb_difference(&a, &f));

    /* A big frame is measured shrunk: scores stay comparable across sizes. */
    vf_rgb8 big = textured(1920, 1080, 24, 1);
    vf_frame_score g;
    CHECK(vf_score_frame(&big, &g) == VF_OK, "big frame");
    CHECK(g.sharpness > 0.3 * a.sharpness && g.sharpness < 3 * a.sharpness,
          "1920x1080 with 6x larger blocks scores like 320x240 (%.1f vs %.1f)", g.sharpness,
          a.sharpness);
    vf_rgb8_free(&sharp);
    vf_rgb8_free(&soft);
    vf_rgb8_free(&flat);
    vf_rgb8_free(&big);
}

/* n scores with sharpness 100 +- a little, distinct thumbnails. */
static vf_frame_score *scores_for(int n)
{
    vf_frame_score *s = calloc((size_t)n, sizeof *s);
    for (int i = 0; i < n; i++) {
        s[i].sharpness = 100 + 10 * ((i * 7) % 5);
        memset(s[i].thumb, (i * 37) % 256, sizeof s[i].thumb);
    }
    return s;
}

static void test_selection(void)
{
    vf_select_params p;
    vf_select_defaults(&p);
    p.max_frames = 10;
    int n = 30;
    vf_frame_score *s = scores_for(n);
    s[7].sharpness = 20;  /* motion blur */
    s[20].sharpness = 30;
    s[21].sharpness = 25; /* two in a row */
    vf_selection sel;
    CHECK(vf_select_frames(s, n, &p, &sel) == VF_OK, "%s", vf_error_message());
    CHECK(sel.chosen_count == 10, "one frame for each of 10 stretches, got %d", sel.chosen_count);
    for (int i = 0; i < n; i++) {
        int blurry = i == 7 || i == 20 || i == 21;
        CHECK((sel.verdict[i] == VF_FRAME_BLURRY) == blurry, "frame %d: %s", i,
              vf_frame_verdict_name(sel.verdict[i]));
    }
    for (int k = 0; k < sel.chosen_count; k++) {
        int i = sel.chosen[k], lo = k * n / 10, hi = (k + 1) * n / 10;
        CHECK(i >= lo && i < hi, "chosen frame %d lies in stretch %d [%d, %d)", i, k, lo, hi);
        for (int j = lo; j < hi; j++)
            CHECK(sel.verdict[j] == VF_FRAME_BLURRY || s[j].sharpness <= s[i].sharpness,
                  "frame %d is the sharpest usable of its stretch", i);
    }
    vf_selection_free(&sel);

    /* Frames 0..11 show the same view (the camera stood still): one of them is kept. */
    for (int i = 1; i < 12; i++)
        memcpy(s[i].thumb, s[0].thumb, sizeof s[0].thumb);
    s[7].sharpness = 100;
    s[20].sharpness = s[21].sharpness = 100;
    CHECK(vf_select_frames(s, n, &p, &sel) == VF_OK, "%s", vf_error_message());
    int still = 0, duplicates = 0;
    for (int i = 0; i < 12; i++) {
        still += sel.verdict[i] == VF_FRAME_CHOSEN;
        duplicates += sel.verdict[i] == VF_FRAME_DUPLICATE;
    }
    CHECK(still == 1, "one frame of the still part, got %d", still);
    CHECK(duplicates >= 3, "the still part's other stretches gave duplicates (%d)", duplicates);
    CHECK(sel.chosen_count == 7, "1 + 6 moving stretches, got %d", sel.chosen_count);
    vf_selection_free(&sel);

    /* Fewer frames than asked for: all kept. */
    CHECK(vf_select_frames(s + 12, 5, &p, &sel) == VF_OK && sel.chosen_count == 5,
          "5 of 5 kept");
    vf_selection_free(&sel);
    CHECK(vf_select_frames(s, 0, &p, &sel) == VF_OK && sel.chosen_count == 0, "empty input");
    vf_selection_free(&sel);
    p.max_frames = 0;
    CHECK(vf_select_frames(s, n, &p, &sel) == VF_EINPUT, "max_frames 0 refused");
    free(s);
}

/* Photos have no capture order: a few plain photos among detailed ones (neighbours in name
 * order) are not blurry, only one far below the median of them all is. */
static void test_unordered(void)
{
    vf_select_params p;
    vf_select_defaults(&p);
    vf_frame_score *s = scores_for(30);
    s[14].sharpness = s[15].sharpness = 30; /* plain but sharp views */
    s[22].sharpness = 10;                    /* truly blurry */
    vf_selection sel;
    CHECK(vf_select_frames(s, 30, &p, &sel) == VF_OK, "%s", vf_error_message());
    CHECK(sel.verdict[14] == VF_FRAME_BLURRY && sel.verdict[22] == VF_FRAME_BLURRY,
          "video rule: both below 0.4 x the local median");
    vf_selection_free(&sel);
    p.unordered = 1;
    p.blur_ratio = 0.2; /* the photo default (vf_ingest_defaults) */
    CHECK(vf_select_frames(s, 30, &p, &sel) == VF_OK, "%s", vf_error_message());
    CHECK(sel.verdict[14] != VF_FRAME_BLURRY && sel.verdict[15] != VF_FRAME_BLURRY &&
              sel.verdict[22] == VF_FRAME_BLURRY,
          "photo rule: only the one under 0.2 x the median of all");
    CHECK(sel.chosen_count == 29, "29 of 30 photos kept, got %d", sel.chosen_count);
    vf_selection_free(&sel);
    free(s);
}

static void test_live_counter(void)
{
    vf_select_params p;
    vf_select_defaults(&p);
    vf_frame_score *s = scores_for(20);
    s[10].sharpness = 10;                        /* blurry */
    memcpy(s[15].thumb, s[14].thumb, sizeof s[15].thumb); /* repeats the one before */
    vf_live_counter counter = {0};
    for (int i = 0; i < 20; i++) {
        int usable = vf_live_counter_add(&counter, &s[i], &p);
        CHECK(usable == (i != 10 && i != 15), "frame %d usable: %d", i, usable);
    }
    CHECK(counter.usable == 18, "18 usable, got %d", counter.usable);
    free(s);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_sharpness);
    CHECK_CASE(test_selection);
    CHECK_CASE(test_unordered);
    CHECK_CASE(test_live_counter);
    return check_finish();
}
