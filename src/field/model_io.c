/* Model files and training checkpoints.
 *
 * A model file is
 *     "VFFIELD\n"  u32 version  u32 header bytes  header  grid values...  u64 checksum
 * with every number little-endian as the machine writes it (the tool runs on x86-64 and
 * arm64, both little-endian). Each grid stores its FIELD_CH_USED used channels per point; the
 * occupancy is recomputed from the densities on load. The checksum (a 64-bit FNV-style hash of
 * every byte before it, written and read in the same pieces) catches truncated and corrupted
 * files. A checkpoint is "VFCKPT\n\0", a version, the trainer's state, the model as above and
 * the optimizer's moments, with its own checksum. Files are written to a temporary name and
 * renamed, so an interrupted save never leaves a half file under the real name. */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "trainer_internal.h"
#include "vf/fsutil.h"
#include "vf/log.h"
#include "vf/workspace.h"

#define MODEL_MAGIC "VFFIELD\n"
#define MODEL_VERSION 1u
#define CHECKPOINT_MAGIC "VFCKPT\n"
#define CHECKPOINT_VERSION 4u /* 2: surroundings model replaced keep_background; 3: colour
                                 model; 4: the photos' appearance */

/* ---- a file with a running checksum ------------------------------------------------------ */

typedef struct stream {
    FILE *fp;
    const char *path;
    uint64_t hash;
    int failed;
} stream;

