/* vf/colmap_model.h: COLMAP's sparse model, read from its text files.
 *
 * `colmap model_converter --output_type TXT` writes a reconstruction as three files:
 *   cameras.txt   CAMERA_ID MODEL WIDTH HEIGHT PARAMS...
 *   images.txt    IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME, then a line of (X Y POINT3D_ID)
 *   points3D.txt  POINT3D_ID X Y Z R G B ERROR (IMAGE_ID POINT2D_IDX)...
 * Poses are world-to-camera in OpenCV axes (x_cam = R(q) x_world + t, q = w,x,y,z); vf/pose.h
 * converts them. Only registered images appear in images.txt. The 2D observations are not
 * kept, only how many of each image's keypoints have a 3D point; a point's track (image id,
 * keypoint index into that image's features in COLMAP's database) is kept.
 *
 * Memory: vf_colmap_model_load fills a model that owns all its arrays; release it with
 * vf_colmap_model_free. */
#ifndef VF_COLMAP_MODEL_H
#define VF_COLMAP_MODEL_H

#include "vf/camera.h"
#include "vf/error.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_COLMAP_MAX_PARAMS 16

typedef struct vf_colmap_camera {
    int id;
    char model[32];          /* "OPENCV", "SIMPLE_RADIAL", "PINHOLE", ... */
    int width, height;
    int param_count;
    double params[VF_COLMAP_MAX_PARAMS];
} vf_colmap_camera;

typedef struct vf_colmap_image {
    int id, camera_id;
    double q[4];             /* world-to-camera rotation, w x y z */
    double t[3];             /* world-to-camera translation */
    char name[512];          /* path relative to COLMAP's image folder */
    int keypoints;           /* 2D points listed for the image */
    int observations;        /* of those, how many see a 3D point */
} vf_colmap_image;

typedef struct vf_colmap_point {
    long long id;
    double xyz[3];
    unsigned char rgb[3];
    double error;            /* mean reprojection error over the track, pixels */
    int track_length;
    int *track;              /* track_length (image_id, point2d_index) pairs, into the model's pool */
} vf_colmap_point;

typedef struct vf_colmap_model {
    int camera_count, image_count, point_count;
    vf_colmap_camera *cameras;
    vf_colmap_image *images;
    vf_colmap_point *points;
    int *track_pool;         /* storage for every point's track */
} vf_colmap_model;

/* Read cameras.txt, images.txt and points3D.txt from `dir`. VF_EINPUT naming the file and line
 * when one is missing or malformed. */
vf_status vf_colmap_model_load(const char *dir, vf_colmap_model *model);
/* Read only points3D.txt from `dir` (a poses stage's WS/poses holds one in the object frame);
 * the model has no cameras or images. */
vf_status vf_colmap_points_load(const char *dir, vf_colmap_model *model);
void vf_colmap_model_free(vf_colmap_model *model);

/* The sparse points each of n photos sees, for depth supervision (vf/field.h): read from a
 * poses stage's folder, its points3D.txt (object frame) and sparse/images.txt (which image each
 * track entry is). Photo i is the registered image with the base name of names[i]; it gets
 * the points whose track includes that image and whose mean reprojection error is at most
 * VF_COLMAP_DEPTH_ERROR pixels (none when COLMAP does not know the photo). */
#define VF_COLMAP_DEPTH_ERROR 2.0
typedef struct vf_colmap_view_points {
    int views;
    int *count;   /* count[i] points of photo i */
    double **xyz; /* xyz[i]: 3 doubles a point */
} vf_colmap_view_points;

vf_status vf_colmap_view_points_load(const char *poses_dir, const char *const *names, int n,
                                     vf_colmap_view_points *out);
void vf_colmap_view_points_free(vf_colmap_view_points *p);

/* The camera or image with this id, or NULL. */
const vf_colmap_camera *vf_colmap_model_camera(const vf_colmap_model *model, int id);
const vf_colmap_image *vf_colmap_model_image(const vf_colmap_model *model, int id);

/* Mean reprojection error over all observations (each point's error weighted by its track
 * length), as COLMAP reports it; 0 for a model without points. */
double vf_colmap_model_reprojection_error(const vf_colmap_model *model);

/* A COLMAP camera as a vf_camera (pinhole + k1, k2, p1, p2). SIMPLE_PINHOLE, PINHOLE,
 * SIMPLE_RADIAL, RADIAL and OPENCV convert exactly; other models are VF_EINPUT. */
vf_status vf_colmap_camera_to_vf(const vf_colmap_camera *in, vf_camera *out);

/* Camera-to-world (OpenGL axes, row-major 4x4) and centre of a registered image. */
void vf_colmap_image_c2w(const vf_colmap_image *image, double c2w_gl[16]);
void vf_colmap_image_center(const vf_colmap_image *image, double center[3]);

#ifdef __cplusplus
}
#endif
#endif
