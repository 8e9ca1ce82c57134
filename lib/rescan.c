/*
 * rescan.c - the chosen contours re-read at a finer scanline step
 * (cdsp_params.refine_step; docs/method.md §3a).
 *
 * The search only has to find the contours; at its step s (default 4) it
 * reads one scanline in s. The partial-area detector takes a point's
 * position from the mean over its window's 3 scanlines (lib/edges.c: the
 * sums S[0..2]), so at s = 4 a contour's points hold 3 of every 4 rows of
 * pixels along it, and points nearer than 3 scanlines would share pixels,
 * and noise: the fit, which takes its points as independent, would
 * overstate what they add (at step 1 its sigma would come out sqrt(3) too
 * small). Step 3 reads every pixel near the contour exactly once, the
 * most information the detector's points hold: refine_step is 0 (off) or
 * at least 3 (lib/pair.c's check). Once a pose's two lines are chosen,
 * this pass reads again only the scanlines' short segments around each
 * line (+-(ceil(inlier_px) + RESCAN_MARGIN) px of where it crosses them,
 * as the tracked path's bands, lib/frame.c), every refine_step-th
 * scanline over the line's extent, and refits each line to the edges
 * found there that are its inliers (p->pair.inlier_px and normal_tol_deg,
 * the line finder's tests, against the search's line; one pass, no point
 * is read twice). Nothing goes through the frame's edge buffer: each
 * segment's few edges are undistorted and added to the line's moments at
 * once (to the sums of a total-least-squares fit), so the frame's edge budget
 * (CDSP_MAX_EDGES) is neither used nor hit, and the search, the ranking
 * and the confidences stay exactly what they were: only the pose's lines,
 * and so the pose and its sigma, change. With the points independent the
 * line's random error falls by sqrt(edge.step / refine_step): by
 * sqrt(4 / 3) = 1.15 against the default search, by 2 against a search at
 * step 12 (tests/lib/test_rescan.c).
 *
 * When the edge-profile model moved a line (cdsp__frame_refine), the move
 * is undone for the refit and the model fitted again about the refitted
 * line (docs/method.md 3a); where it no longer applies, the refitted line
 * is moved by the first amount.
 */
#include "internal.h"

/* the segment read on each scanline: +-(ceil(inlier_px) + RESCAN_MARGIN)
 * px of where the line crosses it (cdsp__frame_band; its candidates are
 * floor(crossing) +- (band - 1), so every inlier within inlier_px is
 * seen, with a pixel to spare) */
#define RESCAN_MARGIN 2
/* edges one segment can hold: a segment of a few px around a 1 px inlier
 * band has one or two; a full buffer is a busy segment, whose edges are
 * taken as far as they go */
#define RESCAN_BUF 16

/* Sums of the inliers' coordinates in the search line's own frame: t
 * along ln->dir from its centroid, d across it (its signed distance), so
 * that the residual across the refitted line comes from the small d's
 * directly: from sums of x and y about a point, the across variance
 * (~0.01 px^2) is the difference of two variances ~1e5 px^2, beyond float
 * precision. */
typedef struct {
    cdsp_real n, st, sd, stt, sdd, std, sg, tmin, tmax;
} td_sums;

/*
 * The point fit (cdsp_params.point_fit; docs/method.md §3a). The partial-
 * area estimate weighs the window's 2h + 1 pixels of a scanline alike,
 * though only the 2-3 on the blurred step say where it is: on a contour of
 * 25 gray levels at noise 2 its points scatter 0.18 px, 2.3 times the
 * Cramer-Rao bound of its 3 x (2h + 1) pixels. The point fit takes the
 * same pixels (the detector's rows t - 1 .. t + 1, h either side of its
 * point) and the least-squares offset d of the model
 *   I(u) = A + C Phi((u - d) / s)
 * (u: a pixel's signed distance from the line through the detector's
 * point, along the search line's normal; Phi the normal integral), A and C
 * this window's own, s the contour's edge spread: the weights fall on the
 * slope's pixels. s is the median of full fits (A, C, d, s) at up to
 * PF_PROFILE points spread along the contour's extent; each point then
 * fits A, C and d only: one Gauss-Newton step from the detector's point
 * (PF_ITERS; 3 steps gave the same noise, 0.099 against 0.1005 px on the
 * shadowed limbs, at 1.8 times the cost). For a symmetric step d and s are
 * orthogonal, so the median's error does not move the line. Side slopes
 * (a shaded limb is not flat) were tried and left out: estimated from the
 * contour's own points, their error moves every point alike, an offset
 * error of the line as large as what the fit saves (docs/method.md §3a).
 * Measured on the rendered rack (tests/bench/probe_point_fit.c, true
 * contours): point noise 0.183 -> 0.099 px on the shadowed limbs, 0.048
 * -> 0.030 on the lit ones, 0.039 -> 0.021 px on a flat-lit pipe; the
 * bias +0.001 -> +0.000, +0.077 -> +0.105 (the lit limb's shading, taken
 * in part for the step) and -0.001 -> -0.000 px.
 *
 * The distortion is ignored inside the window (the search line's
 * undistorted normal): its turn there moves rows t +- 1 oppositely, which
 * cancels in d.
 */
