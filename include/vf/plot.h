/* vf/plot.h: small PNG pictures for reports, drawn with cairo.
 *
 * Two kinds: a line chart (one or more series on shared axes, with a legend) and a contact
 * sheet (a grid of images, each with a caption bar, for example a sample's predicted class).
 * Files are written directly (inside a stage's staging folder that is atomic enough).
 * Everything passed in is borrowed; nothing is kept. */
#ifndef VF_PLOT_H
#define VF_PLOT_H

#include "vf/error.h"
#include "vf/image.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_plot_series {
    const char *name; /* legend entry */
    const double *x, *y;
    int n;
} vf_plot_series;

typedef struct vf_plot_axes {
    const char *title, *x_label, *y_label;
    double y_min, y_max; /* fixed y range when y_min < y_max, else fitted to the data */
} vf_plot_axes;

/* A 800 x 500 line chart of `count` series (each drawn with points when it has few) to
 * path (.png). VF_EINPUT when there is nothing to draw, VF_EINTERNAL when cairo fails. */
vf_status vf_plot_lines(const char *path, const vf_plot_axes *axes, const vf_plot_series *series,
                        int count);

/* A grid of n RGB images (any sizes; tiles take the first image's size), `columns` across,
 * each above a caption of up to two lines ("\n" separated). mark (may be NULL): per image,
 * 1 draws the caption bar red, 0 green (fooled / correctly classified). */
vf_status vf_contact_sheet(const char *path, const vf_image *images, const char *const *captions,
                           const int *mark, int n, int columns);

#ifdef __cplusplus
}
#endif
#endif
