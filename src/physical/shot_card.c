/* The export's shot card (shot_card.h), drawn with cairo. */
#include "shot_card.h"

#include <cairo.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>

#include "vf/fsutil.h"

#define COLUMNS 4
#define PREVIEW 200 /* the preview and the photo are drawn fitted in squares of this side */
#define TILE_W (2 * PREVIEW + 24)
#define LINE_H 15
#define TILE_H (PREVIEW + 30 + LINE_H * (SHOT_CARD_LINES + 1) + 12)
#define MARGIN 16
#define HEADING_H 40

/* A cairo surface holding a float RGB image. */
static cairo_surface_t *preview_surface(const vf_image *img)
{
    cairo_surface_t *s = cairo_image_surface_create(CAIRO_FORMAT_RGB24, img->width, img->height);
    if (cairo_surface_status(s) != CAIRO_STATUS_SUCCESS)
        return s;
    cairo_surface_flush(s);
    unsigned char *data = cairo_image_surface_get_data(s);
    int stride = cairo_image_surface_get_stride(s);
    for (int y = 0; y < img->height; y++) {
        uint32_t *row = (uint32_t *)(data + (size_t)y * stride);
        for (int x = 0; x < img->width; x++) {
            const float *p = img->data + ((size_t)y * img->width + x) * img->channels;
            uint32_t c[3];
            for (int k = 0; k < 3; k++) {
                float v = p[img->channels >= 3 ? k : 0];
                c[k] = (uint32_t)lrintf(255.0f * (v < 0 ? 0 : v > 1 ? 1 : v));
            }
            row[x] = (c[0] << 16) | (c[1] << 8) | c[2];
        }
    }
    cairo_surface_mark_dirty(s);
    return s;
}

/* img fitted in the square at (x, y), keeping its aspect; a grey square saying `missing`
 * when there is none. */
static void draw_fitted(cairo_t *cr, const vf_image *img, double x, double y, const char *missing)
{
    if (!img || !img->data) {
        cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
        cairo_rectangle(cr, x, y, PREVIEW, PREVIEW);
        cairo_fill(cr);
        cairo_set_source_rgb(cr, 0.4, 0.4, 0.4);
        cairo_set_font_size(cr, 11);
        cairo_move_to(cr, x + 10, y + PREVIEW / 2.0);
        cairo_show_text(cr, missing);
        return;
    }
    double s = (double)PREVIEW / (img->width > img->height ? img->width : img->height);
    cairo_surface_t *surface = preview_surface(img);
    cairo_save(cr);
    cairo_translate(cr, x + (PREVIEW - s * img->width) / 2, y + (PREVIEW - s * img->height) / 2);
    cairo_scale(cr, s, s);
    cairo_set_source_surface(cr, surface, 0, 0);
    cairo_paint(cr);
    cairo_restore(cr);
    cairo_surface_destroy(surface);
}

static void draw_tile(cairo_t *cr, const shot_tile *t, double x0, double y0)
{
    double px = x0 + 4, py = y0 + 24;
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
    cairo_set_font_size(cr, 13);
    cairo_move_to(cr, x0 + 4, y0 + 16);
    cairo_show_text(cr, t->title);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    draw_fitted(cr, t->preview, px, py, "no preview (no trained field)");
    draw_fitted(cr, t->photo, px + PREVIEW + 8, py, "no photo");
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    cairo_set_font_size(cr, 11.5);
    cairo_move_to(cr, px, py + PREVIEW + 14);
    cairo_show_text(cr, "the field's render here");
    cairo_move_to(cr, px + PREVIEW + 8, py + PREVIEW + 14);
    cairo_show_text(cr, "the nearest photo");
    for (int i = 0; i < SHOT_CARD_LINES && t->lines[i][0]; i++) {
        cairo_move_to(cr, px, py + PREVIEW + 18 + LINE_H * (i + 1));
        cairo_show_text(cr, t->lines[i]);
    }
}

vf_status vf__shot_card_save(const char *path, const char *heading, const shot_tile *tiles,
                             int count)
{
    int cols = count < COLUMNS ? (count > 0 ? count : 1) : COLUMNS;
    int rows = (count + COLUMNS - 1) / COLUMNS;
    int width = 2 * MARGIN + cols * TILE_W, height = 2 * MARGIN + HEADING_H + rows * TILE_H;
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
    cairo_set_font_size(cr, 16);
    cairo_move_to(cr, MARGIN, MARGIN + 20);
    cairo_show_text(cr, heading);
    for (int i = 0; i < count; i++)
        draw_tile(cr, &tiles[i], MARGIN + (i % COLUMNS) * TILE_W,
                  MARGIN + HEADING_H + (i / COLUMNS) * TILE_H);
    cairo_destroy(cr);
    vf_status status = VF_OK;
    /* cairo writes in place; write beside the target and rename, as every writer here does. */
    char tmp[VF_PATH_MAX + 8];
    snprintf(tmp, sizeof tmp, "%s.tmp", path);
    if (cairo_surface_status(surface) != CAIRO_STATUS_SUCCESS ||
        cairo_surface_write_to_png(surface, tmp) != CAIRO_STATUS_SUCCESS)
        status = vf_fail(VF_EINTERNAL, "cannot write the shot card %s", path);
    else if (rename(tmp, path) != 0)
        status = vf_fail(VF_EINTERNAL, "cannot write the shot card %s", path);
    if (status != VF_OK)
        remove(tmp);
    cairo_surface_destroy(surface);
    return status;
}