#define PF_MAXH 8       /* edge.half_window's largest value */
#define PF_PROFILE 48   /* points the contour's s is the median of */
#define PF_ITERS 1      /* Gauss-Newton steps of a point's (A, C, d) */
#define PF_FULL_ITERS 8 /* of a full fit's four parameters */

#ifdef CDSP_SINGLE
#define PF_ERFC CDSP__MATH(erfcf)
#else
#define PF_ERFC CDSP__MATH(erfc)
#endif

typedef struct {
    cdsp_real v[3][2 * PF_MAXH + 1], u[3][2 * PF_MAXH + 1];
    int n;
} pf_win;

/* the contour's profile: its edge spread s (px) */
typedef struct {
    cdsp_real s;
} pf_prof;

/* The window of the edge e (distorted px, on scanline t of the family
 * horizontal), with u along the unit normal (nx, ny): 0 when it does not
 * fit in the frame. */
static int pf_window(const cdsp_image *img, int horizontal, int h, const cdsp_edge *e, cdsp_real nx,
                     cdsp_real ny, pf_win *w)
{
    cdsp_real pos = horizontal ? e->x : e->y;
    int t = (int)(horizontal ? e->y : e->x), c0 = (int)R_FLOOR(pos + R(0.5)), k, i;
    int ext = horizontal ? img->width : img->height, across = horizontal ? img->height : img->width;
    size_t bpp = img->bits <= 8 ? 1u : 2u;
    if (c0 - h < 0 || c0 + h >= ext || t < 1 || t + 1 >= across)
        return 0;
    w->n = 2 * h + 1;
    for (k = 0; k < 3; k++)
        for (i = 0; i < w->n; i++) {
            int a = c0 - h + i, b = t - 1 + k, x = horizontal ? a : b, y = horizontal ? b : a;
            const unsigned char *q = (const unsigned char *)img->data + (size_t)y * img->stride + (size_t)x * bpp;
            w->v[k][i] = bpp == 2 ? (cdsp_real)*(const uint16_t *)(const void *)q : (cdsp_real)*q;
            w->u[k][i] = nx * ((cdsp_real)x - e->x) + ny * ((cdsp_real)y - e->y);
        }
    return 1;
}

/* Gauss-Newton on the model above: par = (A, C, d, s), the first three
 * free, all four when full; iters steps (each d step clamped to 1 px). 1
 * when it ends with |d| < 2 px and s in [0.2, 4] px. */
