/* Reading COLMAP's text model (cameras.txt, images.txt, points3D.txt). */
#define _GNU_SOURCE
#include "vf/colmap_model.h"

#include <errno.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "vf/fsutil.h"
#include "vf/pose.h"

/* A line reader that counts lines, for error messages. */
typedef struct reader {
    FILE *file;
    char path[VF_PATH_MAX];
    char *line;
    size_t cap;
    int number;
} reader;

static vf_status reader_open(reader *r, const char *dir, const char *name)
{
    memset(r, 0, sizeof *r);
    vf_status status = vf_path_join(r->path, sizeof r->path, dir, name);
    if (status != VF_OK)
        return status;
    r->file = fopen(r->path, "r");
    if (!r->file)
        return vf_fail(VF_EINPUT, "cannot read %s: %s", r->path, strerror(errno));
    return VF_OK;
}

static void reader_close(reader *r)
{
    if (r->file)
        fclose(r->file);
    free(r->line);
    r->file = NULL;
    r->line = NULL;
}

/* The next line without its newline; 0 at the end of the file. */
static int next_line(reader *r)
{
    ssize_t len = getline(&r->line, &r->cap, r->file);
    if (len < 0)
        return 0;
    r->number++;
    while (len > 0 && (r->line[len - 1] == '\n' || r->line[len - 1] == '\r'))
        r->line[--len] = '\0';
    return 1;
}

/* The next line that is neither a comment nor blank; 0 at the end of the file. */
static int next_data_line(reader *r)
{
    while (next_line(r)) {
        const char *p = r->line + strspn(r->line, " \t");
        if (*p && *p != '#')
            return 1;
    }
    return 0;
}

static vf_status malformed(const reader *r, const char *what)
{
    return vf_fail(VF_EINPUT, "%s line %d: %s", r->path, r->number, what);
}

/* Grow an array of `size`-byte items to hold at least count + 1. */
static int grow(void **items, int count, int *capacity, size_t size)
{
    if (count < *capacity)
        return 1;
    int cap = *capacity ? 2 * *capacity : 64;
    void *bigger = realloc(*items, (size_t)cap * size);
    if (!bigger)
        return 0;
    *items = bigger;
    *capacity = cap;
    return 1;
}

static vf_status parse_camera(const reader *r, vf_colmap_camera *cam)
{
    int used = 0;
    memset(cam, 0, sizeof *cam);
    if (sscanf(r->line, "%d %31s %d %d%n", &cam->id, cam->model, &cam->width, &cam->height,
               &used) != 4 || cam->width <= 0 || cam->height <= 0)
        return malformed(r, "expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS...");
    const char *p = r->line + used;
    char *end;
    while (cam->param_count < VF_COLMAP_MAX_PARAMS) {
        double v = strtod(p, &end);
        if (end == p)
            break;
        cam->params[cam->param_count++] = v;
        p = end;
    }
    if (*(p + strspn(p, " \t")))
        return malformed(r, "bad camera parameter");
    return VF_OK;
}

static vf_status load_cameras(const char *dir, vf_colmap_model *m)
{
    reader r;
    int capacity = 0;
    vf_status status = reader_open(&r, dir, "cameras.txt");
    while (status == VF_OK && next_data_line(&r)) {
        if (!grow((void **)&m->cameras, m->camera_count, &capacity, sizeof *m->cameras))
            status = vf_fail(VF_EINTERNAL, "out of memory reading %s", r.path);
        else if ((status = parse_camera(&r, &m->cameras[m->camera_count])) == VF_OK)
            m->camera_count++;
    }
    reader_close(&r);
    return status;
}

