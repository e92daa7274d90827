/* The export stage (vf/export.h): the attack's viewpoints as shots a person can take. */
#define _GNU_SOURCE
#include "vf/export.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "shot_card.h"
#include "vf/attack_file.h"
#include "vf/calib.h"
#include "vf/classifier.h"
#include "vf/csv.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/json.h"
#include "vf/localize.h"
#include "vf/log.h"
#include "vf/resources.h"
#include "vf/targets.h"
#include "vf/view_coverage.h"

#define PREVIEW_SIZE 224

typedef struct target {
    vf_viewpoint v;
    const char *kind; /* "v*" or "sample" */
    int sample;       /* index into attack.json's samples, -1 for v* */
    double c2w[16], c2w_colmap[16];
    vf_target_words words;
    vf_sample_prediction pred;
    vf_view_trust trust;     /* gap to the nearest training photo (gap_deg NAN: no photos) */
    vf_image preview, photo; /* the field's render there; the nearest photo, scaled */
} target;

typedef struct export_run {
    const char *ws;
    int count;
    vf_attack_file attack;
    vf_similarity colmap_from_object;
    int has_colmap; /* the workspace has a COLMAP frame (poses stage) */
    double metres;  /* metres per scene unit, 0 when unknown */
    vf_field *field;
    vf_classifier *cls;
    vf_dataset photos; /* the field's training frames (count 0 when unreadable) */
    double *photo_c2w;
    double trust_limit; /* degrees: the attack's limit, or VF_TRUST_GAP_DEG */
    target *targets;
    int target_count;
} export_run;

static vf_status load_inputs(export_run *run, const vf_workspace *ws, const char *attack)
{
    vf_status status = vf_attack_file_load_workspace(ws, attack, &run->attack);
    if (status == VF_OK)
        status = vf_normalization_load_workspace(ws, NULL, &run->colmap_from_object,
                                                 &run->has_colmap);
    if (status == VF_OK && !run->has_colmap) {
        vf_warn("no WS/poses/normalization.json (a posed import): targets in the object frame "
                "only, no COLMAP frame");
    }
    if (status != VF_OK)
        return status;
    if (!vf_workspace_metres_per_unit(ws, &run->metres))
        run->metres = 0;
    if (vf_workspace_has_stage(ws, "train"))
        status = vf_field_load_workspace(ws, &run->field);
    else
        vf_warn("no trained field (WS/train/model.vff): the shot card has no previews");
    run->trust_limit = run->attack.trust_gap > 0 ? run->attack.trust_gap : VF_TRUST_GAP_DEG;
    if (status == VF_OK && vf_dataset_load_training(ws, &run->photos, NULL) != VF_OK) {
        vf_warn("the training photos cannot be read: targets without their trust");
        memset(&run->photos, 0, sizeof run->photos);
    }
    if (status == VF_OK && run->photos.count > 0 &&
        !(run->photo_c2w = vf_dataset_poses(&run->photos)))
        status = vf_fail(VF_EINTERNAL, "out of memory");
    return status;
}

