/*
 * axis.c - the closed form of the paper (Yao et al. 2024, Eq. 1-6) with the
 * orientation rule of docs/method.md §5:
 *   n_i = K^T l_i / |K^T l_i|, signs such that n1.X_in > 0 > n2.X_in;
 *   v_L = n1 x n2 / |n1 x n2|;  n_m = n1 + n2;
 *   alpha = atan2(|n1 x n2|, n1.n2)   (atan2: acos loses digits for small alpha);
 *   d = r / sin(alpha/2) = 2 r / |n1 - n2|;  u = v_L x n_m / |.|, n1.u > 0;  P_C = d u.
 * Then n1.P = +r and n2.P = -r for every axis point P.
 */
#include "internal.h"

static int normal_from_line(const cdsp_camera *cam, const cdsp_real l[3], cdsp_real n[3])
{
    /* K^T l for K = [[fx,0,cx],[0,fy,cy],[0,0,1]] */
    n[0] = cam->fx * l[0];
    n[1] = cam->fy * l[1];
    n[2] = cam->cx * l[0] + cam->cy * l[1] + l[2];
    return v3_normalize(n) > R(0);
}

/* The solve without the sign convention on v_L (lines keep the caller's
 * order). Shared with the uncertainty propagation in pair.c, which needs the
 * labelling to stay fixed while lines are perturbed. */
cdsp_status cdsp__axis_core(const cdsp_camera *cam, const cdsp_real l1[3], const cdsp_real l2[3],
                            const cdsp_real p_in[2], cdsp_real radius, cdsp__axis *out)
{
    cdsp_real n1[3], n2[3], X[3], c[3], nm[3], u[3], s1, s2, sn, cs, alpha, d, xin;
    int i;
    if (!normal_from_line(cam, l1, n1) || !normal_from_line(cam, l2, n2))
        return CDSP_E_DEGENERATE;
    cdsp_camera_ray(cam, p_in, X);
    xin = v3_norm(X);
    s1 = v3_dot(n1, X);
    s2 = v3_dot(n2, X);
    /* p_in must lie strictly between the lines, not on one (relative test:
     * the normals are unit, X has length xin). */
    if (R_FABS(s1) <= R(64) * R_EPS * xin || R_FABS(s2) <= R(64) * R_EPS * xin)
        return CDSP_E_DEGENERATE;
    if (s1 < R(0))
        v3_scale(n1, R(-1));
    if (s2 > R(0))
        v3_scale(n2, R(-1));
    v3_cross(n1, n2, c);
    sn = v3_norm(c);
    cs = v3_dot(n1, n2);
    /* Parallel back-projection planes: the two lines are one line (or the
     * axis points at the optical centre). The pose's relative error grows
     * as eps / alpha, so only a sine at the rounding level is refused. */
    if (sn <= R(64) * R_EPS)
        return CDSP_E_DEGENERATE;
    alpha = R_ATAN2(sn, cs);
    /* d = r / sin(alpha/2), with sin(alpha/2) = |n1 - n2| / 2 for unit normals:
     * as accurate as |n1 x n2| for small alpha, and no call to sin (whose
     * range reduction is the deepest stack in libm on MCUs). */
    {
        cdsp_real dx = n1[0] - n2[0], dy = n1[1] - n2[1], dz = n1[2] - n2[2];
        d = R(2) * radius / R_SQRT(dx * dx + dy * dy + dz * dz);
    }
    /* alpha -> pi: the optical centre on the pipe's surface or inside it. */
    if (!(d > radius * (R(1) + R(1e-6))) || !R_FINITE(d))
        return CDSP_E_DEGENERATE;
    v3_scale(c, R(1) / sn);
    for (i = 0; i < 3; i++)
        nm[i] = n1[i] + n2[i];
    v3_cross(c, nm, u);
    if (!(v3_normalize(u) > R(0)))
        return CDSP_E_DEGENERATE;
    if (v3_dot(n1, u) < R(0))
        v3_scale(u, R(-1));
    for (i = 0; i < 3; i++) {
        out->point[i] = d * u[i];
        out->direction[i] = c[i];
        out->normals[0][i] = n1[i];
        out->normals[1][i] = n2[i];
    }
    out->distance = d;
    out->alpha = alpha;
    return CDSP_OK;
}

/* Copy the closed form into a result (the caller zeroed it): the lines as
 * given, the segment collapsed onto P_C until extents are known. */
