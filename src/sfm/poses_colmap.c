/* The poses stage's COLMAP steps: the command lines, and picking the model to keep. */
#define _GNU_SOURCE
#include <ctype.h>
#include <dirent.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "poses_internal.h"
#include "vf/json.h"
#include "vf/log.h"

/* Run one COLMAP command and record its wall time under its name, or under "check" while
 * run->checking (summed over repeats). */
vf_status vf__poses_run_step(poses_run *run, const char *label, vf_args *args)
{
    double seconds = 0;
    vf_status status = vf_colmap_run(&run->colmap, label, (size_t)run->frames.count, args,
                                     &seconds);
    const char *name = run->checking ? "check" : args->count ? args->items[0] : "colmap";
    json_t *before = json_object_get(run->seconds, name);
    json_object_set_new(run->seconds, name, vf_json_number(seconds + json_number_value(before)));
    vf_args_free(args);
    return status;
}

/* "fx,fy,cx,cy" (PINHOLE) or with ",k1,k2,p1,p2" (OPENCV), as ImageReader.camera_params. */
static void known_params(const vf_camera *c, char *out, size_t size)
{
    int n = snprintf(out, size, "%.10g,%.10g,%.10g,%.10g", c->fx, c->fy, c->cx, c->cy);
    if (vf_camera_has_distortion(c))
        snprintf(out + n, size - (size_t)n, ",%.10g,%.10g,%.10g,%.10g", c->k1, c->k2, c->p1,
                 c->p2);
}

vf_status vf__poses_extract_features(poses_run *run)
{
    vf_args a = {0};
    vf_args_add(&a, "feature_extractor");
    vf_args_opt(&a, "--database_path", "%s", run->database);
    vf_args_opt(&a, "--image_path", "%s", run->images);
    vf_args_opt(&a, "--ImageReader.camera_model", "%s", run->camera_model);
    vf_args_opt(&a, "--ImageReader.single_camera_per_folder", "1");
    if (run->opt->has_intrinsics) {
        char params[256];
        known_params(&run->opt->known, params, sizeof params);
        vf_args_opt(&a, "--ImageReader.camera_params", "%s", params);
    } else {
        vf_args_opt(&a, "--ImageReader.default_focal_length_factor", "1.2");
    }
    vf_args_opt(&a, "--SiftExtraction.use_gpu", "0");
    vf_args_opt(&a, "--SiftExtraction.max_num_features", "%d", run->opt->max_features);
    return vf__poses_run_step(run, "COLMAP: extracting features", &a);
}

/* A vocabulary tree of the capture's own features (Debian's COLMAP ships none, and the
 * published ones are downloads), trained on at most TREE_IMAGES of the images: building one
 * from all 50 fox photos' features took about 4 minutes on a busy 2-core machine, more than
 * the matching it saves. */
#define TREE_IMAGES 40
static vf_status build_vocab_tree(poses_run *run, char *path, size_t size)
{
    vf_status status = vf_path_join(path, size, run->scratch, "vocab_tree.bin");
    if (status != VF_OK)
        return status;
    int images = run->frames.count < TREE_IMAGES ? run->frames.count : TREE_IMAGES;
    long words = (long)images * run->opt->max_features / 200;
    words = words < 256 ? 256 : words > 65536 ? 65536 : words;
    vf_args a = {0};
    vf_args_add(&a, "vocab_tree_builder");
    vf_args_opt(&a, "--database_path", "%s", run->database);
    vf_args_opt(&a, "--vocab_tree_path", "%s", path);
    vf_args_opt(&a, "--num_visual_words", "%ld", words);
    vf_args_opt(&a, "--max_num_images", "%d", images);
    return vf__poses_run_step(run, "COLMAP: building a vocabulary tree", &a);
}

