/* Unit tests of the radiance-field engine on small synthetic fields: the inlined math, the
 * gradients of the ray marcher against finite differences, the fast renderer against the
 * training forward pass, the empty-space radii and jumps, deterministic rendering, model files (round
 * trip, corrupt and other-version files rejected) and checkpoint resume. */
#include "check.h"

#include <stdlib.h>
#include <string.h>

#include "../src/field/fast_math.h"
#include "../src/field/trainer_internal.h"
#include "vf/error.h"
#include "vf/field.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/pose.h"

static uint64_t rng_state = 0x2545f4914f6cdd1dull;
static float uniform(float lo, float hi)
{
    rng_state ^= rng_state << 13, rng_state ^= rng_state >> 7, rng_state ^= rng_state << 17;
    return lo + (hi - lo) * (float)((rng_state >> 40) / 16777216.0);
}

/* A 12^3 field over [-1, 1]^3 with smooth random density and colour. */
static vf_field *make_field(void)
{
    rng_state = 0x2545f4914f6cdd1dull; /* every case's fields the same, whatever ran before */
    vf_field *f = calloc(1, sizeof *f);
    const int dim[3] = {12, 12, 12};
    const float lo[3] = {-1, -1, -1};
    float voxel = 2.0f / 11;
    if (vf__field_grid_alloc(&f->grids[0], dim, lo, voxel) != VF_OK)
        abort();
    f->grid_count = 1;
    field_grid *g = &f->grids[0];
    for (size_t i = 0; i < g->points; i++) {
        float *v = g->values + i * FIELD_CH;
        int x = (int)(i % 12), y = (int)(i / 12 % 12), z = (int)(i / 144);
        float r2 = ((x - 5.5f) * (x - 5.5f) + (y - 5.5f) * (y - 5.5f) + (z - 5.5f) * (z - 5.5f));
        v[FIELD_CH_DENSITY] = 2.0f - 0.15f * r2 + uniform(-0.5f, 0.5f);
        for (int ch = FIELD_CH_SH; ch < FIELD_CH_USED; ch++)
            v[ch] = uniform(-1, 1);
    }
    f->density_scale = 1.0f / voxel;
    f->density_shift = -2.0f;
    f->step_ratio = 0.5f;
    f->background[0] = f->background[1] = f->background[2] = 1.0f;
    f->occupancy_alpha = 1e-4f;
    f->stop_transmittance = 1e-3f;
    /* 30 wide: rows are marched four rays at a time and two alone (render_march.c) */
    f->camera = (vf_camera){.width = 30, .height = 32, .fx = 40, .fy = 40, .cx = 15, .cy = 16};
    f->camera_distance = 4;
    vf__field_grid_update_occupancy(g, f, f->step_ratio * voxel);
    return f;
}

static void test_fast_math(void)
{
    double worst_exp = 0, worst_sig = 0;
    /* float x * log2(e) rounds: the error grows with |x| */
    for (float x = -20; x < 20; x += 0.0137f) {
        fast_f4 e = fast_exp2_4((fast_f4){x, -x, 0.5f * x, 0} * 1.44269504f);
        worst_exp = fmax(worst_exp, fabs(e[0] - exp((double)x)) / exp((double)x));
        worst_exp = fmax(worst_exp, fabs(e[1] - exp(-(double)x)) / exp(-(double)x));
        fast_f4 s = fast_sigmoid4((fast_f4){x, -x, 0, 0});
        worst_sig = fmax(worst_sig, fabs(s[0] - 1 / (1 + exp(-(double)x))));
        worst_sig = fmax(worst_sig, fabs(s[1] - 1 / (1 + exp((double)x))));
    }
    CHECK(worst_exp < 2e-6, "fast_exp2_4 relative error %g", worst_exp);
    CHECK(worst_sig < 1e-6, "fast_sigmoid4 error %g", worst_sig);
}

/* The renderer's opacity table against 1 - exp(-softplus(d + shift) * scale * step). */
static void test_alpha_table(void)
{
    vf_field *f = make_field();
    field_render_setup setup;
    CHECK(vf__field_render_setup_init(f, &setup) == VF_OK, "render setup");
    const field_render_grid *r = &setup.grids[0];
    double worst = 0;
    for (float d = r->visible_density; d < r->visible_density + 60; d += 0.00731f) {
        double x = (double)d + f->density_shift;
        double exact = -expm1(-log1p(exp(x)) * r->scale_step);
        worst = fmax(worst, fabs(field_render_alpha(r, d) - exact));
    }
    CHECK(fabs(field_render_alpha(r, r->visible_density) - FIELD_VISIBLE_ALPHA) < 1e-6,
          "alpha at the visibility threshold %g", field_render_alpha(r, r->visible_density));
    CHECK(worst < 1e-5, "alpha table error %g", worst);
    vf_field_free(f);
}

/* loss = g . rgb(ray) for a fixed g, plus the weighted transmittance left and distortion
 * loss; its gradient by vf__field_backward and by central differences. */
static double ray_loss(const vf_field *f, const field_ray *ray, field_scratch *sc,
                       const float g[3], field_ray_losses losses)
{
    field_march_result res;
    vf__field_march(f, ray, 0.3f, 0.0f, sc, &res);
    return (double)g[0] * res.rgb[0] + (double)g[1] * res.rgb[1] + (double)g[2] * res.rgb[2] +
           (double)losses.opaque * res.trans +
           losses.distortion * vf__field_distortion_loss(f, sc->samples, res.count) +
           losses.depth * vf__field_depth_loss(f, sc->samples, res.count, losses.depth_target);
}

static void test_gradients(field_ray_losses losses)
{
    vf_field *f = make_field();
    field_grid *grid = &f->grids[0];
    vf__field_grid_fill_occupancy(grid); /* no skipping: the loss is smooth in every value */
    field_scratch sc = {.capacity = vf__field_max_samples(f)};
    sc.samples = malloc((size_t)sc.capacity * sizeof *sc.samples);
    field_grad_sink sink = {0};
    sink.grad[0] = calloc(grid->points * FIELD_CH, sizeof(float));
    sink.touched[0] = calloc(grid->points, 1);
    sink.list[0] = malloc(grid->points * sizeof(uint32_t));

    field_ray ray = {.origin = {0.13f, -0.21f, 4.0f}, .dir = {0.03f, 0.05f, -1.0f}, .tmax = 1e30f};
    float n = sqrtf(ray.dir[0] * ray.dir[0] + ray.dir[1] * ray.dir[1] + ray.dir[2] * ray.dir[2]);
    for (int a = 0; a < 3; a++)
        ray.dir[a] /= n;
    const float g[3] = {0.7f, -0.4f, 0.9f};
    field_march_result res;
    vf__field_march(f, &ray, 0.3f, 0.0f, &sc, &res);
    CHECK(res.count > 10, "the test ray takes %d samples", res.count);
    CHECK(res.trans > 0.01f && res.trans < 0.99f, "the test ray is partly opaque (T = %g)",
          res.trans);
    vf__field_backward(f, &ray, &sc, &res, g, losses, &sink);
    CHECK(sink.count[0] > 8, "the ray touched %zu points", sink.count[0]);

    int checked = 0, bad = 0;
    double worst = 0;
    for (size_t k = 0; k < sink.count[0]; k += 3) {
        size_t i = sink.list[0][k];
        for (int ch = 0; ch < FIELD_CH_USED; ch += 4) {
            float *value = &grid->values[i * FIELD_CH + ch];
            const float saved = *value, h = 1e-2f;
            *value = saved + h;
            double up = ray_loss(f, &ray, &sc, g, losses);
            *value = saved - h;
            double down = ray_loss(f, &ray, &sc, g, losses);
            *value = saved;
            double numeric = (up - down) / (2 * h), analytic = sink.grad[0][i * FIELD_CH + ch];
            double err = fabs(numeric - analytic) / fmax(1e-3, fabs(numeric) + fabs(analytic));
            worst = fmax(worst, err);
            bad += err > 0.02;
            checked++;
        }
    }
    CHECK(checked > 20, "checked %d gradients", checked);
    CHECK(bad == 0,
          "opaque %g, distortion %g, depth %g: %d of %d gradients differ from finite "
          "differences (worst relative %g)",
          losses.opaque, losses.distortion, losses.depth, bad, checked, worst);
    free(sink.grad[0]);
    free(sink.touched[0]);
    free(sink.list[0]);
    free(sc.samples);
    vf_field_free(f);
}