/* v* first, then the spread samples. */
static vf_status choose_targets(export_run *run)
{
    int m = run->count < run->attack.sample_count ? run->count : run->attack.sample_count;
    if (m < run->count)
        vf_warn("attack.json has %d samples of p*(v); exporting %d", run->attack.sample_count, m);
    int *picked = malloc(sizeof(int) * (size_t)(m + 1));
    run->targets = calloc((size_t)m + 1, sizeof *run->targets);
    if (!picked || !run->targets) {
        free(picked);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
    vf_status status = vf_targets_spread(run->attack.samples, run->attack.sample_count,
                                         run->attack.range, m, picked);
    if (status != VF_OK) {
        free(picked);
        return status;
    }
    run->targets[0] = (target){.v = run->attack.v_star,
                               .kind = "v*",
                               .sample = -1,
                               .pred = run->attack.v_star_prediction};
    for (int k = 0; k < m; k++) {
        target *t = &run->targets[k + 1];
        t->v = vf_viewpoint_from_array(run->attack.samples + 6 * picked[k]);
        t->kind = "sample";
        t->sample = picked[k];
        if (run->attack.predictions)
            t->pred = run->attack.predictions[picked[k]];
        else
            t->pred.cls = -1;
    }
    run->target_count = m + 1;
    free(picked);
    for (int i = 0; i < run->target_count; i++) {
        target *t = &run->targets[i];
        vf_viewpoint_to_c2w(&t->v, t->c2w);
        if (run->has_colmap)
            vf_similarity_apply_c2w(&run->colmap_from_object, t->c2w, t->c2w_colmap);
        vf_target_describe(t->c2w, &t->words);
        t->trust = run->photo_c2w ? vf_view_trust_of_pose(run->photo_c2w, run->photos.count, t->c2w)
                                  : (vf_view_trust){.gap_deg = NAN, .nearest = -1};
    }
    return VF_OK;
}

static int trusted(const export_run *run, const target *t)
{
    return t->trust.gap_deg <= run->trust_limit;
}

/* The nearest training photo, scaled to the preview's longer side, for the shot card. */
static vf_status load_nearest_photo(const export_run *run, target *t, int side)
{
    if (t->trust.nearest < 0)
        return VF_OK;
    static const float white[3] = {1, 1, 1};
    vf_image full;
    vf_status status =
        vf_image_load_rgb(run->photos.frames[t->trust.nearest].image_path, white, &full);
    if (status != VF_OK)
        return status;
    double s = (double)side / (full.width > full.height ? full.width : full.height);
    int w = (int)(full.width * s + 0.5), h = (int)(full.height * s + 0.5);
    status = vf_image_resize(&full, w > 0 ? w : 1, h > 0 ? h : 1, &t->photo);
    vf_image_free(&full);
    return status;
}

/* Classify a preview when attack.json does not say what the model predicts there. */
static vf_status predict_preview(export_run *run, target *t)
{
    if (!run->cls) {
        char path[VF_PATH_MAX];
        vf_status status = vf_find_model(
            run->attack.model[0] ? run->attack.model : VF_DEFAULT_MODEL, NULL, path, sizeof path);
        if (status == VF_OK)
            status = vf_class_names_load();
        if (status == VF_OK)
            status = vf_classifier_open(path, &run->cls);
        if (status != VF_OK)
            return status;
    }
    float *probs = malloc(sizeof(float) * VF_NUM_CLASSES);
    if (!probs)
        return vf_fail(VF_EINTERNAL, "out of memory");
    int size = vf_classifier_input_size(run->cls);
    vf_status status;
    if (t->preview.width == size && t->preview.height == size) { /* the classifier's own view */
        float *chw = malloc(sizeof(float) * 3 * (size_t)size * size);
        status = chw ? vf_classifier_normalize(&t->preview, chw)
                     : vf_fail(VF_EINTERNAL, "out of memory");
        if (status == VF_OK)
            status = vf_classifier_forward(run->cls, chw, 1, probs);
        free(chw);
    } else {
        status = vf_classifier_classify_images(run->cls, &t->preview, 1, probs);
    }
    if (status == VF_OK) {
        float p;
        vf_topk(probs, 1, &t->pred.cls, &p);
        t->pred.confidence = p;
        t->pred.fooled = !vf_attack_is_label(&run->attack, t->pred.cls);
        snprintf(t->pred.name, sizeof t->pred.name, "%s", vf_class_short_name(t->pred.cls));
    }
    free(probs);
    return status;
}

static vf_status render_previews(export_run *run, const char *dir)
{
    if (!run->field)
        return VF_OK;
    char folder[VF_PATH_MAX], path[VF_PATH_MAX], name[32];
    vf_camera cam = run->attack.has_camera ? run->attack.camera
                                           : vf_field_classifier_camera(run->field, PREVIEW_SIZE);
    int side = cam.width > cam.height ? cam.width : cam.height;
    if (side > 4 * PREVIEW_SIZE) /* a preview, not a poster (the file allows 100000 px) */
        cam = vf_camera_scaled(&cam, (int)((double)cam.width * 4 * PREVIEW_SIZE / side + 0.5),
                               (int)((double)cam.height * 4 * PREVIEW_SIZE / side + 0.5));
    vf_status status = vf_path_join(folder, sizeof folder, dir, "previews");
    if (status == VF_OK)
        status = vf_mkdirs(folder);
    for (int i = 0; status == VF_OK && i < run->target_count; i++) {
        target *t = &run->targets[i];
        status = vf_field_render(run->field, &cam, t->c2w, &t->preview);
        snprintf(name, sizeof name, "target_%02d.png", i);
        if (status == VF_OK)
            status = vf_path_join(path, sizeof path, folder, name);
        if (status == VF_OK)
            status = vf_image_save(path, &t->preview);
        if (status == VF_OK && t->pred.cls < 0)
            status = predict_preview(run, t);
        if (status == VF_OK)
            status = load_nearest_photo(run, t, PREVIEW_SIZE);
    }
    return status;
}

static double to_metres(const export_run *run, double units)
{
    return run->metres > 0 ? units * run->metres : NAN;
}

static json_t *target_json(const export_run *run, int i)
{
    const target *t = &run->targets[i];
    const vf_target_words *w = &t->words;
    json_t *words = json_pack(
        "{s:o, s:o, s:o, s:o, s:o, s:[o,o,o], s:o}", "azimuth_deg", vf_json_number(w->azimuth_deg),
        "elevation_deg", vf_json_number(w->elevation_deg), "distance", vf_json_number(w->distance),
        "height", vf_json_number(w->height), "roll_deg", vf_json_number(w->roll_deg), "look_at",
        vf_json_number(w->look_at[0]), vf_json_number(w->look_at[1]), vf_json_number(w->look_at[2]),
        "aim_offset", vf_json_number(w->aim_offset));
    if (run->metres > 0) {
        json_object_set_new(words, "distance_m", vf_json_number(to_metres(run, w->distance)));
        json_object_set_new(words, "height_m", vf_json_number(to_metres(run, w->height)));
        json_object_set_new(words, "aim_offset_m", vf_json_number(to_metres(run, w->aim_offset)));
    }
    json_t *o =
        json_pack("{s:i, s:s, s:o, s:o, s:o}", "index", i, "kind", t->kind, "viewpoint",
                  vf_viewpoint_json(&t->v), "c2w_object", vf_json_mat4(t->c2w), "words", words);
    if (run->has_colmap) {
        double look_colmap[3];
        vf_similarity_apply(&run->colmap_from_object, w->look_at, look_colmap);
        json_object_set_new(words, "look_at_colmap",
                            json_pack("[o,o,o]", vf_json_number(look_colmap[0]),
                                      vf_json_number(look_colmap[1]),
                                      vf_json_number(look_colmap[2])));
        json_object_set_new(o, "c2w_colmap", vf_json_mat4(t->c2w_colmap));
    }
    if (t->sample >= 0)
        json_object_set_new(o, "sample", json_integer(t->sample));
    if (t->pred.cls >= 0)
        json_object_set_new(
            o, "prediction",
            json_pack("{s:i, s:s, s:o, s:b}", "class", t->pred.cls, "name", t->pred.name,
                      "confidence", vf_json_number(t->pred.confidence), "fooled", t->pred.fooled));
    if (!isnan(t->trust.gap_deg)) {
        char photo[VF_PATH_MAX];
        vf_path_basename(photo, sizeof photo, run->photos.frames[t->trust.nearest].image_path, 0);
        json_object_set_new(
            o, "trust",
            json_pack("{s:o, s:o, s:b, s:s, s:o, s:o}", "gap_deg", vf_json_number(t->trust.gap_deg),
                      "gap_limit_deg", vf_json_number(run->trust_limit), "trusted", trusted(run, t),
                      "nearest_photo", photo, "angle_deg", vf_json_number(t->trust.angle_deg),
                      "distance_ratio", vf_json_number(t->trust.distance_ratio)));
    }
    if (t->preview.data) {
        char name[48];
        snprintf(name, sizeof name, "previews/target_%02d.png", i);
        json_object_set_new(o, "preview", json_string(name));
    }
    return o;
}

static void distance_text(const export_run *run, double units, char *out, size_t size)
{
    if (run->metres > 0)
        snprintf(out, size, "%.2f m", to_metres(run, units));
    else
        snprintf(out, size, "%.2f units", units);
}

static void fill_tile(const export_run *run, int i, shot_tile *tile)
{
    const target *t = &run->targets[i];
    const vf_target_words *w = &t->words;
    char d[32], h[32];
    memset(tile, 0, sizeof *tile);
    tile->preview = t->preview.data ? &t->preview : NULL;
    tile->photo = t->photo.data ? &t->photo : NULL;
    snprintf(tile->title, sizeof tile->title, "target %d: %s", i,
             t->sample < 0 ? "v* (strongest)" : "sample of p*(v)");
    distance_text(run, w->distance, d, sizeof d);
    distance_text(run, w->height, h, sizeof h);
    snprintf(tile->lines[0], sizeof tile->lines[0], "azimuth %.0f deg, elevation %.0f deg",
             w->azimuth_deg, w->elevation_deg);
    snprintf(tile->lines[1], sizeof tile->lines[1], "distance %s, height %s", d, h);
    snprintf(tile->lines[2], sizeof tile->lines[2], "roll %.0f deg, aim %.2f off centre",
             w->roll_deg, w->aim_offset);
    snprintf(tile->lines[3], sizeof tile->lines[3], "v = (%.0f, %.0f, %.0f, %.2f, %.2f, %.2f)",
             t->v.psi, t->v.theta, t->v.phi, t->v.dx, t->v.dy, t->v.dz);
    if (t->pred.cls >= 0)
        snprintf(tile->lines[4], sizeof tile->lines[4], "predicted: %.40s (%.0f%%)%s",
                 t->pred.name, 100 * t->pred.confidence, t->pred.fooled ? " - fooled" : "");
    else
        snprintf(tile->lines[4], sizeof tile->lines[4], "predicted: unknown");
    if (!isnan(t->trust.gap_deg))
        snprintf(tile->lines[5], sizeof tile->lines[5], "trust: %.0f deg from the nearest photo%s",
                 t->trust.gap_deg, trusted(run, t) ? "" : " - BEYOND the limit");
    else
        snprintf(tile->lines[5], sizeof tile->lines[5], "trust: unknown (no photos)");
}

static vf_status write_csv(const export_run *run, const char *path)
{
    char *text = NULL;
    size_t size = 0;
    FILE *f = open_memstream(&text, &size);
    if (!f)
        return vf_fail(VF_EINTERNAL, "out of memory");
    fprintf(f, "index,kind,psi,theta,phi,dx,dy,dz,azimuth_deg,elevation_deg,distance,height,"
               "roll_deg,look_x,look_y,look_z,distance_m,predicted_class,predicted_name,fooled,"
               "colmap_cam_x,colmap_cam_y,colmap_cam_z,gap_deg,trusted\n");
    for (int i = 0; i < run->target_count; i++) {
        const target *t = &run->targets[i];
        const vf_target_words *w = &t->words;
        fprintf(f, "%d,%s,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%.4f,%.4f,%.6g,%.6g,%.4f,%.6g,%.6g,%.6g,",
                i, t->kind, t->v.psi, t->v.theta, t->v.phi, t->v.dx, t->v.dy, t->v.dz,
                w->azimuth_deg, w->elevation_deg, w->distance, w->height, w->roll_deg,
                w->look_at[0], w->look_at[1], w->look_at[2]);
        if (run->metres > 0)
            fprintf(f, "%.6g", to_metres(run, w->distance));
        if (t->pred.cls >= 0) {
            fprintf(f, ",%d", t->pred.cls);
            vf_csv_next(f, t->pred.name);
            fprintf(f, ",%d", t->pred.fooled);
        } else {
            fprintf(f, ",,,");
        }
        if (run->has_colmap)
            fprintf(f, ",%.9g,%.9g,%.9g", t->c2w_colmap[3], t->c2w_colmap[7], t->c2w_colmap[11]);
        else
            fprintf(f, ",,,");
        if (!isnan(t->trust.gap_deg))
            fprintf(f, ",%.4g,%d\n", t->trust.gap_deg, trusted(run, t));
        else
            fprintf(f, ",,\n");
    }
    fclose(f);
    vf_status status = vf_write_file_atomic(path, text, size);
    free(text);
    return status;
}

static vf_status write_outputs(export_run *run, const char *dir, json_t **summary,
                               json_t **targets)
{
    char path[VF_PATH_MAX];
    int beyond = 0;
    for (int i = 0; i < run->target_count; i++)
        beyond += !isnan(run->targets[i].trust.gap_deg) && !trusted(run, &run->targets[i]);
    if (beyond)
        vf_warn("%d of the %d targets (%s) lie beyond %.0f deg from the nearest photo: the "
                "field may be wrong there, so a re-shoot there tests the field as much as the "
                "classifier",
                beyond, run->target_count, trusted(run, &run->targets[0]) ? "v* is not" : "v* too",
                run->trust_limit);
    vf_status status = render_previews(run, dir);
    json_t *list = json_array();
    for (int i = 0; i < run->target_count; i++)
        json_array_append_new(list, target_json(run, i));
    json_t *doc = json_pack(
        "{s:s, s:s, s:o, s:o}", "convention",
        "c2w: camera-to-world, row-major 4x4, OpenGL camera axes (x right, y "
        "up, looking along -z); object frame z up, object at the origin; "
        "azimuth about +z from -y, counterclockwise seen from above",
        "units", run->metres > 0 ? "scene units and metres" : "scene units", "metres_per_unit",
        run->metres > 0 ? vf_json_number(run->metres) : json_null(), "targets", list);
    if (status == VF_OK &&
        (status = vf_path_join(path, sizeof path, dir, "targets.json")) == VF_OK)
        status = vf_json_save(path, doc);
    if (status == VF_OK && (status = vf_path_join(path, sizeof path, dir, "targets.csv")) == VF_OK)
        status = write_csv(run, path);
    shot_tile *tiles = calloc((size_t)run->target_count, sizeof *tiles);
    if (status == VF_OK && !tiles)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < run->target_count; i++)
        fill_tile(run, i, &tiles[i]);
    char heading[256];
    snprintf(heading, sizeof heading, "vfcapture targets for %.100s (true label: %.100s)", run->ws,
             run->attack.label_text);
    if (status == VF_OK &&
        (status = vf_path_join(path, sizeof path, dir, "shot_card.png")) == VF_OK)
        status = vf__shot_card_save(path, heading, tiles, run->target_count);
    free(tiles);
    if (status == VF_OK)
        *summary = json_pack("{s:i, s:b, s:b}", "targets", run->target_count, "previews",
                             run->field != NULL, "metric", run->metres > 0);
    if (status == VF_OK && targets)
        *targets = json_incref(doc);
    json_decref(doc);
    return status;
}