static int pf_fit(const pf_win *w, cdsp_real par[4], int full, int iters)
{
    int it, k, i, np = full ? 4 : 3;
    for (it = 0; it < iters; it++) {
        cdsp_real H[4][5], J[4];
        int a, b, r;
        for (a = 0; a < np; a++)
            for (b = 0; b <= np; b++)
                H[a][b] = R(0);
        for (k = 0; k < 3; k++)
            for (i = 0; i < w->n; i++) {
                cdsp_real u = w->u[k][i], z = (u - par[2]) / par[3];
                cdsp_real P = R(0.5) * PF_ERFC(-z * R(0.70710678118654752));
                cdsp_real g = R(0.39894228040143268) * R_EXP(R(-0.5) * z * z);
                cdsp_real res = w->v[k][i] - (par[0] + par[1] * P);
                J[0] = R(1);
                J[1] = P;
                J[2] = -par[1] * g / par[3];
                J[3] = -par[1] * g * z / par[3];
                for (a = 0; a < np; a++) {
                    H[a][np] += J[a] * res;
                    for (b = 0; b <= a; b++)
                        H[a][b] += J[a] * J[b];
                }
            }
        for (a = 0; a < np; a++)
            for (b = a + 1; b < np; b++)
                H[a][b] = H[b][a];
        /* Gauss-Jordan on the normal equations (positive definite) */
        for (r = 0; r < np; r++) {
            cdsp_real piv = H[r][r];
            if (!(piv > R(0)))
                return 0;
            for (a = 0; a < np; a++)
                if (a != r) {
                    cdsp_real f = H[a][r] / piv;
                    for (b = r; b <= np; b++)
                        H[a][b] -= f * H[r][b];
                }
        }
        for (a = 0; a < np; a++) {
            cdsp_real x = H[a][np] / H[a][a];
            if (a == 2)
                x = x > R(1) ? R(1) : x < R(-1) ? R(-1) : x;
            par[a] += x;
        }
        if (par[3] < R(0.2))
            par[3] = R(0.2);
        if (par[3] > R(4))
            par[3] = R(4);
    }
    return R_FINITE(par[2]) && R_FABS(par[2]) < R(2) && par[3] > R(0.2) && par[3] < R(4);
}

/* A, C from the window's pixels beyond 2 px on either side, d = 0 */
static void pf_start(const pf_win *w, const pf_prof *pr, cdsp_real par[4])
{
    cdsp_real sa = R(0), sb = R(0), na = R(0), nb = R(0);
    int k, i;
    for (k = 0; k < 3; k++)
        for (i = 0; i < w->n; i++) {
            if (w->u[k][i] < R(-2)) {
                sa += w->v[k][i];
                na += R(1);
            } else if (w->u[k][i] > R(2)) {
                sb += w->v[k][i];
                nb += R(1);
            }
        }
    par[0] = na > R(0) ? sa / na : w->v[1][0];
    par[1] = (nb > R(0) ? sb / nb : w->v[1][w->n - 1]) - par[0];
    par[2] = R(0);
    par[3] = pr->s;
}

/* The point fit's move of e (distorted px) along its scanline: 1 when it
 * converged (e moved), else 0 (e kept). */
static int pf_point(const cdsp_image *img, int horizontal, int h, const pf_prof *pr, cdsp_real nx,
                    cdsp_real ny, cdsp_edge *e)
{
    pf_win w;
    cdsp_real par[4], ns = horizontal ? nx : ny;
    if (!pf_window(img, horizontal, h, e, nx, ny, &w))
        return 0;
    pf_start(&w, pr, par);
    if (!pf_fit(&w, par, 0, PF_ITERS) || !(R_FABS(ns) > R(0.5)))
        return 0;
    if (horizontal)
        e->x += par[2] / ns;
    else
        e->y += par[2] / ns;
    return 1;
}

static void pf_sort(cdsp_real *a, int n)
{
    int i, j;
    for (i = 1; i < n; i++) {
        cdsp_real x = a[i];
        for (j = i; j > 0 && a[j - 1] > x; j--)
            a[j] = a[j - 1];
        a[j] = x;
    }
}

/* The line ln's inliers on the scanlines first, first + step, ... <= last,
 * added to *m (sg: the sum of their gradient lengths). */
