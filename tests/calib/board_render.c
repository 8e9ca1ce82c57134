/* board_render.c: synthetic checkerboard images (see board_render.h). */
#include "board_render.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

void br_rodrigues(const double rv[3], double R[9])
{
    double th = sqrt(rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2]);
    double k[3] = {0, 0, 0}, c, s;
    if (th > 0) {
        k[0] = rv[0] / th;
        k[1] = rv[1] / th;
        k[2] = rv[2] / th;
    }
    c = cos(th);
    s = sin(th);
    /* R = c I + s [k]x + (1 - c) k k^T */
    R[0] = c + (1 - c) * k[0] * k[0];
    R[1] = -s * k[2] + (1 - c) * k[0] * k[1];
    R[2] = s * k[1] + (1 - c) * k[0] * k[2];
    R[3] = s * k[2] + (1 - c) * k[1] * k[0];
    R[4] = c + (1 - c) * k[1] * k[1];
    R[5] = -s * k[0] + (1 - c) * k[1] * k[2];
    R[6] = -s * k[1] + (1 - c) * k[2] * k[0];
    R[7] = s * k[0] + (1 - c) * k[2] * k[1];
    R[8] = c + (1 - c) * k[2] * k[2];
}

int br_project(const br_camera *cam, const double X[3], double pix[2])
{
    double x, y, r2, f;
    if (!(X[2] > 0))
        return 0;
    x = X[0] / X[2];
    y = X[1] / X[2];
    r2 = x * x + y * y;
    f = 1 + cam->k1 * r2 + cam->k2 * r2 * r2;
    pix[0] = cam->fx * x * f + cam->cx;
    pix[1] = cam->fy * y * f + cam->cy;
    return 1;
}

int br_project_board(const br_camera *cam, const br_pose *pose, double X, double Y,
                     double pix[2])
{
    double R[9], P[3];
    int i;
    br_rodrigues(pose->rvec, R);
    for (i = 0; i < 3; i++)
        P[i] = R[3 * i] * X + R[3 * i + 1] * Y + pose->t[i];
    return br_project(cam, P, pix);
}

int br_visible(const br_camera *cam, const br_board *b, const br_pose *pose, double margin)
{
    /* The border's outline, sampled densely: distortion bends its sides. */
    double e = (1 + b->border) * b->square;
    double x0 = -e, x1 = b->cols * b->square - b->square + e;
    double y0 = -e, y1 = b->rows * b->square - b->square + e;
    int k, n = 200;
    for (k = 0; k <= n; k++) {
        double s = (double)k / n, pt[4][2], pix[2];
        int q;
        pt[0][0] = x0 + s * (x1 - x0); pt[0][1] = y0;
        pt[1][0] = x0 + s * (x1 - x0); pt[1][1] = y1;
        pt[2][0] = x0; pt[2][1] = y0 + s * (y1 - y0);
        pt[3][0] = x1; pt[3][1] = y0 + s * (y1 - y0);
        for (q = 0; q < 4; q++) {
            if (!br_project_board(cam, pose, pt[q][0], pt[q][1], pix))
                return 0;
            if (pix[0] < margin || pix[1] < margin || pix[0] > cam->width - 1 - margin ||
                pix[1] > cam->height - 1 - margin)
                return 0;
        }
    }
    return 1;
}

/* Samples of a pixel that straddles regions: the Fibonacci lattice
 * ((a + 1/2) / N, frac((a k + 1/2) / N)), N = 89, k = 55. Every sample has
 * its own column and row, so even an edge along the pixel grid is located
 * to 1/89 px (a square ss x ss grid would quantize it to 1/ss), and the
 * lattice covers the square evenly in every direction. */
#define BR_SAMPLES 89
#define BR_LATTICE_K 55

/* The renderer's mapping, precomputed per pose. */
typedef struct {
    const br_camera *cam;
    const br_board *b;
    double Hinv[9];   /* normalized image point -> board point (homogeneous) */
} mapping;

/* 3x3 inverse by cofactors; the board homography is far from singular
 * for any pose that sees the board. */
static void inv3(const double m[9], double out[9])
{
    double d;
    int i;
    out[0] = m[4] * m[8] - m[5] * m[7];
    out[1] = m[2] * m[7] - m[1] * m[8];
    out[2] = m[1] * m[5] - m[2] * m[4];
    out[3] = m[5] * m[6] - m[3] * m[8];
    out[4] = m[0] * m[8] - m[2] * m[6];
    out[5] = m[2] * m[3] - m[0] * m[5];
    out[6] = m[3] * m[7] - m[4] * m[6];
    out[7] = m[1] * m[6] - m[0] * m[7];
    out[8] = m[0] * m[4] - m[1] * m[3];
    d = m[0] * out[0] + m[1] * out[3] + m[2] * out[6];
    for (i = 0; i < 9; i++)
        out[i] /= d;
}

/* Region of the board at a distorted pixel position: 1 + square index for
 * the squares, -1 the white border, -2 background (off the board, behind
 * the camera, or beyond the fold of the distortion). *shade = intensity. */