static uint64_t hash_bytes(uint64_t h, const void *data, size_t size)
{
    const uint8_t *p = data;
    size_t i = 0;
    for (; i + 8 <= size; i += 8) { /* a word at a time: fast enough for big grids */
        uint64_t w;
        memcpy(&w, p + i, 8);
        h = (h ^ w) * 0x100000001b3ull;
        h ^= h >> 29;
    }
    for (; i < size; i++)
        h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

static void put(stream *s, const void *data, size_t size)
{
    if (s->failed)
        return;
    s->hash = hash_bytes(s->hash, data, size);
    if (fwrite(data, 1, size, s->fp) != size)
        s->failed = 1;
}

static void get(stream *s, void *data, size_t size)
{
    if (s->failed)
        return;
    if (fread(data, 1, size, s->fp) != size) {
        s->failed = 1;
        memset(data, 0, size);
        return;
    }
    s->hash = hash_bytes(s->hash, data, size);
}

static vf_status open_for_write(stream *s, const char *path, char *tmp, size_t tmp_size)
{
    memset(s, 0, sizeof *s);
    s->path = path;
    s->hash = 0xcbf29ce484222325ull;
    snprintf(tmp, tmp_size, "%s.tmp-%ld", path, (long)getpid());
    if (!(s->fp = fopen(tmp, "wb")))
        return vf_fail(VF_EINPUT, "cannot write %s: %s", path, strerror(errno));
    return VF_OK;
}

/* Write the checksum, flush and rename into place. */
static vf_status finish_write(stream *s, const char *tmp)
{
    uint64_t sum = s->hash;
    put(s, &sum, sizeof sum);
    int failed = s->failed || fflush(s->fp) != 0 || fsync(fileno(s->fp)) != 0;
    int saved_errno = errno;
    failed |= fclose(s->fp) != 0;
    if (!failed && rename(tmp, s->path) == 0)
        return VF_OK;
    saved_errno = errno ? errno : saved_errno;
    remove(tmp);
    /* as vf_write_file_atomic: a file that opened but cannot be written (a full disk, an I/O
     * error) is a failure of the machine, exit 2, not bad input */
    return vf_fail(VF_EINTERNAL, "cannot write %s: %s", s->path, strerror(saved_errno));
}

static vf_status open_for_read(stream *s, const char *path)
{
    memset(s, 0, sizeof *s);
    s->path = path;
    s->hash = 0xcbf29ce484222325ull;
    if (!(s->fp = fopen(path, "rb")))
        return vf_fail(VF_EINPUT, "cannot read %s: %s", path, strerror(errno));
    return VF_OK;
}

/* Read and compare the checksum, then close. */
static vf_status finish_read(stream *s, const char *what)
{
    uint64_t expected = s->hash, stored = 0;
    get(s, &stored, sizeof stored);
    int trailing = fgetc(s->fp) != EOF;
    fclose(s->fp);
    if (s->failed)
        return vf_fail(VF_EINPUT, "%s is truncated: %s", s->path, what);
    if (stored != expected || trailing)
        return vf_fail(VF_EINPUT, "%s is corrupt (checksum mismatch): %s", s->path, what);
    return VF_OK;
}

/* ---- the model ------------------------------------------------------------------------- */

/* The fixed part of a model, as stored. */
typedef struct model_header {
    uint32_t grid_count, channels;
    float density_shift, density_scale, step_ratio, background[3], occupancy_alpha,
        stop_transmittance;
    int32_t camera_size[2];
    double camera[8]; /* fx fy cx cy k1 k2 p1 p2 */
    double scene_center[3], camera_distance;
    int32_t dim[FIELD_MAX_GRIDS][3];
    float lo[FIELD_MAX_GRIDS][3], voxel[FIELD_MAX_GRIDS];
} model_header;

static void write_model(stream *s, const vf_field *f)
{
    model_header h;
    memset(&h, 0, sizeof h);
    h.grid_count = (uint32_t)f->grid_count;
    h.channels = FIELD_CH_USED;
    h.density_shift = f->density_shift;
    h.density_scale = f->density_scale;
    h.step_ratio = f->step_ratio;
    memcpy(h.background, f->background, sizeof h.background);
    h.occupancy_alpha = f->occupancy_alpha;
    h.stop_transmittance = f->stop_transmittance;
    h.camera_size[0] = f->camera.width;
    h.camera_size[1] = f->camera.height;
    const double cam[8] = {f->camera.fx, f->camera.fy, f->camera.cx, f->camera.cy,
                           f->camera.k1, f->camera.k2, f->camera.p1, f->camera.p2};
    memcpy(h.camera, cam, sizeof cam);
    memcpy(h.scene_center, f->scene_center, sizeof h.scene_center);
    h.camera_distance = f->camera_distance;
    for (int i = 0; i < f->grid_count; i++) {
        memcpy(h.dim[i], f->grids[i].dim, sizeof h.dim[i]);
        memcpy(h.lo[i], f->grids[i].lo, sizeof h.lo[i]);
        h.voxel[i] = f->grids[i].voxel;
    }
    const uint32_t version = MODEL_VERSION, size = sizeof h;
    put(s, MODEL_MAGIC, 8);
    put(s, &version, sizeof version);
    put(s, &size, sizeof size);
    put(s, &h, sizeof h);
    /* values: the used channels of every point, in chunks */
    enum { CHUNK = 65536 };
    float *buf = malloc((size_t)CHUNK * FIELD_CH_USED * sizeof(float));
    if (!buf) {
        s->failed = 1;
        return;
    }
    for (int i = 0; i < f->grid_count; i++) {
        const field_grid *g = &f->grids[i];
        for (size_t start = 0; start < g->points; start += CHUNK) {
            size_t n = g->points - start < CHUNK ? g->points - start : CHUNK;
            for (size_t p = 0; p < n; p++)
                memcpy(buf + p * FIELD_CH_USED, g->values + (start + p) * FIELD_CH,
                       FIELD_CH_USED * sizeof(float));
            put(s, buf, n * FIELD_CH_USED * sizeof(float));
        }
    }
    free(buf);
}

static int finite_in(double x, double lo, double hi)
{
    return isfinite(x) && x >= lo && x <= hi;
}

/* Everything a model file says is checked before it is trusted (files travel between people):
 * every number finite and in a range training can produce, with margins. The bounds also keep
 * the renderer finite: with step_ratio >= 1e-3 and at most 4096 points an axis a ray takes
 * fewer than 1.3e7 samples a grid, so the float sample counters of the marchers (exact to
 * 2^24) always advance. NULL when sane, else what is wrong. */
static const char *header_problem(const model_header *h)
{
    if (h->grid_count < 1 || h->grid_count > FIELD_MAX_GRIDS || h->channels != FIELD_CH_USED)
        return "grid count or channels";
    if (h->camera_size[0] < 1 || h->camera_size[1] < 1 || h->camera_size[0] > 100000 ||
        h->camera_size[1] > 100000)
        return "camera size";
    for (int i = 0; i < 8; i++)
        if (!finite_in(h->camera[i], i < 2 ? 1e-6 : -1e7, 1e7))
            return "camera";
    if (!finite_in(h->step_ratio, 1e-3, 10) || !finite_in(h->density_scale, 1e-6, 1e6) ||
        !finite_in(h->density_shift, -1e3, 1e3))
        return "step or density scale";
    if (!finite_in(h->occupancy_alpha, 0, 1) || !finite_in(h->stop_transmittance, 0, 1))
        return "occupancy or stop threshold";
    for (int c = 0; c < 3; c++)
        if (!finite_in(h->background[c], 0, 1) || !finite_in(h->scene_center[c], -1e6, 1e6))
            return "background or scene centre";
    if (!finite_in(h->camera_distance, 0, 1e6))
        return "camera distance";
    for (uint32_t i = 0; i < h->grid_count; i++) {
        if (!finite_in(h->voxel[i], 1e-6, 1e3))
            return "voxel size";
        for (int a = 0; a < 3; a++)
            if (h->dim[i][a] < 2 || h->dim[i][a] > 4096 || !finite_in(h->lo[i][a], -1e4, 1e4))
                return "grid box";
    }
    return NULL;
}

/* Bytes left in the file from the current position (-1 when it cannot be told). */
static long long bytes_left(stream *s)
{
    struct stat st;
    long here = ftell(s->fp);
    if (here < 0 || fstat(fileno(s->fp), &st) != 0)
        return -1;
    return (long long)st.st_size - here;
}

/* Read a model; `what` names the kind of file for messages. */
static vf_status read_model(stream *s, vf_field **out)
{
    *out = NULL;
    char magic[8];
    uint32_t version = 0, size = 0;
    get(s, magic, 8);
    if (s->failed || memcmp(magic, MODEL_MAGIC, 8) != 0)
        return vf_fail(VF_EINPUT, "%s is not a vfcapture radiance field (no VFFIELD header)",
                       s->path);
    get(s, &version, sizeof version);
    get(s, &size, sizeof size);
    if (version != MODEL_VERSION)
        return vf_fail(VF_EINPUT,
                       "%s is a radiance field of format version %u; this vfcapture reads "
                       "version %u: train it again",
                       s->path, version, MODEL_VERSION);
    model_header h;
    if (size != sizeof h)
        return vf_fail(VF_EINPUT, "%s is corrupt (header size %u)", s->path, size);
    get(s, &h, sizeof h);
    if (s->failed)
        return vf_fail(VF_EINPUT, "%s is truncated", s->path);
    const char *problem = header_problem(&h);
    if (problem)
        return vf_fail(VF_EINPUT, "%s is corrupt (impossible header values: %s)", s->path,
                       problem);
    /* The grids must fit in what is left of the file before any memory is taken for them. */
    unsigned long long need = 0;
    for (uint32_t i = 0; i < h.grid_count; i++)
        need += (unsigned long long)h.dim[i][0] * h.dim[i][1] * h.dim[i][2] * FIELD_CH_USED *
                sizeof(float);
    long long left = bytes_left(s);
    if (left >= 0 && need > (unsigned long long)left)
        return vf_fail(VF_EINPUT, "%s is truncated or corrupt (its header claims %.0f MB of "
                       "grids, the file holds %.0f MB)", s->path, need / 1e6, left / 1e6);

    vf_field *f = calloc(1, sizeof *f);
    if (!f)
        return vf_fail(VF_EINTERNAL, "out of memory");
    f->grid_count = (int)h.grid_count;
    f->density_shift = h.density_shift;
    f->density_scale = h.density_scale;
    f->step_ratio = h.step_ratio;
    memcpy(f->background, h.background, sizeof f->background);
    f->occupancy_alpha = h.occupancy_alpha;
    f->stop_transmittance = h.stop_transmittance;
    f->camera.width = h.camera_size[0];
    f->camera.height = h.camera_size[1];
    f->camera.fx = h.camera[0];
    f->camera.fy = h.camera[1];
    f->camera.cx = h.camera[2];
    f->camera.cy = h.camera[3];
    f->camera.k1 = h.camera[4];
    f->camera.k2 = h.camera[5];
    f->camera.p1 = h.camera[6];
    f->camera.p2 = h.camera[7];
    memcpy(f->scene_center, h.scene_center, sizeof f->scene_center);
    f->camera_distance = h.camera_distance;

    vf_status status = VF_OK;
    for (int i = 0; status == VF_OK && i < f->grid_count; i++)
        status = vf__field_grid_alloc(&f->grids[i], h.dim[i], h.lo[i], h.voxel[i]);
    enum { CHUNK = 65536 };
    float *buf = status == VF_OK ? malloc((size_t)CHUNK * FIELD_CH_USED * sizeof(float)) : NULL;
    if (status == VF_OK && !buf)
        status = vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < f->grid_count; i++) {
        field_grid *g = &f->grids[i];
        for (size_t start = 0; start < g->points && !s->failed; start += CHUNK) {
            size_t n = g->points - start < CHUNK ? g->points - start : CHUNK;
            get(s, buf, n * FIELD_CH_USED * sizeof(float));
            for (size_t p = 0; p < n * FIELD_CH_USED && !s->failed; p++)
                if (!isfinite(buf[p]) || fabsf(buf[p]) > 1e8f) {
                    status = vf_fail(VF_EINPUT, "%s is corrupt (grid value %g)", s->path,
                                     (double)buf[p]);
                    break;
                }
            if (status != VF_OK)
                break;
            for (size_t p = 0; p < n; p++)
                memcpy(g->values + (start + p) * FIELD_CH, buf + p * FIELD_CH_USED,
                       FIELD_CH_USED * sizeof(float));
        }
    }
    free(buf);
    if (status == VF_OK && s->failed)
        status = vf_fail(VF_EINPUT, "%s is truncated", s->path);
    if (status != VF_OK) {
        vf_field_free(f);
        return status;
    }
    *out = f;
    return VF_OK;
}

