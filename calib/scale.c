/* Metric scale of a workspace (vf/calib.h): points of known separation, seen in posed frames,
 * are triangulated in scene units; the known distance in metres gives metres per unit. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "calib_internal.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/pose.h"

#define SCALE_FILE "scale.json" /* in WS/calib */

#define MAX_MARKERS_PER_FRAME 64

/* One point seen in several frames: frame index and pixel per sighting. */
typedef struct sightings {
    int count;
    int *frame;
    double *uv;
} sightings;

static vf_status sightings_init(sightings *s, int capacity)
{
    s->count = 0;
    s->frame = malloc((size_t)capacity * sizeof *s->frame);
    s->uv = malloc((size_t)capacity * 2 * sizeof *s->uv);
    return s->frame && s->uv ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
}

static void sightings_free(sightings *s)
{
    free(s->frame);
    free(s->uv);
}

/* Pixel distance between where X projects in frame f and where it was seen. */
static double reprojection_px(const vf_frame *f, const double X[3], const double uv[2])
{
    double rot[9], t[3], p[3], u, v;
    vf_c2w_gl_to_w2c_cv(f->c2w, rot, t);
    vf_mat3_apply(rot, X, p);
    for (int k = 0; k < 3; k++)
        p[k] += t[k];
    if (!vf_camera_project(&f->camera, p, &u, &v))
        return INFINITY;
    return hypot(u - uv[0], v - uv[1]);
}

/* Triangulate a point from its sightings; *mean_px gets the mean reprojection error. */
static vf_status triangulate(const vf_dataset *ds, const sightings *s, double X[3],
                             double *mean_px)
{
    double *origin = malloc((size_t)s->count * 3 * sizeof *origin);
    double *dir = malloc((size_t)s->count * 3 * sizeof *dir);
    vf_status status = origin && dir ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < s->count; i++)
        vf__calib_frame_ray(&ds->frames[s->frame[i]], s->uv[2 * i], s->uv[2 * i + 1],
                            origin + 3 * i, dir + 3 * i);
    if (status == VF_OK)
        status = vf_triangulate_rays(origin, dir, s->count, X);
    free(origin);
    free(dir);
    *mean_px = 0;
    for (int i = 0; status == VF_OK && i < s->count; i++)
        *mean_px += reprojection_px(&ds->frames[s->frame[i]], X, s->uv + 2 * i) / s->count;
    return status;
}

static double distance3(const double *a, const double *b)
{
    return sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                (a[2] - b[2]) * (a[2] - b[2]));
}

/* ---- marker ---- */

/* Search every frame for marker `id`; corner k's sightings go to corners[k]. */
static vf_status find_marker(const vf_dataset *ds, int id, sightings corners[4], json_t *frames)
{
    vf_marker found[MAX_MARKERS_PER_FRAME];
    vf_rgb8 img = {0};
    vf_progress progress;
    vf_status status = VF_OK;
    vf_progress_begin(&progress, "looking for the marker", (size_t)ds->count, "frames");
    for (int f = 0; f < ds->count && status == VF_OK; f++) {
        int count = 0;
        status = vf_rgb8_load(ds->frames[f].image_path, &img);
        if (status == VF_OK)
            status = vf_aruco_detect(&img, found, MAX_MARKERS_PER_FRAME, &count);
        for (int m = 0; status == VF_OK && m < count; m++) {
            if (found[m].id != id)
                continue;
            for (int k = 0; k < 4; k++) {
                sightings *s = &corners[k];
                s->frame[s->count] = f;
                memcpy(s->uv + 2 * s->count, found[m].corners + 2 * k, 2 * sizeof *s->uv);
                s->count++;
            }
            char name[VF_PATH_MAX];
            vf_path_basename(name, sizeof name, ds->frames[f].image_path, 0);
            json_array_append_new(frames, json_string(name));
            break; /* one sighting per frame: a second copy of the id would be ambiguous */
        }
        vf_progress_update(&progress, (size_t)f + 1, NULL);
    }
    vf_progress_end(&progress);
    vf_rgb8_free(&img);
    return status;
}

