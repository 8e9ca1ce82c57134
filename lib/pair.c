/*
 * pair.c - from candidate lines to the pipe: which two lines are the pipe's
 * apparent contour, the axis they give, its visible segment and its
 * first-order uncertainty.
 *
 * A pair is a pipe's contour only if (i) the polarities are opposite (the
 * gradients point toward each other when the pipe is brighter, away from each
 * other when darker: a stripe, not a staircase), (ii) the lines are within
 * max_contour_angle of each other, (iii) they overlap along the pipe by
 * min_overlap of the shorter one (both contours span the same stretch of
 * pipe, an end cap's or a support's edge does not), (iv) they do not meet
 * inside that stretch (cylinder contours meet only at the vanishing point,
 * beyond the visible part), and (v) the closed form gives a distance inside
 * the plausible range for the known radius. Among the survivors the pair
 * with the most inliers on the overlapping stretch wins.
 *
 * Uncertainty: each TLS line has two independent parameters about its
 * centroid, the offset along its normal (variance s^2/N) and the angle
 * (variance s^2/sum t_i^2), s^2 = RSS/(N-2) (standard line-fit results).
 * The 4 x 4 diagonal covariance is carried to (P_C, v_L, d) through a
 * central-difference Jacobian of the closed form with steps of one standard
 * deviation (floored at a few ulps of the precision in use).
 */
#include "internal.h"

typedef struct {
    int i, j;
    cdsp_real score;
    cdsp_real p_in[2];
} pair_choice;

/* Interval [lo, hi] of line ln's inliers projected on direction d from o. */
static void extent_on(const cdsp_line *ln, const cdsp_real d[2], const cdsp_real o[2],
                      cdsp_real *lo, cdsp_real *hi)
{
    cdsp_real a0 = ln->centroid[0] + ln->t_min * ln->dir[0] - o[0];
    cdsp_real a1 = ln->centroid[1] + ln->t_min * ln->dir[1] - o[1];
    cdsp_real b0 = ln->centroid[0] + ln->t_max * ln->dir[0] - o[0];
    cdsp_real b1 = ln->centroid[1] + ln->t_max * ln->dir[1] - o[1];
    cdsp_real ta = a0 * d[0] + a1 * d[1], tb = b0 * d[0] + b1 * d[1];
    *lo = ta < tb ? ta : tb;
    *hi = ta < tb ? tb : ta;
}

/* Score a candidate pair; 0 when it is not a pipe contour. */
static cdsp_real pair_score(const cdsp_camera *cam, cdsp_real radius, const cdsp_line *A,
                            const cdsp_line *B, const cdsp_pair_params *p, cdsp_real p_in[2])
{
    cdsp_real dotn = A->l[0] * B->l[0] + A->l[1] * B->l[1];
    cdsp_real w0 = B->centroid[0] - A->centroid[0], w1 = B->centroid[1] - A->centroid[1];
    cdsp_real sa, sb, loA, hiA, loB, hiB, lo, hi, ov, shorter, X[3], tmid, q[2], dq;
    cdsp__axis tmp;
    const cdsp_real *o = A->centroid, *d = A->dir;

    /* (i), (ii): opposite polarity within the contour angle */
    if (!(dotn < -R_COS(p->max_contour_angle_deg * R_PI / R(180))))
        return R(0);
    /* stripe, not staircase: both normals point inward, or both outward */
    sa = A->l[0] * w0 + A->l[1] * w1;
    sb = -(B->l[0] * w0 + B->l[1] * w1);
    if ((sa > R(0)) != (sb > R(0)))
        return R(0);
    if (p->polarity > 0 && !(sa > R(0)))
        return R(0);
    if (p->polarity < 0 && !(sa < R(0)))
        return R(0);
    /* the two contours of a pipe are at least a couple of pixels apart */
    if (R_FABS(sa) < R(2) || R_FABS(sb) < R(2))
        return R(0);
    /* (iii) overlap along the pipe */
    extent_on(A, d, o, &loA, &hiA);
    extent_on(B, d, o, &loB, &hiB);
    lo = loA > loB ? loA : loB;
    hi = hiA < hiB ? hiA : hiB;
    ov = hi - lo;
    shorter = (hiA - loA) < (hiB - loB) ? (hiA - loA) : (hiB - loB);
    if (!(shorter > R(0)) || ov < p->min_overlap * shorter)
        return R(0);
    /* (iv) where do the lines meet? */
    v3_cross(A->l, B->l, X);
    if (R_FABS(X[2]) > R(0)) {
        cdsp_real ix = X[0] / X[2] - o[0], iy = X[1] / X[2] - o[1];
        cdsp_real ti = ix * d[0] + iy * d[1];
        cdsp_real ulo = loA < loB ? loA : loB, uhi = hiA > hiB ? hiA : hiB;
        if (ti >= ulo && ti <= uhi)
            return R(0);
    }
    /* p_in: halfway between the lines at the middle of the overlap */
    tmid = (lo + hi) / R(2);
    q[0] = o[0] + tmid * d[0];
    q[1] = o[1] + tmid * d[1];
    /* q lies on A (A passes through its centroid along d); step half way to B */
    dq = B->l[0] * q[0] + B->l[1] * q[1] + B->l[2];
    p_in[0] = q[0] - R(0.5) * dq * B->l[0];
    p_in[1] = q[1] - R(0.5) * dq * B->l[1];
    /* (v) the closed form and the distance range */
    if (cdsp__axis_core(cam, A->l, B->l, p_in, radius, &tmp) != CDSP_OK)
        return R(0);
    if (p->min_distance > R(0) && tmp.distance < p->min_distance)
        return R(0);
    if (p->max_distance > R(0) && tmp.distance > p->max_distance)
        return R(0);
    /* inliers on the common stretch: each line's count scaled by the
     * fraction of its extent that overlaps */
    return (cdsp_real)A->count * ov / (hiA - loA) + (cdsp_real)B->count * ov / (hiB - loB);
}