vf_status vf__poses_match(poses_run *run)
{
    int sequential = !strcmp(run->matcher, "sequential");
    int retrieval = !strcmp(run->matcher, "retrieval");
    char tree[VF_PATH_MAX] = "";
    vf_status status = VF_OK;
    /* sequential: loop detection only with a tree the user gives (building one costs more
     * than it saves on captures of this size); retrieval: the capture's own tree */
    if (run->opt->vocab_tree)
        snprintf(tree, sizeof tree, "%s", run->opt->vocab_tree);
    else if (retrieval)
        status = build_vocab_tree(run, tree, sizeof tree);
    if (status != VF_OK)
        return status;
    vf_args a = {0};
    vf_args_add(&a, sequential  ? "sequential_matcher"
                    : retrieval ? "vocab_tree_matcher"
                                : "exhaustive_matcher");
    vf_args_opt(&a, "--database_path", "%s", run->database);
    vf_args_opt(&a, "--SiftMatching.use_gpu", "0");
    if (sequential) {
        vf_args_opt(&a, "--SequentialMatching.overlap", "%d", run->opt->overlap);
        vf_args_opt(&a, "--SequentialMatching.quadratic_overlap", "1");
        vf_args_opt(&a, "--SequentialMatching.loop_detection", "%d", tree[0] != '\0');
        if (tree[0])
            vf_args_opt(&a, "--SequentialMatching.vocab_tree_path", "%s", tree);
    } else if (retrieval) {
        int k = run->frames.count - 1 < RETRIEVAL_IMAGES ? run->frames.count - 1
                                                         : RETRIEVAL_IMAGES;
        vf_args_opt(&a, "--VocabTreeMatching.vocab_tree_path", "%s", tree);
        vf_args_opt(&a, "--VocabTreeMatching.num_images", "%d", k);
    } else {
        vf_args_opt(&a, "--ExhaustiveMatching.block_size", "10"); /* finer progress */
    }
    const char *label = sequential  ? "COLMAP: matching neighbours"
                        : retrieval ? "COLMAP: matching similar frames"
                                    : "COLMAP: matching all pairs";
    return vf__poses_run_step(run, label, &a);
}

/* Map into `output`; only the images named in image_list when it is not NULL. `relaxed`
 * admits a frame on half the matches COLMAP asks by default (15 inliers, a 15% inlier
 * ratio, not 30 and 25%): small or noisy frames whose matches are few but right. */
static vf_status run_mapper(poses_run *run, const char *output, const char *image_list,
                            int relaxed)
{
    vf_args a = {0};
    vf_args_add(&a, "mapper");
    vf_args_opt(&a, "--database_path", "%s", run->database);
    vf_args_opt(&a, "--image_path", "%s", run->images);
    vf_args_opt(&a, "--output_path", "%s", output);
    if (image_list)
        vf_args_opt(&a, "--image_list_path", "%s", image_list);
    if (relaxed) {
        vf_args_opt(&a, "--Mapper.abs_pose_min_num_inliers", "15");
        vf_args_opt(&a, "--Mapper.abs_pose_min_inlier_ratio", "0.15");
    }
    if (run->opt->has_intrinsics) {
        vf_args_opt(&a, "--Mapper.ba_refine_focal_length", "0");
        vf_args_opt(&a, "--Mapper.ba_refine_principal_point", "0");
        vf_args_opt(&a, "--Mapper.ba_refine_extra_params", "0");
    }
    const char *label = image_list ? "COLMAP: checking (registering the sample)"
                        : relaxed  ? "COLMAP: registering frames again, on fewer matches"
                                   : "COLMAP: registering frames";
    return vf__poses_run_step(run, label, &a);
}

vf_status vf__poses_convert_to_text(poses_run *run, const char *input, const char *output)
{
    vf_status status = vf_mkdirs(output);
    if (status != VF_OK)
        return status;
    vf_args a = {0};
    vf_args_add(&a, "model_converter");
    vf_args_opt(&a, "--input_path", "%s", input);
    vf_args_opt(&a, "--output_path", "%s", output);
    vf_args_opt(&a, "--output_type", "TXT");
    return vf__poses_run_step(run, NULL, &a);
}

