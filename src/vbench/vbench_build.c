/* Building an ImageNet-V style set: natural and adversarial renders of attacked workspaces.
 * The set is written to OUT.partial and renamed to OUT when complete. */
#define _GNU_SOURCE
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <dirent.h>
#include <jansson.h>
#include <unistd.h>

#include "vf/attack_file.h"
#include "vf/csv.h"
#include "vf/dataset.h"
#include "vf/field.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/pose.h"
#include "vf/rng.h"
#include "vf/vbench.h"
#include "vf/viewfool.h"
#include "vf/workspace.h"

#define RENDER_CHUNK 16

/* What the set needs from one workspace. */
typedef struct vbench_object {
    char name[128];
    vf_field *field;
    vf_attack_file attack; /* the label set and p*(v) */
    vf_dataset natural;    /* the training cameras */
} vbench_object;

static void object_free(vbench_object *o)
{
    vf_field_free(o->field);
    vf_attack_file_free(&o->attack);
    vf_dataset_free(&o->natural);
    memset(o, 0, sizeof *o);
}

static vf_status load_object(const char *root, const char *attack, vbench_object *o)
{
    vf_workspace ws;
    vf_status status = vf_workspace_open(root, 0, &ws);
    if (status != VF_OK)
        return status;
    vf_path_basename(o->name, sizeof o->name, ws.root, 0);
    status = vf_attack_file_load_workspace(&ws, attack, &o->attack);
    if (status == VF_OK && o->attack.components < 1)
        status = vf_fail(VF_EINPUT,
                         "%s: the attack kept no distribution p*(v) (random search): "
                         "run it with --method nes",
                         ws.root);
    if (status == VF_OK)
        status = vf_field_load_workspace(&ws, &o->field);
    if (status == VF_OK)
        status = vf_dataset_load_training(&ws, &o->natural, NULL);
    vf_workspace_close(&ws);
    return status;
}

/* The 256-pixel camera whose centre 224 crop is the attack's classifier view. */
static vf_camera photo_camera(const vf_field *f)
{
    vf_camera cam = vf_field_classifier_camera(f, 224);
    int margin = (VF_VBENCH_IMAGE_SIZE - 224) / 2;
    cam.width = cam.height = VF_VBENCH_IMAGE_SIZE;
    cam.cx += margin;
    cam.cy += margin;
    return cam;
}

/* Viewpoint i of a split: a training camera (spread over them) or a sample of p*(v). */
static void choose_view(const vbench_object *o, vf_vbench_split split, int i, int count,
                        vf_rng *rng, double v[VF_VIEW_DIM], double c2w[16])
{
    if (split == VF_VBENCH_NATURAL) {
        int frames = o->natural.count;
        int f = count <= frames ? (int)((long)i * frames / count) : i % frames;
        memcpy(c2w, o->natural.frames[f].c2w, 16 * sizeof *c2w);
        vf_viewpoint p;
        vf_c2w_to_viewpoint(c2w, &p);
        vf_viewpoint_to_array(&p, v);
        return;
    }
    (void)vf_attack_file_sample(&o->attack, rng, 1, v); /* load_object checked there is p*(v) */
    vf_viewpoint p = vf_viewpoint_from_array(v);
    vf_viewpoint_to_c2w(&p, c2w);
}

static const char *split_name(vf_vbench_split split)
{
    return split == VF_VBENCH_NATURAL ? "natural" : "adversarial";
}

/* Render one object's split, save the PNGs and add them to the index. */
static vf_status render_split(const vbench_object *o, int object, vf_vbench_split split,
                              const vf_vbench_build_options *opt, const char *dir, json_t *index,
                              FILE *csv, vf_progress *progress, size_t *done)
{
    vf_rng rng;
    vf_rng_seed(&rng, opt->seed + 1000003u * (uint64_t)object + (uint64_t)split);
    vf_camera cam = photo_camera(o->field);
    vf_image images[RENDER_CHUNK] = {{0}};
    double views[RENDER_CHUNK][VF_VIEW_DIM], c2w[RENDER_CHUNK * 16];
    vf_status status = VF_OK;
    for (int first = 0; first < opt->count && status == VF_OK; first += RENDER_CHUNK) {
        int n = opt->count - first < RENDER_CHUNK ? opt->count - first : RENDER_CHUNK;
        for (int i = 0; i < n; i++)
            choose_view(o, split, first + i, opt->count, &rng, views[i], c2w + 16 * i);
        status = vf_field_render_batch(o->field, &cam, c2w, n, images);
        for (int i = 0; i < n && status == VF_OK; i++) {
            char file[256], path[VF_PATH_MAX];
            snprintf(file, sizeof file, "images/%s_%s_%03d.png", o->name, split_name(split),
                     first + i);
            status = vf_path_join(path, sizeof path, dir, file);
            if (status == VF_OK)
                status = vf_image_save(path, &images[i]);
            json_t *v = json_array();
            for (int d = 0; d < VF_VIEW_DIM; d++)
                json_array_append_new(v, vf_json_number(views[i][d]));
            json_array_append_new(index, json_pack("{s:s, s:i, s:s, s:o}", "file", file, "object",
                                                   object, "split", split_name(split),
                                                   "viewpoint", v));
            vf_csv_text(csv, file);
            vf_csv_next(csv, o->name);
            fprintf(csv, ",%s,%.4f,%.4f,%.4f,%.5f,%.5f,%.5f\n", split_name(split), views[i][0],
                    views[i][1], views[i][2], views[i][3], views[i][4], views[i][5]);
        }
        *done += (size_t)n;
        vf_progress_update(progress, *done, o->name);
    }
    for (int i = 0; i < RENDER_CHUNK; i++)
        vf_image_free(&images[i]);
    return status;
}

