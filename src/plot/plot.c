/* Line charts with cairo (vf/plot.h). */
#include "vf/plot.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>

#include "plot_internal.h"

#define WIDTH 800
#define HEIGHT 500
#define LEFT 80
#define RIGHT 30
#define TOP 50
#define BOTTOM 60

static const double palette[][3] = {
    {0.12, 0.47, 0.71}, {0.84, 0.15, 0.16}, {0.17, 0.63, 0.17}, {0.58, 0.40, 0.74},
    {1.00, 0.50, 0.05}, {0.55, 0.34, 0.29},
};

/* A "nice" tick step (1, 2 or 5 times a power of ten) giving about `ticks` ticks over span. */
static double tick_step(double span, int ticks)
{
    double raw = span / ticks, mag = pow(10, floor(log10(raw)));
    double f = raw / mag;
    return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * mag;
}

static void data_range(const vf_plot_series *s, int count, double *x0, double *x1, double *y0,
                       double *y1)
{
    *x0 = *y0 = INFINITY;
    *x1 = *y1 = -INFINITY;
    for (int k = 0; k < count; k++)
        for (int i = 0; i < s[k].n; i++) {
            *x0 = fmin(*x0, s[k].x[i]);
            *x1 = fmax(*x1, s[k].x[i]);
            *y0 = fmin(*y0, s[k].y[i]);
            *y1 = fmax(*y1, s[k].y[i]);
        }
    if (*x1 <= *x0)
        *x1 = *x0 + 1;
    if (*y1 <= *y0) {
        *y0 -= 0.5;
        *y1 += 0.5;
    }
}

static void draw_axes(cairo_t *cr, const vf_plot_axes *axes, double x0, double x1, double y0,
                      double y1)
{
    const double pw = WIDTH - LEFT - RIGHT, ph = HEIGHT - TOP - BOTTOM;
    char text[64];
    cairo_set_line_width(cr, 1);
    double xs = tick_step(x1 - x0, 8), ys = tick_step(y1 - y0, 6);
    for (double t = ceil(y0 / ys) * ys; t <= y1 + 1e-9 * ys; t += ys) {
        double py = TOP + ph * (1 - (t - y0) / (y1 - y0));
        cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
        cairo_move_to(cr, LEFT, py);
        cairo_line_to(cr, LEFT + pw, py);
        cairo_stroke(cr);
        snprintf(text, sizeof text, "%g", fabs(t) < 1e-12 * ys ? 0.0 : t);
        cairo_set_source_rgb(cr, 0, 0, 0);
        vf__plot_text(cr, LEFT - 8, py + 4, 12, text, PLOT_ALIGN_RIGHT);
    }
    for (double t = ceil(x0 / xs) * xs; t <= x1 + 1e-9 * xs; t += xs) {
        double px = LEFT + pw * (t - x0) / (x1 - x0);
        cairo_set_source_rgb(cr, 0.9, 0.9, 0.9);
        cairo_move_to(cr, px, TOP);
        cairo_line_to(cr, px, TOP + ph);
        cairo_stroke(cr);
        snprintf(text, sizeof text, "%g", t);
        cairo_set_source_rgb(cr, 0, 0, 0);
        vf__plot_text(cr, px, TOP + ph + 18, 12, text, PLOT_ALIGN_CENTRE);
    }
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_rectangle(cr, LEFT, TOP, pw, ph);
    cairo_stroke(cr);
    vf__plot_text(cr, WIDTH / 2.0, 30, 16, axes->title ? axes->title : "", PLOT_ALIGN_CENTRE);
    vf__plot_text(cr, LEFT + pw / 2, HEIGHT - 15, 13, axes->x_label ? axes->x_label : "",
                  PLOT_ALIGN_CENTRE);
    cairo_save(cr);
    cairo_translate(cr, 22, TOP + ph / 2);
    cairo_rotate(cr, -M_PI / 2);
    vf__plot_text(cr, 0, 0, 13, axes->y_label ? axes->y_label : "", PLOT_ALIGN_CENTRE);
    cairo_restore(cr);
}

static void draw_series(cairo_t *cr, const vf_plot_series *s, const double *rgb, double x0,
                        double x1, double y0, double y1)
{
    const double pw = WIDTH - LEFT - RIGHT, ph = HEIGHT - TOP - BOTTOM;
    cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
    cairo_set_line_width(cr, 2);
    for (int i = 0; i < s->n; i++) {
        double px = LEFT + pw * (s->x[i] - x0) / (x1 - x0);
        double py = TOP + ph * (1 - (fmin(fmax(s->y[i], y0), y1) - y0) / (y1 - y0));
        if (i == 0)
            cairo_move_to(cr, px, py);
        else
            cairo_line_to(cr, px, py);
    }
    cairo_stroke(cr);
    for (int i = 0; s->n <= 30 && i < s->n; i++) {
        double px = LEFT + pw * (s->x[i] - x0) / (x1 - x0);
        double py = TOP + ph * (1 - (fmin(fmax(s->y[i], y0), y1) - y0) / (y1 - y0));
        cairo_arc(cr, px, py, 4, 0, 2 * M_PI);
        cairo_fill(cr);
    }
}

vf_status vf_plot_lines(const char *path, const vf_plot_axes *axes, const vf_plot_series *series,
                        int count)
{
    int points = 0;
    for (int k = 0; k < count; k++)
        points += series[k].n;
    if (count < 1 || points < 1)
        return vf_fail(VF_EINPUT, "nothing to plot in %s", path);
    double x0, x1, y0, y1;
    data_range(series, count, &x0, &x1, &y0, &y1);
    if (axes->y_min < axes->y_max) {
        y0 = axes->y_min;
        y1 = axes->y_max;
    }
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, WIDTH, HEIGHT);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    draw_axes(cr, axes, x0, x1, y0, y1);
    int colours = (int)(sizeof palette / sizeof palette[0]);
    for (int k = 0; k < count; k++) {
        const double *rgb = palette[k % colours];
        draw_series(cr, &series[k], rgb, x0, x1, y0, y1);
        if (count > 1 && series[k].name) { /* legend, top right inside the plot */
            double ly = TOP + 20 + 18 * k;
            cairo_set_source_rgb(cr, rgb[0], rgb[1], rgb[2]);
            cairo_rectangle(cr, WIDTH - RIGHT - 180, ly - 9, 20, 4);
            cairo_fill(cr);
            cairo_set_source_rgb(cr, 0, 0, 0);
            vf__plot_text(cr, WIDTH - RIGHT - 152, ly - 3, 12, series[k].name, PLOT_ALIGN_LEFT);
        }
    }
    return vf__plot_finish(surface, cr, path);
}