static void refresh_occupancy(vf_field *f)
{
    for (int i = 0; i < f->grid_count; i++)
        vf__field_grid_update_occupancy(&f->grids[i], f, f->step_ratio * f->grids[i].voxel);
}

vf_status vf_field_save(const vf_field *f, const char *path)
{
    stream s;
    char tmp[VF_PATH_MAX + 32];
    vf_status status = open_for_write(&s, path, tmp, sizeof tmp);
    if (status != VF_OK)
        return status;
    write_model(&s, f);
    return finish_write(&s, tmp);
}

vf_status vf_field_load(const char *path, vf_field **out)
{
    *out = NULL;
    stream s;
    vf_status status = open_for_read(&s, path);
    if (status != VF_OK)
        return status;
    vf_field *f;
    if ((status = read_model(&s, &f)) != VF_OK) {
        fclose(s.fp);
        return status;
    }
    if ((status = finish_read(&s, "train the model again")) != VF_OK) {
        vf_field_free(f);
        return status;
    }
    /* A loaded field is only rendered, and rendering skips samples under FIELD_VISIBLE_ALPHA:
     * a cell whose corners all stay under it holds no visible sample (values inside are
     * trilinear), so marking it empty skips more and changes no pixel. */
    f->occupancy_alpha = fmaxf(f->occupancy_alpha, FIELD_VISIBLE_ALPHA);
    refresh_occupancy(f);
    *out = f;
    return VF_OK;
}