static void rescan_family(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                          const cdsp_edge_params *edge, const cdsp_line *ln, int horizontal, int first,
                          int last, cdsp_real cos2, const pf_prof *pr, td_sums *m)
{
    int x0, y0, x1, y1, t, h = p->edge.half_window, nodist = cdsp__camera_no_distortion(cam);
    int step = p->refine_step;
    int ext = horizontal ? img->width : img->height;
    cdsp_real band = R_CEIL(p->pair.inlier_px) + R(RESCAN_MARGIN), thr = p->pair.inlier_px;
    cdsp__edges_clip_roi(img, &p->edge.roi, &x0, &y0, &x1, &y1);
    for (t = first; t <= last; t += step) {
        cdsp_edge buf[RESCAN_BUF];
        size_t k, nb;
        int from, to;
        if (!cdsp__frame_band(cam, nodist, ln->l, horizontal, t, band, horizontal ? x0 : y0,
                              horizontal ? x1 : y1, h, ext, &from, &to))
            continue;
        nb = cdsp__edges_scan_segment(img, edge, horizontal, t, from, to, buf, RESCAN_BUF);
        if (pr) /* the point fit, on the frame's pixels: before undistortion */
            for (k = 0; k < nb; k++)
                (void)pf_point(img, horizontal, h, pr, ln->l[0], ln->l[1], &buf[k]);
        if (nb == 0 || cdsp_camera_undistort_edges(cam, buf, &nb) != CDSP_OK)
            continue;
        for (k = 0; k < nb; k++) {
            const cdsp_edge *e = &buf[k];
            cdsp_real d = ln->l[0] * e->x + ln->l[1] * e->y + ln->l[2];
            cdsp_real gn = ln->l[0] * e->gx + ln->l[1] * e->gy, g2 = e->gx * e->gx + e->gy * e->gy, s;
            if (d > thr || d < -thr || !(gn > R(0)) || gn * gn < cos2 * g2)
                continue;
            s = ln->dir[0] * (e->x - ln->centroid[0]) + ln->dir[1] * (e->y - ln->centroid[1]);
            m->n += R(1);
            m->st += s;
            m->sd += d;
            m->stt += s * s;
            m->sdd += d * d;
            m->std += s * d;
            m->sg += R_SQRT(g2);
            m->tmin = s < m->tmin ? s : m->tmin;
            m->tmax = s > m->tmax ? s : m->tmax;
        }
    }
}

/* The contour's profile (pf_prof) for the point fit: full fits at the
 * inliers (as rescan_family tests them) of up to PF_PROFILE scanlines
 * spread evenly over first .. last, their medians; 0 when fewer than 8
 * fits converged (the point fit is then not done on this line). */
static int pf_profile(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                      const cdsp_edge_params *edge, const cdsp_line *ln, int horizontal, int first,
                      int last, cdsp_real cos2, pf_prof *pr)
{
    cdsp_real ss[PF_PROFILE], thr = p->pair.inlier_px;
    cdsp_real band = R_CEIL(p->pair.inlier_px) + R(RESCAN_MARGIN);
    const pf_prof start = {R(1)};
    int x0, y0, x1, y1, j, n = 0, h = p->edge.half_window, nodist = cdsp__camera_no_distortion(cam);
    int ext = horizontal ? img->width : img->height, span = last - first;
    cdsp__edges_clip_roi(img, &p->edge.roi, &x0, &y0, &x1, &y1);
    for (j = 0; j < PF_PROFILE && n < PF_PROFILE; j++) {
        cdsp_edge buf[RESCAN_BUF], und[RESCAN_BUF];
        size_t k, nb, nu;
        int from, to, t = first + (int)(((long)span * (2 * j + 1)) / (2 * PF_PROFILE));
        if (!cdsp__frame_band(cam, nodist, ln->l, horizontal, t, band, horizontal ? x0 : y0,
                              horizontal ? x1 : y1, h, ext, &from, &to))
            continue;
        nb = cdsp__edges_scan_segment(img, edge, horizontal, t, from, to, buf, RESCAN_BUF);
        for (k = 0; k < nb; k++)
            und[k] = buf[k];
        nu = nb;
        if (nb == 0 || cdsp_camera_undistort_edges(cam, und, &nu) != CDSP_OK || nu != nb)
            continue;
        for (k = 0; k < nb && n < PF_PROFILE; k++) {
            const cdsp_edge *e = &und[k];
            cdsp_real d = ln->l[0] * e->x + ln->l[1] * e->y + ln->l[2], par[4];
            cdsp_real gn = ln->l[0] * e->gx + ln->l[1] * e->gy, g2 = e->gx * e->gx + e->gy * e->gy;
            pf_win w;
            if (d > thr || d < -thr || !(gn > R(0)) || gn * gn < cos2 * g2)
                continue;
            if (!pf_window(img, horizontal, h, &buf[k], ln->l[0], ln->l[1], &w))
                continue;
            pf_start(&w, &start, par);
            if (!pf_fit(&w, par, 1, PF_FULL_ITERS))
                continue;
            ss[n++] = par[3];
        }
    }
    if (n < 8)
        return 0;
    pf_sort(ss, n);
    pr->s = ss[n / 2];
    return 1;
}

/* The scanlines (rows when horizontal, else columns) line ln's inlier
 * extent crosses in the distorted frame, within the roi's [lo, hi) and
 * the scans' reach (lib/frame.c's bands: 1 .. hi - 2): [*first, *last];
 * 0 when none, or an end cannot be distorted. */
