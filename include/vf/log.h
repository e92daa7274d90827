/* vf/log.h: messages and progress for people, on stderr.
 *
 * stdout is reserved for results (and the --json document), so everything a person reads while
 * a command works goes to stderr. vf_log_set_quiet(1) silences info and progress; warnings
 * always show. On a terminal, progress redraws one line with a bar, rate and ETA; otherwise it
 * prints a plain line every few seconds so logs stay readable. */
#ifndef VF_LOG_H
#define VF_LOG_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

void vf_log_set_quiet(int quiet);

void vf_info(const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 1, 2)))
#endif
    ;
void vf_warn(const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* A progress line for `total` units of work named `what` (for example "frames"). */
typedef struct vf_progress {
    const char *label;
    const char *unit;
    size_t total;
    size_t done;
    double start_time;
    double last_draw;
    int on_terminal;
    char note[96];
} vf_progress;

void vf_progress_begin(vf_progress *p, const char *label, size_t total, const char *unit);
/* Report `done` units finished; `note` (may be NULL) is shown after the rate, e.g. "loss 0.031". */
void vf_progress_update(vf_progress *p, size_t done, const char *note);
void vf_progress_end(vf_progress *p);

/* Seconds on a monotonic clock. */
double vf_now(void);

#ifdef __cplusplus
}
#endif
#endif
