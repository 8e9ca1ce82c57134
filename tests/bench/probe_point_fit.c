/* probe_point_fit.c - issue 13's per-point estimator study (docs/method.md
 * §3a, the point fit); a diagnostic, built by `make` (tests/bench/rack.mk)
 * as build/bench/probe_point_fit, or by hand:
 *   cc -std=c99 -D_DEFAULT_SOURCE -O2 -Iinclude -Itools -Itests/lib \
 *     tests/bench/probe_point_fit.c tools/tool_rack_scene.c tests/lib/support.c \
 *     build/host/libcdsp.a -lm -o /tmp/probe_point_fit
 *   /tmp/probe_point_fit FRAMES WHICH [H [TRIM]]   (WHICH: 1 rack, 2 flat-lit pipe,
 *                            3 both; H the window's half width, 4; TRIM b7's cut, 1.5)
 * On the exact contour lines (sup_contour_lines), every 3rd scanline, the
 * detector's point (cdsp__edges_scan_segment) against least-squares fits
 * of I(u) = A + C Phi((u - d) / s) over the same 3 x (2H + 1) pixels:
 *   a   the detector;
 *   b1  A, C, d free, s the contour's (median of b4's);
 *   b2  d alone, A, C, s the contour's medians;
 *   b4  A, C, s, d free;
 *   gn1 / gn2: b1 in 1 / 2 Gauss-Newton steps from the detector's point;
 *   b5  b1 with a pipe-side slope D free; b6 b1 with D the contour's median;
 *   b4gn1 / b4gn2: b4 in 1 / 2 steps;
 *   b7  gn1 (2 steps) on the window cut at TRIM px on the pipe side of the
 *       detector's point (the lit limb's ramp left out);
 *   b8  gn1 on the window less each side's ramp k sqrt(|u|) (u from the
 *       detector's point), k the contour's median of per-point regressions
 *       on the OM pixels beyond the window on each row (u 5 .. 4 + OM).
 * Measured (`probe_point_fit 1 3 [4 TRIM]`; sd / bias px, rack shadowed /
 * rack lit / flat-lit):
 *   b8, OM 4:      0.1009 / +0.0015, 0.0274 / +0.0319, 0.0212 / +0.0005;
 *   b8, OM 8:      0.1006 / -0.0020, 0.0277 / +0.0503, 0.0209 / -0.0003;
 *   b7, TRIM 1.5:  0.1593 / -0.0015, 0.0558 / +0.1008, 0.0289 / -0.0006;
 *   b7, TRIM 2.5:  0.1123 / +0.0016, 0.0336 / +0.0851, 0.0231 / -0.0003.
 * b8 in the library (k pooled over the contour, OM 8) was tried and taken
 * out (docs/method.md §3a).
 * sd is about each contour's own mean, bias the mean: a profile parameter
 * taken from the contour's own points (b6's D) moves all its points alike,
 * which the sd does not see; the line's offset does (docs/method.md §3a).
 * Errors beyond 1 px in any estimate drop the point (column crossings).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "cdsp.h"
#include "../lib/internal.h"
#include "tool_rack_scene.h"
#include "support.h"

static int HW = 4;
static double Phi(double z)
{
    return 0.5 * erfc(-z / sqrt(2.0));
}
static double phi(double z)
{
    return exp(-0.5 * z * z) / sqrt(2 * M_PI);
}

typedef struct {
    double v[3][32];
    double u0[3][32];
    int n;
    /* b7/b8: pixels beyond the window, OM on each side of every row */
    double vo[3][2][8], uo[3][2][8];
} win;
static int OM = 4;
static double TRIM = 1.5;
/* b7: the side slopes (gray levels / px) from the pixels beyond the window, one
 * line per side */
