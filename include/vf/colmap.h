/* vf/colmap.h: running COLMAP's command-line tools as child processes.
 *
 * COLMAP (the `colmap` program, 3.8 on Debian) does feature extraction, matching and
 * structure from motion. vfcapture runs it as a child process (vf/process.h: never a shell),
 * appends everything it prints to one log file, and turns the counts it prints ("Processed file
 * [3/50]", "Registering image #7 (12)") into a progress line. The program is `colmap` from PATH,
 * or $VF_COLMAP when set.
 *
 * Memory: a vf_colmap owns its open log file (vf_colmap_close). */
#ifndef VF_COLMAP_H
#define VF_COLMAP_H

#include <stdio.h>

#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/process.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_colmap {
    char program[VF_PATH_MAX]; /* resolved path of the colmap executable */
    char log_path[VF_PATH_MAX];
    FILE *log;
    int last_exit; /* exit code of the last run; -1 when it crashed or could not start */
} vf_colmap;

/* Find the colmap executable ($VF_COLMAP, else PATH) and open (truncate) the log file.
 * VF_EINTERNAL with an install hint when COLMAP is missing. */
vf_status vf_colmap_open(vf_colmap *colmap, const char *log_path);
void vf_colmap_close(vf_colmap *colmap);

/* Run `colmap args...` (args->items[0] is the COLMAP command, e.g. "feature_extractor") and
 * wait for it. Its output goes to the log; `label` names the progress line, sized for `total`
 * units (images; NULL label: no progress line), and `seconds` (may be NULL) receives the wall
 * time. A nonzero exit or a crash is VF_EINTERNAL, quoting COLMAP's last error line;
 * colmap->last_exit (the exit code, -1 for a crash) tells them apart. */
vf_status vf_colmap_run(vf_colmap *colmap, const char *label, size_t total, const vf_args *args,
                        double *seconds);

/* Parse one line of COLMAP output for progress: returns 1 and sets done/total when the line
 * reports a count ("Processed file [i/n]", "Matching image [i/n]", "Matching block [a/b, c/d]",
 * "Undistorting image [i/n]", or "Registering image #id (k)", which gives done = k and leaves
 * total alone), else 0. Exposed for tests. */
int vf_colmap_parse_progress(const char *line, size_t *done, size_t *total);

#ifdef __cplusplus
}
#endif
#endif
