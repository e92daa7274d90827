/* Shared by src/plot only: text drawing and writing the surface out. */
#ifndef VF_PLOT_INTERNAL_H
#define VF_PLOT_INTERNAL_H

#include <cairo.h>

#include "vf/error.h"

typedef enum { PLOT_ALIGN_LEFT, PLOT_ALIGN_CENTRE, PLOT_ALIGN_RIGHT } plot_align;

/* Draw text in the current colour with its baseline at y, aligned on x. */
void vf__plot_text(cairo_t *cr, double x, double y, double size, const char *text,
                   plot_align align);

/* Write the surface to path as PNG and release cr and surface (always). */
vf_status vf__plot_finish(cairo_surface_t *surface, cairo_t *cr, const char *path);

#endif