/* ---- checkpoints ------------------------------------------------------------------------- */

typedef struct checkpoint_state {
    uint64_t fingerprint;
    uint32_t options_size;
    vf_field_train_options options;
    int32_t step, level, loss_count, adam_t, appearance_t;
    float final_voxel;
    double elapsed, loss_avg;
    vf_rng rng;
} checkpoint_state;

vf_status vf_field_trainer_save_checkpoint(vf_field_trainer *t, const char *path)
{
    if (!t->field)
        return vf_fail(VF_EINTERNAL, "nothing to checkpoint");
    const double began = vf_now();
    checkpoint_state st;
    memset(&st, 0, sizeof st);
    st.fingerprint = vf__trainer_views_fingerprint(t);
    st.options_size = sizeof st.options;
    st.options = t->opt;
    st.step = t->step;
    st.level = t->level;
    st.loss_count = t->loss_count;
    st.adam_t = t->adam.t;
    st.appearance_t = t->appearance_t;
    st.final_voxel = t->final_voxel;
    st.elapsed = t->elapsed_before + (vf_now() - t->start_time);
    st.loss_avg = t->loss_avg;
    st.rng = t->rng;

    stream s;
    char tmp[VF_PATH_MAX + 32];
    vf_status status = open_for_write(&s, path, tmp, sizeof tmp);
    if (status != VF_OK)
        return status;
    const uint32_t version = CHECKPOINT_VERSION;
    put(&s, CHECKPOINT_MAGIC, 8);
    put(&s, &version, sizeof version);
    put(&s, &st, sizeof st);
    write_model(&s, t->field);
    for (int i = 0; i < t->field->grid_count; i++) {
        size_t bytes = t->field->grids[i].points * FIELD_CH * sizeof(float);
        put(&s, t->adam.m[i], bytes);
        put(&s, t->adam.v[i], bytes);
    }
    if (t->appearance) /* values and moments */
        put(&s, t->appearance, 3 * 6 * (size_t)t->view_count * sizeof *t->appearance);
    status = finish_write(&s, tmp);
    /* the budget is for training: a run that checkpoints gets the steps of one that does not */
    t->start_time += vf_now() - began;
    return status;
}

