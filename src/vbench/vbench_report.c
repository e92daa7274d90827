/* Reports of a viewpoint benchmark: CSV for machines, a Markdown table for people and a bar
 * chart (cairo) of natural vs adversarial top-1 per model, like the paper's Figure 6. */
#define _GNU_SOURCE
#include <stdio.h>
#include <string.h>

#include <cairo.h>

#include "vf/csv.h"
#include "vf/fsutil.h"
#include "vf/vbench.h"

static double accuracy(const vf_vbench_row *row)
{
    return row->total ? 100.0 * row->correct / row->total : 0.0;
}

static void model_name(const vf_vbench_results *r, int model, char *out, size_t size)
{
    vf_path_basename(out, size, r->models[model], 1);
}

static const vf_vbench_row *find_row(const vf_vbench_results *r, int model, int object,
                                     vf_vbench_split split)
{
    for (int i = 0; i < r->row_count; i++)
        if (r->rows[i].model == model && r->rows[i].object == object && r->rows[i].split == split)
            return &r->rows[i];
    return NULL;
}

static const char *object_name(const vf_vbench_results *r, int object)
{
    return object < 0 ? "all" : r->objects[object];
}

static vf_status write_csv(const vf_vbench_results *r, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return vf_fail(VF_EINPUT, "cannot write %s", path);
    fputs("model,object,split,correct,total,top1_percent\n", f);
    for (int i = 0; i < r->row_count; i++) {
        const vf_vbench_row *row = &r->rows[i];
        char model[256];
        model_name(r, row->model, model, sizeof model);
        vf_csv_text(f, model);
        vf_csv_next(f, object_name(r, row->object));
        fprintf(f, ",%s,%d,%d,%.2f\n", row->split == VF_VBENCH_NATURAL ? "natural" : "adversarial",
                row->correct, row->total, accuracy(row));
    }
    return fclose(f) == 0 ? VF_OK : vf_fail(VF_EINPUT, "cannot write %s (disk full?)", path);
}

/* One line per model: natural and adversarial top-1 per object, then over all objects. */
static vf_status write_markdown(const vf_vbench_results *r, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f)
        return vf_fail(VF_EINPUT, "cannot write %s", path);
    fputs("Top-1 accuracy (%), natural / adversarial viewpoints (correct of total)\n\n| model |", f);
    for (int o = 0; o <= r->object_count; o++)
        fprintf(f, " %s |", object_name(r, o < r->object_count ? o : -1));
    fputs("\n|---|", f);
    for (int o = 0; o <= r->object_count; o++)
        fputs("---|", f);
    fputc('\n', f);
    for (int m = 0; m < r->model_count; m++) {
        char model[256];
        model_name(r, m, model, sizeof model);
        fprintf(f, "| %s |", model);
        for (int o = 0; o <= r->object_count; o++) {
            int object = o < r->object_count ? o : -1;
            const vf_vbench_row *nat = find_row(r, m, object, VF_VBENCH_NATURAL);
            const vf_vbench_row *adv = find_row(r, m, object, VF_VBENCH_ADVERSARIAL);
            fprintf(f, " %.1f / %.1f (%d/%d, %d/%d) |", accuracy(nat), accuracy(adv),
                    nat->correct, nat->total, adv->correct, adv->total);
        }
        fputc('\n', f);
    }
    fputs("\nEngines:", f);
    for (int m = 0; m < r->model_count; m++) {
        char model[256];
        model_name(r, m, model, sizeof model);
        fprintf(f, "%s %s %s", m ? "," : "", model, r->engines && r->engines[m] ? r->engines[m] : "?");
    }
    fputc('\n', f);
    return fclose(f) == 0 ? VF_OK : vf_fail(VF_EINPUT, "cannot write %s (disk full?)", path);
}