static int region(const mapping *m, double u, double v, double *shade)
{
    const br_camera *c = m->cam;
    const br_board *b = m->b;
    double xd = (u - c->cx) / c->fx, yd = (v - c->cy) / c->fy;
    double rd = sqrt(xd * xd + yd * yd), r = rd, x, y, w[3], X, Y, e;
    int it, i, j;

    /* Undistort: solve r (1 + k1 r^2 + k2 r^4) = rd for r by Newton from
     * r = rd; the distortion is monotonic where the derivative is > 0. */
    for (it = 0; it < 50; it++) {
        double r2 = r * r;
        double g = r * (1 + c->k1 * r2 + c->k2 * r2 * r2) - rd;
        double dg = 1 + 3 * c->k1 * r2 + 5 * c->k2 * r2 * r2;
        double step;
        if (!(dg > 0)) {
            *shade = BR_BACKGROUND;
            return -2;
        }
        step = g / dg;
        r -= step;
        if (fabs(step) <= 1e-16 * (1 + r))
            break;
    }
    x = rd > 0 ? xd * r / rd : 0;
    y = rd > 0 ? yd * r / rd : 0;
    for (i = 0; i < 3; i++)
        w[i] = m->Hinv[3 * i] * x + m->Hinv[3 * i + 1] * y + m->Hinv[3 * i + 2];
    if (!(w[2] > 0)) {   /* the ray meets the plane behind the camera */
        *shade = BR_BACKGROUND;
        return -2;
    }
    X = w[0] / w[2] / b->square;   /* in squares */
    Y = w[1] / w[2] / b->square;
    e = 1 + b->border;
    if (X < -e || Y < -e || X > b->cols - 1 + e || Y > b->rows - 1 + e) {
        *shade = BR_BACKGROUND;
        return -2;
    }
    i = (int)floor(X);
    j = (int)floor(Y);
    if (i < -1 || j < -1 || i > b->cols - 1 || j > b->rows - 1) {
        *shade = BR_WHITE;
        return -1;
    }
    /* (i + j) even is black: corner (0, 0) joins squares (-1,-1), (0,0) of
     * one colour and (-1,0), (0,-1) of the other, as every inner corner. */
    *shade = ((i + j) % 2 == 0) ? BR_BLACK : BR_WHITE;
    return 1 + (j + 1) * (b->cols + 1) + (i + 1);
}

int br_render(const br_camera *cam, const br_board *b, const br_pose *pose, double *img)
{
    mapping m;
    double R[9], H[9], shade;
    int W = cam->width, Hh = cam->height, u, v, i;
    int *lab = malloc(sizeof *lab * (size_t)(W + 1) * (size_t)(Hh + 1));
    if (!lab)
        return 0;
    m.cam = cam;
    m.b = b;
    br_rodrigues(pose->rvec, R);
    /* H = [r1 r2 t]: board (X, Y, 1) -> camera ray, up to scale. */
    for (i = 0; i < 3; i++) {
        H[3 * i] = R[3 * i];
        H[3 * i + 1] = R[3 * i + 1];
        H[3 * i + 2] = pose->t[i];
    }
    inv3(H, m.Hinv);

    /* Regions at the pixel corners (u - 0.5, v - 0.5). */
    for (v = 0; v <= Hh; v++)
        for (u = 0; u <= W; u++)
            lab[(size_t)v * (size_t)(W + 1) + (size_t)u] = region(&m, u - 0.5, v - 0.5, &shade);

    for (v = 0; v < Hh; v++)
        for (u = 0; u < W; u++) {
            const int *c0 = lab + (size_t)v * (size_t)(W + 1) + (size_t)u;
            const int *c1 = c0 + W + 1;
            double sum = 0;
            int a;
            if (c0[0] == c0[1] && c0[0] == c1[0] && c0[0] == c1[1]) {
                /* One region at the four corners: the footprint's image on
                 * the board is a near-parallelogram (curvature ~1e-6 px
                 * over a pixel) inside one convex region. */
                region(&m, u, v, &shade);
                img[(size_t)v * (size_t)W + (size_t)u] = shade;
                continue;
            }
            for (a = 0; a < BR_SAMPLES; a++) {
                region(&m, u - 0.5 + (a + 0.5) / BR_SAMPLES,
                       v - 0.5 + fmod((a * BR_LATTICE_K + 0.5) / BR_SAMPLES, 1.0), &shade);
                sum += shade;
            }
            img[(size_t)v * (size_t)W + (size_t)u] = sum / BR_SAMPLES;
        }
    free(lab);
    return 1;
}

void br_rng_seed(br_rng *r, uint64_t seed)
{
    r->s = seed;
    r->have = 0;
    r->spare = 0;
}

static uint64_t splitmix64(uint64_t *s)
{
    uint64_t z = (*s += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double br_rng_normal(br_rng *r)
{
    double u1, u2, rad;
    if (r->have) {
        r->have = 0;
        return r->spare;
    }
    /* Box-Muller; u1 in (0, 1] so the log is finite. */
    u1 = ((double)(splitmix64(&r->s) >> 11) + 1.0) / 9007199254740992.0;
    u2 = (double)(splitmix64(&r->s) >> 11) / 9007199254740992.0;
    rad = sqrt(-2 * log(u1));
    r->spare = rad * sin(2 * 3.14159265358979323846 * u2);
    r->have = 1;
    return rad * cos(2 * 3.14159265358979323846 * u2);
}

int br_write_pgm(const char *path, const double *img, int width, int height,
                 double sigma, br_rng *rng, int maxval)
{
    FILE *f = fopen(path, "wb");
    size_t i, n = (size_t)width * (size_t)height;
    int ok;
    if (!f)
        return 0;
    fprintf(f, "P5\n%d %d\n%d\n", width, height, maxval);
    for (i = 0; i < n; i++) {
        double x = img[i] + sigma * br_rng_normal(rng);
        long q;
        x = x < 0 ? 0 : x > 1 ? 1 : x;
        q = lround(x * maxval);
        if (maxval > 255) {
            fputc((int)(q >> 8), f);
            fputc((int)(q & 0xff), f);
        } else {
            fputc((int)q, f);
        }
    }
    ok = !ferror(f);
    return (fclose(f) == 0) && ok;
}