void cdsp__axis_to_result(const cdsp__axis *a, const cdsp_real l1[3], const cdsp_real l2[3],
                          cdsp_result *r)
{
    int i;
    for (i = 0; i < 3; i++) {
        r->point[i] = a->point[i];
        r->direction[i] = a->direction[i];
        r->normals[0][i] = a->normals[0][i];
        r->normals[1][i] = a->normals[1][i];
        r->lines[0][i] = l1[i];
        r->lines[1][i] = l2[i];
        r->segment[0][i] = r->segment[1][i] = a->point[i];
    }
    r->distance = a->distance;
    r->alpha = a->alpha;
}

/* Swap the roles of the two contours: n1' = -n2, n2' = -n1, so that
 * v_L' = n1' x n2' = -v_L while n1'.P = r and n2'.P = -r still hold. */
void cdsp__axis_swap(cdsp_result *r)
{
    int i;
    for (i = 0; i < 3; i++) {
        cdsp_real t = r->normals[0][i];
        r->normals[0][i] = -r->normals[1][i];
        r->normals[1][i] = -t;
        t = r->lines[0][i];
        r->lines[0][i] = r->lines[1][i];
        r->lines[1][i] = t;
        r->direction[i] = -r->direction[i];
        t = r->segment[0][i];
        r->segment[0][i] = r->segment[1][i];
        r->segment[1][i] = t;
    }
    {
        cdsp_real t = r->rms[0];
        uint32_t c = r->inliers[0];
        uint8_t lb = r->label[0];
        r->rms[0] = r->rms[1];
        r->rms[1] = t;
        r->inliers[0] = r->inliers[1];
        r->inliers[1] = c;
        r->label[0] = r->label[1];
        r->label[1] = lb;
        t = r->edge_offset[0];
        r->edge_offset[0] = r->edge_offset[1];
        r->edge_offset[1] = t;
        t = r->edge_blur[0];
        r->edge_blur[0] = r->edge_blur[1];
        r->edge_blur[1] = t;
        t = r->edge_bound[0];
        r->edge_bound[0] = r->edge_bound[1];
        r->edge_bound[1] = t;
    }
    /* cov(point, direction) changes sign with the direction; so do the
     * factor's direction rows, and its columns follow their contour */
    for (i = 0; i < 3; i++) {
        int j;
        for (j = 3; j < 6; j++) {
            r->cov[i][j] = -r->cov[i][j];
            r->cov[j][i] = -r->cov[j][i];
        }
    }
    for (i = 0; i < 6; i++) {
        int j;
        for (j = 0; j < 2; j++) {
            cdsp_real t = r->cov_factor[i][j];
            r->cov_factor[i][j] = r->cov_factor[i][j + 2];
            r->cov_factor[i][j + 2] = t;
        }
        if (i >= 3)
            for (j = 0; j < 4; j++)
                r->cov_factor[i][j] = -r->cov_factor[i][j];
    }
}

/* The sign rule of cdsp_result.direction without a prior. */
int cdsp__axis_wants_swap(const cdsp_real v[3])
{
    int k = 0;
    if (R_FABS(v[1]) > R_FABS(v[k]))
        k = 1;
    if (R_FABS(v[2]) > R_FABS(v[k]))
        k = 2;
    return v[k] < R(0);
}

cdsp_status cdsp_axis_solve(const cdsp_camera *cam, const cdsp_real l1[3], const cdsp_real l2[3],
                            const cdsp_real p_in[2], cdsp_real radius, cdsp_result *out)
{
    cdsp_result r;
    cdsp__axis a;
    cdsp_status st;
    if (!cam || !l1 || !l2 || !p_in || !out)
        return CDSP_E_ARG;
    st = cdsp_camera_check(cam);
    if (st != CDSP_OK)
        return st;
    if (!v3_finite(l1) || !v3_finite(l2) || !R_FINITE(p_in[0]) || !R_FINITE(p_in[1]) ||
        !R_FINITE(radius))
        return CDSP_E_NONFINITE;
    if (!(radius > R(0)) || radius > R(CDSP_MAX_RADIUS))
        return CDSP_E_ARG;
    st = cdsp__axis_core(cam, l1, l2, p_in, radius, &a);
    if (st != CDSP_OK)
        return st;
    zero_bytes(&r, sizeof r); /* zero uncertainty and counts, no stale padding */
    cdsp__axis_to_result(&a, l1, l2, &r);
    if (cdsp__axis_wants_swap(r.direction))
        cdsp__axis_swap(&r);
    *out = r;
    return CDSP_OK;
}

cdsp_real cdsp_result_point_distance(const cdsp_result *r, const cdsp_real X[3])
{
    cdsp_real d[3], c[3];
    d[0] = X[0] - r->point[0];
    d[1] = X[1] - r->point[1];
    d[2] = X[2] - r->point[2];
    v3_cross(d, r->direction, c);
    return v3_norm(c) / v3_norm(r->direction);
}