static int rescan_range(const cdsp_camera *cam, const cdsp_line *ln, int horizontal, int lo, int hi,
                        int *first, int *last)
{
    cdsp_real a = R_MAX, b = -R_MAX;
    int e;
    for (e = 0; e < 2; e++) {
        cdsp_real q[2], dq[2], c;
        cdsp_real t = e ? ln->t_max : ln->t_min;
        q[0] = ln->centroid[0] + t * ln->dir[0];
        q[1] = ln->centroid[1] + t * ln->dir[1];
        if (cdsp_camera_distort(cam, q, dq) != CDSP_OK)
            return 0;
        c = horizontal ? dq[1] : dq[0];
        a = c < a ? c : a;
        b = c > b ? c : b;
    }
    if (a < (cdsp_real)(lo > 1 ? lo : 1))
        a = (cdsp_real)(lo > 1 ? lo : 1);
    if (b > (cdsp_real)(hi - 2))
        b = (cdsp_real)(hi - 2);
    if (!(b >= a))
        return 0;
    *first = (int)R_CEIL(a);
    *last = (int)R_FLOOR(b);
    return *last >= *first;
}

cdsp_status cdsp__rescan_line(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                              cdsp_real min_step, cdsp_line *ln)
{
    cdsp_edge_params edge = p->edge;
    td_sums m;
    cdsp_line out;
    pf_prof pr;
    const pf_prof *prp = NULL;
    cdsp_real cos_tol, mt, md, ctt, cdd, ctd, h, r, big, small, c, sn, q[2], shift;
    int horizontal = R_FABS(ln->l[0]) >= R_FABS(ln->l[1]), x0, y0, x1, y1, first, last, i;
    if (p->refine_step < 1)
        return CDSP_OK;
    cdsp__edges_clip_roi(img, &p->edge.roi, &x0, &y0, &x1, &y1);
    if (!rescan_range(cam, ln, horizontal, horizontal ? y0 : x0, horizontal ? y1 : x1, &first, &last))
        return CDSP_E_FEW_POINTS;
    /* the frame's threshold, as the search applied it (lib/frame.c) */
    edge.min_contrast = min_step / (cdsp_real)((1 << img->bits) - 1);
    if (!(edge.min_contrast < R(1)))
        edge.min_contrast = R(0.999);
    cos_tol = R_COS(p->pair.normal_tol_deg * R(0.017453292519943295));
    m.n = m.st = m.sd = m.stt = m.sdd = m.std = m.sg = R(0);
    m.tmin = R_MAX;
    m.tmax = -R_MAX;
    if (p->point_fit && pf_profile(img, cam, p, &edge, ln, horizontal, first, last, cos_tol * cos_tol, &pr))
        prp = &pr;
    rescan_family(img, cam, p, &edge, ln, horizontal, first, last, cos_tol * cos_tol, prp, &m);
    if (m.n < (cdsp_real)p->pair.min_inliers || m.n < R(3))
        return CDSP_E_FEW_POINTS;
    /* the TLS line of the points in (t, d): through their mean, along the
     * major axis of their centred scatter [ctt ctd; ctd cdd], at the angle
     * phi from the search line's direction (tan 2 phi = 2 ctd / (ctt -
     * cdd)); the eigenvalues big and small = det / big (no cancellation)
     * are the spread along it and the residual across it, per point */
    mt = m.st / m.n;
    md = m.sd / m.n;
    ctt = m.stt / m.n - mt * mt;
    cdd = m.sdd / m.n - md * md;
    ctd = m.std / m.n - mt * md;
    if (cdd < R(0))
        cdd = R(0);
    h = (ctt - cdd) / R(2);
    r = R_SQRT(h * h + ctd * ctd);
    big = (ctt + cdd) / R(2) + r;
    if (!(h > R(0)) || !(big > R(0)) || !R_FINITE(big))
        return CDSP_E_DEGENERATE; /* the points do not run along the line */
    small = (ctt * cdd - ctd * ctd) / big;
    if (small < R(0))
        small = R(0);
    /* (cos phi, sin phi) from the half-angle of (h, ctd), h > 0 */
    c = R_SQRT((R(1) + h / r) / R(2));
    sn = ctd / (R(2) * r * c);
    out = *ln;
    for (i = 0; i < 2; i++) {
        out.dir[i] = c * ln->dir[i] + sn * ln->l[i];
        out.centroid[i] = ln->centroid[i] + mt * ln->dir[i] + md * ln->l[i];
    }
    /* the normal (a, b) = (dir[1], -dir[0]) turned as the direction: it
     * keeps pointing to the bright side, as ln's (dir = (-b, a)) */
    out.l[0] = out.dir[1];
    out.l[1] = -out.dir[0];
    out.l[2] = -(out.l[0] * out.centroid[0] + out.l[1] * out.centroid[1]);
    out.rms = R_SQRT(small);
    out.spread = big * m.n;
    out.count = (uint32_t)m.n;
    out.strength = m.sg / m.n;
    /* the extent, measured along the search's line, taken along the new
     * one from the new centroid (the two differ by far less than a pixel) */
    q[0] = ln->centroid[0] - out.centroid[0];
    q[1] = ln->centroid[1] - out.centroid[1];
    shift = q[0] * out.dir[0] + q[1] * out.dir[1];
    out.t_min = m.tmin + shift;
    out.t_max = m.tmax + shift;
    if (!R_FINITE(out.l[2]) || !R_FINITE(out.rms))
        return CDSP_E_DEGENERATE;
    *ln = out;
    return CDSP_OK;
}