/* The line of 2D points: (X Y POINT3D_ID) triples; only counted. */
static vf_status parse_points2d(const reader *r, vf_colmap_image *img)
{
    const char *p = r->line;
    char *end;
    for (;;) {
        strtod(p, &end);
        if (end == p) /* the end of the line, or garbage */
            return *(p + strspn(p, " \t")) ? malformed(r, "bad 2D point") : VF_OK;
        p = end;
        strtod(p, &end);
        if (end == p)
            return malformed(r, "2D point without a y coordinate");
        p = end;
        long long id = strtoll(p, &end, 10);
        if (end == p)
            return malformed(r, "2D point without a POINT3D_ID");
        p = end;
        img->keypoints++;
        img->observations += id != -1;
    }
}

static vf_status parse_image(reader *r, vf_colmap_image *img)
{
    int used = 0;
    memset(img, 0, sizeof *img);
    if (sscanf(r->line, "%d %lf %lf %lf %lf %lf %lf %lf %d %n", &img->id, &img->q[0], &img->q[1],
               &img->q[2], &img->q[3], &img->t[0], &img->t[1], &img->t[2], &img->camera_id,
               &used) != 9 || !r->line[used])
        return malformed(r, "expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME");
    if (snprintf(img->name, sizeof img->name, "%s", r->line + used) >= (int)sizeof img->name)
        return malformed(r, "image name too long");
    if (!next_line(r))
        return malformed(r, "missing the line of 2D points");
    return parse_points2d(r, img);
}

static vf_status load_images(const char *dir, vf_colmap_model *m)
{
    reader r;
    int capacity = 0;
    vf_status status = reader_open(&r, dir, "images.txt");
    while (status == VF_OK && next_data_line(&r)) {
        if (!grow((void **)&m->images, m->image_count, &capacity, sizeof *m->images))
            status = vf_fail(VF_EINTERNAL, "out of memory reading %s", r.path);
        else if ((status = parse_image(&r, &m->images[m->image_count])) == VF_OK)
            m->image_count++;
    }
    reader_close(&r);
    return status;
}

/* One point; its track is appended to the pool and its offset kept in pt->track (as an
 * integer, until the pool stops moving). */
static vf_status parse_point(const reader *r, vf_colmap_point *pt, int **pool, int *pool_count,
                             int *pool_capacity)
{
    int used = 0, rgb[3];
    memset(pt, 0, sizeof *pt);
    if (sscanf(r->line, "%lld %lf %lf %lf %d %d %d %lf%n", &pt->id, &pt->xyz[0], &pt->xyz[1],
               &pt->xyz[2], &rgb[0], &rgb[1], &rgb[2], &pt->error, &used) != 8)
        return malformed(r, "expected POINT3D_ID X Y Z R G B ERROR TRACK...");
    for (int k = 0; k < 3; k++)
        pt->rgb[k] = (unsigned char)(rgb[k] < 0 ? 0 : rgb[k] > 255 ? 255 : rgb[k]);
    pt->track = (int *)(intptr_t)*pool_count;
    const char *p = r->line + used;
    char *end;
    for (;;) {
        long v = strtol(p, &end, 10);
        if (end == p)
            break;
        if (!grow((void **)pool, *pool_count, pool_capacity, sizeof **pool))
            return vf_fail(VF_EINTERNAL, "out of memory reading %s", r->path);
        (*pool)[(*pool_count)++] = (int)v;
        p = end;
    }
    int values = *pool_count - (int)(intptr_t)pt->track;
    if (values % 2 || *(p + strspn(p, " \t")))
        return malformed(r, "track must be (IMAGE_ID POINT2D_IDX) pairs");
    pt->track_length = values / 2;
    return VF_OK;
}