vf_status vf_scale_from_marker(const vf_workspace *ws, int id, double size_m,
                               double *metres_per_unit, json_t **details)
{
    if (id < 0 || id >= VF_ARUCO_IDS)
        return vf_fail(VF_EINPUT, "--marker: ArUco ids run from 0 to %d", VF_ARUCO_IDS - 1);
    vf_dataset ds;
    vf_status status = vf__calib_load_posed_frames(ws, &ds);
    if (status != VF_OK)
        return status;
    sightings corners[4] = {{0}};
    for (int k = 0; k < 4 && status == VF_OK; k++)
        status = sightings_init(&corners[k], ds.count);
    json_t *frames = json_array();
    if (status == VF_OK)
        status = find_marker(&ds, id, corners, frames);
    if (status == VF_OK && corners[0].count < 2)
        status = vf_fail(VF_EINPUT,
                         "ArUco marker %d (original dictionary) was found in %d of %d frames; "
                         "it must show in at least 2, seen from different directions: check "
                         "the id, and that the whole marker with its white margin is in view",
                         id, corners[0].count, ds.count);
    double X[4][3], residual[4], worst = 0;
    for (int k = 0; k < 4 && status == VF_OK; k++) {
        status = triangulate(&ds, &corners[k], X[k], &residual[k]);
        worst = fmax(worst, residual[k]);
    }
    if (status == VF_OK) {
        double side[4], mean = 0, spread = 0;
        for (int k = 0; k < 4; k++) {
            side[k] = distance3(X[k], X[(k + 1) % 4]);
            mean += side[k] / 4;
        }
        for (int k = 0; k < 4; k++)
            spread = fmax(spread, fabs(side[k] - mean) / mean);
        if (spread > 0.05 || worst > 3.0)
            vf_warn("the marker's triangulated sides differ by up to %.1f%% and its corners "
                    "reproject within %.1f px: poses or detections are imprecise, treat the "
                    "scale with care",
                    100 * spread, worst);
        *metres_per_unit = size_m / mean;
        json_t *points = json_array(), *sides = json_array(), *errors = json_array();
        for (int k = 0; k < 4; k++) {
            json_array_append_new(points, vf_json_doubles(X[k], 3));
            json_array_append_new(sides, vf_json_number(side[k]));
            json_array_append_new(errors, vf_json_number(residual[k]));
        }
        *details = json_pack("{s:i, s:s, s:o, s:o, s:o, s:o, s:o, s:o, s:o}", "marker_id", id,
                             "dictionary", "ARUCO_ORIGINAL", "size_m", vf_json_number(size_m),
                             "frames", frames, "corners", points, "sides_units", sides,
                             "side_units", vf_json_number(mean), "reprojection_px", errors,
                             "side_spread", vf_json_number(spread));
        frames = NULL;
    }
    json_decref(frames);
    for (int k = 0; k < 4; k++)
        sightings_free(&corners[k]);
    vf_dataset_free(&ds);
    return status;
}

/* ---- picked points ---- */

/* The frame a pick names: its image file name, with or without the extension. */
static int find_frame(const vf_dataset *ds, const char *name)
{
    for (int f = 0; f < ds->count; f++) {
        char full[VF_PATH_MAX], stem[VF_PATH_MAX];
        vf_path_basename(full, sizeof full, ds->frames[f].image_path, 0);
        vf_path_basename(stem, sizeof stem, ds->frames[f].image_path, 1);
        if (!strcmp(full, name) || !strcmp(stem, name))
            return f;
    }
    return -1;
}

static vf_status picks_to_sightings(const vf_dataset *ds, const vf_pick *picks, int n,
                                    sightings *s)
{
    vf_status status = sightings_init(s, n);
    for (int i = 0; status == VF_OK && i < n; i++) {
        int f = find_frame(ds, picks[i].frame);
        if (f < 0)
            return vf_fail(VF_EINPUT, "no posed frame is called '%s' (see %s)", picks[i].frame,
                           ds->source);
        const vf_camera *cam = &ds->frames[f].camera;
        if (picks[i].u > cam->width || picks[i].v > cam->height)
            return vf_fail(VF_EINPUT, "pick %s:%g,%g lies outside the %dx%d frame",
                           picks[i].frame, picks[i].u, picks[i].v, cam->width, cam->height);
        s->frame[s->count] = f;
        s->uv[2 * s->count] = picks[i].u;
        s->uv[2 * s->count + 1] = picks[i].v;
        s->count++;
    }
    return status;
}

