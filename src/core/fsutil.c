#define _GNU_SOURCE
#include "vf/fsutil.h"

#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

vf_status vf_path_join(char *out, size_t size, const char *a, const char *b)
{
    int n = (a[0] == '\0') ? snprintf(out, size, "%s", b)
                           : snprintf(out, size, "%s%s%s", a,
                                      a[strlen(a) - 1] == '/' ? "" : "/", b);
    if (n < 0 || (size_t)n >= size)
        return vf_fail(VF_EINPUT, "path too long: %s/%s", a, b);
    return VF_OK;
}

void vf_path_dirname(char *out, size_t size, const char *path)
{
    const char *slash = strrchr(path, '/');
    if (!slash)
        snprintf(out, size, ".");
    else if (slash == path)
        snprintf(out, size, "/");
    else
        snprintf(out, size, "%.*s", (int)(slash - path), path);
}

void vf_path_basename(char *out, size_t size, const char *path, int strip_ext)
{
    const char *slash = strrchr(path, '/');
    snprintf(out, size, "%s", slash ? slash + 1 : path);
    char *dot = strip_ext ? strrchr(out, '.') : NULL;
    if (dot && dot != out)
        *dot = '\0';
}

int vf_is_file(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISREG(st.st_mode);
}

int vf_is_dir(const char *path)
{
    struct stat st;
    return stat(path, &st) == 0 && S_ISDIR(st.st_mode);
}

vf_status vf_mkdirs(const char *path)
{
    char buf[VF_PATH_MAX];
    if (snprintf(buf, sizeof buf, "%s", path) >= (int)sizeof buf)
        return vf_fail(VF_EINPUT, "path too long: %s", path);
    for (char *p = buf + 1; *p; p++) {
        if (*p != '/')
            continue;
        *p = '\0';
        if (mkdir(buf, 0777) != 0 && errno != EEXIST)
            return vf_fail(VF_EINPUT, "cannot create folder %s: %s", buf, strerror(errno));
        *p = '/';
    }
    if (mkdir(buf, 0777) != 0 && errno != EEXIST)
        return vf_fail(VF_EINPUT, "cannot create folder %s: %s", buf, strerror(errno));
    if (!vf_is_dir(buf))
        return vf_fail(VF_EINPUT, "%s exists and is not a folder", buf);
    return VF_OK;
}

vf_status vf_remove_tree(const char *path)
{
    struct stat st;
    if (lstat(path, &st) != 0)
        return errno == ENOENT ? VF_OK
                               : vf_fail(VF_EINTERNAL, "cannot inspect %s: %s", path, strerror(errno));
    if (S_ISDIR(st.st_mode)) {
        DIR *dir = opendir(path);
        if (!dir)
            return vf_fail(VF_EINTERNAL, "cannot open folder %s: %s", path, strerror(errno));
        struct dirent *entry;
        vf_status status = VF_OK;
        while (status == VF_OK && (entry = readdir(dir))) {
            if (!strcmp(entry->d_name, ".") || !strcmp(entry->d_name, ".."))
                continue;
            char child[VF_PATH_MAX];
            status = vf_path_join(child, sizeof child, path, entry->d_name);
            if (status == VF_OK)
                status = vf_remove_tree(child);
        }
        closedir(dir);
        if (status != VF_OK)
            return status;
        if (rmdir(path) != 0)
            return vf_fail(VF_EINTERNAL, "cannot remove folder %s: %s", path, strerror(errno));
        return VF_OK;
    }
    if (unlink(path) != 0)
        return vf_fail(VF_EINTERNAL, "cannot remove %s: %s", path, strerror(errno));
    return VF_OK;
}

vf_status vf_read_file(const char *path, char **data, size_t *size)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return vf_fail(VF_EINPUT, "cannot open %s: %s", path, strerror(errno));
    size_t cap = 1 << 16, len = 0;
    char *buf = malloc(cap);
    for (;;) {
        if (!buf) {
            fclose(f);
            return vf_fail(VF_EINTERNAL, "out of memory reading %s", path);
        }
        len += fread(buf + len, 1, cap - len - 1, f);
        if (len < cap - 1)
            break;
        cap *= 2;
        char *grown = realloc(buf, cap);
        if (!grown)
            free(buf);
        buf = grown;
    }
    int failed = ferror(f);
    fclose(f);
    if (failed) {
        free(buf);
        return vf_fail(VF_EINPUT, "cannot read %s", path);
    }
    buf[len] = '\0';
    *data = buf;
    if (size)
        *size = len;
    return VF_OK;
}