static void side_slopes(const win *w, double ea, int sq, double g[2])
{
    int k, j, sd;
    for (sd = 0; sd < 2; sd++) {
        double n = 0, su = 0, sv = 0, suu = 0, suv = 0;
        for (k = 0; k < 3; k++)
            for (j = 0; j < OM; j++) {
                double u = w->uo[k][sd][j] - ea, v = w->vo[k][sd][j];
                if (sq)
                    u = sqrt(fabs(u));
                n++;
                su += u;
                sv += v;
                suu += u * u;
                suv += u * v;
            }
        g[sd] = (suv - su * sv / n) / (suu - su * su / n);
    }
}
/* the window with the side slopes taken out: v - g u on each side of the
 * detector's point (u0 - ea) */
static void unslope(const win *w, double ea, int sq, const double g[2], win *o)
{
    int k, i;
    *o = *w;
    for (k = 0; k < 3; k++)
        for (i = 0; i < w->n; i++) {
            double u = w->u0[k][i] - ea;
            o->v[k][i] -= (u < 0 ? g[0] : g[1]) * (sq ? sqrt(fabs(u)) : u);
        }
}
/* fit: params A, C, s, d; mask which are free; u = u0 + d */
static double Dsl;
static int fitx(const win *w, double *A, double *C, double *s, double *d, int freeAC, int frees, int freeD,
                int maxit);
static int fit(const win *w, double *A, double *C, double *s, double *d, int freeAC, int frees)
{
    Dsl = 0;
    return fitx(w, A, C, s, d, freeAC, frees, 0, 20);
}
static int fitx(const win *w, double *A, double *C, double *s, double *d, int freeAC, int frees, int freeD,
                int maxit)
{
    int it, i, k;
    for (it = 0; it < maxit; it++) {
        double J[5], H[5][5] = {{0}}, g[5] = {0}, x[5];
        int np = 0, idx[5], a, b;
        if (freeAC) {
            idx[np++] = 0;
            idx[np++] = 1;
        }
        if (frees)
            idx[np++] = 2;
        if (freeD)
            idx[np++] = 4;
        idx[np++] = 3;
        for (k = 0; k < 3; k++)
            for (i = 0; i < w->n; i++) {
                double u = w->u0[k][i] + *d, z = u / *s, CC = *C + Dsl * u,
                       r = w->v[k][i] - (*A + CC * Phi(z));
                double Jall[5];
                Jall[0] = 1;
                Jall[1] = Phi(z);
                Jall[2] = -CC * phi(z) * z / *s;
                Jall[3] = CC * phi(z) / *s + Dsl * Phi(z);
                Jall[4] = u * Phi(z);
                for (a = 0; a < np; a++)
                    J[a] = Jall[idx[a]];
                for (a = 0; a < np; a++) {
                    g[a] += J[a] * r;
                    for (b = 0; b < np; b++)
                        H[a][b] += J[a] * J[b];
                }
            }
        /* solve H x = g (gauss elim) */
        {
            double M[5][6];
            int r, c, p;
            for (r = 0; r < np; r++) {
                for (c = 0; c < np; c++)
                    M[r][c] = H[r][c];
                M[r][np] = g[r];
            }
            for (p = 0; p < np; p++) {
                double piv = M[p][p];
                if (fabs(piv) < 1e-12)
                    return 0;
                for (r = 0; r < np; r++)
                    if (r != p) {
                        double f = M[r][p] / piv;
                        for (c = p; c <= np; c++)
                            M[r][c] -= f * M[p][c];
                    }
            }
            for (r = 0; r < np; r++)
                x[r] = M[r][np] / M[r][r];
        }
        for (a = 0; a < np; a++) {
            if (idx[a] == 0)
                *A += x[a];
            if (idx[a] == 1)
                *C += x[a];
            if (idx[a] == 2) {
                *s += x[a];
                if (*s < 0.2)
                    *s = 0.2;
                if (*s > 3)
                    *s = 3;
            }
            if (idx[a] == 4)
                Dsl += x[a];
            if (idx[a] == 3) {
                double st = x[a];
                if (st > 1)
                    st = 1;
                if (st < -1)
                    st = -1;
                *d += st;
            }
        }
        if (fabs(x[np - 1]) < 1e-7)
            break;
    }
    return fabs(*d) < 2.5;
}