static double max_diff(const vf_image *a, const vf_image *b)
{
    double worst = 0;
    for (size_t i = 0; i < (size_t)a->width * a->height * a->channels; i++)
        worst = fmax(worst, fabs(a->data[i] - b->data[i]));
    return worst;
}

/* The fast renderer against the training forward pass, pixel by pixel. */
static void test_render_matches_march(void)
{
    vf_field *f = make_field();
    vf_viewpoint v = {.psi = 30, .theta = 10, .phi = 60};
    double c2w[16];
    vf_viewpoint_to_c2w(&v, c2w);
    vf_image img = {0}, again = {0};
    CHECK(vf_field_render(f, &f->camera, c2w, &img) == VF_OK, "render: %s", vf_error_message());
    double worst = 0, coloured = 0;
    for (int y = 0; y < img.height; y++)
        for (int x = 0; x < img.width; x++) {
            field_ray ray;
            field_march_result res;
            vf__field_camera_ray(&f->camera, c2w, x + 0.5, y + 0.5, &ray);
            vf__field_march(f, &ray, 0.5f, f->stop_transmittance, NULL, &res);
            for (int k = 0; k < 3; k++) {
                worst = fmax(worst, fabs(res.rgb[k] - img.data[3 * (y * img.width + x) + k]));
                coloured = fmax(coloured, fabs(res.rgb[k] - 1.0f));
            }
        }
    CHECK(coloured > 0.2, "the field is visible (largest difference from white %g)", coloured);
    /* the renderer skips samples under FIELD_VISIBLE_ALPHA; this test field is a deliberately
     * hazy blob full of them (real fields: see the PSNR of test_data_field) */
    CHECK(worst < 2e-2, "fast render differs from the training forward pass by %g", worst);
    /* deterministic, also through the batch path and in place */
    CHECK(vf_field_render(f, &f->camera, c2w, &again) == VF_OK, "render again");
    CHECK(max_diff(&img, &again) == 0, "two renders differ by %g", max_diff(&img, &again));
    vf_image batch[3] = {{0}};
    vf_viewpoint vs[3] = {v, v, v};
    CHECK(vf_field_render_viewpoints(f, &f->camera, vs, 3, batch) == VF_OK, "batch render");
    for (int i = 0; i < 3; i++)
        CHECK(max_diff(&img, &batch[i]) == 0, "batch render %d differs", i);
    for (int i = 0; i < 3; i++)
        vf_image_free(&batch[i]);
    /* the renderer may read a half copy of the values (FIELD_RENDER_HALF): values beyond the
     * halves' range (65504) stay finite, and the copy follows the values when they change */
    field_grid *g = &f->grids[0];
    for (size_t i = 0; i < g->points; i += 7)
        g->values[i * FIELD_CH + FIELD_CH_SH + i % 12] = i % 2 ? 1e6f : -1e6f;
    vf__field_values_changed(f);
    CHECK(vf_field_render(f, &f->camera, c2w, &again) == VF_OK, "render with huge logits");
    int finite = 1;
    for (size_t i = 0; i < (size_t)3 * again.width * again.height; i++)
        finite &= isfinite(again.data[i]);
    CHECK(finite, "huge colour logits render finite");
    for (size_t i = 0; i < g->points; i++)
        g->values[i * FIELD_CH + FIELD_CH_DENSITY] = FIELD_EMPTY_DENSITY;
    vf__field_values_changed(f);
    CHECK(vf_field_render(f, &f->camera, c2w, &again) == VF_OK, "render emptied");
    double seen = 0;
    for (size_t i = 0; i < (size_t)3 * again.width * again.height; i++)
        seen = fmax(seen, fabs(again.data[i] - f->background[i % 3]));
    CHECK(seen == 0, "the emptied field still shows (%g from its background)", seen);
    vf_image_free(&img);
    vf_image_free(&again);
    vf_field_free(f);
}

/* A 48^3 field over [-1, 1]^3 that is empty but for two small opaque balls: long jumps. */
static vf_field *make_sparse_field(void)
{
    vf_field *f = make_field();
    field_grid *g = &f->grids[0];
    vf__field_grid_free(g);
    const int dim[3] = {48, 48, 48};
    const float lo[3] = {-1, -1, -1}, voxel = 2.0f / 47;
    if (vf__field_grid_alloc(g, dim, lo, voxel) != VF_OK)
        abort();
    const float centres[2][3] = {{-0.4f, 0.1f, 0.2f}, {0.5f, -0.3f, -0.1f}};
    for (size_t i = 0; i < g->points; i++) {
        float *v = g->values + i * FIELD_CH;
        const float p[3] = {lo[0] + voxel * (float)(i % 48), lo[1] + voxel * (float)(i / 48 % 48),
                            lo[2] + voxel * (float)(i / (48 * 48))};
        v[FIELD_CH_DENSITY] = FIELD_EMPTY_DENSITY;
        for (int b = 0; b < 2; b++) {
            float r2 = 0;
            for (int a = 0; a < 3; a++)
                r2 += (p[a] - centres[b][a]) * (p[a] - centres[b][a]);
            if (r2 < 0.25f * 0.25f)
                v[FIELD_CH_DENSITY] = uniform(0.0f, 4.0f);
        }
        for (int ch = FIELD_CH_SH; ch < FIELD_CH_USED; ch++)
            v[ch] = uniform(-1, 1);
    }
    f->density_scale = 1.0f / voxel;
    vf__field_grid_update_occupancy(g, f, f->step_ratio * voxel);
    return f;
}

/* A ray the renderer ends early on an opaque ball is renormalized over the opacity it met:
 * closer to the ray marched to the end than the same stop with the rest taken from the white
 * background, and reported opaque. */
static void test_render_stop_renormalizes(void)
{
    vf_field *f = make_sparse_field();
    f->stop_transmittance = 0.05f;
    f->camera = (vf_camera){.width = 96, .height = 96, .fx = 128, .fy = 128, .cx = 48, .cy = 48};
    vf_viewpoint v = {.psi = 30, .theta = 10, .phi = 60};
    double c2w[16];
    vf_viewpoint_to_c2w(&v, c2w);
    field_render_setup setup;
    CHECK(vf__field_render_setup_init(f, &setup) == VF_OK, "render setup");
    double renorm_error = 0, white_error = 0;
    int stopped = 0, opaque = 0;
    for (int y = 0; y < f->camera.height; y++)
        for (int x = 0; x < f->camera.width; x++) {
            field_ray ray;
            field_march_result full, white, render;
            vf__field_camera_ray(&f->camera, c2w, x + 0.5, y + 0.5, &ray);
            vf__field_march(f, &ray, 0.5f, 1e-6f, NULL, &full);
            vf__field_march(f, &ray, 0.5f, f->stop_transmittance, NULL, &white);
            if (white.trans >= f->stop_transmittance)
                continue;
            vf__field_render_rays(f, &setup, &ray, 1, 0.5f, f->stop_transmittance, &render);
            stopped++;
            opaque += render.trans == 0;
            for (int k = 0; k < 3; k++) {
                renorm_error += fabs(render.rgb[k] - full.rgb[k]);
                white_error += fabs(white.rgb[k] - full.rgb[k]);
            }
        }
    CHECK(stopped > 100, "%d rays end early", stopped);
    CHECK(opaque == stopped, "%d of %d rays ended early are opaque", opaque, stopped);
    CHECK(renorm_error < 0.5 * white_error, "mean error %g renormalized, %g with white",
          renorm_error / (3 * stopped), white_error / (3 * stopped));
    printf("rays ended at 95%%: mean error %.4f renormalized, %.4f with white (%d rays)\n",
           renorm_error / (3 * stopped), white_error / (3 * stopped), stopped);
    vf_field_free(f);
}