vf_status vf_write_file_atomic(const char *path, const void *data, size_t size)
{
    char tmp[VF_PATH_MAX];
    if (snprintf(tmp, sizeof tmp, "%s.tmp-%d", path, (int)getpid()) >= (int)sizeof tmp)
        return vf_fail(VF_EINPUT, "path too long: %s", path);
    int fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd < 0)
        return vf_fail(VF_EINPUT, "cannot write %s: %s", path, strerror(errno));
    const char *p = data;
    size_t left = size;
    while (left > 0) {
        ssize_t n = write(fd, p, left);
        if (n < 0 && errno == EINTR)
            continue;
        if (n <= 0) {
            int err = n < 0 ? errno : ENOSPC;
            close(fd);
            unlink(tmp);
            return vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(err));
        }
        p += n;
        left -= (size_t)n;
    }
    if (fsync(fd) != 0 || close(fd) != 0) {
        int err = errno;
        unlink(tmp);
        return vf_fail(VF_EINTERNAL, "cannot write %s: %s", path, strerror(err));
    }
    if (rename(tmp, path) != 0) {
        int err = errno;
        unlink(tmp);
        return vf_fail(VF_EINTERNAL, "cannot replace %s: %s", path, strerror(err));
    }
    return VF_OK;
}

vf_status vf_copy_file(const char *src, const char *dst)
{
    char *data;
    size_t size;
    vf_status status = vf_read_file(src, &data, &size);
    if (status != VF_OK)
        return status;
    status = vf_write_file_atomic(dst, data, size);
    free(data);
    return status;
}

int vf_path_has_extension(const char *path, const char *const *exts)
{
    const char *dot = strrchr(path, '.');
    if (!dot || strchr(dot, '/'))
        return 0;
    for (; *exts; exts++)
        if (!strcasecmp(dot + 1, *exts))
            return 1;
    return 0;
}

int vf_is_image_name(const char *path)
{
    static const char *const exts[] = {"jpg", "jpeg", "png", NULL};
    return vf_path_has_extension(path, exts);
}

static int compare_names(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

vf_status vf_list_folder(const char *folder, int (*keep)(const char *name), char ***names,
                         int *count)
{
    *names = NULL;
    *count = 0;
    DIR *dir = opendir(folder);
    if (!dir)
        return vf_fail(VF_EINPUT, "cannot open folder %s: %s", folder, strerror(errno));
    struct dirent *entry;
    int capacity = 0;
    vf_status status = VF_OK;
    while (status == VF_OK && (entry = readdir(dir))) {
        if (entry->d_name[0] == '.' || !keep(entry->d_name))
            continue;
        if (*count == capacity) {
            capacity = capacity ? 2 * capacity : 64;
            char **grown = realloc(*names, (size_t)capacity * sizeof *grown);
            if (!grown) {
                status = vf_fail(VF_EINTERNAL, "out of memory listing %s", folder);
                break;
            }
            *names = grown;
        }
        if (!((*names)[*count] = strdup(entry->d_name)))
            status = vf_fail(VF_EINTERNAL, "out of memory listing %s", folder);
        else
            (*count)++;
    }
    closedir(dir);
    if (status != VF_OK) {
        vf_free_names(*names, *count);
        *names = NULL;
        *count = 0;
    } else if (*count > 1) {
        qsort(*names, (size_t)*count, sizeof **names, compare_names);
    }
    return status;
}

vf_status vf_list_images(const char *folder, char ***names, int *count)
{
    return vf_list_folder(folder, vf_is_image_name, names, count);
}

void vf_free_names(char **names, int count)
{
    for (int i = 0; i < count; i++)
        free(names[i]);
    free(names);
}

vf_status vf_keep_failure_log(const char *log_path, const char *who, vf_status status)
{
    struct stat info;
    if (!log_path || !log_path[0] || stat(log_path, &info) != 0 || info.st_size == 0)
        return status;
    const char *tmp = getenv("TMPDIR");
    char copy[VF_PATH_MAX], message[1024];
    snprintf(copy, sizeof copy, "%s/vfcapture-%s-XXXXXX.log", tmp && *tmp ? tmp : "/tmp", who);
    int fd = mkstemps(copy, 4);
    if (fd < 0)
        return status;
    close(fd);
    snprintf(message, sizeof message, "%s", vf_error_message());
    if (vf_copy_file(log_path, copy) == VF_OK)
        vf_fail(status, "%s (%s's log: %s)", message, who, copy);
    else
        unlink(copy);
    return status;
}
