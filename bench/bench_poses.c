/* bench_poses: what the poses stage costs and how right it is, by the size of a photo set.
 *
 * A textured 3D model of data/models_3d (default the antique reflex camera) is rendered once
 * by `vfcapture ingest MODEL.glb --scene room` (Blender: the object on a textured floor inside
 * a textured wall, so that SIFT finds what it finds in a room; measured: on the plain studio
 * background the object alone gives about 100 features a view and no set registers, and with
 * a brick floor neither 25 nor 50 views did, the bricks' copies being alike) from the largest
 * size's number of views, random on the upper hemisphere; each set of N photos is the first N of
 * them, copied under random hash names into a folder (a user's unordered photo folder: the names
 * say nothing). For each N and each matcher it runs `vfcapture ingest DIR` and `vfcapture poses
 * --matcher M` and prints what "auto" would choose, the frames registered, the wall time of each
 * COLMAP step (features, matching, vocabulary tree, mapping, the registration check) and the pose
 * error against the rendered cameras (rotation median and p90 in degrees, position median as a
 * share of the camera distance, after a similarity alignment). Then, per N, which matcher was
 * faster at equal accuracy: the crossover the "auto" defaults are set by.
 *
 * Results are cached in --out DIR (default bench_poses/): a finished (N, matcher) run is not
 * run again, so an interrupted benchmark continues; delete DIR/results.json to measure again.
 * Timings are wall clock on all cores; compare within one run on a shared machine.
 *
 * usage: bench_poses [--model FILE] [--sizes 25,50,100,200] [--matchers exhaustive,retrieval]
 *                    [--render-size PX] [--samples N] [--max-features N] [--out DIR]
 * (--matchers may also name sequential: on photos in no order it shows the check at work) */
#include <jansson.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "bench_shell.h"
#include "vf/dataset.h"
#include "vf/fsutil.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/pose.h"
#include "vf/poses.h"
#include "vf/resources.h"
#include "vf/rng.h"

#define MAX_SIZES 8

typedef struct options {
    const char *model, *matchers, *out;
    int sizes[MAX_SIZES], size_count, render_size, samples, max_features;
} options;

static void die(const char *what)
{
    fprintf(stderr, "bench_poses: %s\n", what);
    exit(1);
}

static void parse(int argc, char **argv, options *o)
{
    static char model[VF_PATH_MAX];
    *o = (options){.matchers = "exhaustive,retrieval",
                   .out = "bench_poses",
                   .sizes = {25, 50, 100, 200},
                   .size_count = 4,
                   .render_size = 320,
                   .samples = 16,
                   .max_features = 1024};
    if (vf_shared_path("data/models_3d/reflex_camera__AntiqueCamera.glb", model, sizeof model) ==
        VF_OK)
        o->model = model;
    for (int i = 1; i < argc; i++) {
        const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!strcmp(a, "--help") || !strcmp(a, "-h")) {
            puts("usage: bench_poses [--model FILE] [--sizes 25,50,100,200] "
                 "[--matchers exhaustive,retrieval]\n"
                 "                   [--render-size PX] [--samples N] [--max-features N] "
                 "[--out DIR]");
            exit(0);
        }
        if (!v)
            die("every option takes a value (see --help)");
        i++;
        if (!strcmp(a, "--model"))
            o->model = v;
        else if (!strcmp(a, "--matchers"))
            o->matchers = v;
        else if (!strcmp(a, "--out"))
            o->out = v;
        else if (!strcmp(a, "--render-size"))
            o->render_size = atoi(v);
        else if (!strcmp(a, "--samples"))
            o->samples = atoi(v);
        else if (!strcmp(a, "--max-features"))
            o->max_features = atoi(v);
        else if (!strcmp(a, "--sizes")) {
            o->size_count = 0;
            for (const char *p = v; *p && o->size_count < MAX_SIZES; p += strcspn(p, ",")) {
                p += *p == ',';
                o->sizes[o->size_count++] = atoi(p);
            }
        } else
            die("unknown option (see --help)");
    }
    if (!o->model)
        die("no model: give --model FILE (data/models_3d was not found)");
    for (int i = 0; i < o->size_count; i++)
        if (o->sizes[i] < 3)
            die("--sizes: each set needs at least 3 photos");
}

static int largest_size(const options *o)
{
    int n = 0;
    for (int i = 0; i < o->size_count; i++)
        n = o->sizes[i] > n ? o->sizes[i] : n;
    return n;
}

