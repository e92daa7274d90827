/* bench_localize: how fast frames are localized against a workspace's sparse model.
 *
 *   bench_localize WS [IMAGE|FOLDER...]
 *
 * WS must have a poses stage (for example: vfcapture ingest FOX/images -o WS; vfcapture
 * poses WS). Frames default to the instant-ngp fox photos in the shared data. Each frame is
 * localized once to warm up, then the whole set timed per setting; prints frames per second,
 * milliseconds per frame and the median inlier count for a few feature budgets and working
 * sizes (frames are shrunk to max_side first), and the time to load the map. */
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/fsutil.h"
#include "vf/localize.h"
#include "vf/log.h"
#include "vf/resources.h"

#define MAX_FRAMES 256

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

static int compare_ints(const void *a, const void *b)
{
    return *(const int *)a - *(const int *)b;
}

/* Load the .jpg/.png images of a folder (name order) or one image, appending to frames. */
static int load_frames(const char *path, vf_rgb8 *frames, int n)
{
    if (!vf_is_dir(path)) {
        if (n < MAX_FRAMES && vf_rgb8_load(path, &frames[n]) == VF_OK)
            n++;
        return n;
    }
    DIR *dir = opendir(path);
    char *names[MAX_FRAMES];
    int count = 0;
    struct dirent *e;
    while (dir && (e = readdir(dir)) && count < MAX_FRAMES)
        if (strstr(e->d_name, ".jpg") || strstr(e->d_name, ".png"))
            names[count++] = strdup(e->d_name);
    if (dir)
        closedir(dir);
    qsort(names, (size_t)count, sizeof *names, compare_names);
    for (int i = 0; i < count; i++) {
        char file[VF_PATH_MAX];
        if (n < MAX_FRAMES && vf_path_join(file, sizeof file, path, names[i]) == VF_OK &&
            vf_rgb8_load(file, &frames[n]) == VF_OK)
            n++;
        free(names[i]);
    }
    return n;
}

static void bench(const char *ws, const vf_rgb8 *frames, int n, int max_features, int max_side)
{
    vf_localize_options opt;
    vf_localize_defaults(&opt);
    opt.max_features = max_features;
    opt.max_side = max_side;
    vf_localizer *loc = NULL;
    vf_workspace workspace = {0};
    double start = vf_now();
    vf_status status = vf_workspace_open(ws, 0, &workspace);
    if (status == VF_OK)
        status = vf_localizer_open(&workspace, &opt, &loc);
    vf_workspace_close(&workspace);
    if (status != VF_OK) {
        fprintf(stderr, "bench_localize: %s\n", vf_error_message());
        exit(1);
    }
    double load = vf_now() - start;
    vf_localize_result r;
    for (int i = 0; i < n && i < 3; i++) /* warm up: first calls allocate */
        vf_localize_frame(loc, &frames[i], &r);
    int *inliers = malloc(sizeof(int) * (size_t)n), localized = 0;
    start = vf_now();
    for (int i = 0; i < n; i++) {
        vf_localize_frame(loc, &frames[i], &r);
        inliers[i] = r.inliers;
        localized += r.localized;
    }
    double seconds = vf_now() - start;
    qsort(inliers, (size_t)n, sizeof *inliers, compare_ints);
    printf("max_features %5d, max_side %5d: %5.2f frames/s, %6.1f ms/frame, %d of %d localized, "
           "median %d inliers (map load %.2f s)\n",
           max_features, max_side, n / seconds, 1000 * seconds / n, localized, n, inliers[n / 2], load);
    free(inliers);
    vf_localizer_close(loc);
}

int main(int argc, char **argv)
{
    if (argc < 2) {
        fprintf(stderr, "usage: bench_localize WS [IMAGE|FOLDER...]\n"
                        "WS needs poses: vfcapture ingest PHOTOS -o WS && vfcapture poses WS\n");
        return 1;
    }
    static vf_rgb8 frames[MAX_FRAMES];
    int n = 0;
    char fox[VF_PATH_MAX];
    if (argc == 2 &&
        vf_shared_path("data/real_captures/instant_ngp_fox/images", fox, sizeof fox) == VF_OK)
        n = load_frames(fox, frames, n);
    for (int i = 2; i < argc; i++)
        n = load_frames(argv[i], frames, n);
    if (n == 0) {
        fprintf(stderr, "bench_localize: no frames\n");
        return 1;
    }
    printf("localizing %d frames of %dx%d against %s\n", n,
           frames[0].width, frames[0].height, argv[1]);
    static const int settings[][2] = {{4096, 1024}, {1024, 1024}, {2048, 640}};
    for (size_t b = 0; b < sizeof settings / sizeof settings[0]; b++)
        bench(argv[1], frames, n, settings[b][0], settings[b][1]);
    for (int i = 0; i < n; i++)
        vf_rgb8_free(&frames[i]);
    return 0;
}
