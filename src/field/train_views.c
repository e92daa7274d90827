/* The training photos, kept compactly (8-bit RGB, background composited) as rays. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "trainer_internal.h"
#include "vf/pose.h"
#include "vf/stats.h"

/* The (shared) ray table of a camera: normalized undistorted coordinates of each pixel. */
static vf_status find_table(vf_field_trainer *t, const vf_camera *cam, int *index)
{
    for (int i = 0; i < t->table_count; i++)
        if (!memcmp(&t->tables[i].camera, cam, sizeof *cam)) {
            *index = i;
            return VF_OK;
        }
    ray_table *grown = realloc(t->tables, (size_t)(t->table_count + 1) * sizeof *grown);
    if (!grown)
        return vf_fail(VF_EINTERNAL, "out of memory");
    t->tables = grown;
    ray_table *table = &t->tables[t->table_count];
    table->camera = *cam;
    table->xy = malloc((size_t)cam->width * cam->height * 2 * sizeof(float));
    if (!table->xy)
        return vf_fail(VF_EINTERNAL, "out of memory");
    int distorted = vf_camera_has_distortion(cam);
#pragma omp parallel for schedule(static)
    for (int y = 0; y < cam->height; y++)
        for (int x = 0; x < cam->width; x++) {
            double d[3] = {(x + 0.5 - cam->cx) / cam->fx, (y + 0.5 - cam->cy) / cam->fy, 1.0};
            if (distorted)
                vf_camera_pixel_ray(cam, x + 0.5, y + 0.5, d);
            float *xy = table->xy + 2 * ((size_t)y * cam->width + x);
            xy[0] = (float)(d[0] / d[2]);
            xy[1] = (float)(d[1] / d[2]);
        }
    *index = t->table_count++;
    return VF_OK;
}

static uint8_t to_byte(float v)
{
    v = v < 0 ? 0 : v > 1 ? 1 : v;
    return (uint8_t)(v * 255.0f + 0.5f);
}

/* 1 where the pixel is not fully transparent. */
static uint8_t *alpha_mask(const vf_image *img)
{
    size_t n = (size_t)img->width * img->height;
    uint8_t *mask = malloc(n);
    if (mask)
        for (size_t i = 0; i < n; i++)
            mask[i] = img->data[i * 4 + 3] > 0.5f / 255.0f;
    return mask;
}

vf_status vf_field_trainer_add_view(vf_field_trainer *t, const vf_camera *cam, const double c2w[16],
                                    const vf_image *image)
{
    if (t->started)
        return vf_fail(VF_EINTERNAL, "views must be added before training starts");
    if (image->width != cam->width || image->height != cam->height)
        return vf_fail(VF_EINPUT, "image is %dx%d but its camera is %dx%d", image->width,
                       image->height, cam->width, cam->height);
    if (image->channels != 3 && image->channels != 4)
        return vf_fail(VF_EINPUT, "training images need 3 or 4 channels, not %d", image->channels);
    if (!(cam->fx > 0) || !(cam->fy > 0))
        return vf_fail(VF_EINPUT, "camera has no focal length");
    if (t->view_count == t->view_capacity) {
        int capacity = t->view_capacity ? 2 * t->view_capacity : 64;
        train_view *grown = realloc(t->views, (size_t)capacity * sizeof *grown);
        if (!grown)
            return vf_fail(VF_EINTERNAL, "out of memory");
        t->views = grown;
        t->view_capacity = capacity;
    }
    size_t n = (size_t)image->width * image->height;
    if (t->pixels + n > UINT32_MAX)
        return vf_fail(VF_EINPUT, "too many training pixels (over 4 billion): use smaller images");
    if (t->pixels + n > t->pixel_capacity) {
        size_t capacity = t->pixel_capacity ? t->pixel_capacity : n * 16;
        while (capacity < t->pixels + n)
            capacity *= 2;
        uint8_t *grown = realloc(t->rgb, capacity * 3);
        if (!grown)
            return vf_fail(VF_EINTERNAL, "out of memory for the training pixels");
        t->rgb = grown;
        t->pixel_capacity = capacity;
    }
    train_view *v = &t->views[t->view_count];
    memset(v, 0, sizeof *v);
    v->camera = *cam;
    memcpy(v->c2w, c2w, sizeof v->c2w);
    v->first_pixel = t->pixels;
    vf_status status = find_table(t, cam, &v->table);
    if (status != VF_OK)
        return status;
    if (image->channels == 4) {
        if (!(v->mask = alpha_mask(image)))
            return vf_fail(VF_EINTERNAL, "out of memory");
        t->has_alpha = 1;
    }
    const float *bg = t->opt.background;
    uint8_t *dst = t->rgb + 3 * t->pixels;
    for (size_t i = 0; i < n; i++) {
        const float *px = image->data + i * image->channels;
        float a = image->channels == 4 ? px[3] : 1.0f;
        for (int k = 0; k < 3; k++)
            dst[3 * i + k] = to_byte(px[k] * a + bg[k] * (1.0f - a));
    }
    t->pixels += n;
    t->view_count++;
    return VF_OK;
}

