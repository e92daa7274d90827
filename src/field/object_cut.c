/* Object mode on a trained field (vf/field.h vf_field_cut_object): the photos' masks vote on
 * every grid point, the surface the object stands on is cut away, the rest is rendered on
 * white; and the field's opacity, for the silhouettes that become the object's masks. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "field_internal.h"

/* One view's camera as a projection: world to OpenCV camera axes, then pixels. */
typedef struct cut_camera {
    double rot[9], t[3];
} cut_camera;

/* Whether the views that see p mostly find it on the object: 1 to keep it. */
static int votes_to_keep(const vf_field_cut_view *views, const cut_camera *cams, int n,
                         const double p[3], double share)
{
    int seen = 0, outside = 0;
    for (int i = 0; i < n; i++) {
        double pc[3], u, v;
        vf_mat3_apply(cams[i].rot, p, pc);
        for (int k = 0; k < 3; k++)
            pc[k] += cams[i].t[k];
        const vf_camera *c = &views[i].camera;
        /* compared as doubles: a point far off the image would overflow an int */
        if (!vf_camera_project(c, pc, &u, &v) ||
            !(u >= 0 && v >= 0 && u < c->width && v < c->height))
            continue;
        seen++;
        outside += !views[i].mask[(size_t)v * c->width + (size_t)u];
    }
    return seen > 0 && outside < share * seen;
}

vf_status vf_field_cut_object(vf_field *f, const vf_field_cut_view *views, int n, double share,
                              const double *plane, double clearance, double *kept_share)
{
    if (n < 1 || !(share > 0 && share <= 1) || !(clearance >= 0))
        return vf_fail(VF_EINTERNAL, "cutting the object needs views, a share in (0, 1] and a "
                                     "clearance >= 0");
    for (int i = 0; i < n; i++)
        if (views[i].camera.width < 1 || views[i].camera.height < 1 || !views[i].mask)
            return vf_fail(VF_EINTERNAL, "view %d of the object cut has no mask", i);
    cut_camera *cams = malloc((size_t)n * sizeof *cams);
    if (!cams)
        return vf_fail(VF_EINTERNAL, "out of memory");
    for (int i = 0; i < n; i++)
        vf_c2w_gl_to_w2c_cv(views[i].c2w, cams[i].rot, cams[i].t);
    size_t kept = 0, visible = 0;
    for (int gi = 0; gi < f->grid_count; gi++) {
        field_grid *g = &f->grids[gi];
        const float d_min =
            vf__field_density_threshold(f, FIELD_VISIBLE_ALPHA, f->step_ratio * g->voxel);
#pragma omp parallel for schedule(dynamic) reduction(+ : kept, visible)
        for (int z = 0; z < g->dim[2]; z++)
            for (int y = 0; y < g->dim[1]; y++)
                for (int x = 0; x < g->dim[0]; x++) {
                    float *d = &g->values[(((size_t)z * g->dim[1] + y) * g->dim[0] + x) * FIELD_CH +
                                          FIELD_CH_DENSITY];
                    if (*d < d_min) /* nothing to cut: skip the projections */
                        continue;
                    visible++;
                    const double p[3] = {g->lo[0] + x * g->voxel, g->lo[1] + y * g->voxel,
                                         g->lo[2] + z * g->voxel};
                    int keep = !plane || plane[0] * p[0] + plane[1] * p[1] + plane[2] * p[2] +
                                                 plane[3] >= clearance;
                    keep = keep && votes_to_keep(views, cams, n, p, share);
                    if (keep)
                        kept++;
                    else
                        *d = FIELD_EMPTY_DENSITY;
                }
    }
    free(cams);
    for (int k = 0; k < 3; k++)
        f->background[k] = 1.0f;
    for (int gi = 0; gi < f->grid_count; gi++)
        vf__field_grid_update_occupancy(&f->grids[gi], f, f->step_ratio * f->grids[gi].voxel);
    if (kept_share)
        *kept_share = visible ? (double)kept / visible : 0;
    return VF_OK;
}
