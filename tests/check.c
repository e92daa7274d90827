#include "check.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "vf/fsutil.h"

int check_passed, check_failed;
static char tmpdir[VF_PATH_MAX];

const char *vf_test_shared(const char *relative)
{
    static char paths[8][VF_PATH_MAX];
    static int slot;
    const char *root = getenv("VF_SHARED_DIR");
    char *out = paths[slot++ % 8];
    snprintf(out, VF_PATH_MAX, "%s/%s", root ? root : VF_DEFAULT_SHARED_DIR, relative);
    return out;
}

const char *vf_test_tmpdir(void)
{
    if (!tmpdir[0]) {
        snprintf(tmpdir, sizeof tmpdir, "/tmp/vftest-XXXXXX");
        if (!mkdtemp(tmpdir)) {
            perror("mkdtemp");
            exit(2);
        }
    }
    return tmpdir;
}

int vf_test_system(const char *fmt, ...)
{
    char cmd[8192];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(cmd, sizeof cmd, fmt, ap);
    va_end(ap);
    int status = system(cmd);
    return status == -1 ? -1 : WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int check_finish(void)
{
    if (tmpdir[0] && !getenv("VF_KEEP_TMP"))
        vf_remove_tree(tmpdir);
    printf("%d passed, %d failed\n", check_passed, check_failed);
    return check_failed ? 1 : 0;
}