/* The samples in occupied cells that the training march records (min_trans 0: rays go through
 * both balls) for every pixel of a view: cell and position of each. Returns the floats written. */
static int record_march(const vf_field *f, const double c2w[16], field_scratch *sc, float *out,
                        int room)
{
    int n = 0;
    const field_grid *g = &f->grids[0];
    for (int y = 0; y < f->camera.height; y++)
        for (int x = 0; x < f->camera.width; x++) {
            field_ray ray;
            field_march_result res;
            vf__field_camera_ray(&f->camera, c2w, x + 0.5, y + 0.5, &ray);
            vf__field_march(f, &ray, 0.5f, 0.0f, sc, &res);
            for (int i = 0; i < res.count && n + 4 <= room; i++) {
                const uint32_t p = sc->samples[i].base;
                const size_t px = p % g->dim[0], py = p / g->dim[0] % g->dim[1];
                const size_t pz = p / g->dim[0] / g->dim[1];
                if (!field_cell_occupied(g, px + g->cells[0] * (py + g->cells[1] * pz)))
                    continue;
                out[n] = (float)p;
                memcpy(out + n + 1, sc->samples[i].frac, 3 * sizeof(float));
                n += 4;
            }
        }
    return n;
}

/* Jumps over empty space skip only empty cells: with the real empty-space radii both marchers
 * take exactly the samples they take when they test every sample (all radii 0; the empty
 * cells hold FIELD_EMPTY_DENSITY, invisible to both). */
static void test_jumps_skip_only_empty(void)
{
    vf_field *f = make_sparse_field();
    field_grid *g = &f->grids[0];
    const size_t cells = (size_t)g->cells[0] * g->cells[1] * g->cells[2];
    int longest = 0;
    for (size_t c = 0; c < cells; c++)
        longest = g->empty_radius[c] > longest ? g->empty_radius[c] : longest;
    CHECK(longest >= 10, "the sparse field has long jumps (largest radius %d)", longest);

    const vf_viewpoint views[3] = {{.psi = 30, .theta = 10, .phi = 60},
                                   {.psi = -70, .theta = -35, .phi = 200, .dx = 0.3},
                                   {.psi = 5, .theta = 60, .phi = 130, .dz = -0.5}};
    field_scratch sc = {.capacity = vf__field_max_samples(f)};
    sc.samples = malloc((size_t)sc.capacity * sizeof *sc.samples);
    const int room = 1 << 20;
    float *recorded[2] = {malloc(room * sizeof(float)), malloc(room * sizeof(float))};
    vf_image img[2] = {{0}}; /* [0] with jumps, [1] testing every sample */
    uint8_t *radii = malloc(cells);
    memcpy(radii, g->empty_radius, cells);
    for (int i = 0; i < 3; i++) {
        double c2w[16];
        vf_viewpoint_to_c2w(&views[i], c2w);
        int n[2];
        for (int pass = 0; pass < 2; pass++) {
            if (pass)
                memset(g->empty_radius, 0, cells);
            CHECK(vf_field_render(f, &f->camera, c2w, &img[pass]) == VF_OK, "render: %s",
                  vf_error_message());
            n[pass] = record_march(f, c2w, &sc, recorded[pass], room);
        }
        memcpy(g->empty_radius, radii, cells);
        CHECK(n[0] > 400 && n[0] < room, "view %d: the march records %d values", i, n[0]);
        CHECK(n[0] == n[1] && memcmp(recorded[0], recorded[1], n[0] * sizeof(float)) == 0,
              "view %d: jumps change the training march's samples", i);
        CHECK(max_diff(&img[0], &img[1]) == 0, "view %d: jumps change the render by %g", i,
              max_diff(&img[0], &img[1]));
    }
    for (int pass = 0; pass < 2; pass++) {
        vf_image_free(&img[pass]);
        free(recorded[pass]);
    }
    free(radii);
    free(sc.samples);
    vf_field_free(f);
}

static int patch_file(const char *path, long offset, const void *bytes, size_t n)
{
    FILE *fp = fopen(path, "r+b");
    if (!fp)
        return -1;
    fseek(fp, offset, SEEK_SET);
    int ok = fwrite(bytes, 1, n, fp) == n;
    fclose(fp);
    return ok ? 0 : -1;
}

static void test_model_files(void)
{
    vf_field *f = make_field();
    char path[512], copy[600];
    snprintf(path, sizeof path, "%s/model.vff", vf_test_tmpdir());
    snprintf(copy, sizeof copy, "%s.bad", path);
    CHECK(vf_field_save(f, path) == VF_OK, "save: %s", vf_error_message());
    vf_field *loaded = NULL;
    CHECK(vf_field_load(path, &loaded) == VF_OK, "load: %s", vf_error_message());
    if (loaded) {
        vf_viewpoint v = {.psi = -40, .theta = 5, .phi = 120, .dy = -0.5};
        vf_image a = {0}, b = {0};
        vf_field_render_viewpoints(f, &f->camera, &v, 1, &a);
        vf_field_render_viewpoints(loaded, &loaded->camera, &v, 1, &b);
        CHECK(a.data && b.data && max_diff(&a, &b) == 0, "saved and loaded fields render alike");
        vf_image_free(&a);
        vf_image_free(&b);
        vf_field_free(loaded);
    }
    /* a flipped byte in the grid values */
    char *bytes = NULL;
    size_t size = 0;
    CHECK(vf_read_file(path, &bytes, &size) == VF_OK && size > 3000, "read %s", path);
    vf_write_file_atomic(copy, bytes, size);
    const unsigned char junk = 0x5a;
    patch_file(copy, 2000, &junk, 1);
    loaded = NULL;
    CHECK(vf_field_load(copy, &loaded) == VF_EINPUT && !loaded, "corrupt file rejected");
    CHECK(strstr(vf_error_message(), "corrupt") != NULL, "message: %s", vf_error_message());
    /* another format version */
    vf_write_file_atomic(copy, bytes, size);
    const uint32_t version = 99;
    patch_file(copy, 8, &version, sizeof version);
    CHECK(vf_field_load(copy, &loaded) == VF_EINPUT && !loaded, "other version rejected");
    CHECK(strstr(vf_error_message(), "version 99") != NULL, "message: %s", vf_error_message());
    /* truncated, and not a model at all */
    vf_write_file_atomic(copy, bytes, 3000);
    CHECK(vf_field_load(copy, &loaded) == VF_EINPUT && !loaded, "truncated file rejected");
    vf_write_file_atomic(copy, "hello\n", 6);
    CHECK(vf_field_load(copy, &loaded) == VF_EINPUT && !loaded, "non-model rejected");
    free(bytes);
    CHECK(vf_field_load("/nonexistent/model.vff", &loaded) == VF_EINPUT, "missing file");
    vf_field_free(f);
}

/* A model file crafted from make_field with one thing broken must be refused with a message
 * naming the file, quickly and without taking the memory its header claims (fuzzing found
 * each of these crashing or hanging the renderer, or exhausting the machine). */
static void check_refused(vf_field *f, const char *why, const char *path)
{
    CHECK(vf_field_save(f, path) == VF_OK, "%s: save", why);
    vf_field *loaded = NULL;
    double t0 = vf_now();
    vf_status s = vf_field_load(path, &loaded);
    CHECK(s == VF_EINPUT && !loaded && strstr(vf_error_message(), path),
          "%s: refused (%s)", why, vf_error_message());
    CHECK(vf_now() - t0 < 2.0, "%s: refused in %.1f s", why, vf_now() - t0);
    vf_field_free(loaded);
    vf_field_free(f);
}