static vf_status load_points(const char *dir, vf_colmap_model *m)
{
    reader r;
    int capacity = 0, pool_count = 0, pool_capacity = 0;
    vf_status status = reader_open(&r, dir, "points3D.txt");
    while (status == VF_OK && next_data_line(&r)) {
        if (!grow((void **)&m->points, m->point_count, &capacity, sizeof *m->points))
            status = vf_fail(VF_EINTERNAL, "out of memory reading %s", r.path);
        else if ((status = parse_point(&r, &m->points[m->point_count], &m->track_pool,
                                       &pool_count, &pool_capacity)) == VF_OK)
            m->point_count++;
    }
    reader_close(&r);
    /* tracks were read as offsets into the pool (which stays NULL when no point has one) */
    for (int i = 0; m->track_pool && i < m->point_count; i++)
        m->points[i].track = m->track_pool + (intptr_t)m->points[i].track;
    return status;
}

vf_status vf_colmap_model_load(const char *dir, vf_colmap_model *model)
{
    memset(model, 0, sizeof *model);
    vf_status status = load_cameras(dir, model);
    if (status == VF_OK)
        status = load_images(dir, model);
    if (status == VF_OK)
        status = load_points(dir, model);
    for (int i = 0; status == VF_OK && i < model->image_count; i++)
        if (!vf_colmap_model_camera(model, model->images[i].camera_id))
            status = vf_fail(VF_EINPUT, "%s/images.txt: image %s uses camera %d, which %s/cameras.txt lacks",
                             dir, model->images[i].name, model->images[i].camera_id, dir);
    if (status != VF_OK)
        vf_colmap_model_free(model);
    return status;
}

vf_status vf_colmap_points_load(const char *dir, vf_colmap_model *model)
{
    memset(model, 0, sizeof *model);
    vf_status status = load_points(dir, model);
    if (status != VF_OK)
        vf_colmap_model_free(model);
    return status;
}

void vf_colmap_model_free(vf_colmap_model *model)
{
    free(model->cameras);
    free(model->images);
    free(model->points);
    free(model->track_pool);
    memset(model, 0, sizeof *model);
}

const vf_colmap_camera *vf_colmap_model_camera(const vf_colmap_model *model, int id)
{
    for (int i = 0; i < model->camera_count; i++)
        if (model->cameras[i].id == id)
            return &model->cameras[i];
    return NULL;
}

const vf_colmap_image *vf_colmap_model_image(const vf_colmap_model *model, int id)
{
    for (int i = 0; i < model->image_count; i++)
        if (model->images[i].id == id)
            return &model->images[i];
    return NULL;
}

double vf_colmap_model_reprojection_error(const vf_colmap_model *model)
{
    double sum = 0;
    long long observations = 0;
    for (int i = 0; i < model->point_count; i++) {
        sum += model->points[i].error * model->points[i].track_length;
        observations += model->points[i].track_length;
    }
    return observations ? sum / (double)observations : 0;
}

vf_status vf_colmap_camera_to_vf(const vf_colmap_camera *in, vf_camera *out)
{
    static const struct {
        const char *name;
        int params;
    } known[] = {{"SIMPLE_PINHOLE", 3}, {"PINHOLE", 4}, {"SIMPLE_RADIAL", 4}, {"RADIAL", 5},
                 {"OPENCV", 8}};
    const double *p = in->params;
    memset(out, 0, sizeof *out);
    out->width = in->width;
    out->height = in->height;
    for (size_t i = 0; i < sizeof known / sizeof known[0]; i++) {
        if (strcmp(in->model, known[i].name))
            continue;
        if (in->param_count != known[i].params)
            return vf_fail(VF_EINPUT, "COLMAP camera %d (%s) has %d parameters, expected %d",
                           in->id, in->model, in->param_count, known[i].params);
        int separate_focal = i == 1 || i == 4; /* PINHOLE, OPENCV: fx fy cx cy */
        out->fx = p[0];
        out->fy = separate_focal ? p[1] : p[0];
        out->cx = p[separate_focal ? 2 : 1];
        out->cy = p[separate_focal ? 3 : 2];
        if (i == 2 || i == 3)
            out->k1 = p[3];
        if (i == 3)
            out->k2 = p[4];
        if (i == 4) {
            out->k1 = p[4];
            out->k2 = p[5];
            out->p1 = p[6];
            out->p2 = p[7];
        }
        return VF_OK;
    }
    return vf_fail(VF_EINPUT, "COLMAP camera model %s is not supported (use OPENCV, RADIAL, "
                              "SIMPLE_RADIAL, PINHOLE or SIMPLE_PINHOLE)", in->model);
}

