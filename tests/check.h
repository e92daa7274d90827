/* tests/check.h: the tiny test harness every tests/test_*.c uses.
 *
 * CHECK(cond, ...) records a failure with a message and carries on; CHECK_NEAR compares
 * numbers with a tolerance. check_finish() prints "N passed, N failed" and returns the exit
 * code. Named cases: main calls check_args(argc, argv) and runs each case through
 * CHECK_CASE(test_resume); `build/test_viewfool resume` then runs only the cases whose name
 * contains "resume" (several words: any of them), `--list` prints the names, and a filter that
 * matches nothing fails. vf_test_shared(rel) gives a path under ../shared (or $VF_SHARED_DIR);
 * vf_test_tmpdir() makes a fresh scratch folder for the test. */
#ifndef VF_TEST_CHECK_H
#define VF_TEST_CHECK_H

#include <math.h>
#include <stdio.h>

extern int check_passed, check_failed;

#define CHECK(cond, ...)                                                                   \
    do {                                                                                   \
        if (cond) {                                                                        \
            check_passed++;                                                                \
        } else {                                                                           \
            check_failed++;                                                                \
            fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond);       \
            fprintf(stderr, __VA_ARGS__);                                                  \
            fputc('\n', stderr);                                                           \
        }                                                                                  \
    } while (0)

#define CHECK_NEAR(a, b, tol)                                                              \
    CHECK(fabs((double)(a) - (double)(b)) <= (tol), "%s = %.9g, %s = %.9g, tolerance %g", #a, \
          (double)(a), #b, (double)(b), (double)(tol))

/* Path under the shared folder (models/, data/); the buffer is static per call slot. */
const char *vf_test_shared(const char *relative);
/* A new empty scratch folder, removed at check_finish() unless VF_KEEP_TMP is set. */
const char *vf_test_tmpdir(void);
/* Run a shell command, return its exit status (-1 when it could not run). */
int vf_test_system(const char *fmt, ...);
int check_finish(void);

void check_args(int argc, char **argv);
/* Whether the case `name` runs under the filter (and says so when filtered). */
int check_case(const char *name);
#define CHECK_CASE(fn)                                                                            \
    do {                                                                                          \
        if (check_case(#fn))                                                                      \
            fn();                                                                                 \
    } while (0)

/* A radiance field trained for `steps` steps (no time limit, so a busy machine gives the same
 * field) on the first `views` frames of ds (all when 0), at most max_points grid points. NULL
 * (and a failed check) when training fails. */
struct vf_dataset;
struct vf_field *vf_test_train_field(const struct vf_dataset *ds, int views, int steps,
                                     double max_points);

#endif
