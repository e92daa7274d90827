/* Object mode (vf/cutout.h): the object's sparse points, and its mask in each photo. */
#include "vf/cutout.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "grabcut_cv.h"
#include "vf/colmap_model.h"
#include "vf/fsutil.h"
#include "vf/image.h"
#include "vf/json.h"
#include "vf/log.h"
#include "vf/plot.h"
#include "vf/pose.h"
#include "vf/rng.h"
#include "vf/stats.h"

#define RANSAC_ROUNDS 500
#define MIN_PLANE_SHARE 0.15 /* a plane holding fewer of the candidates is no surface */
#define MIN_OBJECT_POINTS 8
#define SHEET_VIEWS 12
#define SHEET_HEIGHT 240

void vf_cutout_defaults(vf_cutout_options *o)
{
    *o = (vf_cutout_options){.radius = 2.0,
                             .plane_tolerance = 0.06,
                             .max_side = 480,
                             .iterations = 5,
                             .hull_margin = 0.3,
                             .seed = 1};
}

void vf_object_points_free(vf_object_points *p)
{
    free(p->xyz);
    memset(p, 0, sizeof *p);
}

/* ---- the object's points ---- */

static double dot3(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static double distance3(const double *a, const double *b)
{
    const double d[3] = {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
    return sqrt(dot3(d, d));
}

/* The plane through three points (n unit, n.x + d = 0); 0 when they are nearly collinear. */
static int plane_through(const double *a, const double *b, const double *c, double plane[4])
{
    double u[3], v[3], n[3];
    for (int k = 0; k < 3; k++)
        u[k] = b[k] - a[k], v[k] = c[k] - a[k];
    n[0] = u[1] * v[2] - u[2] * v[1];
    n[1] = u[2] * v[0] - u[0] * v[2];
    n[2] = u[0] * v[1] - u[1] * v[0];
    double len = sqrt(dot3(n, n));
    if (!(len > 1e-9))
        return 0;
    for (int k = 0; k < 3; k++)
        plane[k] = n[k] / len;
    plane[3] = -dot3(plane, a);
    return 1;
}

/* The plane with the most points within tol (RANSAC); its inlier count. */
static int dominant_plane(const double *p, int n, double tol, uint64_t seed, double best[4])
{
    vf_rng rng;
    vf_rng_seed(&rng, seed);
    int best_count = 0;
    for (int round = 0; n >= 3 && round < RANSAC_ROUNDS; round++) {
        double plane[4];
        const double *a = p + 3 * vf_rng_below(&rng, (uint64_t)n);
        const double *b = p + 3 * vf_rng_below(&rng, (uint64_t)n);
        const double *c = p + 3 * vf_rng_below(&rng, (uint64_t)n);
        if (!plane_through(a, b, c, plane))
            continue;
        int count = 0;
        for (int i = 0; i < n; i++)
            count += fabs(dot3(plane, p + 3 * i) + plane[3]) < tol;
        if (count > best_count) {
            best_count = count;
            memcpy(best, plane, sizeof plane);
        }
    }
    return best_count;
}

static int find_root(int *parent, int i)
{
    while (parent[i] != i)
        i = parent[i] = parent[parent[i]];
    return i;
}

/* Group p (n points) by single linkage at a distance of 3 times the median nearest-neighbour
 * distance and keep the group with the most points within radius / 2 of the origin (the point
 * the cameras look at lies in or near the object), with every group at least a third its size
 * that also reaches there (an object in parts: a pair of shoes is two groups of 600 and 555
 * points), moved to the front of p; *kept gets their size. */
static vf_status central_cluster(double *p, int n, const double centre[3], double radius, int *kept)
{
    *kept = 0;
    if (n == 0)
        return VF_OK;
    int *parent = malloc((size_t)n * sizeof *parent), *score = calloc((size_t)n, sizeof *score);
    int *size = calloc((size_t)n, sizeof *size);
    double *nearest = malloc((size_t)n * sizeof *nearest);
    if (!parent || !score || !size || !nearest) {
        free(parent);
        free(score);
        free(size);
        free(nearest);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
#pragma omp parallel for schedule(dynamic, 64)
    for (int i = 0; i < n; i++) {
        double best = INFINITY;
        for (int j = 0; j < n; j++) {
            double d[3] = {p[3 * i] - p[3 * j], p[3 * i + 1] - p[3 * j + 1],
                           p[3 * i + 2] - p[3 * j + 2]};
            double dd = dot3(d, d);
            if (j != i && dd < best)
                best = dd;
        }
        nearest[i] = sqrt(best);
    }
    vf_sort_doubles(nearest, n);
    double link = 3 * vf_sorted_quantile(nearest, n, 0.5), link2 = link * link;
    for (int i = 0; i < n; i++)
        parent[i] = i;
    for (int i = 0; i < n; i++)
        for (int j = i + 1; j < n; j++) {
            double d[3] = {p[3 * i] - p[3 * j], p[3 * i + 1] - p[3 * j + 1],
                           p[3 * i + 2] - p[3 * j + 2]};
            if (dot3(d, d) <= link2)
                parent[find_root(parent, i)] = find_root(parent, j);
        }
    int best = -1;
    for (int i = 0; i < n; i++) {
        int r = find_root(parent, i);
        const int near = distance3(p + 3 * i, centre) < radius / 2;
        size[r]++;
        score[r] += 1 + 1000 * near;
        if (best < 0 || score[r] > score[best])
            best = r;
    }
    for (int i = 0; i < n; i++) {
        const int r = find_root(parent, i);
        if (r == best || (score[r] > size[r] && 3 * size[r] >= size[best]))
            memmove(p + 3 * (*kept)++, p + 3 * i, 3 * sizeof *p);
    }
    free(parent);
    free(score);
    free(size);
    free(nearest);
    return VF_OK;
}

vf_status vf_object_points_find(const char *points_dir, const double *cameras, int camera_count,
                                const vf_cutout_options *o, vf_object_points *out)
{
    memset(out, 0, sizeof *out);
    vf_colmap_model model;
    vf_status status = vf_colmap_points_load(points_dir, &model);
    if (status != VF_OK)
        return status;
    int n = 0;
    double *cand = malloc((size_t)(model.point_count + 1) * 3 * sizeof *cand);
    if (!cand) {
        vf_colmap_model_free(&model);
        return vf_fail(VF_EINTERNAL, "out of memory");
    }
    for (int i = 0; i < model.point_count; i++)
        if (distance3(model.points[i].xyz, o->centre) < o->radius)
            memcpy(cand + 3 * n++, model.points[i].xyz, 3 * sizeof *cand);
    vf_colmap_model_free(&model);
    out->candidates = n;

    /* the surface: its points and everything behind it (away from the cameras) go */
    double plane[4] = {0, 0, 1, 0}; /* stays when no three points span a plane */
    int on_plane = dominant_plane(cand, n, o->plane_tolerance, o->seed, plane);
    double mean_camera = 0; /* turn the plane's normal towards the cameras */
    for (int c = 0; n >= 3 && c < camera_count; c++)
        mean_camera += dot3(plane, cameras + 3 * c) + plane[3];
    if (mean_camera < 0)
        for (int k = 0; k < 4; k++)
            plane[k] = -plane[k];
    /* An object stands (or hangs) in front of its support, and little lies behind a desk, a
     * floor or a wall: a plane with more of the other points behind it than in front is the
     * object's own face (a wall clock's: 133 points in front, 218 behind), not its support.
     * Where the plane lies against the point the cameras look at says nothing: the optical
     * axes of a capture from one side meet near the support (the fox's wall: 0.07 units
     * behind that point; 2937 points in front, 22 behind). */
    int front = 0, behind = 0;
    for (int i = 0; i < n; i++) {
        const double h = dot3(plane, cand + 3 * i) + plane[3];
        front += h > o->plane_tolerance;
        behind += h < -o->plane_tolerance;
    }
    if (n > 0 && on_plane >= MIN_PLANE_SHARE * n && front > behind) {
        out->has_plane = 1;
        memcpy(out->plane, plane, sizeof plane);
        int kept = 0;
        for (int i = 0; i < n; i++)
            if (dot3(plane, cand + 3 * i) + plane[3] > o->plane_tolerance)
                memmove(cand + 3 * kept++, cand + 3 * i, 3 * sizeof *cand);
        out->on_plane = n - kept;
        n = kept;
    }
    int kept = 0;
    if (n > 0 && on_plane >= MIN_PLANE_SHARE * n && !out->has_plane) {
        /* the plane is the object's face: its points, and those in front of it, are the
         * object (clustering them would keep the densest patch only: the clock's dial) */
        for (int i = 0; i < n; i++)
            if (dot3(plane, cand + 3 * i) + plane[3] >= -o->plane_tolerance)
                memmove(cand + 3 * kept++, cand + 3 * i, 3 * sizeof *cand);
    } else {
        /* the object: the cluster of what is left that lies at the centre of attention */
        status = central_cluster(cand, n, o->centre, o->radius, &kept);
    }
    if (status != VF_OK) {
        free(cand);
        return status;
    }
    if (kept < MIN_OBJECT_POINTS) {
        free(cand);
        return vf_fail(VF_EINPUT,
                       "the sparse points show no object near the centre (%d points within %.1f "
                       "of it, %d of them on a surface): object mode needs the object in the "
                       "middle of every photo",
                       out->candidates, o->radius, out->on_plane);
    }
    /* an object stands on its surface: what lies between its points and the plane is it too
     * (sides without texture, and so without points), so the hull takes their footprints */
    out->count = out->hull_count = kept;
    if (out->has_plane) {
        double *grown = realloc(cand, (size_t)(2 * kept) * 3 * sizeof *cand);
        if (!grown) {
            free(cand);
            return vf_fail(VF_EINTERNAL, "out of memory");
        }
        cand = grown;
        for (int i = 0; i < kept; i++) {
            double h = dot3(out->plane, cand + 3 * i) + out->plane[3];
            for (int k = 0; k < 3; k++)
                cand[3 * (kept + i) + k] = cand[3 * i + k] - h * out->plane[k];
        }
        out->hull_count = 2 * kept;
    }
    out->xyz = cand;
    return VF_OK;
}

/* ---- one photo's mask ---- */

typedef struct point2 {
    double x, y;
} point2;

static double cross2(point2 o, point2 a, point2 b)
{
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
}

static int compare_points(const void *a, const void *b)
{
    const point2 *p = a, *q = b;
    return p->x != q->x ? (p->x > q->x) - (p->x < q->x) : (p->y > q->y) - (p->y < q->y);
}

/* Convex hull of p (sorted in place), counter-clockwise in hull (room for n + 1); its size. */
static int convex_hull(point2 *p, int n, point2 *hull)
{
    qsort(p, (size_t)n, sizeof *p, compare_points);
    int k = 0;
    for (int i = 0; i < n; i++) {
        while (k >= 2 && cross2(hull[k - 2], hull[k - 1], p[i]) <= 0)
            k--;
        hull[k++] = p[i];
    }
    for (int i = n - 2, lower = k + 1; i >= 0; i--) {
        while (k >= lower && cross2(hull[k - 2], hull[k - 1], p[i]) <= 0)
            k--;
        hull[k++] = p[i];
    }
    return k > 1 ? k - 1 : k;
}

/* Whether q lies inside the counter-clockwise hull grown by `scale` about c. */
static int inside_hull(const point2 *hull, int n, point2 c, double scale, point2 q)
{
    if (n < 3)
        return 0;
    point2 local = {c.x + (q.x - c.x) / scale, c.y + (q.y - c.y) / scale};
    for (int i = 0; i < n; i++)
        if (cross2(hull[i], hull[(i + 1) % n], local) < 0)
            return 0;
    return 1;
}

/* Keep the 4-connected regions of fg (0/1) that hold a seed pixel; the rest become 0. */
static vf_status keep_seeded_regions(uint8_t *fg, int w, int h, const int *seeds, int seed_count)
{
    int *stack = malloc((size_t)w * h * sizeof *stack);
    if (!stack)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int s = 0; s < seed_count; s++) { /* mark each seeded region 2 */
        if (fg[seeds[s]] != 1)
            continue;
        int top = 0;
        stack[top++] = seeds[s];
        fg[seeds[s]] = 2;
        while (top > 0) {
            int i = stack[--top], x = i % w, y = i / w;
            int next[4] = {x > 0 ? i - 1 : -1, x < w - 1 ? i + 1 : -1, y > 0 ? i - w : -1,
                           y < h - 1 ? i + w : -1};
            for (int k = 0; k < 4; k++)
                if (next[k] >= 0 && fg[next[k]] == 1) {
                    fg[next[k]] = 2;
                    stack[top++] = next[k];
                }
        }
    }
    for (int i = 0; i < w * h; i++)
        fg[i] = fg[i] == 2;
    free(stack);
    return VF_OK;
}

/* Seed GrabCut's labels at the working size from the projected object points (pts, n) and
 * the points whose hull bounds it (hull_in, hn; object points and their footprints). */
static void seed_labels(uint8_t *labels, int w, int h, const point2 *pts, int n,
                        const point2 *hull_in, int hn_in, const vf_cutout_options *o)
{
    point2 *hull = malloc((size_t)(hn_in + 1) * sizeof *hull), c = {0, 0};
    point2 *sorted = malloc((size_t)(hn_in + 1) * sizeof *sorted);
    for (int i = 0; i < n; i++)
        c.x += pts[i].x / n, c.y += pts[i].y / n;
    int hn = 0;
    if (hull && sorted) {
        memcpy(sorted, hull_in, (size_t)hn_in * sizeof *hull_in);
        hn = convex_hull(sorted, hn_in, hull);
    }
    int background = 0;
    for (int y = 0; y < h; y++)
        for (int x = 0; x < w; x++) {
            point2 q = {x + 0.5, y + 0.5};
            uint8_t l = inside_hull(hull, hn, c, 1.0, q)                 ? VF_GC_PR_FGD
                        : inside_hull(hull, hn, c, 1 + o->hull_margin, q) ? VF_GC_PR_BGD
                                                                          : VF_GC_BGD;
            labels[y * w + x] = l;
            background += l != VF_GC_PR_FGD;
        }
    if (!background) /* the object fills the view: the border is the only hint of background */
        for (int x = 0; x < w; x++)
            labels[x] = labels[(h - 1) * w + x] = VF_GC_PR_BGD;
    /* every point of the object projects inside its silhouette, from any side: its pixel is
     * sure object (the points well inside the hull get a disc; at the edge a point may be a
     * pixel off, so only its own pixel) */
    for (int i = 0; i < n; i++) {
        int r = inside_hull(hull, hn, c, 0.8, pts[i]) ? 2 : 0;
        for (int dy = -r; dy <= r; dy++)
            for (int dx = -r; dx <= r; dx++) {
                int x = (int)pts[i].x + dx, y = (int)pts[i].y + dy;
                if (x >= 0 && y >= 0 && x < w && y < h && dx * dx + dy * dy <= r * r)
                    labels[y * w + x] = VF_GC_FGD;
            }
    }
    free(hull);
    free(sorted);
}

vf_status vf_cutout_mask(const vf_rgb8 *photo, const vf_camera *cam, const double c2w[16],
                         const vf_object_points *pts, const vf_cutout_options *o, uint8_t **mask,
                         int *seen)
{
    *mask = NULL;
    *seen = 0;
    int W = photo->width, H = photo->height;
    uint8_t *full = calloc((size_t)W * H, 1);
    point2 *proj = malloc((size_t)(pts->hull_count + 1) * sizeof *proj);
    point2 *hull_pts = malloc((size_t)(pts->hull_count + 1) * sizeof *hull_pts);
    vf_rgb8 small = {0};
    uint8_t *labels = NULL;
    vf_status status = full && proj && hull_pts ? vf_rgb8_fit(photo, o->max_side, &small)
                                                : vf_fail(VF_EINTERNAL, "out of memory");
    double rot[9], t[3];
    vf_c2w_gl_to_w2c_cv(c2w, rot, t);
    int n = 0, hn = 0; /* object points in the photo; hull points in front of the camera */
    for (int i = 0; status == VF_OK && i < pts->hull_count; i++) {
        double p[3], u, v;
        vf_mat3_apply(rot, pts->xyz + 3 * i, p);
        for (int k = 0; k < 3; k++)
            p[k] += t[k];
        if (!vf_camera_project(cam, p, &u, &v))
            continue;
        point2 q = {u * small.width / W, v * small.height / H};
        hull_pts[hn++] = q;
        if (i < pts->count && u >= 0 && v >= 0 && u < W && v < H)
            proj[n++] = q;
    }
    *seen = n;
    int w = small.width, h = small.height;
    if (status == VF_OK && n >= 3) {
        labels = malloc((size_t)w * h);
        int *seeds = malloc((size_t)n * sizeof *seeds);
        if (!labels || !seeds)
            status = vf_fail(VF_EINTERNAL, "out of memory");
        if (status == VF_OK) {
            seed_labels(labels, w, h, proj, n, hull_pts, hn, o);
            status = vf_cv_grabcut(small.data, w, h, labels, o->iterations);
        }
        for (int i = 0; status == VF_OK && i < w * h; i++)
            labels[i] = labels[i] == VF_GC_FGD || labels[i] == VF_GC_PR_FGD;
        for (int i = 0; status == VF_OK && i < n; i++)
            seeds[i] = (int)proj[i].y * w + (int)proj[i].x;
        if (status == VF_OK)
            status = keep_seeded_regions(labels, w, h, seeds, n);
        /* back to full size: bilinear over the 0/1 mask, cut at one half */
        for (int y = 0; status == VF_OK && y < H; y++)
            for (int x = 0; x < W; x++) {
                double sx = (x + 0.5) * w / W - 0.5, sy = (y + 0.5) * h / H - 0.5;
                int x0 = (int)floor(sx), y0 = (int)floor(sy);
                double fx = sx - x0, fy = sy - y0, sum = 0;
                for (int k = 0; k < 4; k++) {
                    int xi = x0 + (k & 1), yi = y0 + (k >> 1);
                    xi = xi < 0 ? 0 : xi >= w ? w - 1 : xi;
                    yi = yi < 0 ? 0 : yi >= h ? h - 1 : yi;
                    sum += labels[yi * w + xi] * ((k & 1) ? fx : 1 - fx) * ((k >> 1) ? fy : 1 - fy);
                }
                full[(size_t)y * W + x] = sum >= 0.5 ? 255 : 0;
            }
        free(seeds);
    }
    free(labels);
    free(proj);
    free(hull_pts);
    vf_rgb8_free(&small);
    if (status == VF_OK)
        *mask = full;
    else
        free(full);
    return status;
}

/* ---- every view ---- */

typedef struct view_result {
    double coverage; /* share of the photo on the object */
    int seen;        /* object points in view */
    vf_image tile;   /* the sheet's picture, for the first few */
} view_result;

/* The photo with its background dimmed, SHEET_HEIGHT high, for the masks sheet. */
static vf_status sheet_tile(const vf_rgb8 *photo, const uint8_t *mask, vf_image *out)
{
    vf_image img;
    vf_status status = vf_image_alloc(&img, photo->width, photo->height, 3);
    for (size_t i = 0; status == VF_OK && i < (size_t)photo->width * photo->height; i++)
        for (int c = 0; c < 3; c++)
            img.data[3 * i + c] = photo->data[3 * i + c] / 255.0f * (mask[i] ? 1.0f : 0.2f);
    if (status == VF_OK) {
        int w = (int)lround((double)photo->width * SHEET_HEIGHT / photo->height);
        status = vf_image_resize(&img, w > 0 ? w : 1, SHEET_HEIGHT, out);
        vf_image_free(&img);
    }
    return status;
}

/* Cut out view i: load, mask, write out_dir/NAME.png (RGBA). */
static vf_status cut_view(const vf_frame *frame, const vf_object_points *pts,
                          const vf_cutout_options *o, const char *out_path, int want_tile,
                          view_result *r)
{
    vf_rgb8 photo = {0};
    uint8_t *mask = NULL;
    vf_image rgba = {0};
    vf_status status = vf_rgb8_load(frame->image_path, &photo);
    if (status == VF_OK)
        status = vf_cutout_mask(&photo, &frame->camera, frame->c2w, pts, o, &mask, &r->seen);
    if (status == VF_OK)
        status = vf_image_alloc(&rgba, photo.width, photo.height, 4);
    size_t pixels = (size_t)photo.width * photo.height, on = 0;
    for (size_t i = 0; status == VF_OK && i < pixels; i++) {
        for (int c = 0; c < 3; c++)
            rgba.data[4 * i + c] = photo.data[3 * i + c] / 255.0f;
        rgba.data[4 * i + 3] = mask[i] ? 1.0f : 0.0f;
        on += mask[i] != 0;
    }
    r->coverage = pixels ? (double)on / pixels : 0;
    if (status == VF_OK)
        status = vf_image_save(out_path, &rgba);
    if (status == VF_OK && want_tile)
        status = sheet_tile(&photo, mask, &r->tile);
    if (status != VF_OK)
        vf_error_prefix("%s", frame->image_path);
    vf_image_free(&rgba);
    free(mask);
    vf_rgb8_free(&photo);
    return status;
}

static vf_status write_sheet(const char *path, view_result *results, const vf_dataset *views,
                             int tiles)
{
    vf_image images[SHEET_VIEWS];
    char captions[SHEET_VIEWS][96];
    const char *caption_list[SHEET_VIEWS];
    for (int k = 0; k < tiles; k++) {
        int i = (int)((long)k * views->count / tiles);
        char name[VF_PATH_MAX];
        vf_path_basename(name, sizeof name, views->frames[i].image_path, 0);
        snprintf(captions[k], sizeof captions[k], "%.60s\nobject %.0f%%, %d points", name,
                 100 * results[i].coverage, results[i].seen);
        images[k] = results[i].tile;
        caption_list[k] = captions[k];
    }
    return vf_contact_sheet(path, images, caption_list, NULL, tiles, 4);
}

vf_status vf_cutout_views(const vf_dataset *views, const char *points_dir, const char *out_dir,
                          const vf_cutout_options *o, vf_dataset *out, json_t **report)
{
    memset(out, 0, sizeof *out);
    *report = NULL;
    double *cameras = malloc((size_t)(views->count + 1) * 3 * sizeof *cameras);
    view_result *results = calloc((size_t)views->count + 1, sizeof *results);
    vf_frame *frames = calloc((size_t)views->count + 1, sizeof *frames);
    vf_object_points pts = {0};
    vf_status status = cameras && results && frames ? vf_mkdirs(out_dir)
                                                    : vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; status == VF_OK && i < views->count; i++)
        vf_mat4_translation(views->frames[i].c2w, cameras + 3 * i);
    if (status == VF_OK)
        status = vf_object_points_find(points_dir, cameras, views->count, o, &pts);
    if (status == VF_OK)
        vf_info("object mode: %d of the %d sparse points near the centre are the object (%d on "
                "the surface it stands on or behind it)",
                pts.count, pts.candidates, pts.on_plane);
    int tiles = views->count < SHEET_VIEWS ? views->count : SHEET_VIEWS, done = 0;
    for (int i = 0; status == VF_OK && i < views->count; i++) {
        char name[VF_PATH_MAX];
        frames[i] = views->frames[i];
        vf_path_basename(name, sizeof name, views->frames[i].image_path, 1);
        status = vf_path_join(frames[i].image_path, sizeof frames[i].image_path, out_dir, name);
        if (status == VF_OK && strlen(frames[i].image_path) + 5 < sizeof frames[i].image_path)
            strcat(frames[i].image_path, ".png");
    }
    vf_progress progress;
    vf_first_error first = {0};
    vf_progress_begin(&progress, "cutting out the object", (size_t)views->count, "photos");
#pragma omp parallel for schedule(dynamic)
    for (int i = 0; i < (status == VF_OK ? views->count : 0); i++) {
        int want_tile = 0;
        for (int k = 0; k < tiles; k++)
            want_tile |= i == (int)((long)k * views->count / tiles);
        vf_first_error_keep(&first, cut_view(&views->frames[i], &pts, o, frames[i].image_path,
                                             want_tile, &results[i]));
#pragma omp critical
        vf_progress_update(&progress, (size_t)++done, NULL);
    }
    vf_progress_end(&progress);
    if (status == VF_OK)
        status = vf_first_error_raise(&first);
    char path[VF_PATH_MAX];
    if (status == VF_OK && (status = vf_path_join(path, sizeof path, out_dir, "masks.jpg")) == VF_OK)
        status = write_sheet(path, results, views, tiles);
    if (status == VF_OK) {
        *out = (vf_dataset){.count = views->count, .frames = frames};
        frames = NULL;
        status = vf_path_join(out->source, sizeof out->source, out_dir, "transforms.json");
    }
    if (status == VF_OK)
        status = vf_dataset_save(out->source, out);
    if (status == VF_OK) {
        json_t *list = json_array();
        double sum = 0;
        int empty = 0;
        for (int i = 0; i < views->count; i++) {
            char name[VF_PATH_MAX];
            vf_path_basename(name, sizeof name, views->frames[i].image_path, 0);
            json_array_append_new(list, json_pack("{s:s, s:o, s:i}", "image", name, "coverage",
                                                  vf_json_number(results[i].coverage), "points",
                                                  results[i].seen));
            sum += results[i].coverage;
            empty += results[i].coverage == 0;
        }
        *report = json_pack("{s:i, s:i, s:i, s:b, s:o, s:i, s:o}", "object_points", pts.count,
                            "candidates", pts.candidates, "on_surface", pts.on_plane,
                            "surface_found", pts.has_plane, "mean_coverage",
                            vf_json_number(views->count ? sum / views->count : 0.0), "empty_views",
                            empty, "views", list);
        if (pts.has_plane) /* the train stage cuts it out of the field too */
            json_object_set_new(
                *report, "surface",
                json_pack("[o,o,o,o]", vf_json_number(pts.plane[0]), vf_json_number(pts.plane[1]),
                          vf_json_number(pts.plane[2]), vf_json_number(pts.plane[3])));
        if (empty)
            vf_warn("object mode: %d of %d views show no object; their masks vote against "
                    "everything they see", empty, views->count);
    }
    if (status != VF_OK)
        vf_dataset_free(out);
    for (int i = 0; i < views->count; i++)
        vf_image_free(&results[i].tile);
    vf_object_points_free(&pts);
    free(results);
    free(frames);
    free(cameras);
    return status;
}