/* Perturb a line: move it by dn along its normal and turn it by da about
 * its centroid. */
static void perturb(const cdsp_line *ln, cdsp_real dn, cdsp_real da, cdsp_real l[3])
{
    cdsp_real c = R_COS(da), s = R_SIN(da);
    l[0] = c * ln->l[0] - s * ln->l[1];
    l[1] = s * ln->l[0] + c * ln->l[1];
    l[2] = -(l[0] * ln->centroid[0] + l[1] * ln->centroid[1]) - dn;
}

static void pose_vec(const cdsp__axis *r, cdsp_real v[7])
{
    int i;
    for (i = 0; i < 3; i++) {
        v[i] = r->point[i];
        v[3 + i] = r->direction[i];
    }
    v[6] = r->distance;
}

static void propagate(const cdsp_camera *cam, cdsp_real radius, const cdsp_line *L[2],
                      const cdsp_real p_in[2], cdsp_result *out)
{
#ifdef CDSP_SINGLE
    const cdsp_real hmin_off = R(1e-3), hmin_ang = R(1e-6);
#else
    const cdsp_real hmin_off = R(1e-7), hmin_ang = R(1e-10);
#endif
    cdsp_real cov7[7][7];
    int k, a, b, i;
    for (a = 0; a < 7; a++)
        for (b = 0; b < 7; b++)
            cov7[a][b] = R(0);
    for (k = 0; k < 4; k++) {
        const cdsp_line *ln = L[k / 2];
        cdsp_real dof = ln->count > 2 ? (cdsp_real)(ln->count - 2) : R(1);
        cdsp_real s2 = ln->rms * ln->rms * (cdsp_real)ln->count / dof;
        cdsp_real var = (k % 2 == 0) ? s2 / (cdsp_real)ln->count
                                     : (ln->spread > R(0) ? s2 / ln->spread : R(0));
        cdsp_real h = R_SQRT(var), lp[3], lm[3], vp[7], vm[7], J[7];
        cdsp__axis rp, rm;
        if (!(var > R(0)))
            continue;
        if (k % 2 == 0 && h < hmin_off)
            h = hmin_off;
        if (k % 2 == 1 && h < hmin_ang)
            h = hmin_ang;
        perturb(ln, k % 2 == 0 ? h : R(0), k % 2 == 1 ? h : R(0), lp);
        perturb(ln, k % 2 == 0 ? -h : R(0), k % 2 == 1 ? -h : R(0), lm);
        if (cdsp__axis_core(cam, k < 2 ? lp : L[0]->l, k < 2 ? L[1]->l : lp, p_in, radius, &rp) !=
                CDSP_OK ||
            cdsp__axis_core(cam, k < 2 ? lm : L[0]->l, k < 2 ? L[1]->l : lm, p_in, radius, &rm) !=
                CDSP_OK)
            continue; /* a perturbation one sigma away is degenerate: leave it out */
        pose_vec(&rp, vp);
        pose_vec(&rm, vm);
        for (i = 0; i < 7; i++)
            J[i] = (vp[i] - vm[i]) / (R(2) * h);
        for (a = 0; a < 7; a++)
            for (b = 0; b < 7; b++)
                cov7[a][b] += J[a] * J[b] * var;
    }
    for (a = 0; a < 6; a++)
        for (b = 0; b < 6; b++)
            out->cov[a][b] = cov7[a][b];
    for (i = 0; i < 3; i++) {
        out->sigma_point[i] = R_SQRT(cov7[i][i]);
        out->sigma_direction[i] = R_SQRT(cov7[3 + i][3 + i]);
    }
    out->sigma_distance = R_SQRT(cov7[6][6]);
}

