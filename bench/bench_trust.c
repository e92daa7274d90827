/* bench_trust: does a viewpoint's gap to the photos (vf/view_coverage.h) predict how wrong the
 * field is there? Calibration of VF_TRUST_GAP_DEG on finished workspaces, no training:
 *
 *   - every held-out photo of the train stage (WS/train/report.json): its PSNR against the
 *     render at its pose, and its gap to the photos the field was trained on;
 *   - every view of every `real` run (WS/real/NAME/real.json, 3D-model workspaces): the PSNR
 *     of the field's render against Blender's render of the model there, whether the
 *     classifier's answers on the two agree (fooled or not), and the view's gap.
 *
 * Prints, per source and pooled over the workspaces, the views in bins of gap with their
 * median PSNR and agreement, the Spearman correlation of gap and PSNR, and how many of the
 * views the object itself says are adversarial (Real) the threshold would keep. --plot PATH
 * draws the median PSNR per bin of each source.
 *
 * usage: bench_trust WS... [--plot PATH] */
#include <dirent.h>
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/dataset.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/plot.h"
#include "vf/stats.h"
#include "vf/view_coverage.h"
#include "vf/workspace.h"

#define MAX_POINTS 20000
static const double bin_edges[] = {0, 5, 10, 15, 20, 30, 45, 60, 90, 180};
#define BINS ((int)(sizeof bin_edges / sizeof bin_edges[0]) - 1)

typedef struct point {
    double gap, psnr;
    int agree;       /* field and object agree on fooled (-1: no object) */
    int real_fooled; /* the object's render fools the classifier (-1: no object) */
} point;

typedef struct source {
    const char *name;
    point *p;
    int n;
} source;

static void add(source *s, point p)
{
    if (s->n < MAX_POINTS)
        s->p[s->n++] = p;
}

static const char *base(const char *path)
{
    const char *slash = strrchr(path, '/');
    return slash ? slash + 1 : path;
}

static int has_name(json_t *held, const char *image)
{
    size_t i;
    json_t *h;
    json_array_foreach(held, i, h) if (!strcmp(json_string_value(json_object_get(h, "image")) ?: "",
                                               image)) return 1;
    return 0;
}

/* The cameras the field trained on (the training views minus the held-out ones), and the
 * held-out photos' points. */
static double *trained_cameras(const vf_workspace *ws, json_t *report, int *count, source *held_out)
{
    vf_dataset ds;
    if (vf_dataset_load_training(ws, &ds, NULL) != VF_OK)
        return NULL;
    json_t *held = json_object_get(report, "held_out");
    double *c2w = malloc(16 * sizeof(double) * (size_t)ds.count);
    int n = 0;
    for (int i = 0; i < ds.count; i++)
        if (!has_name(held, base(ds.frames[i].image_path)))
            memcpy(c2w + 16 * n++, ds.frames[i].c2w, 16 * sizeof(double));
    size_t k;
    json_t *h;
    json_array_foreach(held, k, h)
    {
        const char *image = json_string_value(json_object_get(h, "image"));
        for (int i = 0; image && i < ds.count; i++)
            if (!strcmp(base(ds.frames[i].image_path), image)) {
                vf_view_trust t = vf_view_trust_of_pose(c2w, n, ds.frames[i].c2w);
                add(held_out,
                    (point){t.gap_deg, json_real_value(json_object_get(h, "psnr")), -1, -1});
            }
    }
    vf_dataset_free(&ds);
    *count = n;
    return c2w;
}

/* Every view of every real.json under WS/real/. */
static void real_views(const char *root, const double *c2w, int n, source *out)
{
    char dir[VF_PATH_MAX], path[VF_PATH_MAX + 300];
    snprintf(dir, sizeof dir, "%s/real", root);
    DIR *d = opendir(dir);
    struct dirent *e;
    while (d && (e = readdir(d))) {
        if (e->d_name[0] == '.')
            continue;
        snprintf(path, sizeof path, "%s/%s/real.json", dir, e->d_name);
        json_t *doc = json_load_file(path, 0, NULL);
        size_t i;
        json_t *v;
        json_array_foreach(json_object_get(doc, "views"), i, v)
        {
            double view[VF_VIEW_DIM];
            for (int k = 0; k < VF_VIEW_DIM; k++)
                view[k] = json_number_value(json_array_get(json_object_get(v, "view"), k));
            vf_view_trust t = vf_view_trust_of(c2w, n, view);
            int ff = json_is_true(json_object_get(json_object_get(v, "field"), "fooled"));
            int rf = json_is_true(json_object_get(json_object_get(v, "real"), "fooled"));
            add(out,
                (point){t.gap_deg, json_number_value(json_object_get(v, "psnr")), ff == rf, rf});
        }
        json_decref(doc);
    }
    if (d)
        closedir(d);
}

