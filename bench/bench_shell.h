/* bench/bench_shell.h: what the benchmarks that drive the vfcapture tool share (header only).
 *
 * bench_tool() is $VF_TOOL, else the vfcapture built beside the benchmark, else `vfcapture` on
 * PATH; bench_run() runs a shell command line
 * (printf-style), echoing it to stderr, and returns 0 when it exited 0, else -1. */
#ifndef VF_BENCH_SHELL_H
#define VF_BENCH_SHELL_H

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static inline const char *bench_tool(void)
{
    const char *t = getenv("VF_TOOL");
    if (t && *t)
        return t;
    static char beside[4096];
    ssize_t n = readlink("/proc/self/exe", beside, sizeof beside - 16);
    char *slash = n > 0 ? memchr(beside, '/', (size_t)n) : NULL;
    if (slash) {
        beside[n] = '\0';
        strcpy(strrchr(beside, '/') + 1, "vfcapture");
        if (access(beside, X_OK) == 0)
            return beside;
    }
    return "vfcapture";
}

static inline int bench_run(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static inline int bench_run(const char *fmt, ...)
{
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    fprintf(stderr, "$ %s\n", cmd);
    return system(cmd) == 0 ? 0 : -1;
}

#endif
