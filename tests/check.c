#include "check.h"

#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>

#include "vf/dataset.h"
#include "vf/field.h"
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

static char **filters;
static int filter_count, listing, matched;

void check_args(int argc, char **argv)
{
    listing = argc > 1 && !strcmp(argv[1], "--list");
    filters = argv + 1;
    filter_count = listing ? 0 : argc - 1;
}

int check_case(const char *name)
{
    if (listing) {
        printf("%s\n", name);
        return 0;
    }
    for (int i = 0; i < filter_count; i++)
        if (strstr(name, filters[i])) {
            matched++;
            printf("== %s\n", name);
            return 1;
        }
    return filter_count == 0;
}

int check_finish(void)
{
    if (tmpdir[0] && !getenv("VF_KEEP_TMP"))
        vf_remove_tree(tmpdir);
    if (listing)
        return 0;
    if (filter_count > 0 && matched == 0) {
        fprintf(stderr, "no case matches '%s' (--list names them)\n", filters[0]);
        return 1;
    }
    printf("%d passed, %d failed\n", check_passed, check_failed);
    return check_failed ? 1 : 0;
}

vf_field *vf_test_train_field(const vf_dataset *ds, int views, int steps, double max_points)
{
    vf_field_train_options opt;
    vf_field_train_defaults(&opt);
    opt.seconds = 0;
    opt.steps = steps;
    opt.max_points = max_points;
    vf_field_trainer *t = NULL;
    vf_status s = vf_field_trainer_create(&opt, &t);
    int n = views > 0 && views < ds->count ? views : ds->count;
    for (int i = 0; i < n && s == VF_OK; i++) {
        vf_image img = {0};
        s = vf_image_load(ds->frames[i].image_path, &img);
        if (s == VF_OK)
            s = vf_field_trainer_add_view(t, &ds->frames[i].camera, ds->frames[i].c2w, &img);
        vf_image_free(&img);
    }
    if (s == VF_OK)
        s = vf_field_trainer_start(t);
    vf_field_train_status st = {0};
    while (s == VF_OK && !st.done)
        s = vf_field_trainer_step(t, &st);
    CHECK(s == VF_OK, "training a field: %s", vf_error_message());
    vf_field *f = s == VF_OK ? vf_field_trainer_take_field(t) : NULL;
    vf_field_trainer_free(t);
    if (f)
        printf("field: %d steps on %d views in %.0f s, train PSNR %.1f dB\n", st.step, n,
               st.elapsed, st.psnr);
    return f;
}