/* Prints the bins; x/y get each non-empty bin's middle and median PSNR (returns how many). */
static int report(const source *s, double *x, double *y)
{
    double *gap = malloc(sizeof(double) * 2 * (size_t)(s->n + 1)), *db = gap + s->n;
    for (int i = 0; i < s->n; i++) {
        gap[i] = s->p[i].gap;
        db[i] = s->p[i].psnr;
    }
    printf("%s: %d views, Spearman(gap, PSNR) %.3f\n", s->name, s->n, vf_spearman(gap, db, s->n));
    free(gap);
    printf("  %-12s %6s %12s %10s %10s\n", "gap (deg)", "views", "median PSNR", "agree",
           "Real kept");
    double *psnr = malloc(sizeof(double) * (size_t)(s->n + 1));
    int bins = 0, fooled_all = 0, fooled_kept = 0;
    for (int i = 0; i < s->n; i++)
        if (s->p[i].real_fooled == 1) {
            fooled_all++;
            fooled_kept += s->p[i].gap <= VF_TRUST_GAP_DEG;
        }
    for (int b = 0; b < BINS; b++) {
        int n = 0, agree = 0, known = 0;
        for (int i = 0; i < s->n; i++)
            if (s->p[i].gap >= bin_edges[b] && s->p[i].gap < bin_edges[b + 1]) {
                psnr[n++] = s->p[i].psnr;
                if (s->p[i].agree >= 0) {
                    known++;
                    agree += s->p[i].agree;
                }
            }
        if (!n)
            continue;
        double m = vf_median(psnr, n);
        char range[32], agreement[16] = "-";
        snprintf(range, sizeof range, "[%g, %g)", bin_edges[b], bin_edges[b + 1]);
        if (known)
            snprintf(agreement, sizeof agreement, "%.1f%%", 100.0 * agree / known);
        printf("  %-12s %6d %9.2f dB %10s\n", range, n, m, agreement);
        x[bins] = 0.5 * (bin_edges[b] + bin_edges[b + 1]);
        y[bins++] = m;
    }
    if (fooled_all)
        printf("  views the object itself says fool the classifier: %d, within %.0f deg: %d "
               "(%.1f%%)\n",
               fooled_all, VF_TRUST_GAP_DEG, fooled_kept, 100.0 * fooled_kept / fooled_all);
    free(psnr);
    return bins;
}

int main(int argc, char **argv)
{
    const char *plot = NULL;
    source held = {"held-out photos", calloc(MAX_POINTS, sizeof(point)), 0};
    source real = {"`real` views (field vs model)", calloc(MAX_POINTS, sizeof(point)), 0};
    int workspaces = 0;
    vf_log_set_quiet(1);
    for (int a = 1; a < argc; a++) {
        if (!strcmp(argv[a], "--plot") && a + 1 < argc) {
            plot = argv[++a];
            continue;
        }
        if (argv[a][0] == '-') {
            fprintf(stderr, "usage: bench_trust WS... [--plot PATH]\n");
            return 1;
        }
        vf_workspace ws;
        char path[VF_PATH_MAX + 32];
        snprintf(path, sizeof path, "%s/train/report.json", argv[a]);
        json_t *rep = json_load_file(path, 0, NULL);
        int n = 0;
        double *c2w = NULL;
        if (rep && vf_workspace_open(argv[a], 0, &ws) == VF_OK) {
            int before = held.n;
            c2w = trained_cameras(&ws, rep, &n, &held);
            if (c2w) {
                int real_before = real.n;
                real_views(argv[a], c2w, n, &real);
                printf("%s: %d trained photos, %d held out, %d views of real\n", argv[a], n,
                       held.n - before, real.n - real_before);
                workspaces++;
            }
            vf_workspace_close(&ws);
        }
        if (!c2w)
            fprintf(stderr, "bench_trust: %s: no trained field (%s)\n", argv[a],
                    vf_error_message());
        free(c2w);
        json_decref(rep);
    }
    if (!workspaces)
        return 2;
    double x[2][BINS], y[2][BINS];
    int nx[2] = {report(&held, x[0], y[0]), real.n ? report(&real, x[1], y[1]) : 0};
    if (plot) {
        vf_plot_series series[2] = {{held.name, x[0], y[0], nx[0]}, {real.name, x[1], y[1], nx[1]}};
        vf_plot_axes axes = {"Render error against the gap to the nearest photo",
                             "gap to the nearest trained photo (degrees, bin middle)",
                             "median PSNR (dB)", 0, 0};
        if (vf_plot_lines(plot, &axes, series, nx[1] ? 2 : 1) != VF_OK)
            fprintf(stderr, "bench_trust: %s\n", vf_error_message());
    }
    free(held.p);
    free(real.p);
    return 0;
}
