/* vf/frame_select.h: which frames of a capture to keep.
 *
 * Given every frame's score (vf/sharpness.h), in capture order:
 *   1. a frame much blurrier than its neighbours (sharpness below blur_ratio times the median
 *      of the frames within blur_window of it) is rejected as blurry: motion blur and focus
 *      hunting come and go within a second, while the scene's own amount of detail changes
 *      slowly, so only the local median is a fair yardstick (frames without an order, such
 *      as a folder of photos, are compared with the median of them all);
 *   2. the capture is cut into min(max_frames, count) stretches of equal length, and each
 *      stretch gives its sharpest frame that is not blurry and not a near-duplicate of the
 *      frame chosen before it (thumbnails closer than duplicate_threshold: the camera stood
 *      still), so the kept frames spread evenly over the capture.
 * A stretch may give nothing, so fewer than max_frames may be kept.
 *
 * vf_select_frames fills a vf_selection the caller releases with vf_selection_free.
 * vf_live_counter gives the same verdicts on the fly, for showing progress while capturing. */
#ifndef VF_FRAME_SELECT_H
#define VF_FRAME_SELECT_H

#include "vf/error.h"
#include "vf/sharpness.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_select_params {
    int max_frames;             /* keep at most this many (default 100) */
    double blur_ratio;          /* blurry below this times the local median (default 0.4) */
    int blur_window;            /* neighbours on each side for the local median (default 7) */
    int unordered;              /* frames not in capture order (photos): compare each with the
                                   median of all frames, not of its neighbours (default 0) */
    double duplicate_threshold; /* thumbnail difference below which frames repeat (default 1.5) */
} vf_select_params;

/* The defaults above. */
void vf_select_defaults(vf_select_params *params);

typedef enum {
    VF_FRAME_UNUSED = 0, /* usable, but another frame of its stretch was sharper */
    VF_FRAME_CHOSEN,
    VF_FRAME_BLURRY,
    VF_FRAME_DUPLICATE
} vf_frame_verdict;

typedef struct vf_selection {
    int count;                /* frames scored */
    vf_frame_verdict *verdict;  /* per frame */
    double *local_median;     /* per frame: the median sharpness around it */
    int *duplicate_of;        /* per frame: the chosen frame it repeats, or -1 */
    double *difference;       /* per frame: its thumbnail difference to that frame, or 0 */
    int *chosen;              /* indices of the kept frames, increasing */
    int chosen_count;
} vf_selection;

/* Choose frames. count may be 0 (nothing chosen). VF_EINPUT for bad parameters. */
vf_status vf_select_frames(const vf_frame_score *scores, int count, const vf_select_params *params,
                           vf_selection *out);

/* Release a selection's arrays and zero it; safe on a zeroed or already freed one. */
void vf_selection_free(vf_selection *selection);

/* "chosen", "blurry", "duplicate" or "unused". */
const char *vf_frame_verdict_name(vf_frame_verdict verdict);

/* Counts usable frames while they arrive: a frame is usable when it is not blurry next to the
 * recent frames (the median of the last 2 * blur_window + 1) and not a near-duplicate of the
 * last usable frame. An estimate for the person holding the camera; the kept set comes from
 * vf_select_frames at the end. Zero-initialise, then feed every frame. */
typedef struct vf_live_counter {
    double recent[64];       /* ring of the latest sharpness values */
    int seen;                /* frames fed */
    int usable;              /* frames counted usable */
    vf_frame_score last;     /* the last usable frame */
} vf_live_counter;

/* Feed one frame; returns 1 when it counts as usable. */
int vf_live_counter_add(vf_live_counter *counter, const vf_frame_score *score,
                        const vf_select_params *params);

#ifdef __cplusplus
}
#endif
#endif