/* The offset of the first grid's dims (three int32 12s) in a saved make_field model. */
static long find_dims(const char *path)
{
    char *data;
    size_t size;
    long at = -1;
    const int32_t dims[3] = {12, 12, 12};
    if (vf_read_file(path, &data, &size) != VF_OK)
        return -1;
    for (size_t i = 16; at < 0 && i + sizeof dims <= size && i < 400; i += 4)
        if (!memcmp(data + i, dims, sizeof dims))
            at = (long)i;
    free(data);
    return at;
}

static void test_hostile_models(void)
{
    char path[512];
    snprintf(path, sizeof path, "%s/hostile.vff", vf_test_tmpdir());
    vf_field *f = make_field();
    f->grids[0].values[5 * FIELD_CH + FIELD_CH_DENSITY] = NAN;
    check_refused(f, "a NaN density", path);
    f = make_field();
    f->grids[0].values[77 * FIELD_CH + FIELD_CH_SH + 3] = INFINITY;
    check_refused(f, "an infinite colour", path);
    f = make_field();
    f->grids[0].lo[1] = NAN;
    check_refused(f, "a NaN box", path);
    f = make_field();
    f->density_shift = 1e30f;
    check_refused(f, "an extreme density shift", path);
    f = make_field();
    f->step_ratio = 1e-9f;
    check_refused(f, "a tiny step ratio", path);
    f = make_field();
    f->grids[0].voxel = 0;
    check_refused(f, "a zero voxel", path);

    /* a header claiming a 4000^3 grid in a 100 KB file: refused before allocating */
    f = make_field();
    CHECK(vf_field_save(f, path) == VF_OK, "save");
    vf_field_free(f);
    long at = find_dims(path);
    const int32_t huge[3] = {4000, 4000, 4000};
    CHECK(at > 0 && patch_file(path, at, huge, sizeof huge) == 0, "dims at %ld patched", at);
    vf_field *loaded = NULL;
    CHECK(vf_field_load(path, &loaded) == VF_EINPUT && !loaded &&
              strstr(vf_error_message(), "claims"),
          "huge grid claim refused: %s", vf_error_message());

    /* the renderer's opacity table takes any density, NaN included, without reading outside */
    f = make_field();
    field_render_setup setup;
    CHECK(vf__field_render_setup_init(f, &setup) == VF_OK, "render setup");
    const field_render_grid *r = &setup.grids[0];
    const float odd[5] = {NAN, INFINITY, -INFINITY, 3e38f, -3e38f};
    for (int i = 0; i < 5; i++) {
        float a = field_render_alpha(r, odd[i]);
        CHECK(a >= 0.0f && a <= 1.0f, "alpha of %g is %g", (double)odd[i], (double)a);
    }
    vf_field_free(f);
}

/* Every thread's gradient sink is applied even when OpenMP gives the optimizer a smaller
 * team than the trainer's thread count (here: a nested region, which runs on one thread;
 * OMP_DYNAMIC can do the same). Once, sink 1 was then silently dropped. */
static void touch(field_grad_sink *s, size_t i, float g)
{
    s->grad[0][i * FIELD_CH + FIELD_CH_DENSITY] = g;
    s->touched[0][i] = 1;
    s->list[0][s->count[0]++] = (uint32_t)i;
}

static void test_adam_small_team(void)
{
    vf_field *f = make_field();
    field_adam adam = {0};
    CHECK(vf__field_adam_alloc(&adam, f, 2) == VF_OK, "adam for 2 threads");
    float lr[FIELD_CH];
    for (int ch = 0; ch < FIELD_CH; ch++)
        lr[ch] = 0.1f;
    const size_t a = 10, b = 500;
    const float before_a = f->grids[0].values[a * FIELD_CH], before_b = f->grids[0].values[b * FIELD_CH];
    touch(&adam.sinks[0], a, 1.0f);
    touch(&adam.sinks[1], b, 1.0f);
#pragma omp parallel num_threads(2)
    {
#pragma omp single
        vf__field_adam_step(&adam, f, lr, 0, 0, 0); /* nested: a team of one */
    }
    CHECK(f->grids[0].values[a * FIELD_CH] < before_a - 0.05f, "sink 0 applied");
    CHECK(f->grids[0].values[b * FIELD_CH] < before_b - 0.05f, "sink 1 applied by a team of one");
    CHECK(vf__field_adam_touched(&adam) == 0, "sinks cleared");
    vf__field_adam_free(&adam);
    vf_field_free(f);
}

/* Training views: renders of the synthetic field from a ring of cameras, opaque RGB or (with
 * `alpha`) RGBA with every pixel opaque. */
static void add_views_as(vf_field_trainer *t, const vf_field *f, int count, int alpha)
{
    for (int i = 0; i < count; i++) {
        vf_viewpoint v = {.psi = -180 + 360.0 * i / count, .theta = 0, .phi = 40 + 15 * (i % 5)};
        double c2w[16];
        vf_viewpoint_to_c2w(&v, c2w);
        vf_image img = {0}, rgba = {0};
        vf_field_render(f, &f->camera, c2w, &img);
        if (alpha) {
            vf_image_alloc(&rgba, img.width, img.height, 4);
            for (size_t p = 0; p < (size_t)img.width * img.height; p++) {
                memcpy(rgba.data + 4 * p, img.data + 3 * p, 3 * sizeof(float));
                rgba.data[4 * p + 3] = 1.0f;
            }
        }
        CHECK(vf_field_trainer_add_view(t, &f->camera, c2w, alpha ? &rgba : &img) == VF_OK,
              "add view: %s", vf_error_message());
        vf_image_free(&img);
        vf_image_free(&rgba);
    }
}

static void add_views(vf_field_trainer *t, const vf_field *f, int count)
{
    add_views_as(t, f, count, 0);
}

/* The defaults, on a small budget: `steps` steps of 256 rays over a 16^3 grid, 2 threads. */
static vf_field_train_options small_training(int steps, int levels)
{
    vf_field_train_options opt;
    vf_field_train_defaults(&opt);
    opt.seconds = 0;
    opt.steps = steps;
    opt.batch_rays = 256;
    opt.max_points = 16 * 16 * 16;
    opt.levels = levels;
    opt.threads = 2;
    return opt;
}

/* Sparse points land on the pixel whose training ray passes them, at their distance; points
 * behind the camera or outside the photo are dropped. */
static void test_view_points(void)
{
    vf_field *f = make_field();
    vf_field_train_options opt = small_training(4, 1);
    opt.depth = 1;
    vf_field_trainer *t = NULL;
    CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "create");
    add_views(t, f, 3);
    const double points[] = {0.1, -0.2, 0.3,   0.4, 0.0, -0.1,  -0.3, 0.25, 0.05,
                             0.0, 0.0, 40.0, /* behind the last camera (it sits above) */
                             30.0, 0.0, 0.0}; /* far outside its view */
    CHECK(vf_field_trainer_add_view_points(t, points, 5) == VF_OK, "add points");
    CHECK(t->depth_count == 3, "3 of 5 points kept (%zu)", t->depth_count);
    for (size_t i = 0; i < t->depth_count && i < 3; i++) {
        field_ray ray;
        float rgb[3];
        vf__trainer_pixel_ray(t, t->depth_rays[i].pixel, &ray, rgb);
        double along = 0, off = 0;
        for (int a = 0; a < 3; a++)
            along += (points[3 * i + a] - ray.origin[a]) * ray.dir[a];
        for (int a = 0; a < 3; a++) {
            const double d = points[3 * i + a] - ray.origin[a] - along * ray.dir[a];
            off += d * d;
        }
        /* within half a pixel's diagonal of the ray (0.1 units at the distance of 4) */
        const double pixel = along / f->camera.fx;
        CHECK(sqrt(off) < 0.71 * pixel, "point %zu passes %.4f from its pixel's ray (pixel %.4f)",
              i, sqrt(off), pixel);
        CHECK(fabs(t->depth_rays[i].distance - along) < 0.05 * pixel,
              "point %zu at distance %.4f, along the ray %.4f", i, t->depth_rays[i].distance,
              along);
    }
    /* how far they reach from the origin, per axis: 0.4 (the second point) at the top, 0.3 at
     * the bottom, each within the half pixel (0.05 units) its pixel's ray may miss it by */
    const double origin[3] = {0, 0, 0};
    const double farthest = vf__trainer_points_reach(t, origin, 1.0);
    const double nearest = vf__trainer_points_reach(t, origin, 0.0);
    CHECK(fabs(farthest - 0.4) < 0.06 && fabs(nearest - 0.3) < 0.06,
          "the points reach %.4f (0.4) and %.4f (0.3) from the origin", farthest, nearest);
    vf_field_trainer_free(t);
    vf_field_free(f);
}

