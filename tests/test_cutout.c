/* vf_object_points_find on synthesized sparse points: which surface is the support and which
 * points are the object (the rules in vf/cutout.h), for the layouts real captures have. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check.h"
#include "vf/cutout.h"
#include "vf/fsutil.h"
#include "vf/rng.h"

typedef struct cloud {
    int count;
    double xyz[3 * 8000];
} cloud;

static void add(cloud *c, double x, double y, double z)
{
    if (c->count < 8000) {
        c->xyz[3 * c->count] = x, c->xyz[3 * c->count + 1] = y, c->xyz[3 * c->count + 2] = z;
        c->count++;
    }
}

/* n points on the sphere of radius r around (x, y, z). */
static void add_ball(cloud *c, vf_rng *rng, int n, double x, double y, double z, double r)
{
    for (int i = 0; i < n; i++) {
        double d[3] = {vf_rng_normal(rng), vf_rng_normal(rng), vf_rng_normal(rng)};
        double len = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        add(c, x + r * d[0] / len, y + r * d[1] / len, z + r * d[2] / len);
    }
}

/* The cloud as a poses stage's points3D.txt in a fresh folder; path gets the folder. */
static void write_points(const cloud *c, char *dir, size_t size)
{
    snprintf(dir, size, "%s", vf_test_tmpdir());
    char path[4096];
    vf_path_join(path, sizeof path, dir, "points3D.txt");
    FILE *fp = fopen(path, "w");
    for (int i = 0; fp && i < c->count; i++)
        fprintf(fp, "%d %.6f %.6f %.6f 128 128 128 0.5 1 %d 2 %d\n", i + 1, c->xyz[3 * i],
                c->xyz[3 * i + 1], c->xyz[3 * i + 2], i, i);
    if (fp)
        fclose(fp);
}

/* vf_object_points_find with the default options on the cloud, seen from the cameras. */
static void find_object(const cloud *c, const double *cameras, int camera_count,
                        vf_object_points *p)
{
    char dir[4096];
    write_points(c, dir, sizeof dir);
    vf_cutout_options o;
    vf_cutout_defaults(&o);
    CHECK(vf_object_points_find(dir, cameras, camera_count, &o, p) == VF_OK, "find: %s",
          vf_error_message());
}

/* How many of the found points lie within tol of the sphere (x, y, z, r). */
static int on_ball(const vf_object_points *p, double x, double y, double z, double r, double tol)
{
    int n = 0;
    for (int i = 0; i < p->count; i++) {
        const double *q = p->xyz + 3 * i;
        double d = sqrt((q[0] - x) * (q[0] - x) + (q[1] - y) * (q[1] - y) + (q[2] - z) * (q[2] - z));
        n += fabs(d - r) < tol;
    }
    return n;
}

/* A head mounted on a wall, the cameras in front: their optical axes meet near the wall, so
 * the origin lies just behind it (the fox: 0.07 units). The wall is the support even so. */
static void test_wall_behind_the_origin(void)
{
    static cloud c;
    c.count = 0;
    vf_rng rng;
    vf_rng_seed(&rng, 3);
    for (double x = -1.9; x <= 1.9; x += 0.05) /* the wall, y = -0.07, facing -y */
        for (double z = -1.9; z <= 1.9; z += 0.05)
            if (x * x + z * z < 3.6)
                add(&c, x, -0.07 + 0.004 * vf_rng_normal(&rng), z);
    add_ball(&c, &rng, 1500, 0, -0.8, 0, 0.6); /* the head, in front of it */
    double cameras[3 * 12];
    for (int i = 0; i < 12; i++)
        cameras[3 * i] = 2 * cos(i * 0.5), cameras[3 * i + 1] = -3.5, cameras[3 * i + 2] = sin(i);
    vf_object_points p;
    find_object(&c, cameras, 12, &p);
    const int head = on_ball(&p, 0, -0.8, 0, 0.6, 0.01);
    printf("wall: %d object points (%d on the head of 1500), surface %d (%d points on it)\n",
           p.count, head, p.has_plane, p.on_plane);
    CHECK(p.has_plane && p.plane[1] < -0.99 && p.on_plane > 2000,
          "the wall is the support (normal y %.2f, %d points)", p.plane[1], p.on_plane);
    CHECK(head > 0.95 * 1500 && p.count - head < 50, "the head, not the wall: %d of %d", head,
          p.count);
    vf_object_points_free(&p);
}

/* A pair of shoes on a table: two groups of points, both the object; a box farther out is
 * not. */