/* The options a user sets (train's flags), compared between a checkpoint and a resume; the
 * differences as "--depth 10 (asked 0), ..." into why. Returns how many differ. */
static int options_differ(const vf_field_train_options *ran, const vf_field_train_options *asked,
                          char *why, size_t size)
{
    static const struct {
        const char *flag;
        size_t offset;
    } weights[] = {
        {"--view-smoothing", offsetof(vf_field_train_options, tv_view)},
        {"--depth", offsetof(vf_field_train_options, depth)},
        {"--appearance (rate)", offsetof(vf_field_train_options, appearance)},
    };
    int n = 0;
    size_t used = 0;
    why[0] = 0;
#define WHY(...)                                                                                \
    do {                                                                                        \
        if (used < size)                                                                        \
            used += (size_t)snprintf(why + used, size - used, "%s", n++ ? ", " : "");          \
        if (used < size)                                                                        \
            used += (size_t)snprintf(why + used, size - used, __VA_ARGS__);                    \
    } while (0)
    if (ran->seconds != asked->seconds || ran->steps != asked->steps)
        WHY("a budget of %g%s (asked %g%s)", ran->seconds > 0 ? ran->seconds / 60 : ran->steps,
            ran->seconds > 0 ? " minutes" : " steps",
            asked->seconds > 0 ? asked->seconds / 60 : asked->steps,
            asked->seconds > 0 ? " minutes" : " steps");
    if (ran->surroundings != asked->surroundings)
        WHY("--surroundings %s (asked %s)", vf_field_surroundings_name(ran->surroundings),
            vf_field_surroundings_name(asked->surroundings));
    if (ran->color != asked->color)
        WHY("--color %s (asked %s)", vf_field_color_name(ran->color),
            vf_field_color_name(asked->color));
    for (size_t i = 0; i < sizeof weights / sizeof weights[0]; i++) {
        float a = *(const float *)((const char *)ran + weights[i].offset);
        float b = *(const float *)((const char *)asked + weights[i].offset);
        if (a != b)
            WHY("%s %g (asked %g)", weights[i].flag, a, b);
    }
#undef WHY
    return n;
}