static int dir_is_empty(const char *path)
{
    DIR *d = opendir(path);
    struct dirent *e;
    int empty = 1;
    while (d && (e = readdir(d)))
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, ".."))
            empty = 0;
    if (d)
        closedir(d);
    return empty;
}

static void make_names_unique(vbench_object *objects, int n)
{
    for (int i = 1; i < n; i++)
        for (int j = 0; j < i; j++)
            if (!strcmp(objects[i].name, objects[j].name)) {
                size_t len = strlen(objects[i].name);
                snprintf(objects[i].name + len, sizeof objects[i].name - len, "_%d", i + 1);
                break;
            }
}

static vf_status write_set(vbench_object *objects, int n, const char *dir,
                           const vf_vbench_build_options *opt)
{
    char path[VF_PATH_MAX];
    vf_status status = vf_path_join(path, sizeof path, dir, "images");
    if (status == VF_OK)
        status = vf_mkdirs(path);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, dir, "index.csv");
    FILE *csv = status == VF_OK ? fopen(path, "w") : NULL;
    if (status == VF_OK && !csv)
        return vf_fail(VF_EINPUT, "cannot write %s", path);
    if (csv)
        fputs("file,object,split,psi,theta,phi,dx,dy,dz\n", csv);

    json_t *index = json_array(), *object_list = json_array();
    vf_progress progress;
    size_t done = 0;
    vf_progress_begin(&progress, "rendering", (size_t)n * 2 * opt->count, "images");
    for (int o = 0; o < n && status == VF_OK; o++) {
        json_array_append_new(object_list, json_pack("{s:s, s:O}", "name", objects[o].name,
                                                     "label", objects[o].attack.label));
        for (int split = 0; split < 2 && status == VF_OK; split++)
            status = render_split(&objects[o], o, (vf_vbench_split)split, opt, dir, index, csv,
                                  &progress, &done);
    }
    if (csv && fclose(csv) != 0 && status == VF_OK)
        status = vf_fail(VF_EINPUT, "cannot write %s (disk full?)", path);
    if (status == VF_OK)
        vf_progress_end(&progress);
    json_t *doc = json_pack("{s:i, s:i, s:I, s:o, s:o}", "image_size", VF_VBENCH_IMAGE_SIZE,
                            "count", opt->count, "seed", (json_int_t)opt->seed, "objects",
                            object_list, "images", index);
    if (status == VF_OK)
        status = vf_path_join(path, sizeof path, dir, "index.json");
    if (status == VF_OK)
        status = vf_json_save(path, doc);
    json_decref(doc);
    return status;
}

vf_status vf_vbench_build(const char *const *workspaces, int n, const char *out_dir,
                          const vf_vbench_build_options *opt)
{
    if (n < 1 || opt->count < 1)
        return vf_fail(VF_EINPUT, "give at least one workspace and a positive image count");
    if (vf_is_file(out_dir) || (vf_is_dir(out_dir) && !dir_is_empty(out_dir)))
        return vf_fail(VF_EINPUT, "%s already exists: choose a new output folder", out_dir);
    vbench_object *objects = calloc((size_t)n, sizeof *objects);
    if (!objects)
        return vf_fail(VF_EINTERNAL, "out of memory");
    vf_status status = VF_OK;
    for (int i = 0; i < n && status == VF_OK; i++)
        status = load_object(workspaces[i], opt->attack, &objects[i]);
    make_names_unique(objects, n);

    char partial[VF_PATH_MAX];
    if (status == VF_OK && snprintf(partial, sizeof partial, "%s.partial", out_dir) >=
                               (int)sizeof partial)
        status = vf_fail(VF_EINPUT, "output path too long: %s", out_dir);
    if (status == VF_OK) {
        vf_remove_tree(partial);
        status = vf_mkdirs(partial);
    }
    if (status == VF_OK)
        status = write_set(objects, n, partial, opt);
    if (status == VF_OK) {
        if (vf_is_dir(out_dir))
            rmdir(out_dir); /* empty, checked above */
        if (rename(partial, out_dir) != 0)
            status = vf_fail(VF_EINTERNAL, "cannot move %s into place", partial);
    } else {
        vf_remove_tree(partial);
    }
    for (int i = 0; i < n; i++)
        object_free(&objects[i]);
    free(objects);
    return status;
}
