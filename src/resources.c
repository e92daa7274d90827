#include "vf/resources.h"

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
    char shared_models[VF_PATH_MAX];
    vf_shared_path("models", shared_models, sizeof shared_models);
    const char *env = getenv("VF_MODELS_DIR");
    if (try_model(models_dir, name, out, size) || try_model(env, name, out, size) ||
        try_model(shared_models, name, out, size))
        return VF_OK;
    return vf_fail(VF_EINPUT,
                   "model '%s' not found in %s%s%s%s%s (give a path to an .onnx file, or --models-dir)",
                   name, models_dir ? models_dir : "", models_dir ? ", " : "",
                   env ? env : "", env ? ", " : "", shared_models);
}
