/* vf/error.h: how every vfcapture function reports failure.
 *
 * A fallible function returns a vf_status. On failure it records one human-readable line
 * (what was wrong and, where possible, what to do) in a thread-local buffer with vf_fail();
 * the caller may add context with vf_error_prefix() and the command line prints it once.
 * The status values double as the process exit codes. The message buffer is owned by the
 * library; callers only read it. */
#ifndef VF_ERROR_H
#define VF_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    VF_OK = 0,        /* success */
    VF_EINPUT = 1,    /* the user's input is wrong: missing file, bad value, unusable data */
    VF_EINTERNAL = 2  /* something failed that the user could not have prevented */
} vf_status;

/* Record a formatted message and return code, so callers can write `return vf_fail(...)`.
 * The arguments may include vf_error_message() (to build on the message before). */
vf_status vf_fail(vf_status code, const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 2, 3)))
#endif
    ;

/* Prepend "context: " to the current message (for example the file being processed). */
void vf_error_prefix(const char *fmt, ...)
#ifdef __GNUC__
    __attribute__((format(printf, 1, 2)))
#endif
    ;

/* The last message recorded on this thread ("" when none). */
const char *vf_error_message(void);

void vf_error_clear(void);

/* A worker thread's error, carried out of a parallel loop. Messages are per thread, so the
 * first failure's status and message are kept here and raised again on the caller's thread:
 *
 *     vf_first_error first = {0};
 *     #pragma omp parallel for
 *     for (int i = 0; i < n; i++)
 *         vf_first_error_keep(&first, work(i));   // VF_OK is ignored; thread-safe
 *     return vf_first_error_raise(&first);        // VF_OK, or the first failure again
 */
typedef struct vf_first_error {
    vf_status status;
    char message[1024];
} vf_first_error;

void vf_first_error_keep(vf_first_error *e, vf_status s);
vf_status vf_first_error_raise(const vf_first_error *e);

#ifdef __cplusplus
}
#endif
#endif
