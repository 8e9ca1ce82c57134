/*
 * camera.c - the pinhole + plumb_bob camera model (OpenCV/ROS convention,
 * docs/method.md §1): distortion in closed form, undistortion
 * by Newton's method with a residual measured in distorted pixels.
 */
#include "internal.h"

cdsp_status cdsp_camera_check(const cdsp_camera *cam)
{
    if (!cam)
        return CDSP_E_ARG;
    if (!R_FINITE(cam->fx) || !R_FINITE(cam->fy) || !R_FINITE(cam->cx) || !R_FINITE(cam->cy) ||
        !R_FINITE(cam->k1) || !R_FINITE(cam->k2) || !R_FINITE(cam->p1) || !R_FINITE(cam->p2) ||
        !R_FINITE(cam->k3))
        return CDSP_E_NONFINITE;
    if (!(cam->fx > R(0)) || !(cam->fy > R(0)) || cam->width <= 0 || cam->height <= 0)
        return CDSP_E_ARG;
    return CDSP_OK;
}

/* Normalized undistorted (x, y) -> normalized distorted, and optionally the
 * 2x2 Jacobian d(xd, yd)/d(x, y), row-major. */
static void distort_norm(const cdsp_camera *c, cdsp_real x, cdsp_real y, cdsp_real *xd,
                         cdsp_real *yd, cdsp_real J[4])
{
    cdsp_real r2 = x * x + y * y;
    cdsp_real radial = R(1) + r2 * (c->k1 + r2 * (c->k2 + r2 * c->k3));
    *xd = x * radial + R(2) * c->p1 * x * y + c->p2 * (r2 + R(2) * x * x);
    *yd = y * radial + c->p1 * (r2 + R(2) * y * y) + R(2) * c->p2 * x * y;
    if (J) {
        /* d(radial)/d(r2) */
        cdsp_real dr = c->k1 + r2 * (R(2) * c->k2 + R(3) * c->k3 * r2);
        J[0] = radial + R(2) * x * x * dr + R(2) * c->p1 * y + R(6) * c->p2 * x;
        J[1] = R(2) * x * y * dr + R(2) * c->p1 * x + R(2) * c->p2 * y;
        J[2] = J[1];
        J[3] = radial + R(2) * y * y * dr + R(6) * c->p1 * y + R(2) * c->p2 * x;
    }
}

cdsp_status cdsp_camera_distort(const cdsp_camera *cam, const cdsp_real und[2], cdsp_real dist[2])
{
    cdsp_real xd, yd;
    if (!cam || !und || !dist)
        return CDSP_E_ARG;
    if (!R_FINITE(und[0]) || !R_FINITE(und[1]))
        return CDSP_E_NONFINITE;
    distort_norm(cam, (und[0] - cam->cx) / cam->fx, (und[1] - cam->cy) / cam->fy, &xd, &yd, NULL);
    dist[0] = cam->fx * xd + cam->cx;
    dist[1] = cam->fy * yd + cam->cy;
    return (R_FINITE(dist[0]) && R_FINITE(dist[1])) ? CDSP_OK : CDSP_E_NONFINITE;
}

/* Newton on D(x) = xd*. Returns the status; x, y and the Jacobian at the
 * solution (for carrying gradients through) are written in every case. */
static cdsp_status undistort_norm(const cdsp_camera *c, cdsp_real xt, cdsp_real yt, cdsp_real *xo,
                                  cdsp_real *yo, cdsp_real J[4])
{
    cdsp_real x = xt, y = yt;
    int it;
    for (it = 0; it <= CDSP_UNDISTORT_MAX_ITER; it++) {
        cdsp_real xd, yd, fx_, fy_, det;
        distort_norm(c, x, y, &xd, &yd, J);
        fx_ = xd - xt;
        fy_ = yd - yt;
        /* residual in distorted pixels: the unit the tolerance is stated in */
        if (R_FABS(fx_) * c->fx <= R(CDSP_UNDISTORT_TOL_PX) &&
            R_FABS(fy_) * c->fy <= R(CDSP_UNDISTORT_TOL_PX)) {
            *xo = x;
            *yo = y;
            return CDSP_OK;
        }
        if (it == CDSP_UNDISTORT_MAX_ITER)
            break;
        det = J[0] * J[3] - J[1] * J[2];
        /* A non-positive Jacobian means the model folds over here (far
         * outside the calibrated field): no unique undistorted point. */
        if (!(det > R(1e-6)) || !R_FINITE(det))
            break;
        x -= (J[3] * fx_ - J[1] * fy_) / det;
        y -= (-J[2] * fx_ + J[0] * fy_) / det;
        if (!R_FINITE(x) || !R_FINITE(y))
            break;
    }
    *xo = x;
    *yo = y;
    return CDSP_E_NOCONVERGE;
}