static int is_number(const char *name)
{
    if (!*name)
        return 0;
    for (; *name; name++)
        if (!isdigit((unsigned char)*name))
            return 0;
    return 1;
}

/* The models COLMAP wrote under sparse_dir (numbered folders), each converted to text under
 * text_root: the one with the most images (then points) in *best, its binary and text folders
 * in best_dir and best_text, how many there were in *count. None leaves *best empty. */
static vf_status load_largest_model(poses_run *run, const char *sparse_dir, const char *text_root,
                                    vf_colmap_model *best, char best_dir[VF_PATH_MAX],
                                    char best_text[VF_PATH_MAX], int *count)
{
    DIR *dir = opendir(sparse_dir);
    if (!dir)
        return vf_fail(VF_EINTERNAL, "cannot open %s: %s", sparse_dir, strerror(errno));
    vf_status status = VF_OK;
    struct dirent *entry;
    while (status == VF_OK && (entry = readdir(dir))) {
        if (!is_number(entry->d_name))
            continue;
        char bin[VF_PATH_MAX], txt[VF_PATH_MAX];
        vf_colmap_model model;
        status = vf_path_join(bin, VF_PATH_MAX, sparse_dir, entry->d_name);
        if (status == VF_OK)
            status = vf_path_join(txt, sizeof txt, text_root, entry->d_name);
        if (status == VF_OK)
            status = vf__poses_convert_to_text(run, bin, txt);
        if (status == VF_OK)
            status = vf_colmap_model_load(txt, &model);
        if (status != VF_OK)
            break;
        (*count)++;
        if (model.image_count > best->image_count ||
            (model.image_count == best->image_count && model.point_count > best->point_count)) {
            vf_colmap_model_free(best);
            *best = model;
            snprintf(best_dir, VF_PATH_MAX, "%s", bin);
            snprintf(best_text, VF_PATH_MAX, "%s", txt);
        } else {
            vf_colmap_model_free(&model);
        }
    }
    closedir(dir);
    return status;
}

/* Move the chosen model's text files to stage/sparse (replacing those of an earlier mapping
 * of this run: the check's fallback maps again). */
vf_status vf__poses_keep_model_text(poses_run *run, const char *text)
{
    char to[VF_PATH_MAX];
    vf_status status = vf_path_join(to, sizeof to, run->stage.dir, "sparse");
    if (status == VF_OK)
        status = vf_remove_tree(to);
    if (status == VF_OK && rename(text, to) != 0)
        status = vf_fail(VF_EINTERNAL, "cannot move %s to %s: %s", text, to, strerror(errno));
    return status;
}

/* One mapping into scratch/<name> (binary models) and scratch/<name>_text, its largest model
 * in *best (text folder in best_text), the count of models in *count. */
static vf_status map_into(poses_run *run, const char *name, int relaxed, vf_colmap_model *best,
                          char best_dir[VF_PATH_MAX], char best_text[VF_PATH_MAX], int *count)
{
    char sparse[VF_PATH_MAX], text[VF_PATH_MAX], text_name[64];
    snprintf(text_name, sizeof text_name, "%s_text", name);
    vf_status status = vf_path_join(sparse, sizeof sparse, run->scratch, name);
    if (status == VF_OK)
        status = vf_path_join(text, sizeof text, run->scratch, text_name);
    if (status == VF_OK)
        status = vf_remove_tree(sparse);
    if (status == VF_OK)
        status = vf_remove_tree(text);
    if (status == VF_OK)
        status = vf_mkdirs(sparse);
    if (status != VF_OK)
        return status;
    /* The mapper exits 1 ("failed to create sparse model") when no pair of frames starts a
     * model: the input's fault, which the registration check reports (0 registered). */
    status = run_mapper(run, sparse, NULL, relaxed);
    if (status != VF_OK && run->colmap.last_exit != 1)
        return status;
    return load_largest_model(run, sparse, text, best, best_dir, best_text, count);
}

