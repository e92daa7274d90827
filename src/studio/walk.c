/* The studio's person: smooth random signals, the hand that holds the phone, the capture's
 * walk around the object. */
#include <math.h>
#include <stdlib.h>

#include "studio_internal.h"

#define DEG (M_PI / 180.0)

void vf__wave_init(studio_wave *w, vf_rng *rng, double f_lo, double f_hi, double amplitude)
{
    for (int k = 0; k < STUDIO_WAVES; k++) {
        w->freq[k] = f_lo + (f_hi - f_lo) * vf_rng_uniform(rng);
        w->phase[k] = 2 * M_PI * vf_rng_uniform(rng);
    }
    /* a sum of K unit sines has variance K/2 */
    w->amplitude = amplitude / sqrt(STUDIO_WAVES / 2.0);
}

double vf__wave_at(const studio_wave *w, double t)
{
    double sum = 0;
    for (int k = 0; k < STUDIO_WAVES; k++)
        sum += sin(2 * M_PI * w->freq[k] * t + w->phase[k]);
    return w->amplitude * sum;
}

void vf__hand_init(studio_hand *h, vf_rng *rng, double shake, double distance)
{
    for (int k = 0; k < 3; k++) {
        vf__wave_init(&h->pos[k], rng, 0.3, 2.0, shake * 0.01 * distance); /* arm sway */
        vf__wave_init(&h->tremor[k], rng, 2.0, 9.0, shake * 0.25 * DEG);  /* tremor */
    }
    vf__wave_init(&h->roll, rng, 0.05, 0.3, shake * 1.5 * DEG); /* the phone not quite level */
}

static void normalize3(double v[3])
{
    double n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++)
        v[k] /= n;
}

static void cross3(const double a[3], const double b[3], double out[3])
{
    out[0] = a[1] * b[2] - a[2] * b[1];
    out[1] = a[2] * b[0] - a[0] * b[2];
    out[2] = a[0] * b[1] - a[1] * b[0];
}

void vf__hand_camera(const studio_hand *h, double t, const double eye[3], const double aim[3],
                     double c2w[16])
{
    double f[3], r[3], u[3], up[3] = {0, 0, 1};
    for (int k = 0; k < 3; k++)
        f[k] = aim[k] - eye[k];
    normalize3(f);
    cross3(f, up, r);
    normalize3(r);
    cross3(r, f, u);
    /* camera axes x right, y up, z backwards (OpenGL), as columns */
    double look[9] = {r[0], u[0], -f[0], r[1], u[1], -f[1], r[2], u[2], -f[2]};
    double steady[16];
    vf_mat4_from_rt(look, eye, steady);
    vf__hand_move(h, t, steady, c2w);
}

void vf__hand_move(const studio_hand *h, double t, const double steady[16], double c2w[16])
{
    double rot[9], pos[3], local[9], moved[9];
    vf_mat4_rotation(steady, rot);
    vf_mat4_translation(steady, pos);
    double tremor[3] = {vf__wave_at(&h->tremor[0], t), vf__wave_at(&h->tremor[1], t),
                        vf__wave_at(&h->tremor[2], t) + vf__wave_at(&h->roll, t)};
    vf_rot_from_axis_angle(tremor, local); /* about the camera's own axes */
    vf_mat3_mul(rot, local, moved);
    for (int k = 0; k < 3; k++)
        pos[k] += vf__wave_at(&h->pos[k], t);
    vf_mat4_from_rt(moved, pos, c2w);
}

vf_camera vf__phone_camera(const vf_studio_phone *p)
{
    double f = 0.5 * p->height / tan(0.5 * p->fov_y * DEG);
    return (vf_camera){.width = p->width, .height = p->height, .fx = f, .fy = f,
                       .cx = 0.5 * p->width, .cy = 0.5 * p->height};
}

static double smoothstep(double x)
{
    x = x < 0 ? 0 : x > 1 ? 1 : x;
    return x * x * (3 - 2 * x);
}

int vf__capture_walk(const vf_studio_capture_options *o, double **c2w)
{
    const vf_studio_phone *p = &o->phone;
    double seconds = o->loops * o->loop_seconds;
    int n = (int)lround(seconds * p->fps);
    *c2w = malloc(sizeof(double) * 16 * (size_t)(n > 0 ? n : 1));
    if (!*c2w)
        return -1;
    vf_rng rng;
    vf_rng_seed(&rng, p->seed);
    double start = 2 * M_PI * vf_rng_uniform(&rng);
    studio_wave pace, breathe, aim[3];
    vf__wave_init(&pace, &rng, 0.05, 0.2, p->shake * 0.12);      /* radians of azimuth */
    vf__wave_init(&breathe, &rng, 0.05, 0.3, p->shake * 0.03);   /* share of the distance */
    for (int k = 0; k < 3; k++)                                   /* where the eye rests */
        vf__wave_init(&aim[k], &rng, 0.1, 0.5, p->shake * (k == 2 ? 0.04 : 0.06));
    studio_hand hand;
    vf__hand_init(&hand, &rng, p->shake, o->distance);
    for (int i = 0; i < n; i++) {
        double t = i / p->fps;
        double azimuth = start + 2 * M_PI * t / o->loop_seconds + vf__wave_at(&pace, t);
        /* one loop a height; the person rises in the last and first 15% of two loops */
        double elevation = o->elevation_low;
        for (int k = 1; k < o->loops; k++) {
            double step = (o->elevation_high - o->elevation_low) / (o->loops - 1);
            elevation += step * smoothstep((t - (k - 0.15) * o->loop_seconds) /
                                           (0.3 * o->loop_seconds));
        }
        double d = o->distance * (1 + vf__wave_at(&breathe, t));
        double eye[3] = {d * cos(elevation * DEG) * cos(azimuth),
                         d * cos(elevation * DEG) * sin(azimuth), d * sin(elevation * DEG)};
        double at[3] = {vf__wave_at(&aim[0], t), vf__wave_at(&aim[1], t),
                        vf__wave_at(&aim[2], t)};
        vf__hand_camera(&hand, t, eye, at, *c2w + 16 * i);
    }
    return n;
}
