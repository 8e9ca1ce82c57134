/*
 * support.c - see support.h.
 */
#define _POSIX_C_SOURCE 199309L
#include "support.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

void sup_camera(cdsp_camera *cam, int w, int h, double f, double k1, double k2)
{
    memset(cam, 0, sizeof *cam);
    cam->fx = (cdsp_real)f;
    cam->fy = (cdsp_real)f;
    cam->cx = (cdsp_real)((w - 1) / 2.0);
    cam->cy = (cdsp_real)((h - 1) / 2.0);
    cam->k1 = (cdsp_real)k1;
    cam->k2 = (cdsp_real)k2;
    cam->width = w;
    cam->height = h;
}

void sup_paper_camera(cdsp_camera *cam, double k1, double k2)
{
    sup_camera(cam, 2448, 2048, 12.0 / 3.45e-3, k1, k2);
}

static void cross(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static void normalize(double a[3])
{
    double n = sqrt(dot(a, a));
    a[0] /= n;
    a[1] /= n;
    a[2] /= n;
}

/* Camera at C = (150, 200, 300) in the world looking at the origin; camera
 * Y down: x_c = R (X_w - C), rows of R = (right, down, forward). The world
 * "up" for choosing right/down is +Z_w. */
static void world_rotation(double Rm[3][3], double C[3])
{
    double fwd[3], up[3] = {0, 0, 1}, right[3], down[3];
    C[0] = 150;
    C[1] = 200;
    C[2] = 300;
    fwd[0] = -C[0];
    fwd[1] = -C[1];
    fwd[2] = -C[2];
    normalize(fwd);
    cross(fwd, up, right);
    normalize(right);
    cross(fwd, right, down);
    normalize(down);
    memcpy(Rm[0], right, sizeof right);
    memcpy(Rm[1], down, sizeof down);
    memcpy(Rm[2], fwd, sizeof fwd);
}

void sup_world_to_camera(const double Xw[3], double Xc[3])
{
    double Rm[3][3], C[3], d[3];
    int i;
    world_rotation(Rm, C);
    for (i = 0; i < 3; i++)
        d[i] = Xw[i] - C[i];
    for (i = 0; i < 3; i++)
        Xc[i] = dot(Rm[i], d);
}

void sup_paper_pipe(int i, double point[3], double dir[3])
{
    /* p1 along X_W through the origin; p2 = p1 moved -100 along Y_W (away
     * from the camera, docs/method.md); p3 along Y_W; p4 = p3 moved -100 along X_W */
    double pw[3] = {0, 0, 0}, dw[3] = {0, 0, 0}, Rm[3][3], C[3];
    int k;
    if (i == 0 || i == 1) {
        dw[0] = 1;
        if (i == 1)
            pw[1] = -100;
    } else {
        dw[1] = 1;
        if (i == 3)
            pw[0] = -100;
    }
    sup_world_to_camera(pw, point);
    world_rotation(Rm, C);
    for (k = 0; k < 3; k++)
        dir[k] = dot(Rm[k], dw);
}

static double urand(cdsp_rng *rng)
{
    return (double)cdsp_rng_u32(rng) / 4294967296.0;
}

void sup_random_pipe(cdsp_rng *rng, double zmin, double zmax, double point[3], double dir[3])
{
    double z = zmin + (zmax - zmin) * urand(rng);
    for (;;) {
        double th = 2 * SUP_PI * urand(rng), ph = acos(2 * urand(rng) - 1);
        dir[0] = sin(ph) * cos(th);
        dir[1] = sin(ph) * sin(th);
        dir[2] = cos(ph);
        /* keep the axis at least 25 degrees off the line of sight */
        if (fabs(dir[2]) < cos(25 * SUP_PI / 180))
            break;
    }
    point[0] = (urand(rng) - 0.5) * 0.2 * z;
    point[1] = (urand(rng) - 0.5) * 0.2 * z;
    point[2] = z;
}

double sup_line_dist(const double P[3], const double v[3], const double X[3])
{
    double d[3] = {X[0] - P[0], X[1] - P[1], X[2] - P[2]}, c[3];
    cross(d, v, c);
    return sqrt(dot(c, c) / dot(v, v));
}

double sup_axis_rmse(const double a[3], const double b[3], const double P[3], const double v[3],
                     int n)
{
    double s = 0;
    int i;
    for (i = 0; i < n; i++) {
        double t = n > 1 ? (double)i / (n - 1) : 0.5, X[3], d;
        int k;
        for (k = 0; k < 3; k++)
            X[k] = a[k] + t * (b[k] - a[k]);
        d = sup_line_dist(P, v, X);
        s += d * d;
    }
    return sqrt(s / n);
}

double sup_axis_angle(const double u[3], const double v[3])
{
    double c[3];
    cross(u, v, c);
    return atan2(sqrt(dot(c, c)), fabs(dot(u, v)));
}

/* The two tangent planes through the optical centre of the cylinder
 * (point, dir, radius), in double and independent of the library: with F
 * the foot of the axis (d = |F| > r), e1 = F/d, e2 = v x e1, the normals
 * n = (r/d) e1 +- sqrt(1 - r^2/d^2) e2 satisfy n.v = 0 and n.F = r. Also
 * the unit axis direction and the foot. Returns 0 when the camera is inside. */
static int tangent_planes(const double point[3], const double dir[3], double radius,
                          double n[2][3], double v[3], double foot[3])
{
    double e1[3], e2[3], d, c, s, t;
    int j;
    v[0] = dir[0];
    v[1] = dir[1];
    v[2] = dir[2];
    normalize(v);
    t = dot(point, v);
    for (j = 0; j < 3; j++)
        foot[j] = point[j] - t * v[j];
    d = sqrt(dot(foot, foot));
    if (d <= radius)
        return 0;
    for (j = 0; j < 3; j++)
        e1[j] = foot[j] / d;
    cross(v, e1, e2);
    c = radius / d;
    s = sqrt(1 - c * c);
    for (j = 0; j < 3; j++) {
        n[0][j] = c * e1[j] + s * e2[j];
        n[1][j] = c * e1[j] - s * e2[j];
    }
    return 1;
}

size_t sup_contour_points(const cdsp_camera *cam, const double point[3], const double dir[3],
                          double radius, double s0, double s1, size_t per_line, double sigma,
                          double contrast, cdsp_rng *rng, cdsp_edge *out, size_t cap,
                          double visible_px[2])
{
    double v[3], foot[3], n[2][3];
    size_t cnt = 0, i;
    int k, j;
    if (!tangent_planes(point, dir, radius, n, v, foot))
        return 0;
    for (k = 0; k < 2; k++) {
        /* the generator of plane k passes through foot - r n_k, along v;
         * first find the part of [s0, s1] whose image lies inside the frame
         * (a camera sees nothing else), then spread the points over it */
        double g0[3], t_lo = 0, t_hi = 0;
        int found = 0, steps = 4000, q;
        for (j = 0; j < 3; j++)
            g0[j] = point[j] - radius * n[k][j]; /* any axis point - r n_k is on it */
        for (q = 0; q <= steps; q++) {
            double t = s0 + (s1 - s0) * q / steps, X[3], u, w;
            for (j = 0; j < 3; j++)
                X[j] = g0[j] + t * v[j];
            if (X[2] <= 0)
                continue;
            u = (double)cam->fx * X[0] / X[2] + (double)cam->cx;
            w = (double)cam->fy * X[1] / X[2] + (double)cam->cy;
            if (u < 0 || w < 0 || u > cam->width - 1 || w > cam->height - 1)
                continue;
            if (!found)
                t_lo = t;
            t_hi = t;
            found = 1;
        }
        if (!found)
            continue;
        for (i = 0; i < per_line && cnt < cap; i++) {
            double t = t_lo + (t_hi - t_lo) * (per_line > 1 ? (double)i / (per_line - 1) : 0.5), X[3];
            double u, w, a, b, len, nz;
            for (j = 0; j < 3; j++)
                X[j] = g0[j] + t * v[j];
            u = (double)cam->fx * X[0] / X[2] + (double)cam->cx;
            w = (double)cam->fy * X[1] / X[2] + (double)cam->cy;
            /* image line normal of plane k: K^-T n, toward the pipe side */
            a = n[k][0] / (double)cam->fx;
            b = n[k][1] / (double)cam->fy;
            len = sqrt(a * a + b * b);
            a /= len;
            b /= len;
            nz = sigma > 0 ? sigma * (double)cdsp_rng_normal(rng) : 0;
            out[cnt].x = (cdsp_real)(u + nz * a);
            out[cnt].y = (cdsp_real)(w + nz * b);
            out[cnt].gx = (cdsp_real)(contrast * a);
            out[cnt].gy = (cdsp_real)(contrast * b);
            cnt++;
        }
        if (visible_px) {
            double A[3], B[3], ua, wa, ub, wb;
            for (j = 0; j < 3; j++) {
                A[j] = g0[j] + t_lo * v[j];
                B[j] = g0[j] + t_hi * v[j];
            }
            ua = (double)cam->fx * A[0] / A[2];
            wa = (double)cam->fy * A[1] / A[2];
            ub = (double)cam->fx * B[0] / B[2];
            wb = (double)cam->fy * B[1] / B[2];
            visible_px[k] = sqrt((ua - ub) * (ua - ub) + (wa - wb) * (wa - wb));
        }
    }
    return cnt;
}

int sup_contour_lines(const cdsp_camera *cam, const double point[3], const double dir[3],
                      double radius, double l[2][3], double p_in[2])
{
    double v[3], foot[3], nn[2][3], X[3];
    double fx = (double)cam->fx, fy = (double)cam->fy, cx = (double)cam->cx, cy = (double)cam->cy;
    int k, j;
    if (!tangent_planes(point, dir, radius, nn, v, foot))
        return 0;
    for (k = 0; k < 2; k++) {
        const double *n = nn[k];
        double a, b, len;
        a = n[0] / fx;
        b = n[1] / fy;
        len = sqrt(a * a + b * b);
        l[k][0] = a / len;
        l[k][1] = b / len;
        l[k][2] = (n[2] - cx * n[0] / fx - cy * n[1] / fy) / len;
    }
    memcpy(X, foot, sizeof X);
    if (X[2] <= 0) {
        double step = (1 - foot[2]) / v[2] + radius;
        for (j = 0; j < 3; j++)
            X[j] = foot[j] + step * v[j];
    }
    p_in[0] = fx * X[0] / X[2] + cx;
    p_in[1] = fy * X[1] / X[2] + cy;
    return 1;
}

void sup_result_pose(const cdsp_result *r, double point[3], double dir[3], double seg[2][3])
{
    int i;
    for (i = 0; i < 3; i++) {
        point[i] = (double)r->point[i];
        dir[i] = (double)r->direction[i];
        if (seg) {
            seg[0][i] = (double)r->segment[0][i];
            seg[1][i] = (double)r->segment[1][i];
        }
    }
}

void sup_scene(cdsp_scene *s, const double point[3], const double dir[3], double radius)
{
    int i;
    cdsp_scene_default(s);
    for (i = 0; i < 3; i++) {
        s->axis_point[i] = (cdsp_real)point[i];
        s->axis_dir[i] = (cdsp_real)dir[i];
    }
    s->radius = (cdsp_real)radius;
}

void *sup_render(const cdsp_scene *s, const cdsp_camera *cam, int bits, uint64_t seed,
                 cdsp_image *img)
{
    size_t bpp = bits <= 8 ? 1 : 2, nscr = cdsp_render_scratch_size(cam->width, cam->height);
    void *buf = malloc((size_t)cam->width * (size_t)cam->height * bpp);
    float *scr = s->blur_sigma_px > 0 ? malloc(nscr * sizeof(float)) : NULL;
    cdsp_rng rng;
    cdsp_rng_seed(&rng, seed, 7);
    if (!buf || (s->blur_sigma_px > 0 && !scr) ||
        cdsp_render(s, cam, buf, 0, bits, scr, nscr, &rng) != CDSP_OK) {
        free(buf);
        free(scr);
        return NULL;
    }
    free(scr);
    img->data = buf;
    img->width = cam->width;
    img->height = cam->height;
    img->stride = (size_t)cam->width * bpp;
    img->bits = bits;
    return buf;
}

double sup_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}