static void export_free(export_run *run)
{
    for (int i = 0; run->targets && i < run->target_count; i++) {
        vf_image_free(&run->targets[i].preview);
        vf_image_free(&run->targets[i].photo);
    }
    free(run->targets);
    free(run->photo_c2w);
    vf_dataset_free(&run->photos);
    vf_attack_file_free(&run->attack);
    vf_field_free(run->field);
    vf_classifier_close(run->cls);
}

void vf_export_defaults(vf_export_options *o) { *o = (vf_export_options){.count = 8}; }

const char *vf_export_attack(const vf_workspace *ws)
{
    const json_t *params = json_object_get(vf_workspace_stage_record(ws, "export"), "params");
    return json_string_value(json_object_get(params, "attack"));
}

vf_status vf_export_run(vf_workspace *ws, const vf_export_options *o, json_t **result)
{
    export_run run = {.ws = ws->root, .count = o->count};
    json_t *summary = NULL, *targets = NULL;
    vf_stage stage;
    if (result)
        *result = NULL;
    vf_status status =
        o->count >= 0 && o->count <= VF_EXPORT_MAX_COUNT
            ? VF_OK
            : vf_fail(VF_EINPUT, "export 0 to %d samples, not %d", VF_EXPORT_MAX_COUNT, o->count);
    if (status == VF_OK && (status = load_inputs(&run, ws, o->attack)) == VF_OK &&
        (status = choose_targets(&run)) == VF_OK &&
        (status = vf_stage_begin(ws, "export", &stage)) == VF_OK) {
        status = vf_stage_uses(&stage, run.attack.stage);
        if (status == VF_OK)
            status = write_outputs(&run, stage.dir, &summary, &targets);
        if (status == VF_OK)
            status = vf_stage_commit(&stage,
                                     json_pack("{s:s, s:i}", "attack", run.attack.stage + 7,
                                               "count", run.count),
                                     json_incref(summary));
        else
            vf_stage_abort(&stage);
    }
    if (status == VF_OK && result)
        *result = json_incref(targets);
    json_decref(targets);
    json_decref(summary);
    export_free(&run);
    return status;
}
