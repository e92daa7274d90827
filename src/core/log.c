#include "vf/log.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

static int quiet_mode;

void vf_log_set_quiet(int quiet) { quiet_mode = quiet; }

double vf_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void vf_info(const char *fmt, ...)
{
    if (quiet_mode)
        return;
    va_list ap;
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

void vf_warn(const char *fmt, ...)
{
    va_list ap;
    fputs("warning: ", stderr);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

static void format_duration(char *out, size_t size, double seconds)
{
    if (seconds < 0 || seconds > 360000)
        snprintf(out, size, "--:--");
    else if (seconds >= 3600)
        snprintf(out, size, "%d:%02d:%02d", (int)seconds / 3600, ((int)seconds / 60) % 60,
                 (int)seconds % 60);
    else
        snprintf(out, size, "%d:%02d", (int)seconds / 60, (int)seconds % 60);
}

static void draw(vf_progress *p, int final)
{
    double elapsed = vf_now() - p->start_time;
    double rate = elapsed > 0 ? (double)p->done / elapsed : 0;
    double eta = rate > 0 && p->total > p->done ? (double)(p->total - p->done) / rate : 0;
    char eta_text[32], elapsed_text[32];
    format_duration(eta_text, sizeof eta_text, eta);
    format_duration(elapsed_text, sizeof elapsed_text, elapsed);
    double fraction = p->total ? (double)p->done / (double)p->total : 1.0;
    const char *sep = p->note[0] ? "  " : "";

    /* Without a unit (work measured as a fraction) only the share done and the time show. */
    char counts[96] = "";
    if (p->unit[0])
        snprintf(counts, sizeof counts, "%zu/%zu %s, %.1f %s/s, ", p->done, p->total, p->unit, rate,
                 p->unit);
    if (p->on_terminal) {
        char bar[26];
        int filled = (int)(fraction * 24 + 0.5);
        for (int i = 0; i < 24; i++)
            bar[i] = i < filled ? '#' : '.';
        bar[24] = '\0';
        fprintf(stderr, "\r\033[K%s [%s] %3.0f%%  %s%s %s%s%s", p->label, bar, 100.0 * fraction,
                counts, final ? "took" : "eta", final ? elapsed_text : eta_text, sep, p->note);
        if (final)
            fputc('\n', stderr);
    } else {
        fprintf(stderr, "%s: %3.0f%%, %s%s %s%s%s\n", p->label, 100.0 * fraction, counts,
                final ? "took" : "eta", final ? elapsed_text : eta_text, sep, p->note);
    }
    fflush(stderr);
    p->last_draw = vf_now();
}

void vf_progress_begin(vf_progress *p, const char *label, size_t total, const char *unit)
{
    memset(p, 0, sizeof *p);
    p->label = label;
    p->unit = unit;
    p->total = total;
    p->start_time = vf_now();
    p->on_terminal = isatty(STDERR_FILENO);
}

void vf_progress_update(vf_progress *p, size_t done, const char *note)
{
    p->done = done;
    if (note)
        snprintf(p->note, sizeof p->note, "%s", note);
    if (quiet_mode)
        return;
    /* Redraw a terminal line ~5 times a second; a log line every 5 seconds. */
    double interval = p->on_terminal ? 0.2 : 5.0;
    if (vf_now() - p->last_draw >= interval)
        draw(p, 0);
}

void vf_progress_end(vf_progress *p)
{
    if (!quiet_mode)
        draw(p, 1);
}