#define MAXP 4096
typedef struct {
    double ea, x, y;
    win w;
    double A, C, s, d4;
    int ok4;
    double s5, D5;
    int ok5;
} pt;
static pt P[MAXP];
static int cmpd(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}
static double median(double *v, int n)
{
    qsort(v, n, sizeof *v, cmpd);
    return n ? v[n / 2] : 0;
}
static double tmp[MAXP];

#define NV 12
typedef struct {
    double n, s1[NV], s2[NV];
} acc;
static void acc_add(acc *a, const double e[NV])
{
    int i;
    a->n++;
    for (i = 0; i < NV; i++) {
        a->s1[i] += e[i];
        a->s2[i] += e[i] * e[i];
    }
}
static int v8dbg;
static acc pooled[2]; /* 0 shadowed/low contrast, 1 lit */

/* one contour: true line L (double, normalised, toward the pipe), along range
 * [s0, s1] */
static void contour(const cdsp_image *img, const double L[3], double s0, double s1, int step, const char *tag,
                    double cthr)
{
    int horizontal = fabs(L[0]) >= fabs(L[1]), n = 0, i, k, c;
    double tx = -L[1], ty = L[0];
    cdsp_edge_params ep;
    double sC, sA, sS, lo, hi, sS5, D5m, gmed[4];
    acc a;
    memset(&a, 0, sizeof a);
    cdsp_edge_params_default(&ep);
    ep.min_contrast = 6.0 / 255;
    /* scanlines crossed: rows (horizontal) or columns */
    {
        double pa[2] = {-L[2] * L[0] + s0 * tx, -L[2] * L[1] + s0 * ty},
               pb[2] = {-L[2] * L[0] + s1 * tx, -L[2] * L[1] + s1 * ty};
        lo = horizontal ? fmin(pa[1], pb[1]) : fmin(pa[0], pb[0]);
        hi = horizontal ? fmax(pa[1], pb[1]) : fmax(pa[0], pb[0]);
    }
    for (int t = (int)ceil(lo); t <= (int)floor(hi) && n < MAXP; t += step) {
        double xc;
        int from, to;
        cdsp_edge buf[16];
        size_t nb, j, best = 99;
        double bd = 1.5;
        if (t < 6 || t >= (horizontal ? img->height : img->width) - 6)
            continue;
        xc = horizontal ? -(L[1] * t + L[2]) / L[0] : -(L[0] * t + L[2]) / L[1];
        if (xc < 10 || xc > (horizontal ? img->width : img->height) - 10)
            continue;
        from = (int)floor(xc) - 3;
        to = (int)floor(xc) + 3;
        nb = cdsp__edges_scan_segment(img, &ep, horizontal, t, from, to, buf, 16);
        for (j = 0; j < nb; j++) {
            double dd = L[0] * buf[j].x + L[1] * buf[j].y + L[2];
            if (fabs(dd) < bd && (L[0] * buf[j].gx + L[1] * buf[j].gy) * 1.0 != 0) {
                bd = fabs(dd);
                best = j;
            }
        }
        if (best == 99)
            continue;
        {
            pt *q = &P[n];
            double xd = horizontal ? buf[best].x : buf[best].y;
            int s0i = (int)floor(xd + 0.5);
            q->ea = L[0] * buf[best].x + L[1] * buf[best].y + L[2];
            q->w.n = 2 * HW + 1;
            for (k = -1; k <= 1; k++)
                for (c = -HW; c <= HW; c++) {
                    int X = horizontal ? s0i + c : t + k, Y = horizontal ? t + k : s0i + c;
                    q->w.v[k + 1][c + HW] = ((const uint8_t *)img->data)[(size_t)Y * img->stride + X];
                    q->w.u0[k + 1][c + HW] =
                        L[0] * X + L[1] * Y + L[2]; /* distance to the true line; fit d: u = u0 - d_err */
                }
            for (k = -1; k <= 1; k++)
                for (c = 0; c < OM; c++) {
                    int sd;
                    for (sd = 0; sd < 2; sd++) {
                        int cc = sd ? s0i + HW + 1 + c : s0i - HW - 1 - c;
                        int X = horizontal ? cc : t + k, Y = horizontal ? t + k : cc;
                        q->w.vo[k + 1][sd][c] = ((const uint8_t *)img->data)[(size_t)Y * img->stride + X];
                        q->w.uo[k + 1][sd][c] = L[0] * X + L[1] * Y + L[2];
                    }
                }
            n++;
        }
    }
    if (n < 20)
        return;
    /* local 4-param fits; init A, C from the window's ends (u<0 bg side... use
     * sign of u0) */
    for (i = 0; i < n; i++) {
        pt *q = &P[i];
        double vm = 0, vp = 0;
        int nm = 0, np_ = 0;
        for (k = 0; k < 3; k++)
            for (c = 0; c < q->w.n; c++) {
                if (q->w.u0[k][c] < -2) {
                    vm += q->w.v[k][c];
                    nm++;
                }
                if (q->w.u0[k][c] > 2) {
                    vp += q->w.v[k][c];
                    np_++;
                }
            }
        q->A = nm ? vm / nm : 0;
        q->C = (np_ ? vp / np_ : 0) - q->A;
        q->s = 0.85;
        q->d4 = -q->ea;
        q->ok4 = fit(&q->w, &q->A, &q->C, &q->s, &q->d4, 1, 1);
    }
    for (i = 0, k = 0; i < n; i++)
        if (P[i].ok4)
            tmp[k++] = P[i].s;
    sS = median(tmp, k);
    for (i = 0, k = 0; i < n; i++)
        if (P[i].ok4)
            tmp[k++] = P[i].C;
    sC = median(tmp, k);
    for (i = 0, k = 0; i < n; i++)
        if (P[i].ok4)
            tmp[k++] = P[i].A;
    sA = median(tmp, k);
    {
        double g[2];
        int sd, sq;
        for (sq = 0; sq < 2; sq++)
            for (sd = 0; sd < 2; sd++) {
                for (i = 0, k = 0; i < n; i++) {
                    side_slopes(&P[i].w, P[i].ea, sq, g);
                    tmp[k++] = g[sd];
                }
                gmed[2 * sq + sd] = median(tmp, k);
            }
    }
    for (i = 0; i < n; i++) {
        pt *q = &P[i];
        double A5 = q->A, C5 = q->C, s5 = sS, d5 = q->d4;
        Dsl = 0;
        q->ok5 = q->ok4 && fitx(&q->w, &A5, &C5, &s5, &d5, 1, 1, 1, 20);
        q->s5 = s5;
        q->D5 = Dsl;
    }
    for (i = 0, k = 0; i < n; i++)
        if (P[i].ok5)
            tmp[k++] = P[i].s5;
    sS5 = median(tmp, k);
    for (i = 0, k = 0; i < n; i++)
        if (P[i].ok5)
            tmp[k++] = P[i].D5;
    D5m = median(tmp, k);
    for (i = 0; i < n; i++) {
        pt *q = &P[i];
        double A1, C1, s1_ = sS, d1 = -q->ea, A2 = sA, C2 = sC, s2 = sS, d2 = -q->ea, e[NV];
        double vm = 0, vp = 0;
        int nm = 0, np_ = 0;
        for (k = 0; k < 3; k++)
            for (c = 0; c < q->w.n; c++) {
                if (q->w.u0[k][c] < -2) {
                    vm += q->w.v[k][c];
                    nm++;
                }
                if (q->w.u0[k][c] > 2) {
                    vp += q->w.v[k][c];
                    np_++;
                }
            }
        A1 = nm ? vm / nm : sA;
        C1 = (np_ ? vp / np_ : sA + sC) - A1;
        if (!fit(&q->w, &A1, &C1, &s1_, &d1, 1, 0))
            continue;
        if (!fit(&q->w, &A2, &C2, &s2, &d2, 0, 0))
            continue;
        /* the error of a fitted d: the edge at u0 = -d, i.e. the estimated line is
         * offset by -d from the true line */
        e[0] = q->ea;
        e[1] = -d1;
        e[2] = -d2;
        e[3] = q->ok4 ? -q->d4 : 0;
        {
            double Ai = nm ? vm / nm : sA, Ci = (np_ ? vp / np_ : sA + sC) - Ai, si = sS, di = -q->ea;
            Dsl = 0;
            fitx(&q->w, &Ai, &Ci, &si, &di, 1, 0, 0, 1);
            e[4] = -di;
            Ai = nm ? vm / nm : sA;
            Ci = (np_ ? vp / np_ : sA + sC) - Ai;
            si = sS;
            di = -q->ea;
            Dsl = 0;
            fitx(&q->w, &Ai, &Ci, &si, &di, 1, 0, 0, 2);
            e[5] = -di;
            Ai = nm ? vm / nm : sA;
            Ci = (np_ ? vp / np_ : sA + sC) - Ai;
            si = sS;
            di = -q->ea;
            Dsl = 0;
            fitx(&q->w, &Ai, &Ci, &si, &di, 1, 0, 1, 20);
            e[6] = -di;
            Ai = nm ? vm / nm : sA;
            Ci = (np_ ? vp / np_ : sA + sC) - Ai;
            si = 0.85;
            di = -q->ea;
            Dsl = 0;
            fitx(&q->w, &Ai, &Ci, &si, &di, 1, 1, 0, 1);
            e[7] = -di;
            Ai = nm ? vm / nm : sA;
            Ci = (np_ ? vp / np_ : sA + sC) - Ai;
            si = 0.85;
            di = -q->ea;
            Dsl = 0;
            fitx(&q->w, &Ai, &Ci, &si, &di, 1, 1, 0, 2);
            e[8] = -di;
            Ai = nm ? vm / nm : sA;
            Ci = (np_ ? vp / np_ : sA + sC) - Ai;
            si = sS5;
            di = -q->ea;
            Dsl = D5m;
            fitx(&q->w, &Ai, &Ci, &si, &di, 1, 0, 0, 20);
            e[9] = -di;
            Dsl = 0;
            {
                /* b7: gn1 on the window less the per-point side slopes; b8: less the
                 * contour's medians */
                double g[2], gs[2];
                win wo;
                int v8;
                side_slopes(&q->w, q->ea, 0, g);
                for (v8 = 0; v8 < 2; v8++) {
                    int sd;
                    for (sd = 0; sd < 2; sd++)
                        gs[sd] = gmed[2 * v8 + sd];
                    /* side 0 of uo is the one at u < 0 when uo[.][0] < 0, else swap */
                    if (q->w.uo[1][0][0] > 0) {
                        double x = gs[0];
                        gs[0] = gs[1];
                        gs[1] = x;
                    }
                    unslope(&q->w, q->ea, v8, gs, &wo);
                    Ai = nm ? vm / nm : sA;
                    Ci = (np_ ? vp / np_ : sA + sC) - Ai;
                    si = sS;
                    di = -q->ea;
                    fitx(&wo, &Ai, &Ci, &si, &di, 1, 0, 0, 1);
                    e[10 + v8] = -di;
                    if (v8) { /* b7: gn1 on the window cut at TRIM px on the pipe side (u0 - ea > TRIM dropped) */
                        int kk, ii, l0 = 0, cnt;
                        wo = q->w;
                        cnt = 0;
                        for (ii = 0; ii < q->w.n; ii++)
                            if (q->w.u0[1][ii] - q->ea <= TRIM)
                                cnt++;
                        if (q->w.u0[1][0] > q->w.u0[1][q->w.n - 1])
                            l0 = q->w.n - cnt;
                        for (kk = 0; kk < 3; kk++)
                            for (ii = 0; ii < cnt; ii++) {
                                wo.v[kk][ii] = q->w.v[kk][l0 + ii];
                                wo.u0[kk][ii] = q->w.u0[kk][l0 + ii];
                            }
                        wo.n = cnt;
                        Ai = nm ? vm / nm : sA;
                        Ci = (np_ ? vp / np_ : sA + sC) - Ai;
                        si = sS;
                        di = -q->ea;
                        fitx(&wo, &Ai, &Ci, &si, &di, 1, 0, 0, 2);
                        e[10] = -di;
                    }
                }
                if (v8dbg < 3 && fabs(sC) >= cthr) {
                    fprintf(stderr, "%s g %+.2f %+.2f med %+.2f %+.2f sq %+.2f %+.2f C %.1f\n", tag, g[0],
                            g[1], gmed[0], gmed[1], gmed[2], gmed[3], sC);
                    v8dbg++;
                }
            }
        }
        for (k = 0; k < NV; k++)
            if (!(fabs(e[k]) <= 1))
                break;
        if (k < NV || !q->ok4)
            continue;
        acc_add(&a, e);
        acc_add(&pooled[fabs(sC) < cthr ? 0 : 1], e);
    }
    {
        double m[NV], sd[NV];
        for (k = 0; k < NV; k++) {
            m[k] = a.s1[k] / a.n;
            sd[k] = sqrt(a.s2[k] / a.n - m[k] * m[k]);
        }
        printf("%-14s n %4.0f/%4d C %6.1f A %6.1f s %.3f | sd a %.4f b1 %.4f b2 "
               "%.4f b4 %.4f | bias a %+.4f b1 "
               "%+.4f b2 %+.4f b4 %+.4f | ratio a/b1 %.2f a/b2 %.2f | s5 %.3f D5 "
               "%+.2f b6 sd %.4f bias %+.4f\n",
               tag, a.n, n, sC, sA, sS, sd[0], sd[1], sd[2], sd[3], m[0], m[1], m[2], m[3], sd[0] / sd[1],
               sd[0] / sd[2], sS5, D5m, sd[9], m[9]);
    }
}