static void test_object_in_parts(void)
{
    static cloud c;
    c.count = 0;
    vf_rng rng;
    vf_rng_seed(&rng, 4);
    for (double x = -1.9; x <= 1.9; x += 0.05) /* the table, z = -0.45, facing up */
        for (double y = -1.9; y <= 1.9; y += 0.05)
            if (x * x + y * y < 3.6)
                add(&c, x, y, -0.45 + 0.004 * vf_rng_normal(&rng));
    add_ball(&c, &rng, 700, -0.5, 0, -0.05, 0.35); /* the shoes */
    add_ball(&c, &rng, 600, 0.5, 0.1, -0.05, 0.35);
    add_ball(&c, &rng, 200, 1.25, 1.25, -0.25, 0.15); /* something else, off centre */
    double cameras[3 * 12];
    for (int i = 0; i < 12; i++)
        cameras[3 * i] = 3 * cos(i * 0.5), cameras[3 * i + 1] = 3 * sin(i * 0.5),
        cameras[3 * i + 2] = 2.5;
    vf_object_points p;
    find_object(&c, cameras, 12, &p);
    const int left = on_ball(&p, -0.5, 0, -0.05, 0.35, 0.01);
    const int right = on_ball(&p, 0.5, 0.1, -0.05, 0.35, 0.01);
    const int other = on_ball(&p, 1.25, 1.25, -0.25, 0.15, 0.01);
    printf("pair: %d object points: %d and %d on the shoes (of 700, 600), %d off centre\n",
           p.count, left, right, other);
    CHECK(p.has_plane && p.plane[2] > 0.99, "the table is the support (normal z %.2f)",
          p.plane[2]);
    CHECK(left > 0.8 * 700 && right > 0.8 * 600, "both shoes: %d, %d", left, right);
    CHECK(other == 0, "not the box off centre: %d of its points", other);
    vf_object_points_free(&p);
}

/* A wall clock: its flat face is the dominant plane, with a dense dial and a sparser case;
 * what lies behind the face (its sides, the room reflected in its glass) outnumbers what
 * lies in front, so the face is the object, not a support, and all of it is kept (single
 * linkage kept the dense dial alone: 269 of the real clock's 1517 points). */
static void test_object_face(void)
{
    static cloud c;
    c.count = 0;
    vf_rng rng;
    vf_rng_seed(&rng, 5);
    for (int i = 0; i < 700; i++) { /* the dial: a disc of radius 0.25, y = -0.1 */
        double r = 0.25 * sqrt(vf_rng_uniform(&rng)), a = 2 * M_PI * vf_rng_uniform(&rng);
        add(&c, r * cos(a), -0.1 + 0.004 * vf_rng_normal(&rng), 0.4 + r * sin(a));
    }
    int case_points = 0;
    for (int i = 0; i < 2000 && case_points < 300; i++) { /* the case around it, sparse */
        double x = vf_rng_uniform(&rng) - 0.5, z = 2 * vf_rng_uniform(&rng) - 1;
        if (x * x + (z - 0.4) * (z - 0.4) > 0.3 * 0.3)
            add(&c, x, -0.1 + 0.004 * vf_rng_normal(&rng), z), case_points++;
    }
    for (int i = 0; i < 250; i++) /* behind the face: sides, reflections */
        add(&c, vf_rng_uniform(&rng) - 0.5, 0.1 + 0.5 * vf_rng_uniform(&rng),
            2 * vf_rng_uniform(&rng) - 1);
    double cameras[3 * 12];
    for (int i = 0; i < 12; i++)
        cameras[3 * i] = 2 * cos(i * 0.5), cameras[3 * i + 1] = -3.5, cameras[3 * i + 2] = sin(i);
    vf_object_points p;
    find_object(&c, cameras, 12, &p);
    int face = 0, sparse = 0;
    for (int i = 0; i < p.count; i++) {
        const double *q = p.xyz + 3 * i;
        face += fabs(q[1] + 0.1) < 0.02;
        sparse += fabs(q[1] + 0.1) < 0.02 && q[0] * q[0] + (q[2] - 0.4) * (q[2] - 0.4) > 0.09;
    }
    printf("face: %d object points, %d on the face (%d of the case's %d), surface %d\n",
           p.count, face, sparse, case_points, p.has_plane);
    CHECK(!p.has_plane, "the face is no support");
    CHECK(face > 0.95 * (700 + case_points) && sparse > 0.95 * case_points,
          "the whole face: %d points, %d of the case", face, sparse);
    CHECK(p.count - face < 25, "not what lies behind it: %d", p.count - face);
    vf_object_points_free(&p);
}

int main(int argc, char **argv)
{
    check_args(argc, argv);
    CHECK_CASE(test_wall_behind_the_origin);
    CHECK_CASE(test_object_in_parts);
    CHECK_CASE(test_object_face);
    return check_finish();
}
