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

/* A failed stage's log (COLMAP's, Blender's) lives in the staging folder, which the failure
 * removes: copy it to $TMPDIR (or /tmp) as vfcapture-<who>-XXXXXX.log and append "(<who>'s
 * log: PATH)" to the current error message. Returns `status` unchanged; does nothing when the
 * log is missing or empty. */
vf_status vf_keep_failure_log(const char *log_path, const char *who, vf_status status);

/* Whether path's extension (after its last '.', any case) is one of exts (NULL-terminated,
 * without dots: {"jpg", "png", NULL}). */
int vf_path_has_extension(const char *path, const char *const *exts);
/* Whether a file name looks like a JPEG or PNG image (.jpg, .jpeg, .png, any case). */
int vf_is_image_name(const char *path);

/* The names (not paths) in a folder that keep() accepts, hidden files never, sorted by name,
 * in *names (count of them, possibly 0). The caller frees them with vf_free_names. VF_EINPUT
 * naming the folder when it cannot be opened. The one folder scan: vf_list_images and the
 * frame source (vf/frames.h) list through it. */
vf_status vf_list_folder(const char *folder, int (*keep)(const char *name), char ***names,
                         int *count);
/* vf_list_folder keeping the JPEG and PNG images (vf_is_image_name). */
vf_status vf_list_images(const char *folder, char ***names, int *count);
/* Free a list from vf_list_folder / vf_list_images; NULL is fine. */
void vf_free_names(char **names, int count);

#ifdef __cplusplus
}
#endif
#endif
