/* vf/resources.h: where the tool finds its models and bundled data.
 *
 * The shared folder (models/, data/) is $VF_SHARED_DIR when set, else the folder fixed at
 * build time (../shared beside the source tree). The per-user data folder is
 * $XDG_DATA_HOME/vfcapture (default ~/.local/share/vfcapture): a user's own models go in its
 * models/, and scripts/setup.sh installs ONNX Runtime into its onnxruntime/. Models are looked
 * up by name in an explicit folder (--models-dir), then $VF_MODELS_DIR, then <user>/models,
 * then <shared>/models; a name with a '/' or ending in .onnx that exists is taken as a path.
 * Output buffers are the caller's. */
#ifndef VF_RESOURCES_H
#define VF_RESOURCES_H

#include <stddef.h>

#include "vf/error.h"
#include "vf/fsutil.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The shared folder (no trailing slash). */
const char *vf_shared_dir(void);

/* <shared>/<relative> into out. */
vf_status vf_shared_path(const char *relative, char *out, size_t size);

/* <user data>/<relative> into out (relative may be ""). VF_EINTERNAL when neither
 * $XDG_DATA_HOME nor $HOME is set. */
vf_status vf_user_data_path(const char *relative, char *out, size_t size);

/* The folders searched for models by name, in order (models_dir may be NULL; unset ones are
 * left out): writes up to max paths of VF_PATH_MAX bytes into dirs and returns their number. */
int vf_model_dirs(const char *models_dir, char dirs[][VF_PATH_MAX], int max);

/* Every .onnx file in those folders, by name, sorted within each folder; a name found in an
 * earlier folder hides the same name later (as vf_find_model would). Writes up to max paths
 * and returns how many there are (may exceed max). */
int vf_model_list(const char *models_dir, char paths[][VF_PATH_MAX], int max);

/* Resolve a model given by name ("mobilenet_v2_1.0_224_quant", with or without .onnx) or path.
 * Searched in vf_model_dirs(models_dir) order. VF_EINPUT with the places tried when not found. */
vf_status vf_find_model(const char *name_or_path, const char *models_dir, char *out, size_t size);

#define VF_DEFAULT_MODEL "mobilenet_v2_1.0_224_quant"

#ifdef __cplusplus
}
#endif
#endif