vf_status vf_scale_from_picks(const vf_workspace *ws, const vf_pick *p1, int n1,
                              const vf_pick *p2, int n2, double distance_m,
                              double *metres_per_unit, json_t **details)
{
    vf_dataset ds;
    vf_status status = vf__calib_load_posed_frames(ws, &ds);
    if (status != VF_OK)
        return status;
    sightings s[2] = {{0}};
    double X[2][3], residual[2];
    status = picks_to_sightings(&ds, p1, n1, &s[0]);
    if (status == VF_OK)
        status = picks_to_sightings(&ds, p2, n2, &s[1]);
    for (int k = 0; k < 2 && status == VF_OK; k++) {
        status = triangulate(&ds, &s[k], X[k], &residual[k]);
        if (status == VF_OK && residual[k] > 5.0)
            status = vf_fail(VF_EINPUT, "the picks of point %d disagree: they miss the "
                                        "triangulated point by %.1f px on average; pick the "
                                        "same physical point in every frame",
                             k + 1, residual[k]);
    }
    double units = status == VF_OK ? distance3(X[0], X[1]) : 0;
    if (status == VF_OK && !(units > 1e-9))
        status = vf_fail(VF_EINPUT, "the two points triangulate to the same place: pick two "
                                    "different points");
    if (status == VF_OK) {
        *metres_per_unit = distance_m / units;
        *details =
            json_pack("{s:o, s:[o, o], s:o, s:[o, o]}", "distance_m", vf_json_number(distance_m),
                      "points", vf_json_doubles(X[0], 3), vf_json_doubles(X[1], 3),
                      "distance_units", vf_json_number(units), "reprojection_px",
                      vf_json_number(residual[0]), vf_json_number(residual[1]));
    }
    sightings_free(&s[0]);
    sightings_free(&s[1]);
    vf_dataset_free(&ds);
    return status;
}

int vf_workspace_metres_per_unit(const vf_workspace *ws, double *metres_per_unit)
{
    char path[VF_PATH_MAX];
    json_t *doc;
    if (!vf_workspace_has_stage(ws, "calib") ||
        vf_workspace_path(ws, "calib", SCALE_FILE, path, sizeof path) != VF_OK ||
        !vf_is_file(path) || vf_json_load(path, &doc) != VF_OK) {
        vf_error_clear();
        return 0;
    }
    double s = json_number_value(json_object_get(doc, "metres_per_unit"));
    json_decref(doc);
    if (!(s > 0) || !isfinite(s))
        return 0;
    *metres_per_unit = s;
    return 1;
}

#define MAX_PICKS 64

static vf_status measure(const vf_scale_request *r, const vf_workspace *ws, double *s,
                         json_t **details)
{
    if (!r->p1)
        return vf_scale_from_marker(ws, r->marker, r->size_m, s, details);
    vf_pick p1[MAX_PICKS], p2[MAX_PICKS];
    int n1, n2;
    vf_status status = vf_parse_picks(r->p1, p1, MAX_PICKS, &n1);
    if (status == VF_OK)
        status = vf_parse_picks(r->p2, p2, MAX_PICKS, &n2);
    if (status == VF_OK)
        status = vf_scale_from_picks(ws, p1, n1, p2, n2, r->distance_m, s, details);
    return status;
}

vf_status vf_calib_scale_run(vf_workspace *ws, const vf_scale_request *r, json_t **result)
{
    *result = NULL;
    vf_status status;
    double s = 0;
    json_t *details = NULL, *doc = NULL;
    const char *method = r->p1 ? "distance" : "marker";
    vf_stage stage;
    char path[VF_PATH_MAX];
    status = measure(r, ws, &s, &details);
    if (status == VF_OK) {
        doc = json_pack("{s:o, s:o, s:s, s:o}", "metres_per_unit", vf_json_number(s),
                        "units_per_metre", vf_json_number(1.0 / s), "method", method, "details",
                        details);
        status = vf_stage_begin(ws, "calib", &stage);
    } else {
        json_decref(details);
    }
    if (status == VF_OK) {
        status = vf_path_join(path, sizeof path, stage.dir, SCALE_FILE);
        if (status == VF_OK)
            status = vf_json_save(path, doc);
        if (status == VF_OK)
            status = vf_stage_commit(&stage, json_pack("{s:s}", "method", method),
                                     json_pack("{s:o}", "metres_per_unit", vf_json_number(s)));
        else
            vf_stage_abort(&stage);
    }
    if (status == VF_OK)
        *result = doc;
    else
        json_decref(doc);
    return status;
}