/* The outer grid of an opaque capture holds the room its sparse points show: a point 16 units
 * down the last camera's axis (12 past the centre) takes the outer grid out to 1.1 times its
 * reach, while without points it keeps its default half-size (4 x the view's half-width at
 * the centre: 4 x 4 x 15 / 40 = 6). */
static void test_outer_grid_reach(void)
{
    vf_field *f = make_field();
    for (int with_point = 0; with_point < 2; with_point++) {
        vf_field_train_options opt = small_training(4, 1);
        vf_field_trainer *t = NULL;
        CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "create");
        add_views(t, f, 3);
        double reach = 0;
        if (with_point) {
            const double *m = t->views[t->view_count - 1].c2w;
            const double p[3] = {m[3] - 16 * m[2], m[7] - 16 * m[6], m[11] - 16 * m[10]};
            CHECK(vf_field_trainer_add_view_points(t, p, 1) == VF_OK && t->depth_count == 1,
                  "the far point is in view");
            for (int a = 0; a < 3; a++)
                reach = fmax(reach, fabs(p[a]));
        }
        CHECK(vf_field_trainer_start(t) == VF_OK, "start: %s", vf_error_message());
        const vf_field *trained = vf_field_trainer_field(t);
        CHECK(trained->grid_count == 2, "opaque views get an outer grid");
        const field_grid *outer = &trained->grids[1];
        const double half = 0.5 * (outer->dim[0] - 1) * outer->voxel;
        const double want = with_point ? 1.1 * reach : 6.0;
        printf("outer grid %s points: half-size %.3f (want %.3f, voxel %.3f)\n",
               with_point ? "with" : "without", half, want, outer->voxel);
        /* the point is rebuilt from its pixel's ray: within half a pixel, 0.2 units at 16 */
        const double slack = with_point ? 1.1 * 0.2 : 0.01;
        CHECK(half >= want - slack && half < want + outer->voxel + slack,
              "outer grid half-size %.3f, want %.3f (%s the far point)", half, want,
              with_point ? "with" : "without");
        vf_field_trainer_free(t);
    }
    vf_field_free(f);
}

/* An opaque capture's boxes go round what its photos centre, not where the optical axes
 * meet: 40 sparse points on the last camera's axis, 4.5 to 4.9 units out (the axes meet at
 * 4), move the object box's centre to their median; 20 points off the photo's middle do not
 * count. */
static void test_box_on_central_points(void)
{
    vf_field *f = make_field();
    vf_field_train_options opt = small_training(4, 1);
    vf_field_trainer *t = NULL;
    CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "create");
    add_views(t, f, 3);
    const double *m = t->views[t->view_count - 1].c2w;
    const double eye[3] = {m[3], m[7], m[11]}, ahead[3] = {-m[2], -m[6], -m[10]};
    const double right[3] = {m[0], m[4], m[8]};
    double points[3 * 60], want[3];
    for (int i = 0; i < 60; i++) {
        const double along = i < 40 ? 4.5 + 0.01 * i : 4.0, side = i < 40 ? 0.05 : 1.0;
        for (int a = 0; a < 3; a++)
            points[3 * i + a] = eye[a] + along * ahead[a] + side * right[a];
    }
    for (int a = 0; a < 3; a++) /* the median of 40: between the 20th and the 21st */
        want[a] = eye[a] + 4.695 * ahead[a] + 0.05 * right[a];
    CHECK(vf_field_trainer_add_view_points(t, points, 60) == VF_OK && t->depth_count == 60,
          "all 60 points in view (%zu)", t->depth_count);
    CHECK(vf_field_trainer_start(t) == VF_OK, "start: %s", vf_error_message());
    const field_grid *g = &vf_field_trainer_field(t)->grids[0];
    double off = 0;
    for (int a = 0; a < 3; a++) {
        const double c = 0.5 * (g->lo[a] + g->hi[a]);
        off = fmax(off, fabs(c - want[a]));
    }
    printf("object box centre %.3f from the central points' median (voxel %.3f)\n", off,
           g->voxel);
    /* the lattice is centred on the box; points are rebuilt from their pixels' rays */
    CHECK(off < 0.6 * g->voxel + 0.02, "object box centred %.3f off the central points", off);
    vf_field_trainer_free(t);
    vf_field_free(f);
}

/* Object mode's cut (vf_field_cut_object) on a known scene: ball A (the object) and ball B
 * (clutter) on a slab (the surface). Six views' masks are discs round A's projection, one
 * of them empty (a failed cut-out): the vote keeps A (but for what no view sees) and drops
 * B; the slab under A, inside most masks, goes with the plane only; the silhouette is A's. */
/* The mask of a ball (centre, radius) in the view of cam from c2w: its disc, `scale` times
 * as wide (a cut-out with a margin: 1.3). */
static void ball_mask(const vf_camera *cam, const double c2w[16], const double centre[3],
                      double radius, double scale, uint8_t *mask)
{
    double rot[9], t[3], pc[3], u, w;
    vf_c2w_gl_to_w2c_cv(c2w, rot, t);
    vf_mat3_apply(rot, centre, pc);
    for (int k = 0; k < 3; k++)
        pc[k] += t[k];
    vf_camera_project(cam, pc, &u, &w);
    const double r = scale * cam->fx * radius / pc[2];
    for (int y = 0; y < cam->height; y++)
        for (int x = 0; x < cam->width; x++)
            mask[y * cam->width + x] =
                (x + 0.5 - u) * (x + 0.5 - u) + (y + 0.5 - w) * (y + 0.5 - w) < r * r;
}