void vf_colmap_image_c2w(const vf_colmap_image *image, double c2w_gl[16])
{
    double rot[9];
    vf_rot_from_quat(image->q, rot);
    vf_w2c_cv_to_c2w_gl(rot, image->t, c2w_gl);
}

void vf_colmap_image_center(const vf_colmap_image *image, double center[3])
{
    double c2w[16];
    vf_colmap_image_c2w(image, c2w);
    vf_mat4_translation(c2w, center);
}

void vf_colmap_view_points_free(vf_colmap_view_points *p)
{
    for (int i = 0; p->xyz && i < p->views; i++)
        free(p->xyz[i]);
    free(p->xyz);
    free(p->count);
    memset(p, 0, sizeof *p);
}

vf_status vf_colmap_view_points_load(const char *poses_dir, const char *const *names, int n,
                                     vf_colmap_view_points *out)
{
    memset(out, 0, sizeof *out);
    char sparse[VF_PATH_MAX];
    vf_colmap_model images = {0}, points = {0};
    vf_status status = vf_path_join(sparse, sizeof sparse, poses_dir, "sparse");
    if (status == VF_OK)
        status = vf_colmap_model_load(sparse, &images);
    if (status == VF_OK)
        status = vf_colmap_points_load(poses_dir, &points);
    int *view_of = NULL; /* per COLMAP image (by index): the photo, or -1 */
    if (status == VF_OK) {
        out->views = n;
        out->count = calloc((size_t)n + 1, sizeof *out->count);
        out->xyz = calloc((size_t)n + 1, sizeof *out->xyz);
        view_of = malloc(((size_t)images.image_count + 1) * sizeof *view_of);
        if (!out->count || !out->xyz || !view_of)
            status = vf_fail(VF_EINTERNAL, "out of memory");
    }
    for (int k = 0; status == VF_OK && k < images.image_count; k++) {
        char image[VF_PATH_MAX], photo[VF_PATH_MAX];
        vf_path_basename(image, sizeof image, images.images[k].name, 0);
        view_of[k] = -1;
        for (int i = 0; i < n && view_of[k] < 0; i++) {
            vf_path_basename(photo, sizeof photo, names[i], 0);
            if (!strcmp(image, photo))
                view_of[k] = i;
        }
    }
    /* two passes over the tracks: count, then fill */
    for (int pass = 0; status == VF_OK && pass < 2; pass++) {
        for (int i = 0; pass == 1 && i < n; i++) {
            out->xyz[i] = malloc(((size_t)out->count[i] + 1) * 3 * sizeof(double));
            if (!out->xyz[i])
                status = vf_fail(VF_EINTERNAL, "out of memory");
            out->count[i] = 0;
        }
        for (int p = 0; status == VF_OK && p < points.point_count; p++) {
            const vf_colmap_point *pt = &points.points[p];
            if (!(pt->error <= VF_COLMAP_DEPTH_ERROR))
                continue;
            for (int e = 0; e < pt->track_length; e++) {
                int k = 0;
                while (k < images.image_count && images.images[k].id != pt->track[2 * e])
                    k++;
                const int view = k < images.image_count ? view_of[k] : -1;
                if (view < 0)
                    continue;
                if (pass == 1)
                    memcpy(out->xyz[view] + 3 * out->count[view], pt->xyz, 3 * sizeof(double));
                out->count[view]++;
            }
        }
    }
    free(view_of);
    vf_colmap_model_free(&images);
    vf_colmap_model_free(&points);
    if (status != VF_OK)
        vf_colmap_view_points_free(out);
    return status;
}