/* Parameter s of the axis point closest to the ray through undistorted
 * pixel q (closest points of two lines). */
static int axis_param_of_pixel(const cdsp_camera *cam, const cdsp_result *r, const cdsp_real q[2],
                               cdsp_real *s)
{
    cdsp_real Q[3], a, b, dd, e, den;
    cdsp_camera_ray(cam, q, Q);
    a = v3_dot(Q, Q);
    b = v3_dot(Q, r->direction);
    dd = -v3_dot(Q, r->point);
    e = -v3_dot(r->direction, r->point);
    den = a - b * b; /* |v| = 1 */
    if (!(den > R_EPS * a))
        return 0;
    *s = (a * e - b * dd) / den;
    return 1;
}

static void visible_segment(const cdsp_camera *cam, const cdsp_line *L[2], cdsp_result *out)
{
    cdsp_real smin = R_MAX, smax = -R_MAX;
    int k, e, i, any = 0;
    for (k = 0; k < 2; k++)
        for (e = 0; e < 2; e++) {
            cdsp_real t = e ? L[k]->t_max : L[k]->t_min, q[2], s;
            q[0] = L[k]->centroid[0] + t * L[k]->dir[0];
            q[1] = L[k]->centroid[1] + t * L[k]->dir[1];
            if (!axis_param_of_pixel(cam, out, q, &s))
                continue;
            any = 1;
            if (s < smin)
                smin = s;
            if (s > smax)
                smax = s;
        }
    if (!any)
        return;
    for (i = 0; i < 3; i++) {
        out->segment[0][i] = out->point[i] + smin * out->direction[i];
        out->segment[1][i] = out->point[i] + smax * out->direction[i];
    }
}

cdsp_status cdsp__pair_solve(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts,
                             size_t n, uint8_t *label, const cdsp_params *p,
                             const cdsp_result *prior, cdsp_rng *rng, const cdsp_image *img,
                             cdsp_profile_ws *pws, cdsp_result *out)
{
    cdsp_line lines[CDSP_MAX_LINES];
    const cdsp_line *L[2];
    int nlines = 0, i, j, profiled = 0;
    cdsp_real edge_offset[2] = {0, 0}, edge_blur[2] = {0, 0};
    pair_choice best;
    cdsp_result r;
    cdsp__axis ax;
    cdsp_status st;

    if (n < 4)
        return CDSP_E_FEW_POINTS;
    st = cdsp__lines_find(pts, n, label, &p->pair, R_COS(p->pair.normal_tol_deg * R_PI / R(180)),
                          rng, lines, &nlines);
    if (st != CDSP_OK)
        return st;
    if (nlines < 2)
        return CDSP_E_NO_PIPE;
    best.i = best.j = -1;
    best.score = R(0);
    for (i = 0; i < nlines; i++)
        for (j = i + 1; j < nlines; j++) {
            cdsp_real pin[2], sc = pair_score(cam, radius, &lines[i], &lines[j], &p->pair, pin);
            if (sc > best.score) {
                best.score = sc;
                best.i = i;
                best.j = j;
                best.p_in[0] = pin[0];
                best.p_in[1] = pin[1];
            }
        }
    if (best.i < 0)
        return CDSP_E_NO_PIPE;
    L[0] = &lines[best.i];
    L[1] = &lines[best.j];
    /* the edge-profile model moves each line to its modelled silhouette
     * (lib/profile.c); a contour it cannot model keeps the detector's line */
    if (img && pws && p->profile.enable) {
        for (i = 0; i < 2; i++) {
            cdsp_profile pr;
            cdsp_real moved = R(0);
            if (cdsp__profile_refine(img, cam, pts, n, label, (uint8_t)((i ? best.j : best.i) + 1),
                                     &lines[i ? best.j : best.i], best.p_in, &p->profile,
                                     p->edge.half_window, pws, &pr, &moved) == CDSP_OK) {
                edge_offset[i] = moved;
                edge_blur[i] = pr.blur;
                profiled++;
            }
        }
    }
    st = cdsp__axis_core(cam, L[0]->l, L[1]->l, best.p_in, radius, &ax);
    if (st != CDSP_OK)
        return st;
    zero_bytes(&r, sizeof r); /* no stale bytes, padding included, reach the caller */
    cdsp__axis_to_result(&ax, L[0]->l, L[1]->l, &r);
    r.rms[0] = L[0]->rms;
    r.rms[1] = L[1]->rms;
    r.inliers[0] = L[0]->count;
    r.inliers[1] = L[1]->count;
    r.label[0] = (uint8_t)(best.i + 1);
    r.label[1] = (uint8_t)(best.j + 1);
    r.n_edges = (uint32_t)n;
    r.flags = profiled == 2 ? CDSP_FLAG_PROFILE : 0u;
    for (i = 0; i < 2; i++) {
        r.edge_offset[i] = edge_offset[i];
        r.edge_blur[i] = edge_blur[i];
    }
    propagate(cam, radius, L, best.p_in, &r);
    visible_segment(cam, L, &r);
    if (prior ? v3_dot(r.direction, prior->direction) < R(0) : cdsp__axis_wants_swap(r.direction))
        cdsp__axis_swap(&r);
    *out = r;
    return CDSP_OK;
}

