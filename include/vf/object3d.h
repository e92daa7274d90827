/* vf/object3d.h: a textured 3D model as an object whose ground truth is known.
 *
 * The ViewFool paper's main protocol: render 100 views of a 3D model on the upper hemisphere,
 * train the radiance field on them, attack the field, and check the adversarial viewpoints
 * against the object itself by rendering the model there (the paper's Real(v*) column).
 * Blender is the renderer (the NeRF-synthetic scenes were made with it); vfcapture runs it as a
 * program, as it runs COLMAP (vf/process.h), with a Python script of its own that is built into
 * the tool (src/object3d/blender_render.py) and written next to Blender's log when it runs.
 *
 * Frames. Blender's importer turns the model's axes into Blender's z-up world; the model is
 * then centred (bounding-box centre) and scaled into the unit sphere, x_object = scale *
 * (x_blender - center): the object frame of vf/pose.h (z up, object at the origin, cameras at
 * distance 4), so an imported model is a posed set like any NeRF-synthetic scene and every later
 * stage treats it so. The transform is recorded and reused, so the model rendered again later
 * sits exactly where the field learned it.
 *
 * A workspace made from a model holds WS/ingest/object.json (the model file, its size, the
 * transform and the render settings) beside the posed set: transforms.json (training views),
 * transforms_test.json (held-out views), images/, test/, blender.log.
 *
 * Memory: plain structs; vf_object3d_render_images fills images the caller frees. */
#ifndef VF_OBJECT3D_H
#define VF_OBJECT3D_H

#include <jansson.h>
#include <stdint.h>

#include "vf/camera.h"
#include "vf/error.h"
#include "vf/fsutil.h"
#include "vf/image.h"
#include "vf/pose.h"
#include "vf/rgb8.h"
#include "vf/workspace.h"

#ifdef __cplusplus
extern "C" {
#endif

#define VF_OBJECT3D_FILE "object.json"      /* in WS/ingest */
#define VF_NERF_CAMERA_ANGLE_X 0.6911112070083618 /* the NeRF-synthetic camera (radians) */

/* x_object = scale * (x_blender - center). */
typedef struct vf_object3d_transform {
    double center[3];
    double scale;
} vf_object3d_transform;

/* What a workspace records about its model. */
typedef struct vf_object3d {
    char model[VF_PATH_MAX];        /* absolute path of the model file */
    vf_object3d_transform transform;
    int samples;                    /* Cycles samples the training views were rendered with */
    char scene[16];                 /* "studio" or "room", as the training views */
} vf_object3d;

/* Whether path names a file Blender imports here (.glb, .gltf, .obj, .blend), by its extension. */
int vf_object3d_is_model(const char *path);

typedef struct vf_object3d_capture {
    int views;              /* training views on the upper hemisphere (default 100) */
    int test_views;         /* held-out views, other random ones (default 25) */
    int size;               /* square render side in pixels (default 256: the classifier
                               camera's 224 crop of the 256-resized view then samples the field
                               at its training resolution; measured on the water bottle at 2300
                               steps: field natural accuracy 67% against 61% at 200 px, the
                               object's own 84%) */
    int samples;            /* Cycles samples a pixel (default 32; no denoiser in Debian's build) */
    double distance;        /* camera distance (default 4) */
    double camera_angle_x;  /* horizontal field of view, radians (default the NeRF camera) */
    double min_elevation;   /* degrees above the horizon (default 5) */
    uint64_t seed;          /* where on the hemisphere the views are (default 0) */
    const char *scene;      /* "studio": white light from everywhere, transparent background
                             * (default, the paper's); "room": the object on a textured floor
                             * inside a textured wall, opaque (features for structure from
                             * motion, as around a real object) */
} vf_object3d_capture;

void vf_object3d_capture_defaults(vf_object3d_capture *c);

/* The camera poses of the capture: views then test_views camera-to-world matrices (OpenGL
 * axes, object frame), looking at the origin from the upper hemisphere, uniform over its area
 * above min_elevation. c2w holds (views + test_views) * 16 doubles. */
void vf_object3d_capture_poses(const vf_object3d_capture *c, double *c2w);

/* Render the capture of the model into out_dir (a staging folder): images/r_NNN.png and
 * test/r_NNN.png (RGBA with a transparent background in the studio, RGB in the room),
 * transforms.json, transforms_test.json,
 * object.json and blender.log. Views already rendered there are kept (an interrupted ingest
 * resumes). Errors, one line each: Blender missing (VF_EINTERNAL, with the install line), a
 * file it cannot import (VF_EINPUT, naming a missing glTF extension and how to convert),
 * a model without geometry or whose studio views are all empty (VF_EINPUT; in the room the
 * background hides how much the object covers, and mean_coverage is null). *report (may be NULL)
 * gets the manifest summary: frames, test_frames, width, height, seconds, the transform. */
vf_status vf_object3d_ingest(const char *model_path, const vf_object3d_capture *c,
                             const char *out_dir, json_t **report);

/* Read WS/ingest/object.json. VF_EINPUT when the workspace was not made from a 3D model (or
 * the record is damaged), saying so. */
vf_status vf_object3d_load(const vf_workspace *ws, vf_object3d *out);

/* Render the model at n camera poses (c2w, object frame) with camera cam (pinhole; its
 * distortion is ignored) into dir/PREFIXNNN.png, keeping files already there, and load them
 * composited onto white into images[n] (RGB). progress_label (may be NULL) names the
 * progress line. Blender's log goes to dir/blender.log. */
vf_status vf_object3d_render_images(const vf_object3d *obj, const vf_camera *cam,
                                    const double *c2w, int n, const char *dir,
                                    const char *prefix, const char *progress_label,
                                    vf_image *images);

/* Render the frames of a video of the model: camera c2w[i] (object frame) is frame i, the
 * camera moves from frame to frame and Cycles blurs each frame over `shutter` of the frame
 * interval (0.5: a 1/60 s shutter at 30 fps; 0: no blur). An animated model keeps its first
 * frame. Files are dir/PREFIXNNN.png (RGB in the room), kept when already there (a resumed
 * render). With obj->transform.scale == 0 the model is fitted into the unit sphere as ingest
 * does it, and *fit (may be NULL) gets that transform; otherwise the given one is used. */
vf_status vf_object3d_render_video(const vf_object3d *obj, const vf_camera *cam,
                                   const double *c2w, int n, double shutter, const char *dir,
                                   const char *prefix, const char *progress_label,
                                   vf_object3d_transform *fit);

/* ---- a live camera: one Blender kept open, rendering a view when asked ---- */

/* For a camera that moves as its user decides from frame to frame (the studio's closed loop,
 * vf/studio.h): Blender loads the model once and then renders one view a request, a fraction
 * of a second each instead of its start-up of seconds. No motion blur. */
typedef struct vf_object3d_live vf_object3d_live;

/* Start Blender on obj (its recorded transform, scene and samples) with camera cam, renders and
 * blender.log in dir; returns once the model is loaded. Errors as vf_object3d_render_video's. */
vf_status vf_object3d_live_open(const vf_object3d *obj, const vf_camera *cam, const char *dir,
                                vf_object3d_live **out);

/* Render the view from c2w (object frame, OpenGL axes) into *frame (RGB, reused). A Blender
 * that stopped or hangs (300 s) is an error naming its log. */
vf_status vf_object3d_live_render(vf_object3d_live *live, const double c2w[16], vf_rgb8 *frame);

/* Stop Blender and free; NULL is fine. */
void vf_object3d_live_close(vf_object3d_live *live);

#ifdef __cplusplus
}
#endif
#endif
