/* The attack stage's pictures: v_star.png, samples.png, loss.png, fluctuation.png. */
#include "attack_internal.h"

#include <stdio.h>
#include <stdlib.h>

#include "vf/classifier.h"
#include "vf/fsutil.h"
#include "vf/plot.h"

#define SHEET_SAMPLES 24 /* samples of p*(v) on the contact sheet */

static vf_status write_sheet(const char *path, vf_view_loss *vl, const vf_attack_eval *ev)
{
    int n = ev->sample_count < SHEET_SAMPLES ? ev->sample_count : SHEET_SAMPLES;
    vf_image images[SHEET_SAMPLES] = {{0}};
    char text[SHEET_SAMPLES][160];
    const char *captions[SHEET_SAMPLES];
    int mark[SHEET_SAMPLES];
    vf_status status = VF_OK;
    for (int i = 0; i < n && status == VF_OK; i++) {
        const vf_view_prediction *p = &ev->sample_pred[i];
        const double *v = ev->samples + VF_VIEW_DIM * i;
        status = vf_view_loss_render(vl, v, &images[i]);
        snprintf(text[i], sizeof text[i], "%.26s %.0f%%\npsi %.0f theta %.0f phi %.0f",
                 vf_class_short_name(p->top_class), 100.0 * p->top_prob, v[0], v[1], v[2]);
        captions[i] = text[i];
        mark[i] = !p->correct;
    }
    if (status == VF_OK)
        status = vf_contact_sheet(path, images, captions, mark, n, 6);
    for (int i = 0; i < n; i++)
        vf_image_free(&images[i]);
    return status;
}

static vf_status write_loss_plot(const char *path, const vf_attack_state *st)
{
    int n = st->step;
    double *x = malloc(3 * (size_t)(n ? n : 1) * sizeof *x), *mean = x + n, *top = x + 2 * n;
    if (!x)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int s = 0; s < n; s++) {
        x[s] = s + 1;
        mean[s] = st->history[s].mean_loss;
        top[s] = st->history[s].max_loss;
    }
    vf_plot_series series[2] = {{"mean over the step", x, mean, n},
                                {"highest of the step", x, top, n}};
    vf_plot_axes axes = {"ViewFool: cross-entropy of the true label set", "step",
                         "cross-entropy (nats)", 0, 0};
    vf_status status = vf_plot_lines(path, &axes, series, 2);
    free(x);
    return status;
}

static vf_status write_fluctuation_plot(const char *path, const vf_attack_eval *ev)
{
    double r[VF_FLUCT_LEVELS], asr[VF_FLUCT_LEVELS];
    for (int i = 0; i < VF_FLUCT_LEVELS; i++) {
        r[i] = i + 1;
        asr[i] = 100 * ev->fluct_asr[i];
    }
    vf_plot_series series = {"ASR", r, asr, VF_FLUCT_LEVELS};
    vf_plot_axes axes = {"Camera fluctuation around v*", "r (% of each parameter's range)",
                         "attack success rate (%)", 0, 100};
    return vf_plot_lines(path, &axes, &series, 1);
}

vf_status vf__attack_write_pictures(const char *dir, vf_view_loss *vl, const vf_attack_state *st,
                                    const vf_attack_eval *ev)
{
    char path[VF_PATH_MAX];
    vf_image img = {0};
    vf_status status = vf_view_loss_render(vl, ev->v_star, &img);
    if (status == VF_OK && (status = vf_path_join(path, sizeof path, dir, "v_star.png")) == VF_OK)
        status = vf_image_save(path, &img);
    vf_image_free(&img);
    if (status == VF_OK && (status = vf_path_join(path, sizeof path, dir, "samples.png")) == VF_OK)
        status = write_sheet(path, vl, ev);
    if (status == VF_OK && st && st->step > 0 &&
        (status = vf_path_join(path, sizeof path, dir, "loss.png")) == VF_OK)
        status = write_loss_plot(path, st);
    if (status == VF_OK &&
        (status = vf_path_join(path, sizeof path, dir, "fluctuation.png")) == VF_OK)
        status = write_fluctuation_plot(path, ev);
    return status;
}