static void test_object_cut(void)
{
    enum { VIEWS = 6, SIDE = 64 };
    const vf_camera cam = {.width = SIDE, .height = SIDE, .fx = 80, .fy = 80, .cx = 32, .cy = 32};
    const double a_centre[3] = {-0.4, 0.1, 0.2}; /* make_sparse_field's first ball */
    vf_field_cut_view views[VIEWS];
    static uint8_t masks[VIEWS][SIDE * SIDE];
    for (int i = 0; i < VIEWS; i++) {
        const vf_viewpoint v = {.psi = 60.0 * i, .theta = 30};
        views[i].camera = cam;
        vf_viewpoint_to_c2w(&v, views[i].c2w);
        views[i].mask = masks[i];
        ball_mask(&cam, views[i].c2w, a_centre, 0.25, 1.3, masks[i]);
        if (i == 2)
            memset(masks[i], 0, sizeof masks[i]);
    }
    /* z = 0: A reaches down to -0.05, so the plane and its clearance of 0.02 take A's bottom */
    const double plane[4] = {0, 0, 1, 0};
    for (int with_plane = 0; with_plane < 2; with_plane++) {
        vf_field *f = make_sparse_field();
        field_grid *g = &f->grids[0];
        const float d_min =
            vf__field_density_threshold(f, FIELD_VISIBLE_ALPHA, f->step_ratio * g->voxel);
        for (size_t i = 0; i < g->points; i++)
            if (fabsf(g->lo[2] + g->voxel * (float)(i / (48 * 48)) + 0.175f) < 0.075f)
                g->values[i * FIELD_CH + FIELD_CH_DENSITY] = 2.0f; /* the slab, just under A */
        int a_total = 0, a_kept = 0, a_above = 0, b_kept = 0, slab_kept = 0;
        char *was = calloc(g->points, 1);
        for (size_t i = 0; i < g->points; i++)
            was[i] = g->values[i * FIELD_CH + FIELD_CH_DENSITY] >= d_min;
        double kept = -1;
        CHECK(vf_field_cut_object(f, views, VIEWS, 0.5, with_plane ? plane : NULL, 0.02, &kept) ==
                  VF_OK,
              "cut: %s", vf_error_message());
        for (size_t i = 0; i < g->points; i++) {
            if (!was[i])
                continue;
            const double p[3] = {g->lo[0] + g->voxel * (double)(i % 48),
                                 g->lo[1] + g->voxel * (double)(i / 48 % 48),
                                 g->lo[2] + g->voxel * (double)(i / (48 * 48))};
            const int on = g->values[i * FIELD_CH + FIELD_CH_DENSITY] >= d_min;
            double da = 0;
            for (int k = 0; k < 3; k++)
                da += (p[k] - a_centre[k]) * (p[k] - a_centre[k]);
            if (p[2] < -0.1)
                slab_kept += on;
            else if (da < 0.3 * 0.3)
                a_total++, a_kept += on, a_above += p[2] >= 0.02;
            else
                b_kept += on;
        }
        free(was);
        printf("object cut %s the plane: ball A %d of %d points kept (%d above the plane's "
               "clearance), ball B %d, slab %d; kept share %.3f\n",
               with_plane ? "with" : "without", a_kept, a_total, a_above, b_kept, slab_kept,
               kept);
        if (with_plane)
            CHECK(a_above > 100 && a_above < a_total && a_kept == a_above,
                  "the object stays, but for its points under the clearance (%d of %d, %d above)",
                  a_kept, a_total, a_above);
        else /* a point deep inside A that no view sees (behind A's surface by more than the
              * visibility margin in every view) may go: 839 of 840 with one random field */
            CHECK(a_total > 100 && a_kept >= 0.99 * a_total, "the object stays (%d of %d)",
                  a_kept, a_total);
        CHECK(b_kept == 0, "the clutter goes (%d points left)", b_kept);
        /* the masks' discs cover the slab just under A from most views, so the vote keeps a
         * piece of it (26 points): apart from A and small against it, a scrap that goes */
        CHECK(slab_kept == 0, "the slab goes (%d points left)", slab_kept);
        CHECK(f->background[0] == 1 && f->background[1] == 1 && f->background[2] == 1,
              "white background");
        vf_image opacity = {0};
        uint8_t *sil = NULL, *sil_half = NULL;
        CHECK(vf_field_render_opacity(f, &cam, views[0].c2w, &opacity) == VF_OK &&
                  opacity.channels == 1,
              "opacity render");
        CHECK(vf_field_silhouette(f, &cam, views[0].c2w, 0, &sil) == VF_OK &&
                  vf_field_silhouette(f, &cam, views[0].c2w, SIDE / 2, &sil_half) == VF_OK,
              "silhouettes");
        int inside = 0, outside = 0, leaks = 0, same = 0, half_same = 0;
        for (int p = 0; p < SIDE * SIDE; p++) {
            if (masks[0][p])
                inside += sil[p];
            else
                leaks += sil[p], outside++;
            same += sil[p] == (opacity.data[p] > 0.5f);
            half_same += sil[p] == sil_half[p];
        }
        printf("  view 0: %d pixels opaque inside the mask, %d of %d outside; the silhouette "
               "rendered at half size differs at %d pixels\n",
               inside, leaks, outside, SIDE * SIDE - half_same);
        CHECK(inside > 50 && (!with_plane || leaks == 0),
              "the silhouette is the object's (%d in, %d out)", inside, leaks);
        CHECK(same == SIDE * SIDE, "the silhouette is the opacity over a half");
        /* only the outline may move, by a pixel of the half-size render (measured: 15 of 65) */
        CHECK(SIDE * SIDE - half_same < inside / 2, "half-size silhouette (%d pixels differ)",
              SIDE * SIDE - half_same);
        free(sil);
        free(sil_half);
        vf_image_free(&opacity);
        vf_field_free(f);
    }
}

/* Object mode without a support plane (a wall clock: its wall has no points): a view votes
 * on a point only where it sees it. Ball A before a wall, every view from the front: the
 * wall behind A lies inside A's mask (its exact disc) in every view, but the views in which
 * A hides it have no say, and those that see it see it beside A: all of it goes. */
static void test_object_cut_hidden(void)
{
    enum { VIEWS = 5, SIDE = 64 };
    const vf_camera cam = {.width = SIDE, .height = SIDE, .fx = 80, .fy = 80, .cx = 32, .cy = 32};
    const double a_centre[3] = {-0.4, 0.1, 0.2}; /* make_sparse_field's first ball */
    vf_field_cut_view views[VIEWS];
    static uint8_t masks[VIEWS][SIDE * SIDE];
    double towards[3] = {0, 0, 0}; /* the cameras' mean direction from A */
    for (int i = 0; i < VIEWS; i++) {
        const vf_viewpoint v = {.psi = 15.0 * (i - 2), .theta = 20};
        views[i].camera = cam;
        vf_viewpoint_to_c2w(&v, views[i].c2w);
        views[i].mask = masks[i];
        ball_mask(&cam, views[i].c2w, a_centre, 0.25, 1.0, masks[i]);
        for (int k = 0; k < 3; k++)
            towards[k] += views[i].c2w[4 * k + 3] - a_centre[k];
    }
    const double len = sqrt(towards[0] * towards[0] + towards[1] * towards[1] +
                            towards[2] * towards[2]);
    vf_field *f = make_sparse_field();
    field_grid *g = &f->grids[0];
    const float d_min =
        vf__field_density_threshold(f, FIELD_VISIBLE_ALPHA, f->step_ratio * g->voxel);
    int wall = 0, wall_kept = 0, behind = 0, behind_kept = 0, front = 0, front_kept = 0;
    for (int pass = 0; pass < 2; pass++) {
        for (size_t i = 0; i < g->points; i++) {
            const double p[3] = {g->lo[0] + g->voxel * (double)(i % 48),
                                 g->lo[1] + g->voxel * (double)(i / 48 % 48),
                                 g->lo[2] + g->voxel * (double)(i / (48 * 48))};
            double along = 0, r2 = 0;
            for (int k = 0; k < 3; k++)
                along += (p[k] - a_centre[k]) * towards[k] / len;
            for (int k = 0; k < 3; k++) {
                const double off = p[k] - a_centre[k] - along * towards[k] / len;
                r2 += off * off;
            }
            float *d = &g->values[i * FIELD_CH + FIELD_CH_DENSITY];
            const int in_wall = along > -0.55 && along < -0.4 && r2 < 0.45 * 0.45;
            const int in_front = along > 0.05 && r2 + along * along < 0.25 * 0.25;
            if (pass == 0 && in_wall)
                *d = 2.0f; /* the wall, a slab behind A as the cameras see it */
            if (pass == 1) {
                wall += in_wall, wall_kept += in_wall && *d >= d_min;
                behind += in_wall && r2 < 0.2 * 0.2;
                behind_kept += in_wall && r2 < 0.2 * 0.2 && *d >= d_min;
                front += in_front, front_kept += in_front && *d >= d_min;
            }
        }
        if (pass == 0) {
            vf__field_grid_update_occupancy(g, f, f->step_ratio * g->voxel);
            CHECK(vf_field_cut_object(f, views, VIEWS, 0.5, NULL, 0.02, NULL) == VF_OK,
                  "cut: %s", vf_error_message());
        }
    }
    printf("object cut, no plane, views from the front: wall %d of %d points kept (%d of the %d "
           "right behind A), A's front %d of %d\n",
           wall_kept, wall, behind_kept, behind, front_kept, front);
    CHECK(behind > 100 && behind_kept == 0, "the wall behind A goes (%d of %d points left)",
          behind_kept, behind);
    CHECK(wall_kept < 0.05 * wall, "the wall goes (%d of %d points left)", wall_kept, wall);
    CHECK(front > 50 && front_kept == front, "A's front stays (%d of %d)", front_kept, front);
    vf_field_free(f);
}