static void along(const double L[3], const double p[2], double *s)
{
    *s = -L[1] * p[0] + L[0] * p[1];
}
static void projp(const cdsp_camera *cam, const double X[3], double p[2])
{
    p[0] = cam->fx * X[0] / X[2] + cam->cx;
    p[1] = cam->fy * X[1] / X[2] + cam->cy;
}

static void pipe_contours(const cdsp_image *img, const cdsp_camera *cam, const double c[3], const double v[3],
                          double r, double half, const char *tag, double cthr)
{
    double l[2][3], pin[2], E0[3], E1[3], p0[2], p1[2];
    int k, i;
    if (!sup_contour_lines(cam, c, v, r, l, pin))
        return;
    for (i = 0; i < 3; i++) {
        E0[i] = c[i] - half * v[i];
        E1[i] = c[i] + half * v[i];
    }
    projp(cam, E0, p0);
    projp(cam, E1, p1);
    for (k = 0; k < 2; k++) {
        double sa, sb;
        char t[64];
        along(l[k], p0, &sa);
        along(l[k], p1, &sb);
        snprintf(t, sizeof t, "%s c%d", tag, k);
        contour(img, l[k], fmin(sa, sb) + 30, fmax(sa, sb) - 30, 3, t, cthr);
    }
}

int main(int argc, char **argv)
{
    int frames = argc > 1 ? atoi(argv[1]) : 1, which = argc > 2 ? atoi(argv[2]) : 3;
    cdsp_camera cam;
    size_t sl = cdsp_render_scratch_size(RACK_W, RACK_H);
    float *scratch = malloc(sl * sizeof *scratch);
    uint8_t *buf = malloc((size_t)RACK_W * RACK_H);
    int arr, g, f, k;
    if (argc > 3)
        HW = atoi(argv[3]);
    if (argc > 4)
        TRIM = atof(argv[4]);
    tool_rack_camera(&cam);
    if (which & 1)
        for (arr = 0; arr < 2; arr++)
            for (g = 0; g < RACK_GROUPS; g++)
                for (f = 0; f < frames; f++) {
                    cdsp_scene s;
                    cdsp_rng rng;
                    cdsp_image img;
                    double c[2][3], v[3];
                    char tag[32];
                    tool_rack_frame(arr, g, f, &s, c, v);
                    cdsp_rng_seed(&rng, 1, (uint64_t)(1000 * arr + 100 * g + f));
                    cdsp_render(&s, &cam, buf, 0, 8, scratch, sl, &rng);
                    img.data = buf;
                    img.width = RACK_W;
                    img.height = RACK_H;
                    img.stride = RACK_W;
                    img.bits = 8;
                    for (k = 0; k < 2; k++) {
                        snprintf(tag, sizeof tag, "%c%d f%d p%d", 'A' + arr, g + 1, f, k);
                        pipe_contours(&img, &cam, c[k], v, RACK_R, RACK_HALF, tag, 40);
                    }
                }
    if (which & 1) {
        const char *nm[2] = {"rack shadowed", "rack lit"};
        for (k = 0; k < 2; k++) {
            acc *a = &pooled[k];
            double m[NV], sd[NV];
            int i;
            for (i = 0; i < NV; i++) {
                m[i] = a->s1[i] / a->n;
                sd[i] = sqrt(a->s2[i] / a->n - m[i] * m[i]);
            }
            printf("POOLED %-14s n %6.0f sd a %.4f b1 %.4f b2 %.4f b4 %.4f | bias a "
                   "%+.4f b1 %+.4f b2 %+.4f "
                   "b4 %+.4f | a/b1 %.2f a/b2 %.2f || gn1 %.4f %+.4f gn2 %.4f %+.4f "
                   "b5 %.4f %+.4f || b4gn1 "
                   "%.4f %+.4f b4gn2 %.4f %+.4f b6 %.4f %+.4f || b7 %.4f %+.4f b8 "
                   "%.4f %+.4f\n",
                   nm[k], a->n, sd[0], sd[1], sd[2], sd[3], m[0], m[1], m[2], m[3], sd[0] / sd[1],
                   sd[0] / sd[2], sd[4], m[4], sd[5], m[5], sd[6], m[6], sd[7], m[7], sd[8], m[8], sd[9],
                   m[9], sd[10], m[10], sd[11], m[11]);
        }
    }
    if (which & 2) {
        cdsp_camera pc;
        int i;
        memset(pooled, 0, sizeof pooled);
        sup_paper_camera(&pc, 0, 0);
        for (i = 0; i < 4; i++)
            for (f = 0; f < frames; f++) {
                double pt_[3], dir[3];
                cdsp_scene s;
                cdsp_image img;
                void *im;
                char tag[32];
                sup_paper_pipe(i, pt_, dir);
                sup_scene(&s, pt_, dir, 8);
                s.half_length = 250;
                s.ambient = 1;
                s.blur_sigma_px = (cdsp_real)0.8;
                s.noise_sigma = (cdsp_real)(2.0 / 255);
                s.texture = 0;
                im = sup_render(&s, &pc, 8, (uint64_t)(100 + 10 * i + f), &img);
                if (!im)
                    continue;
                snprintf(tag, sizeof tag, "flat p%d f%d", i + 1, f);
                pipe_contours(&img, &pc, pt_, dir, 8, 250, tag, 1e9);
                free(im);
            }
        {
            acc *a = &pooled[0];
            double m[NV], sd[NV];
            for (i = 0; i < NV; i++) {
                m[i] = a->s1[i] / a->n;
                sd[i] = sqrt(a->s2[i] / a->n - m[i] * m[i]);
            }
            printf("POOLED flat-lit       n %6.0f sd a %.4f b1 %.4f b2 %.4f b4 %.4f "
                   "| bias a %+.4f b1 %+.4f "
                   "b2 %+.4f b4 %+.4f | a/b1 %.2f a/b2 %.2f || gn1 %.4f %+.4f gn2 "
                   "%.4f %+.4f b5 %.4f %+.4f "
                   "|| b4gn1 %.4f %+.4f b4gn2 %.4f %+.4f b6 %.4f %+.4f || b7 %.4f "
                   "%+.4f b8 %.4f %+.4f\n",
                   a->n, sd[0], sd[1], sd[2], sd[3], m[0], m[1], m[2], m[3], sd[0] / sd[1], sd[0] / sd[2],
                   sd[4], m[4], sd[5], m[5], sd[6], m[6], sd[7], m[7], sd[8], m[8], sd[9], m[9], sd[10],
                   m[10], sd[11], m[11]);
        }
    }
    return 0;
}
