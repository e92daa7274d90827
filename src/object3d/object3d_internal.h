/* src/object3d/object3d_internal.h: the Blender runner shared by the capture and the real
 * check. Private to src/object3d. */
#ifndef VF_OBJECT3D_INTERNAL_H
#define VF_OBJECT3D_INTERNAL_H

#include <jansson.h>

#include "vf/object3d.h"

/* The Python adapter (blender_render.py), built into the tool by CMake. */
extern const char vf__blender_script[];

/* One call of Blender: render `count` views of a model into out_dir/PREFIXNNN.png. */
typedef struct vf__blender_job {
    const char *model;
    const vf_object3d_transform *transform; /* NULL: fit the model into the unit sphere */
    vf_camera camera;
    int samples;
    const char *scene;     /* "studio" or "room" (blender_render.py) */
    double shutter;        /* > 0: the views are video frames, blurred over this share of a
                              frame's interval; 0: stills */
    const double *c2w;     /* count x 16, object frame, OpenGL axes */
    int count;
    const char *out_dir;   /* the PNGs */
    const char *prefix;
    const char *work_dir;  /* the job file, the script, the fit and blender.log */
    const char *label;     /* progress line (NULL: none) */
    int serve;             /* no views: a live camera (vf_object3d_live_open) */
} vf__blender_job;

/* Run Blender on the job and wait. *fit (may be NULL) gets what the script measured:
 * {"center", "scale", "vertices", "meshes", "bbox_min", "bbox_max", "radius"} (a new
 * reference). Views whose file exists are not rendered again. */
vf_status vf__blender_render(const vf__blender_job *job, json_t **fit);

/* The file name of view i of a job: PREFIX%03d.png. */
void vf__blender_view_file(const char *prefix, int i, char *out, size_t size);

#endif
