/* What an input is, by content (vf_ingest_input_identity in vf/ingest.h). */
#define _GNU_SOURCE /* struct stat's st_mtim */
#include "vf/ingest.h"

#include <inttypes.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

/* A 64-bit hash of bytes, 8 at a time (multiply and rotate): it tells a changed file from an
 * unchanged one, no more; a video of gigabytes hashes at memory speed. */
typedef struct content_hash {
    uint64_t h;
    uint64_t bytes;
} content_hash;

static void hash_bytes(content_hash *c, const unsigned char *p, size_t n)
{
    const uint64_t k = 0x9e3779b97f4a7c15ull;
    size_t i = 0;
    for (; i + 8 <= n; i += 8) {
        uint64_t w;
        memcpy(&w, p + i, 8);
        c->h = ((c->h ^ w) * k);
        c->h = (c->h << 29) | (c->h >> 35);
    }
    for (; i < n; i++)
        c->h = (c->h ^ p[i]) * 0x100000001b3ull;
    c->bytes += n;
}

static vf_status hash_file(content_hash *c, const char *path)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return vf_fail(VF_EINPUT, "cannot read %s", path);
    static _Thread_local unsigned char buf[1 << 20];
    size_t n;
    while ((n = fread(buf, 1, sizeof buf, f)) > 0)
        hash_bytes(c, buf, n); /* whole chunks but the last */
    int failed = ferror(f);
    fclose(f);
    return failed ? vf_fail(VF_EINPUT, "cannot read %s", path) : VF_OK;
}

static int any_name(const char *name)
{
    (void)name;
    return 1;
}

/* A folder: its files' names and contents in name order (sub-folders are not read). */
static vf_status hash_folder(content_hash *c, const char *dir, int *files)
{
    char **names = NULL;
    int n = 0;
    vf_status s = vf_list_folder(dir, any_name, &names, &n);
    *files = 0;
    for (int i = 0; i < n && s == VF_OK; i++) {
        char path[VF_PATH_MAX];
        if ((s = vf_path_join(path, sizeof path, dir, names[i])) == VF_OK && vf_is_file(path)) {
            hash_bytes(c, (const unsigned char *)names[i], strlen(names[i]) + 1);
            s = hash_file(c, path);
            (*files)++;
        }
    }
    vf_free_names(names, n);
    return s;
}

vf_status vf_ingest_input_identity(const char *path, json_t **identity)
{
    *identity = NULL;
    struct stat st;
    if (stat(path, &st) != 0)
        return vf_fail(VF_EINPUT, "%s does not exist", path);
    content_hash c = {.h = 0xcbf29ce484222325ull};
    int files = 1;
    vf_status s = S_ISDIR(st.st_mode) ? hash_folder(&c, path, &files) : hash_file(&c, path);
    if (s != VF_OK)
        return s;
    char hash[24], mtime[48];
    snprintf(hash, sizeof hash, "%016" PRIx64, c.h);
    snprintf(mtime, sizeof mtime, "%lld.%09ld", (long long)st.st_mtim.tv_sec,
             (long)st.st_mtim.tv_nsec);
    *identity = json_pack("{s:I, s:i, s:s, s:s}", "bytes", (json_int_t)c.bytes, "files", files,
                          "mtime", mtime, "hash", hash);
    return *identity ? VF_OK : vf_fail(VF_EINTERNAL, "out of memory");
}