/* The hash name of rendered view i (the same in every set, so sets share their photos). */
static void hashed_name(int i, char *out, size_t size)
{
    vf_rng rng;
    vf_rng_seed(&rng, 1000 + (uint64_t)i);
    snprintf(out, size, "%08x%08x.png", (unsigned)vf_rng_next(&rng), (unsigned)vf_rng_next(&rng));
}

/* DIR/photos_N: the first n rendered views under their hash names. */
static void make_set(const options *o, const vf_dataset *views, int n, char *dir, size_t size)
{
    snprintf(dir, size, "%s/photos_%d", o->out, n);
    if (vf_mkdirs(dir) != VF_OK)
        die(vf_error_message());
    for (int i = 0; i < n; i++) {
        char name[64], dst[VF_PATH_MAX];
        hashed_name(i, name, sizeof name);
        if (vf_path_join(dst, sizeof dst, dir, name) != VF_OK)
            die(vf_error_message());
        if (!vf_is_file(dst) && vf_copy_file(views->frames[i].image_path, dst) != VF_OK)
            die(vf_error_message());
    }
}

/* The pose error of WS/poses/transforms.json against the rendered views. */
static json_t *pose_error(const char *ws, const vf_dataset *views, int n)
{
    char path[VF_PATH_MAX * 3];
    snprintf(path, sizeof path, "%s/poses/transforms.json", ws);
    vf_dataset ours;
    if (vf_dataset_load(path, &ours) != VF_OK)
        return json_null();
    const double **a = malloc(sizeof *a * ((size_t)ours.count + 1));
    const double **b = malloc(sizeof *b * ((size_t)ours.count + 1));
    int m = 0;
    for (int i = 0; i < ours.count; i++)
        for (int k = 0; k < n; k++) {
            char name[64];
            hashed_name(k, name, sizeof name);
            name[16] = '\0'; /* ingest keeps the stem inside its own frame name */
            if (strstr(ours.frames[i].image_path, name)) {
                a[m] = ours.frames[i].c2w;
                b[m++] = views->frames[k].c2w;
                break;
            }
        }
    vf_pose_agreement g;
    json_t *out = json_null();
    if (vf_pose_compare(a, b, m, VF_CAMERA_DISTANCE, &g) == VF_OK)
        out = json_pack("{s:i, s:o, s:o, s:o, s:o}", "compared", m, "rotation_median_deg",
                        vf_json_number(g.rot_median), "rotation_p90_deg", vf_json_number(g.rot_p90),
                        "rotation_max_deg", vf_json_number(g.rot_max), "position_median",
                        vf_json_number(g.pos_median));
    free(a);
    free(b);
    vf_dataset_free(&ours);
    return out;
}

/* One (n, matcher) measurement: from the cache, or run now and cached. */
static json_t *measure(const options *o, json_t *cache, const vf_dataset *views, int n,
                       const char *matcher)
{
    char key[96], dir[VF_PATH_MAX], ws[VF_PATH_MAX * 2], out[VF_PATH_MAX * 3];
    snprintf(key, sizeof key, "%d/%s", n, matcher);
    json_t *row = json_object_get(cache, key);
    if (row)
        return row;
    make_set(o, views, n, dir, sizeof dir);
    snprintf(ws, sizeof ws, "%s/ws_%d_%s", o->out, n, matcher);
    snprintf(out, sizeof out, "%s/poses.json", ws);
    vf_remove_tree(ws);
    if (bench_run("'%s' ingest '%s' -o '%s' -n %d --quiet", bench_tool(), dir, ws, n))
        return NULL;
    int failed = bench_run("'%s' poses '%s' --matcher %s --max-features %d --json --quiet >'%s'",
                           bench_tool(), ws, matcher, o->max_features, out);
    json_t *summary = failed ? NULL : json_load_file(out, 0, NULL);
    row = json_pack("{s:b, s:O, s:O, s:O, s:O, s:O, s:o}", "ok", summary != NULL, "registered",
                    json_object_get(summary, "registered") ?: json_integer(0), "models",
                    json_object_get(summary, "models") ?: json_null(), "seconds",
                    json_object_get(summary, "seconds") ?: json_object(), "check",
                    json_object_get(summary, "check") ?: json_null(), "fallback_from",
                    json_object_get(summary, "fallback_from") ?: json_null(), "error",
                    summary ? pose_error(ws, views, n) : json_null());
    json_decref(summary);
    json_object_set_new(cache, key, row);
    char cache_path[VF_PATH_MAX * 2];
    snprintf(cache_path, sizeof cache_path, "%s/results.json", o->out);
    json_dump_file(cache, cache_path, JSON_INDENT(1));
    vf_remove_tree(ws); /* the images and database of 200 frames: keep only the figures */
    return row;
}