cdsp_status cdsp__rescan_pair(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                              cdsp_real min_step, cdsp_pair_set *set, const cdsp_pair_eval *c,
                              const cdsp__profile_src *src, cdsp__pair_refined *ref)
{
    cdsp_line L[2];
    cdsp_real off[2], sig[2];
    int i;
    if (p->refine_step < 1)
        return CDSP_OK;
    for (i = 0; i < 2; i++) {
        cdsp_line *ln = &set->lines[i ? c->j : c->i];
        cdsp_real moved = ref ? ref->offset[i] : R(0), side, s;
        cdsp_status st;
        L[i] = *ln;
        /* the model's move undone first: the inliers are the detector's
         * points, about the detector's line */
        side = L[i].l[0] * c->p_in[0] + L[i].l[1] * c->p_in[1] + L[i].l[2];
        s = side > R(0) ? R(1) : R(-1);
        L[i].l[2] += moved * s;
        L[i].centroid[0] -= moved * s * L[i].l[0];
        L[i].centroid[1] -= moved * s * L[i].l[1];
        st = cdsp__rescan_line(img, cam, p, min_step, &L[i]);
        if (st != CDSP_OK)
            return st; /* neither line changed */
        off[i] = moved;
        sig[i] = ref ? ref->sigma_offset[i] : R(0);
        if (src && sig[i] > R(0)) {
            /* the model measured again about the refitted line: its
             * silhouette does not depend on the line it starts from (to
             * first order), so the line sits on it whatever the refit's
             * own offset error, or bias (the point fit's lit limb, +0.03
             * px beyond the detector's, docs/method.md 3a), and its noise
             * is the silhouette's alone (lib/pair.c propagate) */
            cdsp_line t = L[i];
            cdsp_profile pr;
            cdsp_real mv, smv;
            int k = i ? c->j : c->i;
            if (cdsp__profile_refine(img, cam, src->pts, src->n, src->label, (uint8_t)(k + 1), &t, c->p_in,
                                     &p->profile, p->edge.half_window, src->noise, src->pws, &pr, &mv,
                                     &smv) == CDSP_OK &&
                smv > R(0)) {
                L[i] = t;
                off[i] = mv;
                sig[i] = smv;
                continue;
            }
        }
        /* else the detector's move done again on the refitted line, toward
         * the pipe (its noise then the model's on the detector's line) */
        side = L[i].l[0] * c->p_in[0] + L[i].l[1] * c->p_in[1] + L[i].l[2];
        s = side > R(0) ? R(1) : R(-1);
        L[i].l[2] -= moved * s;
        L[i].centroid[0] += moved * s * L[i].l[0];
        L[i].centroid[1] += moved * s * L[i].l[1];
    }
    set->lines[c->i] = L[0];
    set->lines[c->j] = L[1];
    if (ref) { /* the lines' points now at refine_step's spacing */
        ref->var_scale = cdsp__edges_scan_var(p->refine_step);
        for (i = 0; i < 2; i++) {
            ref->offset[i] = off[i];
            ref->sigma_offset[i] = sig[i];
        }
    }
    return CDSP_OK;
}
