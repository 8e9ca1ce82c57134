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
 * When the edge-profile model moved a line (cdsp__frame_refine), the
 * refitted line is moved by the same amount: the model measures the edge's
 * shape, which the scanline step does not change.
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

/* The line ln's inliers on the scanlines first, first + step, ... <= last,
 * added to *m (sg: the sum of their gradient lengths). */
static void rescan_family(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                          const cdsp_edge_params *edge, const cdsp_line *ln, int horizontal, int first,
                          int last, cdsp_real cos2, td_sums *m)
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
    rescan_family(img, cam, p, &edge, ln, horizontal, first, last, cos_tol * cos_tol, &m);
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
                              cdsp__pair_refined *ref)
{
    cdsp_line L[2];
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
        /* and done again on the refitted line, toward the pipe */
        side = L[i].l[0] * c->p_in[0] + L[i].l[1] * c->p_in[1] + L[i].l[2];
        s = side > R(0) ? R(1) : R(-1);
        L[i].l[2] -= moved * s;
        L[i].centroid[0] += moved * s * L[i].l[0];
        L[i].centroid[1] += moved * s * L[i].l[1];
    }
    set->lines[c->i] = L[0];
    set->lines[c->j] = L[1];
    if (ref) /* the lines' points now at refine_step's spacing */
        ref->var_scale = cdsp__edges_scan_var(p->refine_step);
    return CDSP_OK;
}
