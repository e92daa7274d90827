#include "vf/error.h"

#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static _Thread_local char error_text[1024];

vf_status vf_fail(vf_status code, const char *fmt, ...)
{
    /* formatted aside first: an argument may be vf_error_message() itself, as in
     * vf_fail(s, "%s; and then ...", vf_error_message()) */
    char text[sizeof error_text];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(text, sizeof text, fmt, ap);
    va_end(ap);
    memcpy(error_text, text, sizeof error_text);
    return code;
}

void vf_error_prefix(const char *fmt, ...)
{
    char old[sizeof error_text];
    memcpy(old, error_text, sizeof old);
    va_list ap;
    va_start(ap, fmt);
    int n = vsnprintf(error_text, sizeof error_text, fmt, ap);
    va_end(ap);
    size_t used = n < 0 ? 0 : (size_t)n < sizeof error_text ? (size_t)n : sizeof error_text - 1;
    /* "context: old message", cut at the buffer's end */
    snprintf(error_text + used, sizeof error_text - used, ": %.1000s", old);
}

const char *vf_error_message(void) { return error_text; }

void vf_error_clear(void) { error_text[0] = '\0'; }

void vf_first_error_keep(vf_first_error *e, vf_status s)
{
    if (s == VF_OK)
        return;
#pragma omp critical(vf_first_error)
    if (e->status == VF_OK) {
        e->status = s;
        snprintf(e->message, sizeof e->message, "%s", vf_error_message());
    }
}

vf_status vf_first_error_raise(const vf_first_error *e)
{
    return e->status == VF_OK ? VF_OK : vf_fail(e->status, "%s", e->message);
}
