/* Image grids with captions, and the text and PNG helpers of src/plot (vf/plot.h). */
#include <cairo.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#include "plot_internal.h"
#include "vf/plot.h"

#define CAPTION_HEIGHT 36
#define GAP 4

void vf__plot_text(cairo_t *cr, double x, double y, double size, const char *text,
                   plot_align align)
{
    cairo_text_extents_t ext;
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, text, &ext);
    double left = align == PLOT_ALIGN_LEFT     ? x
                  : align == PLOT_ALIGN_CENTRE ? x - ext.width / 2 - ext.x_bearing
                                               : x - ext.width - ext.x_bearing;
    cairo_move_to(cr, left, y);
    cairo_show_text(cr, text);
}

vf_status vf__plot_finish(cairo_surface_t *surface, cairo_t *cr, const char *path)
{
    cairo_surface_flush(surface);
    cairo_status_t st = cairo_status(cr);
    if (st == CAIRO_STATUS_SUCCESS)
        st = cairo_surface_write_to_png(surface, path);
    cairo_destroy(cr);
    cairo_surface_destroy(surface);
    if (st != CAIRO_STATUS_SUCCESS)
        return vf_fail(VF_EINTERNAL, "cannot draw %s: %s", path, cairo_status_to_string(st));
    return VF_OK;
}

/* Copy an RGB float image into the surface at (x0, y0), cropped to w x h. */
static void blit(cairo_surface_t *surface, const vf_image *img, int x0, int y0, int w, int h)
{
    unsigned char *base = cairo_image_surface_get_data(surface);
    int stride = cairo_image_surface_get_stride(surface);
    for (int y = 0; y < h && y < img->height; y++) {
        uint32_t *row = (uint32_t *)(base + (size_t)(y0 + y) * stride) + x0;
        for (int x = 0; x < w && x < img->width; x++) {
            const float *p = img->data + ((size_t)y * img->width + x) * img->channels;
            uint32_t c[3];
            for (int k = 0; k < 3; k++) {
                float v = p[img->channels >= 3 ? k : 0];
                v = v < 0 ? 0 : v > 1 ? 1 : v;
                c[k] = (uint32_t)(v * 255.0f + 0.5f);
            }
            row[x] = 0xff000000u | c[0] << 16 | c[1] << 8 | c[2];
        }
    }
    cairo_surface_mark_dirty(surface);
}

vf_status vf_contact_sheet(const char *path, const vf_image *images, const char *const *captions,
                           const int *mark, int n, int columns)
{
    if (n < 1 || columns < 1)
        return vf_fail(VF_EINPUT, "no images for the contact sheet %s", path);
    int tw = images[0].width, th = images[0].height;
    int rows = (n + columns - 1) / columns;
    int cols = n < columns ? n : columns;
    int width = GAP + cols * (tw + GAP), height = GAP + rows * (th + CAPTION_HEIGHT + GAP);
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 0.25, 0.25, 0.25);
    cairo_paint(cr);
    cairo_surface_flush(surface);
    for (int i = 0; i < n; i++) {
        int x = GAP + (i % columns) * (tw + GAP);
        int y = GAP + (i / columns) * (th + CAPTION_HEIGHT + GAP);
        blit(surface, &images[i], x, y, tw, th);
        if (mark)
            cairo_set_source_rgb(cr, mark[i] ? 0.75 : 0.15, mark[i] ? 0.1 : 0.55, 0.1);
        else
            cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
        cairo_rectangle(cr, x, y + th, tw, CAPTION_HEIGHT);
        cairo_fill(cr);
        cairo_set_source_rgb(cr, 1, 1, 1);
        char line[2][128] = {"", ""};
        const char *text = captions && captions[i] ? captions[i] : "";
        const char *nl = strchr(text, '\n');
        snprintf(line[0], sizeof line[0], "%.*s", nl ? (int)(nl - text) : (int)strlen(text), text);
        if (nl)
            snprintf(line[1], sizeof line[1], "%s", nl + 1);
        vf__plot_text(cr, x + 4, y + th + 15, 11, line[0], PLOT_ALIGN_LEFT);
        vf__plot_text(cr, x + 4, y + th + 30, 11, line[1], PLOT_ALIGN_LEFT);
    }
    return vf__plot_finish(surface, cr, path);
}