vf_status vf__poses_map(poses_run *run)
{
    char text[VF_PATH_MAX] = "";
    vf_colmap_model_free(&run->model); /* a second mapping (the check's fallback) starts over */
    run->model_count = 0;
    run->relaxed = 0;
    vf_status status =
        map_into(run, "sparse", 0, &run->model, run->model_dir, text, &run->model_count);
    /* A model that left out more than a tenth of the frames often grows when frames with few
     * matches may join (a studio capture at 216x384: models of 21 and 40 of 50 frames, or one
     * of 21, then all 50). */
    if (status == VF_OK && 10 * run->model.image_count < 9 * run->frames.count) {
        vf_colmap_model again = {0};
        char again_dir[VF_PATH_MAX], again_text[VF_PATH_MAX];
        int again_count = 0;
        vf_info("%d of %d frames registered (the largest of %d model%s): mapping again, "
                "admitting frames on fewer matches",
                run->model.image_count, run->frames.count, run->model_count,
                run->model_count == 1 ? "" : "s");
        status = map_into(run, "sparse_relaxed", 1, &again, again_dir, again_text, &again_count);
        if (status == VF_OK && again.image_count > run->model.image_count) {
            vf_colmap_model_free(&run->model);
            run->model = again;
            run->model_count = again_count;
            run->relaxed = 1;
            snprintf(run->model_dir, sizeof run->model_dir, "%s", again_dir);
            snprintf(text, sizeof text, "%s", again_text);
        } else {
            vf_colmap_model_free(&again);
        }
    }
    if (status == VF_OK && run->model.image_count > 0)
        status = vf__poses_keep_model_text(run, text);
    return status;
}

/* The check's sample: up to CHECK_FRAMES registered images spread evenly over the model's
 * list, as indices into run->model.images. */
static int check_sample(const poses_run *run, int sample[CHECK_FRAMES])
{
    int n = run->model.image_count, k = n < CHECK_FRAMES ? n : CHECK_FRAMES;
    for (int i = 0; i < k; i++)
        sample[i] = (int)((long)i * n / k);
    return k;
}

/* The sample's names (image list) and all its pairs (match list) as COLMAP reads them. */
static vf_status write_check_lists(const poses_run *run, const int *sample, int k,
                                   const char *list, const char *pairs)
{
    FILE *lf = fopen(list, "w"), *pf = fopen(pairs, "w");
    for (int i = 0; lf && pf && i < k; i++) {
        fprintf(lf, "%s\n", run->model.images[sample[i]].name);
        for (int j = i + 1; j < k; j++)
            fprintf(pf, "%s %s\n", run->model.images[sample[i]].name,
                    run->model.images[sample[j]].name);
    }
    int ok = lf && pf && !ferror(lf) && !ferror(pf);
    ok &= (lf && fclose(lf) == 0) & (pf && fclose(pf) == 0);
    return ok ? VF_OK : vf_fail(VF_EINTERNAL, "cannot write %s: %s", list, strerror(errno));
}

/* Our poses of the check model's images beside its own, compared. */
static vf_status compare_check(const poses_run *run, const vf_colmap_model *check,
                               poses_check *out)
{
    int n = 0;
    double(*ours)[16] = malloc(sizeof *ours * (size_t)(check->image_count + 1));
    double(*theirs)[16] = malloc(sizeof *theirs * (size_t)(check->image_count + 1));
    const double **a = malloc(sizeof *a * (size_t)(check->image_count + 1));
    const double **b = malloc(sizeof *b * (size_t)(check->image_count + 1));
    vf_status status = ours && theirs && a && b ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < check->image_count; i++)
        for (int j = 0; j < run->model.image_count; j++)
            if (!strcmp(check->images[i].name, run->model.images[j].name)) {
                vf_colmap_image_c2w(&run->model.images[j], ours[n]);
                vf_colmap_image_c2w(&check->images[i], theirs[n]);
                a[n] = ours[n];
                b[n] = theirs[n];
                n++;
                break;
            }
    out->registered = n;
    if (status == VF_OK && n >= 3)
        status = vf_pose_compare(a, b, n, 0, &out->agreement);
    free(ours);
    free(theirs);
    free(a);
    free(b);
    return status;
}