vf_status vf_field_trainer_add_view_points(vf_field_trainer *t, const double *xyz, int n)
{
    if (t->started)
        return vf_fail(VF_EINTERNAL, "points must be added before training starts");
    if (t->view_count == 0 || n < 0)
        return vf_fail(VF_EINTERNAL, "points need a view to belong to");
    const train_view *v = &t->views[t->view_count - 1];
    double rot[9], shift[3];
    vf_c2w_gl_to_w2c_cv(v->c2w, rot, shift);
    for (int i = 0; i < n; i++) {
        double cv[3], u, w;
        vf_mat3_apply(rot, xyz + 3 * i, cv);
        for (int a = 0; a < 3; a++)
            cv[a] += shift[a];
        if (!vf_camera_project(&v->camera, cv, &u, &w) || !(u >= 0 && u < v->camera.width) ||
            !(w >= 0 && w < v->camera.height))
            continue;
        if (t->depth_count == t->depth_capacity) {
            size_t capacity = t->depth_capacity ? 2 * t->depth_capacity : 4096;
            depth_ray *grown = realloc(t->depth_rays, capacity * sizeof *grown);
            if (!grown)
                return vf_fail(VF_EINTERNAL, "out of memory");
            t->depth_rays = grown;
            t->depth_capacity = capacity;
        }
        /* the pixel's ray passes within half a pixel of the point: its distance along the
         * ray is the point's distance from the camera */
        t->depth_rays[t->depth_count++] = (depth_ray){
            (uint32_t)(v->first_pixel + (size_t)w * v->camera.width + (size_t)u),
            (float)sqrt(cv[0] * cv[0] + cv[1] * cv[1] + cv[2] * cv[2])};
    }
    return VF_OK;
}

static int compare_floats(const void *a, const void *b)
{
    const float x = *(const float *)a, y = *(const float *)b;
    return x < y ? -1 : x > y;
}

double vf__trainer_points_reach(const vf_field_trainer *t, const double center[3], double share)
{
    if (t->depth_count == 0)
        return 0;
    float *reach = malloc(t->depth_count * sizeof *reach);
    if (!reach)
        return 0; /* only an enlargement is lost */
    for (size_t i = 0; i < t->depth_count; i++) {
        field_ray ray;
        float rgb[3];
        vf__trainer_pixel_ray(t, t->depth_rays[i].pixel, &ray, rgb);
        float far = 0;
        for (int a = 0; a < 3; a++)
            far = fmaxf(far, fabsf(ray.origin[a] + ray.dir[a] * t->depth_rays[i].distance -
                                   (float)center[a]));
        reach[i] = far;
    }
    qsort(reach, t->depth_count, sizeof *reach, compare_floats);
    const double q = reach[(size_t)(share * (double)(t->depth_count - 1))];
    free(reach);
    return q;
}

