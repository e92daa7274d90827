/* vf/cutout.h: the object separated from its surroundings ("object mode").
 *
 * A phone capture shows the object on a desk, a floor or a wall, with the room around it. The
 * paper photographed its objects on white paper and its classifiers' test images have white
 * backgrounds, so object mode renders the object alone on white: each photo is cut out
 * (RGBA, the rest transparent, this module), and the train stage cuts the object out of the
 * field trained on the whole photos by those masks' vote and this module's support plane
 * (vf/field.h vf_field_cut_object).
 *
 * Where the object is comes from the poses stage's sparse points (WS/poses/points3D.txt, in
 * the object frame: the object at the origin, cameras at a mean distance of 4):
 *   1. points within `radius` of the origin (or a given centre) are candidates (the rest is
 *      the room);
 *   2. the surface the object stands on (or hangs from) is the dominant plane among them
 *      (RANSAC, seeded) when it holds 15% of them and more of the rest lie in front of it
 *      (towards the cameras) than behind: its points, and those behind it, are dropped;
 *   3. the rest is grouped by single linkage (3 times the median distance between
 *      neighbours); the group with the most points within radius / 2 of the centre (the point
 *      the cameras look at lies in or near the object) is the object, with every other group
 *      near the origin at least a third its size (an object in parts: a pair of shoes);
 *   2'. a dominant plane with more points behind it than in front is the object's own face (a
 *      wall clock's: 1189 of its 1517 points, the plain wall behind it has hardly any): its
 *      points and those in front of it are the object, not grouped (grouping kept the dense
 *      dial alone, 269 points, and the masks cut out the dial).
 * In each photo those points project to where the object is. They seed OpenCV's GrabCut on a
 * shrunk copy: the points well inside their projected convex hull are sure object, the hull
 * (of the points and their footprints on the surface: an object stands on it, and its
 * untextured sides have no points) probable object, a margin around it probable background
 * and the photo beyond sure background; GrabCut's colour models decide the pixels between. The mask
 * keeps the connected regions that hold object points, is scaled back up and becomes the alpha
 * channel.
 *
 * Memory: vf_object_points owns its array (vf_object_points_free); a mask is malloc'd
 * width * height bytes (0 or 255) the caller frees. */
#ifndef VF_CUTOUT_H
#define VF_CUTOUT_H

#include <jansson.h>
#include <stdint.h>

#include "vf/camera.h"
#include "vf/dataset.h"
#include "vf/error.h"
#include "vf/rgb8.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vf_cutout_options {
    double centre[3];       /* where the object is looked for (default the origin: the point
                               the cameras look at; train's check uses its object box's) */
    double radius;          /* candidates within this distance of the centre (default 2) */
    double plane_tolerance; /* a point this close to the plane is on it (default 0.06) */
    int max_side;           /* GrabCut's working size, longer side in pixels (default 480) */
    int iterations;         /* GrabCut iterations (default 5) */
    double hull_margin;     /* probable background: the hull grown by this share (0.3) */
    uint64_t seed;          /* RANSAC's (default 1) */
} vf_cutout_options;

void vf_cutout_defaults(vf_cutout_options *o);

typedef struct vf_object_points {
    int count;            /* the object's points: xyz[0 .. 3 count) */
    int hull_count;       /* then, up to hull_count, their footprints on the surface */
    double *xyz;          /* object frame */
    int candidates;       /* points within the radius */
    int on_plane;         /* of those, dropped as the surface or behind it */
    int has_plane;
    double plane[4];      /* n.x + d = 0, n towards the cameras (when has_plane) */
} vf_object_points;

/* Pick the object's points from the sparse points in points_dir/points3D.txt; cameras
 * (count camera centres, 3 each, object frame) orient the plane. VF_EINPUT when fewer than
 * 8 points are left: "the sparse points show no object near the centre ...". */
vf_status vf_object_points_find(const char *points_dir, const double *cameras, int camera_count,
                                const vf_cutout_options *o, vf_object_points *out);
void vf_object_points_free(vf_object_points *p);

/* The object's mask in one photo (its camera and OpenGL camera-to-world in the object frame):
 * *mask gets width * height bytes, 255 on the object. *seen gets how many object points fell
 * in the photo; with fewer than 3 the mask is empty (the object is out of view). */
vf_status vf_cutout_mask(const vf_rgb8 *photo, const vf_camera *cam, const double c2w[16],
                         const vf_object_points *pts, const vf_cutout_options *o, uint8_t **mask,
                         int *seen);

/* Cut the object out of every view of `views` into out_dir: NAME.png (RGBA, alpha the mask),
 * transforms.json (the same cameras) and masks.jpg (a contact sheet of photos with their masks
 * drawn on). *out is that set; *report (a new reference) says how the points were picked
 * and each view's share of object pixels. Views are done in parallel. */
vf_status vf_cutout_views(const vf_dataset *views, const char *points_dir, const char *out_dir,
                          const vf_cutout_options *o, vf_dataset *out, json_t **report);

#ifdef __cplusplus
}
#endif
#endif
