/* vf/fsutil.h: small file-system helpers with vf_status errors.
 *
 * Every writer here is atomic: data goes to a temporary file beside the target, is flushed,
 * and is renamed over the target only when complete, so a crash or a full disk never leaves a
 * half-written file behind. Paths are caller-owned buffers of VF_PATH_MAX bytes. */
#ifndef VF_FSUTIL_H
#define VF_FSUTIL_H

#include <stddef.h>

#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_PATH_MAX 4096

/* out = a + "/" + b; fails (VF_EINPUT) when the result does not fit. */
vf_status vf_path_join(char *out, size_t size, const char *a, const char *b);
/* The folder part of path ("." when none), written to out. */
void vf_path_dirname(char *out, size_t size, const char *path);
/* The last component of path, without its extension when strip_ext is set. */
void vf_path_basename(char *out, size_t size, const char *path, int strip_ext);

int vf_is_file(const char *path);
int vf_is_dir(const char *path);

/* mkdir -p */
vf_status vf_mkdirs(const char *path);
/* rm -rf; missing paths are fine. */
vf_status vf_remove_tree(const char *path);

/* Read a whole file into a NUL-terminated malloc'd buffer the caller frees. */
vf_status vf_read_file(const char *path, char **data, size_t *size);
vf_status vf_write_file_atomic(const char *path, const void *data, size_t size);
vf_status vf_copy_file(const char *src, const char *dst);

/* The JPEG and PNG file names (.jpg, .jpeg, .png, any case; no hidden files) in a folder,
 * sorted by name, in *names (count of them, possibly 0). Free with vf_free_names. */
vf_status vf_list_images(const char *folder, char ***names, int *count);
void vf_free_names(char **names, int count);

#ifdef __cplusplus
}
#endif
#endif
