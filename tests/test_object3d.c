/* The 3D-model capture's cameras: the paper's protocol is upright photos from the upper
 * hemisphere, uniform over its area, all looking at the object at the capture distance. */
#include <math.h>
#include <stdlib.h>

#include "check.h"
#include "vf/object3d.h"

static void test_capture_poses(void)
{
    vf_object3d_capture c;
    vf_object3d_capture_defaults(&c);
    int n = c.views + c.test_views;
    double *c2w = malloc((size_t)n * 16 * sizeof *c2w);
    vf_object3d_capture_poses(&c, c2w);
    double z0 = sin(c.min_elevation * M_PI / 180), mean_z = 0;
    int upright = 0, looking = 0, placed = 0;
    for (int i = 0; i < n; i++) {
        const double *m = c2w + 16 * i; /* row-major; columns x, y, z axes, then position */
        double pos[3] = {m[3], m[7], m[11]}, up_z = m[9], back[3] = {m[2], m[6], m[10]};
        double dist = sqrt(pos[0] * pos[0] + pos[1] * pos[1] + pos[2] * pos[2]);
        placed += fabs(dist - c.distance) < 1e-9 && pos[2] >= c.distance * z0 - 1e-9;
        /* OpenGL axes: the camera looks along -z, so its z axis points from the origin to it. */
        looking += fabs(back[0] * pos[0] + back[1] * pos[1] + back[2] * pos[2] - dist) < 1e-9;
        upright += up_z > 0; /* world up is up in the image */
        mean_z += pos[2] / dist / n;
    }
    CHECK(placed == n, "%d of %d cameras at distance %g above %g deg", placed, n, c.distance,
          c.min_elevation);
    CHECK(looking == n, "%d of %d cameras look at the origin", looking, n);
    CHECK(upright == n, "%d of %d photos are upright", upright, n);
    /* uniform over the area: the height is uniform on [z0, 1], mean (z0 + 1) / 2, sd 0.26/sqrt n */
    CHECK(fabs(mean_z - (z0 + 1) / 2) < 0.08, "mean height %.3f, expected %.3f", mean_z,
          (z0 + 1) / 2);
    free(c2w);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_capture_poses);
    return check_finish();
}