static void draw_text(cairo_t *cr, double x, double y, double size, const char *text, int centre)
{
    cairo_text_extents_t ext;
    cairo_set_font_size(cr, size);
    cairo_text_extents(cr, text, &ext);
    cairo_move_to(cr, centre ? x - ext.width / 2 - ext.x_bearing : x, y);
    cairo_show_text(cr, text);
}

static vf_status write_chart(const vf_vbench_results *r, const char *path)
{
    const double group = 120, left = 60, top = 50, plot_h = 300, bottom = 90;
    int width = (int)(left + group * r->model_count + 110), height = (int)(top + plot_h + bottom);
    if (width < 420)
        width = 420;
    cairo_surface_t *surface = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
    cairo_t *cr = cairo_create(surface);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

    /* axes and gridlines every 20% */
    cairo_set_line_width(cr, 1);
    for (int pct = 0; pct <= 100; pct += 20) {
        double y = top + plot_h * (1 - pct / 100.0);
        cairo_set_source_rgb(cr, 0.85, 0.85, 0.85);
        cairo_move_to(cr, left, y);
        cairo_line_to(cr, width - 20, y);
        cairo_stroke(cr);
        char label[16];
        snprintf(label, sizeof label, "%d%%", pct);
        cairo_set_source_rgb(cr, 0.2, 0.2, 0.2);
        draw_text(cr, left - 40, y + 4, 11, label, 0);
    }
    static const double colour[2][3] = {{0.30, 0.55, 0.80}, {0.85, 0.35, 0.25}};
    for (int m = 0; m < r->model_count; m++) {
        double x0 = left + group * m + 20;
        for (int split = 0; split < 2; split++) {
            const vf_vbench_row *row = find_row(r, m, -1, (vf_vbench_split)split);
            double h = plot_h * accuracy(row) / 100.0, x = x0 + split * 40;
            cairo_set_source_rgb(cr, colour[split][0], colour[split][1], colour[split][2]);
            cairo_rectangle(cr, x, top + plot_h - h, 36, h);
            cairo_fill(cr);
            char value[16];
            snprintf(value, sizeof value, "%.0f", accuracy(row));
            cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
            draw_text(cr, x + 18, top + plot_h - h - 4, 10, value, 1);
        }
        char model[256];
        model_name(r, m, model, sizeof model);
        cairo_save(cr); /* model names slanted below their bars */
        cairo_move_to(cr, x0 + 40, top + plot_h + 14);
        cairo_rotate(cr, 0.35);
        cairo_set_font_size(cr, 9);
        cairo_show_text(cr, model);
        cairo_restore(cr);
    }
    cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
    draw_text(cr, left, 22, 14, "Top-1 accuracy: natural vs adversarial viewpoints", 0);
    for (int split = 0; split < 2; split++) {
        double x = left + split * 130;
        cairo_set_source_rgb(cr, colour[split][0], colour[split][1], colour[split][2]);
        cairo_rectangle(cr, x, 32, 12, 10);
        cairo_fill(cr);
        cairo_set_source_rgb(cr, 0.1, 0.1, 0.1);
        draw_text(cr, x + 16, 41, 11, split ? "adversarial (p*(v))" : "natural", 0);
    }
    cairo_destroy(cr);
    cairo_status_t written = cairo_surface_write_to_png(surface, path);
    cairo_surface_destroy(surface);
    return written == CAIRO_STATUS_SUCCESS ? VF_OK
                                           : vf_fail(VF_EINPUT, "cannot write %s: %s", path,
                                                     cairo_status_to_string(written));
}

vf_status vf_vbench_write_reports(const vf_vbench_results *r, const char *dir)
{
    char path[VF_PATH_MAX];
    vf_status status = vf_path_join(path, sizeof path, dir, "results.csv");
    if (status == VF_OK)
        status = write_csv(r, path);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, dir, "results.md");
    if (status == VF_OK)
        status = write_markdown(r, path);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, dir, "accuracy.png");
    if (status == VF_OK)
        status = write_chart(r, path);
    return status;
}