static vf_status check_model(poses_run *run, poses_check *out);

vf_status vf__poses_check(poses_run *run, poses_check *out)
{
    double start = vf_now();
    run->checking = 1;
    vf_status status = check_model(run, out);
    run->checking = 0;
    out->seconds = vf_now() - start;
    return status;
}

static vf_status check_model(poses_run *run, poses_check *out)
{
    *out = (poses_check){.verdict = "inconclusive"};
    int sample[CHECK_FRAMES];
    int k = check_sample(run, sample);
    out->sampled = k;
    char dir[VF_PATH_MAX], sparse[VF_PATH_MAX], text[VF_PATH_MAX], list[VF_PATH_MAX],
        pairs[VF_PATH_MAX];
    vf_status status = vf_path_join(dir, sizeof dir, run->scratch, "check");
    if (status == VF_OK)
        status = vf_path_join(sparse, sizeof sparse, dir, "sparse");
    if (status == VF_OK)
        status = vf_path_join(text, sizeof text, dir, "text");
    if (status == VF_OK)
        status = vf_path_join(list, sizeof list, dir, "images.txt");
    if (status == VF_OK)
        status = vf_path_join(pairs, sizeof pairs, dir, "pairs.txt");
    if (status == VF_OK)
        status = vf_mkdirs(sparse);
    if (status == VF_OK)
        status = write_check_lists(run, sample, k, list, pairs);
    if (status != VF_OK)
        return status;
    vf_args a = {0};
    vf_args_add(&a, "matches_importer"); /* pairs matched already are kept, not redone */
    vf_args_opt(&a, "--database_path", "%s", run->database);
    vf_args_opt(&a, "--match_list_path", "%s", pairs);
    vf_args_opt(&a, "--match_type", "pairs");
    vf_args_opt(&a, "--SiftMatching.use_gpu", "0");
    status = vf__poses_run_step(run, "COLMAP: checking (all pairs of a sample)", &a);
    if (status == VF_OK) {
        status = run_mapper(run, sparse, list, 0);
        if (status != VF_OK && run->colmap.last_exit == 1)
            return VF_OK; /* no model from the sample: inconclusive */
    }
    vf_colmap_model check = {0};
    char check_dir[VF_PATH_MAX] = "", check_text[VF_PATH_MAX] = "";
    int models = 0;
    if (status == VF_OK)
        status = load_largest_model(run, sparse, text, &check, check_dir, check_text, &models);
    if (status == VF_OK && check.image_count >= 3)
        status = compare_check(run, &check, out);
    vf_colmap_model_free(&check);
    if (status != VF_OK || 4 * out->registered < 3 * k || out->registered < 3)
        return status; /* too few of the sample re-registered for it to be a reference */
    const vf_pose_agreement *g = &out->agreement;
    int bad = g->rot_median > CHECK_MAX_ROTATION_DEG || 5 * g->rot_over_5deg > g->count ||
              g->pos_median > CHECK_MAX_POSITION;
    out->verdict = bad ? "disagrees" : "agrees";
    return VF_OK;
}

/* Drop what image_undistorter writes for dense stereo; only the images are needed. */
static void drop_stereo_files(const char *out_dir)
{
    static const char *const extras[] = {"stereo", "sparse", "run-colmap-geometric.sh",
                                         "run-colmap-photometric.sh"};
    for (size_t i = 0; i < sizeof extras / sizeof extras[0]; i++) {
        char path[VF_PATH_MAX];
        if (vf_path_join(path, sizeof path, out_dir, extras[i]) == VF_OK)
            vf_remove_tree(path);
    }
}

/* The ingest frame behind COLMAP image `name` when it had an alpha channel, else NULL. */
static const vf_sfm_frame *frame_with_alpha(const poses_run *run, const char *name)
{
    for (int i = 0; i < run->frames.count; i++)
        if (run->frames.frames[i].had_alpha && !strcmp(run->frames.frames[i].name, name))
            return &run->frames.frames[i];
    return NULL;
}