static void test_checkpoint_resume(void)
{
    vf_field *truth = make_field();
    vf_field_train_options opt = small_training(40, 2);
    char ckpt[512];
    snprintf(ckpt, sizeof ckpt, "%s/train.ckpt", vf_test_tmpdir());

    vf_field_trainer *t = NULL;
    CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "create");
    add_views(t, truth, 12);
    CHECK(vf_field_trainer_start(t) == VF_OK, "start: %s", vf_error_message());
    vf_field_train_status st;
    for (int i = 0; i < 15; i++)
        vf_field_trainer_step(t, &st);
    CHECK(st.step == 15, "15 steps taken (%d)", st.step);
    CHECK(vf_field_trainer_save_checkpoint(t, ckpt) == VF_OK, "checkpoint: %s",
          vf_error_message());

    vf_field_trainer *r = NULL;
    vf_field_trainer_create(&opt, &r);
    add_views(r, truth, 12);
    CHECK(vf_field_trainer_resume(r, ckpt) == VF_OK, "resume: %s", vf_error_message());
    /* the resumed trainer holds exactly the checkpointed field */
    const field_grid *a = &vf_field_trainer_field(t)->grids[0];
    const field_grid *b = &vf_field_trainer_field(r)->grids[0];
    CHECK(a->points == b->points &&
              !memcmp(a->values, b->values, a->points * FIELD_CH * sizeof(float)),
          "a resumed run starts from the checkpointed field");
    vf_field_train_status rs;
    CHECK(vf_field_trainer_step(r, &rs) == VF_OK && rs.step == 16, "resumed at step 16 (%d)",
          rs.step);
    while (!rs.done)
        vf_field_trainer_step(r, &rs);
    CHECK(rs.step == 40, "resumed run ends at the step budget (%d)", rs.step);

    /* other views: rejected */
    vf_field_trainer *other = NULL;
    vf_field_trainer_create(&opt, &other);
    add_views(other, truth, 11);
    CHECK(vf_field_trainer_resume(other, ckpt) == VF_EINPUT, "checkpoint of other views refused");
    vf_field_trainer_free(other);

    /* another budget: refused with a message, not silently replaced by the old one */
    opt.steps = 80;
    vf_field_trainer_create(&opt, &other);
    add_views(other, truth, 12);
    CHECK(vf_field_trainer_resume(other, ckpt) == VF_EINPUT &&
              strstr(vf_error_message(), "budget of 40 steps"),
          "a new budget on resume refused: %s", vf_error_message());
    vf_field_trainer_free(other);

    /* other loss weights: refused naming each (the old check compared the budget, the
     * surroundings and the colour model only, and kept the checkpoint's weights silently) */
    opt.steps = 40;
    vf_field_train_options asked = opt;
    asked.depth = 0, asked.tv_view = 1e-4f, asked.appearance = 1e-3f;
    vf_field_trainer_create(&asked, &other);
    add_views(other, truth, 12);
    const char *message = vf_field_trainer_resume(other, ckpt) == VF_EINPUT ? vf_error_message() : "";
    CHECK(strstr(message, "--depth") && strstr(message, "--view-smoothing") &&
              strstr(message, "--appearance") && !strstr(message, "budget"),
          "other loss weights on resume refused, each named: %s", message);
    vf_field_trainer_free(other);
    vf_field_trainer_free(r);
    vf_field_trainer_free(t);
    vf_field_free(truth);
}

/* Renders of the synthetic field around a ring, every other one darker (two exposures). */
static void add_exposed_views(vf_field_trainer *t, const vf_field *truth)
{
    for (int i = 0; i < 12; i++) {
        vf_viewpoint v = {.psi = -180 + 30.0 * i, .theta = 0, .phi = 40 + 15 * (i % 5)};
        double c2w[16];
        vf_viewpoint_to_c2w(&v, c2w);
        vf_image img = {0};
        vf_field_render(truth, &truth->camera, c2w, &img);
        for (size_t k = 0; k < (size_t)img.width * img.height * 3; k++)
            img.data[k] *= i % 2 ? 0.9f : 0.6f;
        CHECK(vf_field_trainer_add_view(t, &truth->camera, c2w, &img) == VF_OK, "add view");
        vf_image_free(&img);
    }
}

/* Per-photo appearance: photos of one scene at two exposures, taken in turn around the ring.
 * With the appearance learned, the field fits both (training PSNR well above the field that
 * must explain them alone) and the gains tell the two exposures apart; a checkpoint keeps
 * them. */
static void test_appearance(void)
{
    vf_field *truth = make_field();
    char ckpt[512];
    snprintf(ckpt, sizeof ckpt, "%s/appearance.ckpt", vf_test_tmpdir());
    double psnr[2] = {0};
    for (int learn = 0; learn < 2; learn++) {
        vf_field_train_options opt = small_training(300, 1);
        opt.appearance = learn ? 0.01f : 0.0f;
        vf_field_trainer *t = NULL;
        CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "create");
        add_exposed_views(t, truth);
        CHECK(vf_field_trainer_start(t) == VF_OK, "start: %s", vf_error_message());
        CHECK(!learn == !t->appearance, "appearance state only when asked for");
        vf_field_train_status st = {0};
        while (!st.done)
            vf_field_trainer_step(t, &st);
        psnr[learn] = st.psnr;
        if (!learn) {
            vf_field_trainer_free(t);
            continue;
        }
        /* what a photo makes of a mid-grey render, bright photos over dark ones */
        for (int k = 0; k < 3; k++) {
            double bright = 0, dark = 0;
            for (int i = 0; i < 12; i++) {
                const float *a = t->appearance + 6 * i;
                *(i % 2 ? &bright : &dark) += (1 + a[k]) * 0.5 + a[3 + k];
            }
            CHECK(bright / dark > 1.3 && bright / dark < 1.8,
                  "channel %d: bright photos seen %.3f times the dark ones "
                  "(truth 1.5)", k, bright / dark);
        }
        CHECK(vf_field_trainer_save_checkpoint(t, ckpt) == VF_OK, "checkpoint");
        vf_field_trainer *r = NULL;
        vf_field_trainer_create(&opt, &r);
        add_exposed_views(r, truth);
        CHECK(vf_field_trainer_resume(r, ckpt) == VF_OK, "resume: %s", vf_error_message());
        CHECK(r->appearance && r->appearance_t == t->appearance_t &&
                  !memcmp(r->appearance, t->appearance, 3 * 6 * 12 * sizeof(float)),
              "a resumed run keeps the photos' appearance and its moments");
        vf_field_trainer_free(r);
        vf_field_trainer_free(t);
    }
    CHECK(psnr[1] > psnr[0] + 3, "training PSNR %.2f dB with appearance, %.2f without", psnr[1],
          psnr[0]);
    vf_field_free(truth);
}

/* Colour models: a diffuse field never moves its degree-1 harmonics off zero, a view-dependent
 * one does; a checkpoint made with another model is refused naming it. */
