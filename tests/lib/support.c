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
    cdsp_render_paper_camera(cam); /* the one definition, lib/render.c */
    cam->k1 = (cdsp_real)k1;
    cam->k2 = (cdsp_real)k2;
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

void sup_world_to_camera(const double Xw[3], double Xc[3])
{
    cdsp_real Rm[9], C[3];
    double d[3];
    int i;
    cdsp_render_paper_pose(Rm, C);
    for (i = 0; i < 3; i++)
        d[i] = Xw[i] - (double)C[i];
    for (i = 0; i < 3; i++)
        Xc[i] = (double)Rm[3 * i] * d[0] + (double)Rm[3 * i + 1] * d[1] + (double)Rm[3 * i + 2] * d[2];
}

void sup_paper_pipe(int i, double point[3], double dir[3])
{
    cdsp_real p[3], v[3];
    int k;
    if (cdsp_render_paper_pipe(i, p, v, NULL) != CDSP_OK)
        return;
    for (k = 0; k < 3; k++) {
        point[k] = (double)p[k];
        dir[k] = (double)v[k];
    }
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

void sup_add_bar(cdsp_scene *s, const double a[3], const double b[3], double half_width, double level)
{
    cdsp_clutter *c;
    int k;
    if (s->n_clutter >= CDSP_RENDER_MAX_CLUTTER)
        return;
    c = &s->clutter[s->n_clutter++];
    for (k = 0; k < 3; k++) {
        c->p0[k] = (cdsp_real)a[k];
        c->p1[k] = (cdsp_real)b[k];
    }
    c->half_width = (cdsp_real)half_width;
    c->level = (cdsp_real)level;
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
    int need = s->blur_sigma_px > 0 || s->motion_px[0] != 0 || s->motion_px[1] != 0;
    float *scr = need ? malloc(nscr * sizeof(float)) : NULL;
    cdsp_rng rng;
    cdsp_rng_seed(&rng, seed, 7);
    if (!buf || (need && !scr) ||
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

void sup_edge_spec_default(sup_edge_spec *e)
{
    memset(e, 0, sizeof *e);
    e->width = e->height = 128;
    e->bits = 8;
    e->radius_px = 80;
    e->pipe = 160;
    e->background = 60;
    e->ambient = 1;
    e->light_v = 1;
    e->blur_px = 0.7;
    e->spec_width = 1;
    e->seed = 1;
}

static void edge_normal(const sup_edge_spec *e, double n[2])
{
    double a = e->angle_deg * SUP_PI / 180;
    /* contour direction (sin a, cos a); the pipe on the side of (cos a, -sin a) */
    n[0] = cos(a);
    n[1] = -sin(a);
}

double sup_edge_u(const sup_edge_spec *e, double x, double y)
{
    double n[2];
    edge_normal(e, n);
    return (x - (e->width - 1) / 2.0) * n[0] + (y - (e->height - 1) / 2.0) * n[1] - e->offset_px;
}

/* The unblurred scene at distance u from the silhouette. */
static double edge_scene(const sup_edge_spec *e, double u)
{
    double c, s, sh, lit;
    if (u < 0)
        return e->background;
    c = 1 - u / e->radius_px;
    if (c < -1)
        c = -1; /* beyond the far limb: the pipe's middle continues (never reached in a frame) */
    s = sqrt(1 - c * c);
    lit = e->light_n * c + e->light_v * s;
    sh = e->ambient + (1 - e->ambient) * (lit > 0 ? lit : 0);
    return e->pipe * sh +
           e->spec_amp * exp(-0.5 * (u - e->spec_u) * (u - e->spec_u) / (e->spec_width * e->spec_width));
}

/* In place: mean over [u - w/2, u + w/2] on a grid of spacing h (the exact
 * box average of the piecewise-linear function through the samples, from
 * its running integral). Ends replicate. */
static void box_filter(double *f, double *tmp, int n, double h, double w)
{
    int i;
    double *cum = tmp;
    if (w <= 1e-9)
        return;
    cum[0] = 0;
    for (i = 1; i < n; i++)
        cum[i] = cum[i - 1] + 0.5 * (f[i - 1] + f[i]) * h;
    for (i = 0; i < n; i++) {
        double lo = i * h - w / 2, hi = i * h + w / 2, c[2], pos[2] = {lo, hi};
        int k;
        for (k = 0; k < 2; k++) {
            double t = pos[k] / h;
            int j = (int)floor(t);
            if (j < 0)
                c[k] = cum[0] + (pos[k]) * f[0];
            else if (j >= n - 1)
                c[k] = cum[n - 1] + (pos[k] - (n - 1) * h) * f[n - 1];
            else {
                double fr = t - j, fj = f[j] + (f[j + 1] - f[j]) * fr;
                c[k] = cum[j] + 0.5 * (f[j] + fj) * fr * h;
            }
        }
        f[n + i] = (c[1] - c[0]) / w; /* the upper half of the buffer holds the result */
    }
    memcpy(f, f + n, (size_t)n * sizeof *f);
}

void *sup_edge_render(const sup_edge_spec *e, cdsp_image *img, double n_pipe[2], double l[3])
{
    const double h = 1.0 / 32, U = 0.5 * sqrt((double)e->width * e->width + (double)e->height * e->height) +
                                  fabs(e->offset_px) + 4;
    int n = 2 * (int)ceil(U / h) + 1, i, x, y, rad = (int)ceil(4 * e->blur_px / h);
    double *f = malloc(sizeof(double) * (size_t)n * 2), *g = malloc(sizeof(double) * (size_t)n * 2);
    double nn[2], full = (double)((1L << e->bits) - 1), u0 = -(n / 2) * h, rc2;
    size_t bpp = e->bits <= 8 ? 1 : 2;
    void *buf = malloc((size_t)e->width * (size_t)e->height * bpp);
    cdsp_rng rng;
    if (!f || !g || !buf) {
        free(f);
        free(g);
        free(buf);
        return NULL;
    }
    edge_normal(e, nn);
    /* the samples stand for the piecewise-linear scene through them: the
     * one at u = 0 takes the mean of both sides so the step's midpoint
     * stays at u = 0 (not h/2 to one side) */
    for (i = 0; i < n; i++)
        f[i] = i == n / 2 ? 0.5 * (e->background + edge_scene(e, 0)) : edge_scene(e, u0 + i * h);
    /* pixel footprint on the normal, then the motion box */
    box_filter(f, g, n, h, fabs(nn[0]));
    box_filter(f, g, n, h, fabs(nn[1]));
    box_filter(f, g, n, h, e->motion_px * fabs(cos(e->motion_deg * SUP_PI / 180)));
    if (e->blur_px > 0) {
        double *k = malloc(sizeof(double) * (size_t)(2 * rad + 1)), ks = 0;
        if (!k) {
            free(f);
            free(g);
            free(buf);
            return NULL;
        }
        for (i = -rad; i <= rad; i++)
            ks += k[i + rad] = exp(-0.5 * (i * h / e->blur_px) * (i * h / e->blur_px));
        for (i = 0; i < n; i++) {
            double acc = 0;
            int j;
            for (j = -rad; j <= rad; j++) {
                int idx = i + j < 0 ? 0 : (i + j >= n ? n - 1 : i + j);
                acc += k[j + rad] * f[idx];
            }
            g[i] = acc / ks;
        }
        memcpy(f, g, (size_t)n * sizeof *f);
        free(k);
    }
    cdsp_rng_seed(&rng, e->seed, 11);
    rc2 = ((e->width - 1) / 2.0) * ((e->width - 1) / 2.0) + ((e->height - 1) / 2.0) * ((e->height - 1) / 2.0);
    for (y = 0; y < e->height; y++)
        for (x = 0; x < e->width; x++) {
            double u = sup_edge_u(e, x, y), t = (u - u0) / h, v, dx = x - (e->width - 1) / 2.0,
                   dy = y - (e->height - 1) / 2.0;
            int j = (int)floor(t);
            long q;
            if (j < 0)
                j = 0;
            if (j > n - 2)
                j = n - 2;
            v = f[j] + (f[j + 1] - f[j]) * (t - j);
            v *= 1 - e->vignette * (dx * dx + dy * dy) / rc2;
            if (e->noise > 0)
                v += e->noise * (double)cdsp_rng_normal(&rng);
            q = (long)floor(v + 0.5);
            q = q < 0 ? 0 : (q > (long)full ? (long)full : q);
            if (bpp == 1)
                ((unsigned char *)buf)[(size_t)y * (size_t)e->width + (size_t)x] = (unsigned char)q;
            else
                ((uint16_t *)buf)[(size_t)y * (size_t)e->width + (size_t)x] = (uint16_t)q;
        }
    free(f);
    free(g);
    img->data = buf;
    img->width = e->width;
    img->height = e->height;
    img->stride = (size_t)e->width * bpp;
    img->bits = e->bits;
    if (n_pipe) {
        n_pipe[0] = nn[0];
        n_pipe[1] = nn[1];
    }
    if (l) {
        /* u = n.(p - c) - offset; brighter side at the silhouette: the pipe's
         * limb value against the background */
        double sgn = edge_scene(e, 1e-9) >= e->background ? 1 : -1;
        l[0] = sgn * nn[0];
        l[1] = sgn * nn[1];
        l[2] = -sgn * (nn[0] * (e->width - 1) / 2.0 + nn[1] * (e->height - 1) / 2.0 + e->offset_px);
    }
    return buf;
}

int sup_edge_line(const sup_edge_spec *e, const cdsp_image *img, cdsp_edge *pts, size_t cap, size_t *m,
                  cdsp_line *ln)
{
    cdsp_edge_params ep;
    size_t n, i, k = 0;
    int round;
    cdsp_edge_params_default(&ep);
    ep.min_contrast = (cdsp_real)0.03; /* 10 gray levels at 8 bit are to be found */
    ep.step = 2;
    if (cdsp_edges_detect(img, &ep, pts, cap, &n) != CDSP_OK)
        n = 0;
    for (i = 0; i < n; i++)
        if (fabs(sup_edge_u(e, (double)pts[i].x, (double)pts[i].y)) < 10)
            pts[k++] = pts[i];
    for (round = 0; round < 3; round++) {
        size_t j = 0;
        if (k < 20 || cdsp_line_fit(pts, NULL, k, ln) != CDSP_OK)
            return 0;
        if (round == 2)
            break;
        for (i = 0; i < k; i++)
            if (fabs((double)(ln->l[0] * pts[i].x + ln->l[1] * pts[i].y + ln->l[2])) < (round ? 1.0 : 2.0))
                pts[j++] = pts[i];
        k = j;
    }
    *m = k;
    return 1;
}

cdsp_status sup_edge_profile(const sup_edge_spec *e, const cdsp_image *img, const cdsp_line *ln,
                             const double n_pipe[2], const cdsp_profile_params *pp, cdsp_profile_ws *ws,
                             cdsp_profile *pr)
{
    double c0[2];
    cdsp_real ends[2][2], pin[2];
    int j;
    c0[0] = (e->width - 1) / 2.0 + e->offset_px * n_pipe[0];
    c0[1] = (e->height - 1) / 2.0 + e->offset_px * n_pipe[1];
    for (j = 0; j < 2; j++) {
        cdsp_real t = j ? ln->t_max : ln->t_min;
        ends[j][0] = ln->centroid[0] + t * ln->dir[0];
        ends[j][1] = ln->centroid[1] + t * ln->dir[1];
    }
    /* the pipe's middle: its distance is the limb's radius */
    pin[0] = (cdsp_real)(c0[0] + e->radius_px * n_pipe[0]);
    pin[1] = (cdsp_real)(c0[1] + e->radius_px * n_pipe[1]);
    return cdsp_profile_fit(img, ln->l, pin, (const cdsp_real(*)[2])ends, pp, ws, pr);
}

void sup_paper_bound_scene(cdsp_scene *s, int i, double ambient, double point[3], double dir[3])
{
    sup_paper_pipe(i, point, dir);
    sup_scene(s, point, dir, 8);
    s->half_length = 250;
    s->noise_sigma = (cdsp_real)0.002;
    s->ambient = (cdsp_real)ambient;
}

static const double sup_second_light[3] = {-0.6, 0.3, -0.75};
const sup_paper_light sup_paper_lights[SUP_PAPER_NLIGHTS] = {
    {"flat light (ambient 1)", 1, NULL},
    {"directional, default light, ambient 0.85", 0.85, NULL},
    {"directional, default light, ambient 0.4", 0.4, NULL},
    {"directional, second light, ambient 0.85", 0.85, sup_second_light},
    {"directional, second light, ambient 0.4", 0.4, sup_second_light},
};

void sup_paper_light_scene(cdsp_scene *s, int i, int row, double point[3], double dir[3])
{
    const sup_paper_light *L = &sup_paper_lights[row];
    int k;
    sup_paper_bound_scene(s, i, L->ambient, point, dir);
    if (L->light)
        for (k = 0; k < 3; k++)
            s->light[k] = (cdsp_real)L->light[k];
}

double sup_true_distance(const double point[3], const double dir[3])
{
    double t = point[0] * dir[0] + point[1] * dir[1] + point[2] * dir[2], f[3];
    int k;
    for (k = 0; k < 3; k++)
        f[k] = point[k] - t * dir[k];
    return sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
}

void sup_row_pipes(int pipes, double roll_deg, double c[2][3], double v[3])
{
    double r = roll_deg * SUP_PI / 180, n;
    int k;
    v[0] = cos(r);
    v[1] = sin(r);
    v[2] = 0.2;
    n = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (k = 0; k < 3; k++)
        v[k] /= n;
    for (k = 0; k < 2; k++) {
        double off = pipes == 2 ? (k ? 24 : -24) : 0;
        c[k][0] = -off * sin(r) + 3;
        c[k][1] = off * cos(r) - 2;
        c[k][2] = 420;
    }
}

void sup_row_scene(int pipes, const double c[2][3], const double v[3], cdsp_scene *s)
{
    int i;
    sup_scene(s, c[0], v, 8);
    s->half_length = 400;
    s->ambient = 1; /* flat: no shading bias */
    s->texture = 0;
    if (pipes == 2) {
        s->n_extra_pipes = 1;
        for (i = 0; i < 3; i++) {
            s->extra_pipe[0].axis_point[i] = (cdsp_real)c[1][i];
            s->extra_pipe[0].axis_dir[i] = (cdsp_real)v[i];
        }
        s->extra_pipe[0].radius = 8;
        s->extra_pipe[0].half_length = 400;
    }
}

int sup_find_axis(const cdsp_result *out, size_t n, const double c[3], const double v[3], double tol_mm)
{
    double d[3], t = c[0] * v[0] + c[1] * v[1] + c[2] * v[2];
    size_t k;
    int i;
    for (i = 0; i < 3; i++)
        d[i] = c[i] - t * v[i];
    for (k = 0; k < n; k++) {
        double dot = 0, e = 0;
        for (i = 0; i < 3; i++) {
            dot += (double)out[k].direction[i] * v[i];
            e += ((double)out[k].point[i] - d[i]) * ((double)out[k].point[i] - d[i]);
        }
        if (fabs(dot) > cos(2 * SUP_PI / 180) && sqrt(e) < tol_mm)
            return (int)k;
    }
    return -1;
}