/* Replace COLMAP's undistorted RGB of every frame that had alpha (a removed background) by
 * the frame undistorted with its alpha (a white background keyed out), so that training knows
 * where the object ends. */
static vf_status restore_alpha(poses_run *run, const vf_colmap_model *undistorted,
                               const char *image_dir)
{
    vf_status status = VF_OK;
    int white_keyed = 0;
    vf_progress progress;
    vf_progress_begin(&progress, "undistorting alpha", (size_t)undistorted->image_count,
                      "images");
    for (int i = 0; i < undistorted->image_count && status == VF_OK; i++) {
        const vf_colmap_image *image = &undistorted->images[i];
        const vf_sfm_frame *frame = frame_with_alpha(run, image->name);
        const vf_colmap_image *original = vf_colmap_model_image(&run->model, image->id);
        const vf_colmap_camera *from =
            original ? vf_colmap_model_camera(&run->model, original->camera_id) : NULL;
        const vf_colmap_camera *to = vf_colmap_model_camera(undistorted, image->camera_id);
        if (!frame || !from || !to)
            continue;
        vf_camera lens, pinhole;
        vf_image src = {0}, out = {0};
        char path[VF_PATH_MAX];
        status = vf_colmap_camera_to_vf(from, &lens);
        if (status == VF_OK)
            status = vf_colmap_camera_to_vf(to, &pinhole);
        int keyed = 0;
        if (status == VF_OK)
            status = vf_image_load(frame->source, &src);
        if (status == VF_OK)
            status = vf_sfm_key_white_background(&src, &keyed);
        white_keyed += keyed;
        if (status == VF_OK)
            status = vf_sfm_undistort_frame(&src, &lens, &pinhole, &out);
        if (status == VF_OK)
            status = vf_path_join(path, sizeof path, image_dir, image->name);
        if (status == VF_OK)
            status = vf_image_save(path, &out);
        vf_image_free(&src);
        vf_image_free(&out);
        vf_progress_update(&progress, (size_t)i + 1, NULL);
    }
    vf_progress_end(&progress);
    if (status == VF_OK && white_keyed > 0)
        vf_info("%d frames had their background removed to white: it was made transparent "
                "again, so that training sees the object's outline", white_keyed);
    return status;
}

vf_status vf__poses_undistort(poses_run *run, vf_colmap_model *out)
{
    char out_dir[VF_PATH_MAX], sparse[VF_PATH_MAX], txt[VF_PATH_MAX];
    vf_status status = vf_path_join(out_dir, sizeof out_dir, run->stage.dir, "undistorted");
    if (status == VF_OK)
        status = vf_path_join(sparse, sizeof sparse, out_dir, "sparse");
    if (status == VF_OK)
        status = vf_path_join(txt, sizeof txt, run->scratch, "undistorted");
    if (status != VF_OK)
        return status;
    vf_args a = {0};
    vf_args_add(&a, "image_undistorter");
    vf_args_opt(&a, "--image_path", "%s", run->images);
    vf_args_opt(&a, "--input_path", "%s", run->model_dir);
    vf_args_opt(&a, "--output_path", "%s", out_dir);
    vf_args_opt(&a, "--output_type", "COLMAP");
    status = vf__poses_run_step(run, "COLMAP: undistorting", &a);
    if (status == VF_OK)
        status = vf__poses_convert_to_text(run, sparse, txt);
    if (status == VF_OK)
        status = vf_colmap_model_load(txt, out);
    drop_stereo_files(out_dir);
    char image_dir[VF_PATH_MAX];
    if (status == VF_OK && run->frames.with_alpha > 0 &&
        (status = vf_path_join(image_dir, sizeof image_dir, out_dir, "images")) == VF_OK)
        status = restore_alpha(run, out, image_dir);
    return status;
}