static void test_color_models(void)
{
    vf_field *truth = make_field();
    vf_field_train_options opt = small_training(20, 1);
    char ckpt[512];
    snprintf(ckpt, sizeof ckpt, "%s/color.ckpt", vf_test_tmpdir());
    CHECK(opt.color == VF_COLOR_VIEW && opt.tv_view == 0, "default: view-dependent, unsmoothed");
    opt.tv_view = 1e-4f; /* the smoothing a 3D model gets must not stop the view terms */
    for (int diffuse = 0; diffuse < 2; diffuse++) {
        opt.color = diffuse ? VF_COLOR_DIFFUSE : VF_COLOR_VIEW;
        vf_field_trainer *t = NULL;
        CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "create");
        add_views(t, truth, 12);
        CHECK(vf_field_trainer_start(t) == VF_OK, "start: %s", vf_error_message());
        vf_field_train_status st = {0};
        while (!st.done)
            vf_field_trainer_step(t, &st);
        const field_grid *g = &vf_field_trainer_field(t)->grids[0];
        double constant = 0, degree1 = 0;
        for (size_t i = 0; i < g->points; i++)
            for (int ch = FIELD_CH_SH; ch < FIELD_CH_USED; ch++)
                *((ch - FIELD_CH_SH) % 4 ? &degree1 : &constant) +=
                    fabs(g->values[i * FIELD_CH + ch]);
        CHECK(constant > 0 && (diffuse ? degree1 == 0 : degree1 > 0),
              "%s: constant terms %g, degree-1 terms %g", vf_field_color_name(opt.color), constant,
              degree1);
        if (!diffuse)
            CHECK(vf_field_trainer_save_checkpoint(t, ckpt) == VF_OK, "checkpoint");
        vf_field_trainer_free(t);
    }
    vf_field_trainer *other = NULL;
    vf_field_trainer_create(&opt, &other); /* diffuse, on a checkpoint of view */
    add_views(other, truth, 12);
    CHECK(vf_field_trainer_resume(other, ckpt) == VF_EINPUT &&
              strstr(vf_error_message(), "--color view"),
          "a checkpoint of another colour model refused: %s", vf_error_message());
    vf_field_trainer_free(other);
    vf_field_free(truth);
}

/* The automatic options are resolved at start from what the photos are: opaque photos (an
 * outer grid) get the longer ramp and the colour smoothing, photos with alpha the sharp fit;
 * values the caller gave are kept. */
static void test_automatic_options(void)
{
    vf_field *truth = make_field();
    for (int kind = 0; kind < 3; kind++) { /* opaque, with alpha, opaque with explicit values */
        vf_field_train_options opt = small_training(3, 0);
        CHECK(opt.levels == 0 && opt.tv_color < 0 && opt.max_points == 16 * 16 * 16,
              "levels and colour smoothing are automatic by default");
        if (kind == 2) {
            opt.levels = 2;
            opt.tv_color = 0;
        }
        vf_field_trainer *t = NULL;
        CHECK(vf_field_trainer_create(&opt, &t) == VF_OK, "create: %s", vf_error_message());
        add_views_as(t, truth, 8, kind == 1);
        CHECK(vf_field_trainer_start(t) == VF_OK, "start: %s", vf_error_message());
        const vf_field_train_options *used = vf_field_trainer_options(t);
        const int outer = vf_field_trainer_field(t)->grid_count == 2;
        const int want_levels = kind == 2 ? 2 : kind == 0 ? 6 : 3;
        const float want_tv = kind == 0 ? 1e-4f : 0.0f;
        CHECK(outer == (kind != 1) && used->levels == want_levels && used->tv_color == want_tv &&
                  used->max_points == 16 * 16 * 16,
              "case %d: outer grid %d, levels %d, colour smoothing %g, %g points", kind, outer,
              used->levels, (double)used->tv_color, used->max_points);
        vf_field_trainer_free(t);
    }
    vf_field_free(truth);
    /* the automatic grid size follows the budget for opaque photos with an outer grid */
    const double minutes[4] = {0.5, 1, 2, 10}, want[4] = {2e6, 2e6, 4e6, 6e6};
    for (int i = 0; i < 4; i++) {
        vf_field_train_options opt;
        vf_field_train_defaults(&opt);
        opt.seconds = 60 * minutes[i];
        vf__field_resolve_automatic(&opt, 1);
        CHECK(fabs(opt.max_points - want[i]) < 1, "%g minutes: %g points, want %g", minutes[i],
              opt.max_points, want[i]);
    }
    vf_field_train_options with = {.steps = 2250}, without = with;
    vf__field_resolve_automatic(&with, 1);
    vf__field_resolve_automatic(&without, 0);
    CHECK(fabs(with.max_points - 3e6) < 1 && without.max_points == 128.0 * 128 * 128,
          "2250 steps: %g points with an outer grid, %g without", with.max_points,
          without.max_points);
}

/* The empty-space radius of every cell is its Chebyshev distance to the nearest occupied
 * cell (brute force over a 40 x 30 x 20 grid with two occupied cells), capped. */
static void test_empty_radius(void)
{
    field_grid g;
    const int dim[3] = {41, 31, 21}, occupied[2][3] = {{5, 7, 3}, {30, 20, 15}};
    const float lo[3] = {0, 0, 0};
    CHECK(vf__field_grid_alloc(&g, dim, lo, 1.0f) == VF_OK, "alloc");
    const int nx = g.cells[0], ny = g.cells[1], nz = g.cells[2];
    size_t cells = (size_t)nx * ny * nz;
    memset(g.cell_bits, 0, (cells + 63) / 64 * 8);
    for (int k = 0; k < 2; k++) {
        size_t c = (size_t)occupied[k][0] +
                   (size_t)nx * (occupied[k][1] + (size_t)ny * occupied[k][2]);
        g.cell_bits[c >> 6] |= 1ull << (c & 63);
    }
    uint8_t *scratch = malloc(cells);
    vf__field_grid_update_empty_radius(&g, scratch);
    int wrong = 0;
    for (int z = 0; z < nz; z++)
        for (int y = 0; y < ny; y++)
            for (int x = 0; x < nx; x++) {
                int best = FIELD_MAX_RADIUS;
                for (int k = 0; k < 2; k++) {
                    int d = abs(x - occupied[k][0]);
                    d = abs(y - occupied[k][1]) > d ? abs(y - occupied[k][1]) : d;
                    d = abs(z - occupied[k][2]) > d ? abs(z - occupied[k][2]) : d;
                    best = d < best ? d : best;
                }
                wrong += g.empty_radius[(size_t)x + (size_t)nx * (y + (size_t)ny * z)] != best;
            }
    CHECK(wrong == 0, "%d cells with a wrong empty-space radius", wrong);
    free(scratch);
    vf__field_grid_free(&g);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_fast_math);
    CHECK_CASE(test_alpha_table);
    CHECK_CASE(test_empty_radius);
    test_gradients((field_ray_losses){0});
    test_gradients((field_ray_losses){.opaque = 0.7f});
    test_gradients((field_ray_losses){.distortion = 2.0f});
    test_gradients((field_ray_losses){.depth = 3.0f, .depth_target = 0.9f});
    test_gradients((field_ray_losses){0.7f, 2.0f, 3.0f, 1.1f});
    CHECK_CASE(test_render_matches_march);
    CHECK_CASE(test_jumps_skip_only_empty);
    CHECK_CASE(test_model_files);
    CHECK_CASE(test_hostile_models);
    CHECK_CASE(test_adam_small_team);
    CHECK_CASE(test_view_points);
    CHECK_CASE(test_outer_grid_reach);
    CHECK_CASE(test_box_on_central_points);
    CHECK_CASE(test_object_cut);
    CHECK_CASE(test_object_cut_hidden);
    CHECK_CASE(test_checkpoint_resume);
    CHECK_CASE(test_color_models);
    CHECK_CASE(test_appearance);
    CHECK_CASE(test_automatic_options);
    CHECK_CASE(test_render_stop_renormalizes);
    return check_finish();
}
