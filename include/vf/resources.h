/* vf/resources.h: where the tool finds its models and bundled data.
 *
 * The shared folder (models/, data/) is $VF_SHARED_DIR when set, else the folder fixed at
 * build time (../shared beside the source tree). Models are looked up by name in
 * $VF_MODELS_DIR, then <shared>/models; a name with a '/' or ending in .onnx that exists is
 * taken as a path. Output buffers are the caller's. */
#ifndef VF_RESOURCES_H
#define VF_RESOURCES_H

#include <stddef.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

/* The shared folder (no trailing slash). */
const char *vf_shared_dir(void);

/* <shared>/<relative> into out. */
vf_status vf_shared_path(const char *relative, char *out, size_t size);

/* Resolve a model given by name ("mobilenet_v2_1.0_224_quant", with or without .onnx) or path.
 * models_dir (may be NULL) is searched first. VF_EINPUT with the places tried when not found. */
vf_status vf_find_model(const char *name_or_path, const char *models_dir, char *out, size_t size);

#define VF_DEFAULT_MODEL "mobilenet_v2_1.0_224_quant"

#ifdef __cplusplus
}
#endif
#endif
