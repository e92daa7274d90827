#include "vf/resources.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/fsutil.h"

const char *vf_shared_dir(void)
{
    const char *env = getenv("VF_SHARED_DIR");
    return env && env[0] ? env : VF_DEFAULT_SHARED_DIR;
}

vf_status vf_shared_path(const char *relative, char *out, size_t size)
{
    return vf_path_join(out, size, vf_shared_dir(), relative);
}

static int try_model(const char *dir, const char *name, char *out, size_t size)
{
    if (!dir || !dir[0])
        return 0;
    size_t len = strlen(name);
    int has_ext = len > 5 && !strcmp(name + len - 5, ".onnx");
    int n = snprintf(out, size, "%s/%s%s", dir, name, has_ext ? "" : ".onnx");
    return n > 0 && (size_t)n < size && vf_is_file(out);
}

vf_status vf_user_data_path(const char *relative, char *out, size_t size)
{
    const char *xdg = getenv("XDG_DATA_HOME"), *home = getenv("HOME");
    char base[VF_PATH_MAX];
    if (xdg && xdg[0] == '/')
        snprintf(base, sizeof base, "%s/vfcapture", xdg);
    else if (home && home[0])
        snprintf(base, sizeof base, "%s/.local/share/vfcapture", home);
    else
        return vf_fail(VF_EINTERNAL, "neither XDG_DATA_HOME nor HOME is set");
    return relative[0] ? vf_path_join(out, size, base, relative)
                       : (snprintf(out, size, "%s", base), VF_OK);
}

int vf_model_dirs(const char *models_dir, char dirs[][VF_PATH_MAX], int max)
{
    int n = 0;
    const char *env = getenv("VF_MODELS_DIR");
    if (models_dir && models_dir[0] && n < max)
        snprintf(dirs[n++], VF_PATH_MAX, "%s", models_dir);
    if (env && env[0] && n < max)
        snprintf(dirs[n++], VF_PATH_MAX, "%s", env);
    if (n < max && vf_user_data_path("models", dirs[n], VF_PATH_MAX) == VF_OK)
        n++;
    if (n < max && vf_shared_path("models", dirs[n], VF_PATH_MAX) == VF_OK)
        n++;
    return n;
}

static int by_name(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

/* Sorted .onnx names in dir (malloc'd strings); returns their number. */
static int onnx_names(const char *dir, char ***names)
{
    DIR *d = opendir(dir);
    int n = 0, cap = 0;
    *names = NULL;
    for (struct dirent *e; d && (e = readdir(d));) {
        size_t len = strlen(e->d_name);
        if (len <= 5 || strcmp(e->d_name + len - 5, ".onnx") || e->d_name[0] == '.')
            continue;
        if (n == cap) {
            cap = cap ? 2 * cap : 16;
            char **grown = realloc(*names, (size_t)cap * sizeof *grown);
            if (!grown)
                break;
            *names = grown;
        }
        if (((*names)[n] = strdup(e->d_name)))
            n++;
    }
    if (d)
        closedir(d);
    if (n)
        qsort(*names, (size_t)n, sizeof **names, by_name);
    return n;
}

int vf_model_list(const char *models_dir, char paths[][VF_PATH_MAX], int max)
{
    char dirs[4][VF_PATH_MAX];
    int ndirs = vf_model_dirs(models_dir, dirs, 4), count = 0;
    for (int i = 0; i < ndirs; i++) {
        char **names;
        int n = onnx_names(dirs[i], &names);
        for (int k = 0; k < n; k++) {
            int hidden = 0; /* the same name in an earlier folder wins */
            for (int j = 0; j < i && !hidden; j++) {
                char earlier[VF_PATH_MAX];
                hidden = vf_path_join(earlier, sizeof earlier, dirs[j], names[k]) == VF_OK &&
                         vf_is_file(earlier);
            }
            if (!hidden && count < max)
                vf_path_join(paths[count], VF_PATH_MAX, dirs[i], names[k]);
            count += !hidden;
            free(names[k]);
        }
        free(names);
    }
    return count;
}

vf_status vf_find_model(const char *name_or_path, const char *models_dir, char *out, size_t size)
{
    const char *name = name_or_path && name_or_path[0] ? name_or_path : VF_DEFAULT_MODEL;
    size_t len = strlen(name);
    if (strchr(name, '/') || (len > 5 && !strcmp(name + len - 5, ".onnx"))) {
        if (vf_is_file(name)) {
            snprintf(out, size, "%s", name);
            return VF_OK;
        }
        if (strchr(name, '/'))
            return vf_fail(VF_EINPUT, "model file %s does not exist", name);
    }
    char dirs[4][VF_PATH_MAX], tried[4 * VF_PATH_MAX + 8] = "";
    int n = vf_model_dirs(models_dir, dirs, 4);
    for (int i = 0; i < n; i++) {
        if (try_model(dirs[i], name, out, size))
            return VF_OK;
        snprintf(tried + strlen(tried), sizeof tried - strlen(tried), "%s%s", i ? ", " : "",
                 dirs[i]);
    }
    return vf_fail(VF_EINPUT,
                   "model '%s' not found in %s (give a path to an .onnx file, or --models-dir)",
                   name, tried);
}