int vf__trainer_points_center(const vf_field_trainer *t, double central, double center[3])
{
    double *axis = malloc(3 * t->depth_count * sizeof *axis + 1); /* x values, y values, z */
    if (!axis)
        return 0;
    int n = 0;
    const size_t stride = t->depth_count;
    for (size_t i = 0; i < t->depth_count; i++) {
        field_ray ray;
        float rgb[3];
        const size_t p = t->depth_rays[i].pixel;
        vf__trainer_pixel_ray(t, p, &ray, rgb);
        const double *m = t->views[vf__trainer_pixel_view(t, p)].c2w;
        const double along = -(ray.dir[0] * m[2] + ray.dir[1] * m[6] + ray.dir[2] * m[10]);
        if (!(along > 0) || sqrt(fmax(1 - along * along, 0)) > central * along)
            continue;
        for (int a = 0; a < 3; a++)
            axis[a * stride + n] = ray.origin[a] + ray.dir[a] * t->depth_rays[i].distance;
        n++;
    }
    if (n >= 32)
        for (int a = 0; a < 3; a++)
            center[a] = vf_median(axis + a * stride, n);
    free(axis);
    return n >= 32;
}

int vf__trainer_pixel_view(const vf_field_trainer *t, size_t p)
{
    int lo = 0, hi = t->view_count - 1;
    while (lo < hi) { /* the last view whose first pixel is <= p */
        int mid = (lo + hi + 1) / 2;
        if (t->views[mid].first_pixel <= p)
            lo = mid;
        else
            hi = mid - 1;
    }
    return lo;
}

void vf__trainer_pixel_ray(const vf_field_trainer *t, size_t p, field_ray *ray, float rgb[3])
{
    const train_view *v = &t->views[vf__trainer_pixel_view(t, p)];
    const float *xy = t->tables[v->table].xy + 2 * (p - v->first_pixel);
    const double d_gl[3] = {xy[0], -xy[1], -1.0}; /* OpenCV (x, y, 1) to OpenGL axes */
    const double *m = v->c2w;
    float norm = 0;
    for (int r = 0; r < 3; r++) {
        ray->dir[r] = (float)(m[4 * r] * d_gl[0] + m[4 * r + 1] * d_gl[1] + m[4 * r + 2] * d_gl[2]);
        ray->origin[r] = (float)m[4 * r + 3];
        norm += ray->dir[r] * ray->dir[r];
    }
    norm = 1.0f / sqrtf(norm);
    for (int r = 0; r < 3; r++)
        ray->dir[r] *= norm;
    ray->tmin = 0.0f;
    ray->tmax = 1e30f;
    for (int k = 0; k < 3; k++)
        rgb[k] = t->rgb[3 * p + k] * (1.0f / 255.0f);
}

static uint64_t fnv1a(uint64_t h, const void *data, size_t size)
{
    const uint8_t *p = data;
    for (size_t i = 0; i < size; i++)
        h = (h ^ p[i]) * 0x100000001b3ull;
    return h;
}

uint64_t vf__trainer_views_fingerprint(const vf_field_trainer *t)
{
    uint64_t h = 0xcbf29ce484222325ull;
    h = fnv1a(h, &t->view_count, sizeof t->view_count);
    for (int i = 0; i < t->view_count; i++) {
        h = fnv1a(h, &t->views[i].camera, sizeof t->views[i].camera);
        h = fnv1a(h, t->views[i].c2w, sizeof t->views[i].c2w);
    }
    /* every 97th pixel byte: cheap, and catches different photos */
    for (size_t i = 0; i < 3 * t->pixels; i += 97)
        h = fnv1a(h, &t->rgb[i], 1);
    return h;
}

void vf__trainer_views_free(vf_field_trainer *t)
{
    for (int i = 0; i < t->view_count; i++)
        free(t->views[i].mask);
    for (int i = 0; i < t->table_count; i++)
        free(t->tables[i].xy);
    free(t->views);
    free(t->tables);
    free(t->rgb);
    free(t->pool);
    free(t->depth_rays);
    t->depth_rays = NULL;
    t->depth_count = t->depth_capacity = 0;
    t->views = NULL;
    t->tables = NULL;
    t->rgb = NULL;
    t->pool = NULL;
    t->view_count = t->table_count = 0;
}