static double seconds_of(const json_t *row, const char *step)
{
    const json_t *v = json_object_get(json_object_get(row, "seconds"), step);
    return json_is_number(v) ? json_number_value(v) : 0;
}

static double error_of(const json_t *row, const char *what)
{
    const json_t *v = json_object_get(json_object_get(row, "error"), what);
    return json_is_number(v) ? json_number_value(v) : NAN;
}

int main(int argc, char **argv)
{
    options o;
    parse(argc, argv, &o);
    char render[VF_PATH_MAX * 2], path[VF_PATH_MAX * 3];
    int most = largest_size(&o);
    snprintf(render, sizeof render, "%s/render", o.out);
    snprintf(path, sizeof path, "%s/ingest/transforms.json", render);
    if (vf_mkdirs(o.out) != VF_OK)
        die(vf_error_message());
    vf_dataset views = {0};
    if (vf_dataset_load(path, &views) != VF_OK || views.count < most) {
        vf_remove_tree(render);
        if (bench_run("'%s' ingest '%s' -o '%s' --views %d --test-views 0 --render-size %d "
                      "--samples %d --scene room --quiet",
                      bench_tool(), o.model, render, most, o.render_size, o.samples) ||
            vf_dataset_load(path, &views) != VF_OK)
            die("could not render the views (see above)");
    }
    snprintf(path, sizeof path, "%s/results.json", o.out);
    json_t *cache = json_load_file(path, 0, NULL);
    if (!json_is_object(cache)) {
        json_decref(cache);
        cache = json_object();
    }

    printf("bench_poses: %s in a room, %d px renders, %d SIFT features a photo; times in "
           "seconds, errors against the rendered cameras\n",
           o.model, o.render_size, o.max_features);
    printf("%5s %-11s %4s %10s %8s %8s %7s %7s %7s %8s %8s %8s %9s  %s\n", "N", "matcher", "auto",
           "registered", "extract", "match", "tree", "map", "check", "total", "rot_med", "rot_p90",
           "pos_med%", "check verdict");
    for (int s = 0; s < o.size_count; s++) {
        int n = o.sizes[s];
        double best_total = INFINITY;
        char best[32] = "-";
        for (const char *m = o.matchers; *m;) {
            char matcher[32];
            size_t len = strcspn(m, ",");
            snprintf(matcher, sizeof matcher, "%.*s", (int)len, m);
            m += len + (m[len] == ',');
            json_t *row = measure(&o, cache, &views, n, matcher);
            if (!row) {
                printf("%5d %-11s (ingest failed)\n", n, matcher);
                continue;
            }
            double total = seconds_of(row, "total");
            double match = seconds_of(row, "exhaustive_matcher") +
                           seconds_of(row, "sequential_matcher") +
                           seconds_of(row, "vocab_tree_matcher");
            double rot = error_of(row, "rotation_median_deg");
            const char *verdict =
                json_string_value(json_object_get(json_object_get(row, "check"), "verdict"));
            const char *fell = json_string_value(json_object_get(row, "fallback_from"));
            printf("%5d %-11s %4s %5lld/%-4d %8.1f %8.1f %7.1f %7.1f %7.1f %8.1f %8.3f %8.3f "
                   "%9.3f  %s%s%s\n",
                   n, matcher, strcmp(vf_poses_auto_matcher(n, 0), matcher) ? "" : "*",
                   json_integer_value(json_object_get(row, "registered")), n,
                   seconds_of(row, "feature_extractor"), match,
                   seconds_of(row, "vocab_tree_builder"), seconds_of(row, "mapper"),
                   seconds_of(row, "check"), total, rot, error_of(row, "rotation_p90_deg"),
                   100 * error_of(row, "position_median"), verdict ? verdict : "-",
                   fell ? ", fell back from " : "", fell ? fell : "");
            if (!json_is_true(json_object_get(row, "ok")))
                printf("%5d %-11s poses failed (see the log above)\n", n, matcher);
            /* faster at equal accuracy: 95% registered, rotation median under 1 deg */
            if (json_integer_value(json_object_get(row, "registered")) >= 0.95 * n && rot < 1.0 &&
                total < best_total) {
                best_total = total;
                snprintf(best, sizeof best, "%s", matcher);
            }
        }
        printf("%5d fastest with 95%% of the photos registered and rotation median < 1 deg: %s\n",
               n, best);
    }
    json_decref(cache);
    vf_dataset_free(&views);
    return 0;
}
