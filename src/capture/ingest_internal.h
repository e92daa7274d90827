/* src/capture/ingest_internal.h (internal): what the three ingest sources (ingest_video.c,
 * ingest_photos.c, ingest_camera.c) share: a growing list of frame scores, writing frames,
 * and the parts of report.json that do not depend on the source. */
#ifndef VF_INGEST_INTERNAL_H
#define VF_INGEST_INTERNAL_H

#include <jansson.h>

#include "vf/frame_select.h"
#include "vf/fsutil.h"
#include "vf/ingest.h"
#include "vf/rgb8.h"

#define INGEST_IMAGES "images"
#define INGEST_REPORT "report.json"

typedef struct score_list {
    vf_frame_score *items;
    int count, capacity;
} score_list;

/* Append a score (the list grows as needed). */
vf_status vf__score_list_push(score_list *list, const vf_frame_score *score);
void vf__score_list_free(score_list *list);

/* Check the options every source uses. */
vf_status vf__ingest_check_options(const vf_ingest_options *options);

/* A new report {"source": {"kind": kind, "path": absolute path}}. */
json_t *vf__ingest_report_new(const char *kind, const char *path);

/* Make OUT/images; its path goes to images_dir (VF_PATH_MAX bytes). */
vf_status vf__ingest_make_images_dir(const char *out_dir, char *images_dir);

/* Shrink a frame to max_size and write it as images_dir/name; *width, *height (may be NULL)
 * get the size written. */
vf_status vf__ingest_save_frame(const char *images_dir, const char *name, const vf_rgb8 *frame,
                                int max_size, int *width, int *height);

/* Run the selection, fail with "no usable frame in SOURCE" when nothing is kept, and record
 * it in the report: parameters, counts, chosen indices. */
vf_status vf__ingest_select(const score_list *scores, const vf_select_params *params,
                            const char *source, json_t *report, vf_selection *selection);

/* Complete the report (stolen) with "files" (the names written, in chosen order; stolen),
 * the output size, the rejected frames with their reasons and every frame's sharpness; save
 * it as OUT/report.json and hand it out through *out (or release it when out is NULL). */
vf_status vf__ingest_finish(json_t *report, json_t *files, int out_width, int out_height,
                            const score_list *scores, const vf_selection *selection,
                            const char *out_dir, json_t **out);

#endif