static int edges_finite(const cdsp_edge *e, size_t n)
{
    size_t i;
    for (i = 0; i < n; i++)
        if (!R_FINITE(e[i].x) || !R_FINITE(e[i].y) || !R_FINITE(e[i].gx) || !R_FINITE(e[i].gy))
            return 0;
    return 1;
}

cdsp_status cdsp__params_check(const cdsp_params *p)
{
    const cdsp_pair_params *q = &p->pair;
    if (!(q->inlier_px > R(0)) || !(q->normal_tol_deg > R(0)) || !(q->normal_tol_deg < R(90)) ||
        !(q->confidence > R(0)) || !(q->confidence < R(1)) || q->max_iterations < 1 ||
        q->max_lines < 2 || q->min_inliers < 2 || !(q->min_overlap >= R(0)) ||
        !(q->min_overlap <= R(1)) || !(q->max_contour_angle_deg > R(0)) ||
        !(q->max_contour_angle_deg < R(90)) || q->min_distance < R(0) || q->max_distance < R(0))
        return CDSP_E_ARG;
    if (!(p->track_band_px > R(0)) || p->track_min_inliers < 2 ||
        cdsp__profile_params_check(&p->profile) != CDSP_OK)
        return CDSP_E_ARG;
    return cdsp__edge_params_check(&p->edge);
}

cdsp_status cdsp__solve_args_check(const cdsp_camera *cam, cdsp_real radius, const cdsp_params *p)
{
    cdsp_status st = cdsp_camera_check(cam);
    if (st != CDSP_OK)
        return st;
    if (!R_FINITE(radius))
        return CDSP_E_NONFINITE;
    if (!(radius > R(0)) || radius > R(CDSP_MAX_RADIUS))
        return CDSP_E_ARG;
    return cdsp__params_check(p);
}

cdsp_status cdsp_params_check(const cdsp_params *p)
{
    return p ? cdsp__params_check(p) : CDSP_E_ARG;
}

cdsp_status cdsp_points_solve(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts,
                              size_t n, const cdsp_params *p, const cdsp_result *prior,
                              cdsp_points_ws *ws, cdsp_rng *rng, cdsp_result *out)
{
    cdsp_status st;
    if (!cam || !p || !ws || !rng || !out || (!pts && n))
        return CDSP_E_ARG;
    st = cdsp__solve_args_check(cam, radius, p);
    if (st != CDSP_OK)
        return st;
    if (n > CDSP_MAX_POINTS)
        return CDSP_E_CAPACITY;
    if (!edges_finite(pts, n))
        return CDSP_E_NONFINITE;
    return cdsp__pair_solve(cam, radius, pts, n, ws->label, p, prior, rng, NULL, NULL, out);
}

void cdsp_params_default(cdsp_params *p)
{
    cdsp_edge_params_default(&p->edge);
    cdsp_pair_params_default(&p->pair);
    p->track_band_px = R(12);
    p->track_min_inliers = 30;
    cdsp_profile_params_default(&p->profile);
}