cdsp_status cdsp_camera_undistort(const cdsp_camera *cam, const cdsp_real dist[2], cdsp_real und[2])
{
    cdsp_real x, y, J[4];
    cdsp_status s;
    if (!cam || !dist || !und)
        return CDSP_E_ARG;
    if (!R_FINITE(dist[0]) || !R_FINITE(dist[1]))
        return CDSP_E_NONFINITE;
    s = undistort_norm(cam, (dist[0] - cam->cx) / cam->fx, (dist[1] - cam->cy) / cam->fy, &x, &y, J);
    und[0] = cam->fx * x + cam->cx;
    und[1] = cam->fy * y + cam->cy;
    return s;
}

cdsp_status cdsp_camera_project(const cdsp_camera *cam, const cdsp_real X[3], cdsp_real pix[2])
{
    cdsp_real und[2];
    if (!cam || !X || !pix)
        return CDSP_E_ARG;
    if (!v3_finite(X))
        return CDSP_E_NONFINITE;
    if (!(X[2] > R(0)))
        return CDSP_E_DEGENERATE;
    und[0] = cam->fx * X[0] / X[2] + cam->cx;
    und[1] = cam->fy * X[1] / X[2] + cam->cy;
    return cdsp_camera_distort(cam, und, pix);
}

void cdsp_camera_ray(const cdsp_camera *cam, const cdsp_real und[2], cdsp_real ray[3])
{
    ray[0] = (und[0] - cam->cx) / cam->fx;
    ray[1] = (und[1] - cam->cy) / cam->fy;
    ray[2] = R(1);
}

/* Whether the camera has no distortion (every coefficient zero; the
 * paper's camera, rectified frames). Then distort_norm is the identity in
 * floating point, not only in exact arithmetic: radial = 1 + r2 * 0 = 1
 * and every other term is a product with a zero coefficient, so
 * xd = x * 1 + 0 + 0 = x (finite x, y); the Jacobian is the identity; and
 * Newton's first residual is 0, so undistort_norm returns its start. The
 * fast forms below use exactly the arithmetic that remains: the same
 * numbers, without the polynomial and the iteration (internal.h). */
int cdsp__camera_no_distortion(const cdsp_camera *c)
{
    return c->k1 == R(0) && c->k2 == R(0) && c->k3 == R(0) && c->p1 == R(0) && c->p2 == R(0);
}

cdsp_status cdsp_camera_undistort_edges(const cdsp_camera *cam, cdsp_edge *e, size_t *n)
{
    size_t i, k = 0;
    if (!cam || !n || (!e && *n))
        return CDSP_E_ARG;
    if (cdsp__camera_no_distortion(cam)) {
        /* und = f * ((d - c) / f) + c, what undistort_norm's start gives
         * back through the pixel map; the gradient is unchanged (identity
         * Jacobian: len1 = len0). An edge the general path drops is
         * dropped: a non-finite start, or r2 (or the 2 x^2 of the p2
         * term) overflowing, where the polynomial gives NaN and no
         * residual is within the tolerance. */
        for (i = 0; i < *n; i++) {
            cdsp_real x = (e[i].x - cam->cx) / cam->fx, y = (e[i].y - cam->cy) / cam->fy;
            if (!R_FINITE(R(3) * (x * x + y * y)))
                continue;
            e[k].x = cam->fx * x + cam->cx;
            e[k].y = cam->fy * y + cam->cy;
            e[k].gx = e[i].gx;
            e[k].gy = e[i].gy;
            k++;
        }
        *n = k;
        return CDSP_OK;
    }
    for (i = 0; i < *n; i++) {
        cdsp_real x, y, J[4], gx, gy, g0, g1, len0, len1;
        if (undistort_norm(cam, (e[i].x - cam->cx) / cam->fx, (e[i].y - cam->cy) / cam->fy, &x, &y,
                           J) != CDSP_OK)
            continue;
        /* Curve normals map by the transpose of the pixel Jacobian
         * Jp = diag(fx,fy) J diag(1/fx,1/fy): (Jp^T n) . t_u = n . (Jp t_u) = 0. */
        g0 = e[i].gx;
        g1 = e[i].gy;
        gx = J[0] * g0 + J[2] * (cam->fy / cam->fx) * g1;
        gy = J[1] * (cam->fx / cam->fy) * g0 + J[3] * g1;
        len0 = R_SQRT(g0 * g0 + g1 * g1);
        len1 = R_SQRT(gx * gx + gy * gy);
        if (len1 > R(0)) {
            gx *= len0 / len1;
            gy *= len0 / len1;
        }
        e[k].x = cam->fx * x + cam->cx;
        e[k].y = cam->fy * y + cam->cy;
        e[k].gx = gx;
        e[k].gy = gy;
        k++;
    }
    *n = k;
    return CDSP_OK;
}