vf_status vf__trainer_checkpoint_read(vf_field_trainer *t, const char *path)
{
    stream s;
    vf_status status = open_for_read(&s, path);
    if (status != VF_OK)
        return status;
    char magic[8];
    uint32_t version = 0;
    checkpoint_state st;
    char why[512];
    get(&s, magic, 8);
    get(&s, &version, sizeof version);
    if (s.failed || memcmp(magic, CHECKPOINT_MAGIC, 8) != 0)
        status = vf_fail(VF_EINPUT, "%s is not a vfcapture training checkpoint", path);
    else if (version != CHECKPOINT_VERSION)
        status = vf_fail(VF_EINPUT, "%s is a checkpoint of format version %u, not %u", path,
                         version, CHECKPOINT_VERSION);
    if (status == VF_OK) {
        get(&s, &st, sizeof st);
        if (s.failed || st.options_size != sizeof st.options)
            status = vf_fail(VF_EINPUT, "%s is truncated or from another build", path);
        else if (st.fingerprint != vf__trainer_views_fingerprint(t))
            status = vf_fail(VF_EINPUT, "%s was made from other training images or poses", path);
        else if (options_differ(&st.options, &t->opt, why, sizeof why))
            /* what ran must be what the user asked (and the manifest records): the schedule
             * (upsampling, pruning) is laid out over the budget, the losses over their weights */
            status = vf_fail(VF_EINPUT,
                             "the interrupted training in %s ran with %s; give the same to "
                             "continue it, or --restart",
                             path, why);
    }
    vf_field *f = NULL;
    if (status == VF_OK)
        status = read_model(&s, &f);
    if (status != VF_OK) {
        fclose(s.fp);
        return status;
    }
    /* Rebuild the trainer around the stored field, then read the moments into place. */
    t->opt = st.options;
    t->field = f;
    t->level = st.level;
    t->final_voxel = st.final_voxel;
    t->step = st.step;
    t->loss_count = st.loss_count;
    t->loss_avg = st.loss_avg;
    t->rng = st.rng;
    t->elapsed_before = st.elapsed;
    refresh_occupancy(f);
    status = vf__field_adam_alloc(&t->adam, f, t->threads);
    for (int i = 0; status == VF_OK && i < f->grid_count; i++) {
        size_t bytes = f->grids[i].points * FIELD_CH * sizeof(float);
        get(&s, t->adam.m[i], bytes);
        get(&s, t->adam.v[i], bytes);
    }
    if (status == VF_OK && (status = vf__trainer_alloc_appearance(t)) == VF_OK && t->appearance)
        get(&s, t->appearance, 3 * 6 * (size_t)t->view_count * sizeof *t->appearance);
    if (status != VF_OK) {
        fclose(s.fp);
        return status;
    }
    if ((status = finish_read(&s, "delete it to start afresh")) != VF_OK)
        return status;
    t->adam.t = st.adam_t;
    t->appearance_t = st.appearance_t;
    return VF_OK;
}

vf_status vf_field_load_workspace(const vf_workspace *ws, vf_field **out)
{
    char path[VF_PATH_MAX];
    *out = NULL;
    if (!vf_workspace_has_stage(ws, "train"))
        return vf_fail(VF_EINPUT,
                       "workspace %s has no trained radiance field: run 'vfcapture "
                       "train %s' first",
                       ws->root, ws->root);
    if (vf_workspace_is_stale(ws, "train", NULL, 0)) /* poses or ingest rerun since */
        return vf_workspace_need(ws, "train");
    vf_status s = vf_workspace_path(ws, "train", VF_FIELD_FILE, path, sizeof path);
    return s == VF_OK ? vf_field_load(path, out) : s;
}
