/*
 * render.c - simulated frames of a finite cylinder of known pose, for tests,
 * tools and the daemon's simulated camera.
 *
 * Geometry is exact: every pixel's centre is undistorted (Newton, warm-started
 * from its left neighbour) and its ray is cast against the pipe, its end caps
 * and the clutter bars (also cylinders). Anti-aliasing:
 * - along the pipe's two long contours, exact area coverage: the contour is
 *   a straight line within a pixel, so the covered fraction of the pixel is
 *   the area of a unit square cut by a half-plane (closed form below), with
 *   the line's position and normal carried into the distorted frame by the
 *   local Jacobian of the distortion;
 * - elsewhere, where probes half a pixel away see a different surface (end
 *   caps, clutter), 4 x 4 supersampling.
 * Then optional Gaussian blur (separable, in the caller's float scratch),
 * optional linear motion blur (a box along the motion vector), Gaussian
 * sensor noise from the caller's PCG32, and rounding to 8 or 16 bit.
 * Options added later (background ramp, specular highlight, motion blur)
 * are skipped entirely when zero, so older scenes render bit-identically.
 */
#include "internal.h"

enum { HIT_NONE = 0, HIT_BODY = 1, HIT_CAP = 2, HIT_CLUTTER = 3 };

void cdsp_scene_default(cdsp_scene *s)
{
    int i;
    s->axis_point[0] = R(0);
    s->axis_point[1] = R(0);
    s->axis_point[2] = R(400);
    s->axis_dir[0] = R(0.2);
    s->axis_dir[1] = R(1);
    s->axis_dir[2] = R(0.1);
    s->radius = R(8);
    s->half_length = R(0);
    s->pipe_level = R(0.7);
    s->cap_level = R(0.5);
    s->background_level = R(0.25);
    s->light[0] = R(0.3);
    s->light[1] = R(-0.6);
    s->light[2] = R(-0.75);
    s->ambient = R(0.85);
    s->texture = R(0.03);
    s->texture_scale_px = R(40);
    s->blur_sigma_px = R(0.7);
    s->noise_sigma = R(0.004);
    s->n_clutter = 0;
    for (i = 0; i < CDSP_RENDER_MAX_CLUTTER; i++) {
        int k;
        for (k = 0; k < 3; k++)
            s->clutter[i].p0[k] = s->clutter[i].p1[k] = R(0);
        s->clutter[i].half_width = R(0);
        s->clutter[i].level = R(0);
    }
    s->texture_seed = 1u;
    s->background_ramp[0] = s->background_ramp[1] = R(0);
    s->specular = R(0);
    s->specular_exp = R(0);
    s->motion_px[0] = s->motion_px[1] = R(0);
    s->n_extra_pipes = 0;
    for (i = 0; i < CDSP_RENDER_MAX_PIPES - 1; i++) {
        int k;
        for (k = 0; k < 3; k++)
            s->extra_pipe[i].axis_point[k] = s->extra_pipe[i].axis_dir[k] = R(0);
        s->extra_pipe[i].radius = s->extra_pipe[i].half_length = R(0);
    }
}

/* ---- the exact contours (ground truth and the renderer's anti-aliasing) - */

/* Tangent planes through the optical centre: with P the foot of the axis
 * from O (d = |P| > r), e1 = P/d, e2 = v x e1, the normals
 * n = (r/d) e1 +- sqrt(1 - r^2/d^2) e2 satisfy n.v = 0 and n.P = r. */
static cdsp_status contour_planes(const cdsp_real P0[3], const cdsp_real dir[3], cdsp_real r,
                                  cdsp_real n[2][3], cdsp_real foot[3])
{
    cdsp_real v[3] = {dir[0], dir[1], dir[2]}, e1[3], e2[3], d, c, s, t;
    int i;
    if (!(v3_normalize(v) > R(0)))
        return CDSP_E_ARG;
    t = v3_dot(P0, v);
    for (i = 0; i < 3; i++)
        foot[i] = P0[i] - t * v[i];
    d = v3_norm(foot);
    if (!(d > r))
        return CDSP_E_DEGENERATE;
    for (i = 0; i < 3; i++)
        e1[i] = foot[i] / d;
    v3_cross(v, e1, e2);
    c = r / d;
    s = R_SQRT(R(1) - c * c);
    for (i = 0; i < 3; i++) {
        n[0][i] = c * e1[i] + s * e2[i];
        n[1][i] = c * e1[i] - s * e2[i];
    }
    return CDSP_OK;
}

/* Image line of the plane n.X = 0: l = K^-T n, scaled to a^2 + b^2 = 1
 * (positive scale: l.p > 0 exactly where n.X > 0). */
static int plane_line(const cdsp_camera *cam, const cdsp_real n[3], cdsp_real l[3])
{
    cdsp_real a = n[0] / cam->fx, b = n[1] / cam->fy, len = R_SQRT(a * a + b * b);
    if (!(len > R(0)))
        return 0;
    l[0] = a / len;
    l[1] = b / len;
    l[2] = (n[2] - cam->cx * n[0] / cam->fx - cam->cy * n[1] / cam->fy) / len;
    return 1;
}

cdsp_status cdsp_cylinder_contours(const cdsp_camera *cam, const cdsp_real axis_point[3],
                                   const cdsp_real axis_dir[3], cdsp_real radius, int pipe_brighter,
                                   cdsp_real l1[3], cdsp_real l2[3], cdsp_real p_in[2])
{
    cdsp_real n[2][3], foot[3], v[3], X[3];
    cdsp_status st;
    int i;
    if (!cam || !axis_point || !axis_dir || !l1 || !l2 || !p_in)
        return CDSP_E_ARG;
    st = cdsp_camera_check(cam); /* fuzzing: an infinite fx gave CDSP_OK and Inf */
    if (st != CDSP_OK)
        return st;
    if (!v3_finite(axis_point) || !v3_finite(axis_dir) || !R_FINITE(radius))
        return CDSP_E_NONFINITE;
    if (!(radius > R(0)))
        return CDSP_E_ARG;
    st = contour_planes(axis_point, axis_dir, radius, n, foot);
    if (st != CDSP_OK)
        return st;
    if (!plane_line(cam, n[0], l1) || !plane_line(cam, n[1], l2))
        return CDSP_E_DEGENERATE;
    if (!pipe_brighter)
        for (i = 0; i < 3; i++) {
            l1[i] = -l1[i];
            l2[i] = -l2[i];
        }
    /* a pixel on the pipe: the image of an axis point in front of the camera */
    for (i = 0; i < 3; i++)
        v[i] = axis_dir[i];
    v3_normalize(v);
    for (i = 0; i < 3; i++)
        X[i] = foot[i];
    if (!(X[2] > R(0))) {
        /* the foot is behind: walk along the axis toward +Z */
        cdsp_real step;
        if (R_FABS(v[2]) < R(1e-6))
            return CDSP_E_DEGENERATE;
        step = (R(1) - foot[2]) / v[2] + radius;
        for (i = 0; i < 3; i++)
            X[i] = foot[i] + step * v[i];
        if (!(X[2] > R(0)))
            return CDSP_E_DEGENERATE;
    }
    p_in[0] = cam->fx * X[0] / X[2] + cam->cx;
    p_in[1] = cam->fy * X[1] / X[2] + cam->cy;
    /* a pipe grazing the camera's plane projects beyond the reals */
    if (!v3_finite(l1) || !v3_finite(l2) || !R_FINITE(p_in[0]) || !R_FINITE(p_in[1]))
        return CDSP_E_DEGENERATE;
    return CDSP_OK;
}

/* ---- ray casting ------------------------------------------------------- */

typedef struct {
    cdsp_real p0[3];  /* centre of the cylinder */
    cdsp_real v[3];   /* unit axis */
    cdsp_real r, half; /* radius, half length (0: infinite) */
} cyl;

/* One pipe of the scene with its exact contours. */
typedef struct {
    cyl c;
    cdsp_real n[2][3];   /* contour planes of the pipe (pipe side positive) */
    cdsp_real l[2][3];   /* their image lines (undistorted px) */
    int have_contours;
} pipe_geo;

typedef struct {
    const cdsp_scene *s;
    const cdsp_camera *cam;
    pipe_geo pipes[CDSP_RENDER_MAX_PIPES]; /* the scene's pipe first, then extra_pipe[] */
    int npipes;
    cyl bars[CDSP_RENDER_MAX_CLUTTER];
    int nbars;
    cdsp_real light[3];
    cdsp_real full;      /* full scale of the output */
} ctx;

/* Nearest hit t > 0 of ray t*D on a capped cylinder; *kind body or cap,
 * *ax the hit's axial parameter, hit point in X. */
static int cyl_hit(const cyl *c, const cdsp_real D[3], cdsp_real *t_out, int *kind, cdsp_real X[3])
{
    cdsp_real w[3], Dp[3], wp[3], dv = v3_dot(D, c->v), wv, a, b, cc, disc, best = R_MAX, t;
    int i, found = 0;
    for (i = 0; i < 3; i++)
        w[i] = -c->p0[i];
    wv = v3_dot(w, c->v);
    for (i = 0; i < 3; i++) {
        Dp[i] = D[i] - dv * c->v[i];
        wp[i] = w[i] - wv * c->v[i];
    }
    a = v3_dot(Dp, Dp);
    b = R(2) * v3_dot(Dp, wp);
    cc = v3_dot(wp, wp) - c->r * c->r;
    disc = b * b - R(4) * a * cc;
    if (a > R(0) && disc >= R(0)) {
        t = (-b - R_SQRT(disc)) / (R(2) * a);
        if (t > R(0)) {
            cdsp_real ax = t * dv + wv; /* (tD - p0).v */
            if (c->half <= R(0) || R_FABS(ax) <= c->half) {
                best = t;
                *kind = HIT_BODY;
                found = 1;
            }
        }
    }
    if (c->half > R(0) && R_FABS(dv) > R(0)) {
        int e;
        for (e = -1; e <= 1; e += 2) {
            /* plane (X - p0).v = e*half */
            t = ((cdsp_real)e * c->half - wv) / dv;
            if (t > R(0) && t < best) {
                cdsp_real q[3], qa, q2;
                for (i = 0; i < 3; i++)
                    q[i] = t * D[i] - c->p0[i];
                qa = v3_dot(q, c->v);
                q2 = v3_dot(q, q) - qa * qa;
                if (q2 <= c->r * c->r) {
                    best = t;
                    *kind = HIT_CAP;
                    found = 1;
                }
            }
        }
    }
    if (found) {
        *t_out = best;
        for (i = 0; i < 3; i++)
            X[i] = best * D[i];
    }
    return found;
}

/* Smooth value noise in [-1, 1] (hash lattice, smoothstep interpolation). */
static cdsp_real lattice(uint32_t seed, int32_t x, int32_t y)
{
    uint32_t h = seed ^ ((uint32_t)x * 0x8da6b343u) ^ ((uint32_t)y * 0xd8163841u);
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return (cdsp_real)(h & 0xffffu) / R(32767.5) - R(1);
}

static cdsp_real value_noise(uint32_t seed, cdsp_real x, cdsp_real y)
{
    cdsp_real fx = R_FLOOR(x), fy = R_FLOOR(y), tx = x - fx, ty = y - fy, a, b, c, d;
    int32_t ix, iy;
    /* cells beyond +-1e9 (a tiny texture_scale_px) are flat: the lattice
     * index must fit an int32 */
    if (!(R_FABS(fx) < R(1e9)) || !(R_FABS(fy) < R(1e9)))
        return R(0);
    ix = (int32_t)fx;
    iy = (int32_t)fy;
    tx = tx * tx * (R(3) - R(2) * tx);
    ty = ty * ty * (R(3) - R(2) * ty);
    a = lattice(seed, ix, iy);
    b = lattice(seed, ix + 1, iy);
    c = lattice(seed, ix, iy + 1);
    d = lattice(seed, ix + 1, iy + 1);
    return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

static cdsp_real background(const ctx *k, cdsp_real u, cdsp_real v)
{
    const cdsp_scene *s = k->s;
    cdsp_real val = s->background_level;
    if (s->texture > R(0) && s->texture_scale_px > R(0)) {
        cdsp_real sc = s->texture_scale_px;
        val += s->texture * (R(0.7) * value_noise(s->texture_seed, u / sc, v / sc) +
                             R(0.3) * value_noise(s->texture_seed + 7u, u * R(2.7) / sc,
                                                  v * R(2.7) / sc));
    }
    if (s->background_ramp[0] != R(0) || s->background_ramp[1] != R(0))
        val += s->background_ramp[0] * (u - k->cam->cx) + s->background_ramp[1] * (v - k->cam->cy);
    return val;
}

static cdsp_real shade(const ctx *k, const cdsp_real normal[3])
{
    cdsp_real c = v3_dot(normal, k->light);
    return k->s->ambient + (R(1) - k->s->ambient) * (c > R(0) ? c : R(0));
}

/* Blinn-Phong highlight at surface point X with unit normal nrm: the half
 * vector between the light and the view direction -X/|X| (Blinn 1977); a
 * stripe along a cylinder where n.h peaks. */
static cdsp_real highlight(const ctx *k, const cdsp_real X[3], const cdsp_real nrm[3])
{
    cdsp_real h[3], c;
    int i;
    cdsp_real xl = v3_norm(X);
    if (!(xl > R(0)))
        return R(0);
    for (i = 0; i < 3; i++)
        h[i] = k->light[i] - X[i] / xl;
    if (!(v3_normalize(h) > R(0)))
        return R(0);
    c = v3_dot(nrm, h);
    if (!(c > R(0)))
        return R(0);
    return k->s->specular * R_EXP(k->s->specular_exp * R_LOG(c));
}

/* Intensity (fraction of full scale) seen along the ray through undistorted
 * pixel q, which surface it is, and (body or cap) which pipe. */
static cdsp_real cast(const ctx *k, const cdsp_real q[2], int *what, int *which)
{
    cdsp_real D[3], t, best = R_MAX, X[3], val = R(0);
    int kind, i, b, pi;
    cdsp_camera_ray(k->cam, q, D);
    *what = HIT_NONE;
    *which = -1;
    for (pi = 0; pi < k->npipes; pi++) {
        const cyl *c = &k->pipes[pi].c;
        cdsp_real rel[3], ax, nrm[3];
        if (!cyl_hit(c, D, &t, &kind, X) || !(t < best))
            continue;
        best = t;
        for (i = 0; i < 3; i++)
            rel[i] = X[i] - c->p0[i];
        ax = v3_dot(rel, c->v);
        if (kind == HIT_BODY) {
            for (i = 0; i < 3; i++)
                nrm[i] = (rel[i] - ax * c->v[i]) / c->r;
            val = k->s->pipe_level * shade(k, nrm);
            if (k->s->specular > R(0))
                val += highlight(k, X, nrm);
        } else {
            for (i = 0; i < 3; i++)
                nrm[i] = ax > R(0) ? c->v[i] : -c->v[i];
            val = k->s->cap_level * shade(k, nrm);
        }
        *what = kind;
        *which = pi;
    }
    for (b = 0; b < k->nbars; b++) {
        if (cyl_hit(&k->bars[b], D, &t, &kind, X) && t < best) {
            best = t;
            val = k->s->clutter[b].level;
            *what = HIT_CLUTTER + b;
            *which = -1;
        }
    }
    if (*what == HIT_NONE)
        val = background(k, q[0], q[1]);
    return val;
}

/* Area of the unit pixel on the positive side of a line at signed distance
 * s from its centre with unit normal (nx, ny): with a >= b the absolute
 * normal components, the profile is linear for |s| <= (a-b)/2 and quadratic
 * in the corners up to (a+b)/2. */
static cdsp_real coverage(cdsp_real s, cdsp_real nx, cdsp_real ny)
{
    cdsp_real a = R_FABS(nx), b = R_FABS(ny), w1, w2;
    if (b > a) {
        cdsp_real t = a;
        a = b;
        b = t;
    }
    w1 = (a - b) / R(2);
    w2 = (a + b) / R(2);
    if (s >= w2)
        return R(1);
    if (s <= -w2)
        return R(0);
    if (s >= -w1 && s <= w1)
        return R(0.5) + s / a;
    if (s > w1)
        return R(1) - (w2 - s) * (w2 - s) / (R(2) * a * b);
    return (w2 + s) * (w2 + s) / (R(2) * a * b);
}

/* Pixel value (fraction of full scale) of the pixel whose undistorted
 * centre is q, with pixel Jacobian Jp = d(dist)/d(und) there. */
static cdsp_real pixel(const ctx *k, const cdsp_real q[2], const cdsp_real Jp[4])
{
    cdsp_real Ju[4], det = Jp[0] * Jp[3] - Jp[1] * Jp[2], val, probe[2];
    int what, which, pw, pwh, same = 1, i, pi, near = 0;
    static const cdsp_real off[4][2] = {{-0.5, 0}, {0.5, 0}, {0, -0.5}, {0, 0.5}};
    /* Ju = Jp^-1 maps distorted offsets to undistorted ones */
    Ju[0] = Jp[3] / det;
    Ju[1] = -Jp[1] / det;
    Ju[2] = -Jp[2] / det;
    Ju[3] = Jp[0] / det;
    val = cast(k, q, &what, &which);

    /* Near a long contour of a pipe and away from its ends: exact coverage
     * (the first contour within a pixel decides; a rack's pipes are never
     * within a pixel of each other's contours where this applies). */
    for (pi = 0; pi < k->npipes && !near; pi++) {
        const pipe_geo *g = &k->pipes[pi];
        int c;
        if (!g->have_contours || what == HIT_CAP || what >= HIT_CLUTTER ||
            (what == HIT_BODY && which != pi))
            continue;
        for (c = 0; c < 2; c++) {
            const cdsp_real *l = g->l[c];
            /* gradient of l.und(p) in distorted px: Ju^T (a, b) */
            cdsp_real gx = Ju[0] * l[0] + Ju[2] * l[1], gy = Ju[1] * l[0] + Ju[3] * l[1];
            cdsp_real gl = R_SQRT(gx * gx + gy * gy);
            cdsp_real sd = (l[0] * q[0] + l[1] * q[1] + l[2]) / gl;
            if (R_FABS(sd) < R(1)) {
                /* the limb point's axial position must be well inside the pipe */
                cdsp_real D[3], rel[3], Dv, ax, tnear, lim[3], cov, body, outside;
                int ok = 1, w2;
                near = 1;
                cdsp_camera_ray(k->cam, q, D);
                Dv = v3_dot(D, g->c.v);
                /* closest approach of the ray to the axis */
                {
                    cdsp_real wv = -v3_dot(g->c.p0, g->c.v), a = v3_dot(D, D);
                    cdsp_real bb = Dv, dd = -v3_dot(D, g->c.p0), den = a - bb * bb;
                    tnear = den > R(0) ? (bb * wv - dd) / den : R(0);
                    for (i = 0; i < 3; i++)
                        rel[i] = tnear * D[i] - g->c.p0[i];
                    ax = v3_dot(rel, g->c.v);
                }
                if (g->c.half > R(0)) {
                    /* a pixel's footprint at that depth, plus the radius (the
                     * cap's outline reaches r beyond the end along the view) */
                    cdsp_real foot = R(4) * tnear / (k->cam->fx < k->cam->fy ? k->cam->fx : k->cam->fy);
                    if (R_FABS(ax) > g->c.half - g->c.r - foot)
                        ok = 0;
                }
                /* clutter, a cap or another pipe in front of or behind the
                 * limb: leave it to supersampling */
                for (w2 = 0; ok && w2 < 4; w2++) {
                    int pk, pkh;
                    probe[0] = q[0] + Ju[0] * off[w2][0] + Ju[1] * off[w2][1];
                    probe[1] = q[1] + Ju[2] * off[w2][0] + Ju[3] * off[w2][1];
                    (void)cast(k, probe, &pk, &pkh);
                    if (pk >= HIT_CLUTTER || pk == HIT_CAP || (pk == HIT_BODY && pkh != pi))
                        ok = 0;
                }
                if (ok) {
                    /* The pipe's part of the pixel: its mean intensity, not
                     * the limb's. Shading near a limb changes like the square
                     * root of the distance from it, so the covered span
                     * [-sd, w2] along the inward normal (u, in distorted px)
                     * is integrated by 4-point Gauss-Legendre, one ray each. */
                    static const cdsp_real gx4[4] = {-0.8611363115940526, -0.3399810435848563,
                                                     0.3399810435848563, 0.8611363115940526};
                    static const cdsp_real gw4[4] = {0.3478548451374538, 0.6521451548625461,
                                                     0.6521451548625461, 0.3478548451374538};
                    cdsp_real ux = gx / gl, uy = gy / gl, half = (R_FABS(ux) + R_FABS(uy)) / R(2);
                    cdsp_real t0 = -sd > -half ? -sd : -half, t1 = half, acc = R(0);
                    int gq;
                    for (i = 0; i < 3; i++)
                        lim[i] = -g->n[c][i]; /* outward normal at the limb */
                    body = k->s->pipe_level * shade(k, lim);
                    for (gq = 0; gq < 4; gq++) {
                        cdsp_real tt = (t0 + t1) / R(2) + (t1 - t0) / R(2) * gx4[gq], pk[2], val_g;
                        int hit, hw;
                        pk[0] = q[0] + Ju[0] * tt * ux + Ju[1] * tt * uy;
                        pk[1] = q[1] + Ju[2] * tt * ux + Ju[3] * tt * uy;
                        val_g = cast(k, pk, &hit, &hw);
                        /* a node a hair outside the limb misses: the limb's value */
                        acc += gw4[gq] * (hit == HIT_BODY && hw == pi ? val_g : body);
                    }
                    body = acc / R(2);
                    outside = background(k, q[0], q[1]);
                    cov = coverage(sd, ux, uy);
                    return outside + (body - outside) * cov;
                }
                break;
            }
        }
    }
    /* Elsewhere: supersample where the surface changes within the pixel. */
    for (i = 0; i < 4 && same; i++) {
        probe[0] = q[0] + Ju[0] * off[i][0] + Ju[1] * off[i][1];
        probe[1] = q[1] + Ju[2] * off[i][0] + Ju[3] * off[i][1];
        (void)cast(k, probe, &pw, &pwh);
        same = pw == what && pwh == which;
    }
    if (!same) {
        cdsp_real sum = R(0);
        int a, b;
        for (a = 0; a < 4; a++)
            for (b = 0; b < 4; b++) {
                cdsp_real du = (R(a) + R(0.5)) / R(4) - R(0.5), dv = (R(b) + R(0.5)) / R(4) - R(0.5);
                probe[0] = q[0] + Ju[0] * du + Ju[1] * dv;
                probe[1] = q[1] + Ju[2] * du + Ju[3] * dv;
                sum += cast(k, probe, &pw, &pwh);
            }
        val = sum / R(16);
    }
    return val;
}

size_t cdsp_render_scratch_size(int width, int height)
{
    if (width <= 0 || height <= 0)
        return 0;
    return 2 * (size_t)width * (size_t)height + (size_t)(width > height ? width : height);
}

/* Newton undistortion of pixel (u, v) from the initial guess q (in/out) and
 * the pixel Jacobian at the result. */
static int undistort_px(const cdsp_camera *c, cdsp_real u, cdsp_real v, cdsp_real q[2],
                        cdsp_real Jp[4])
{
    int it;
    for (it = 0; it < CDSP_UNDISTORT_MAX_ITER; it++) {
        cdsp_real x = (q[0] - c->cx) / c->fx, y = (q[1] - c->cy) / c->fy;
        cdsp_real r2 = x * x + y * y, radial = R(1) + r2 * (c->k1 + r2 * (c->k2 + r2 * c->k3));
        cdsp_real dr = c->k1 + r2 * (R(2) * c->k2 + R(3) * c->k3 * r2);
        cdsp_real xd = x * radial + R(2) * c->p1 * x * y + c->p2 * (r2 + R(2) * x * x);
        cdsp_real yd = y * radial + c->p1 * (r2 + R(2) * y * y) + R(2) * c->p2 * x * y;
        cdsp_real J0 = radial + R(2) * x * x * dr + R(2) * c->p1 * y + R(6) * c->p2 * x;
        cdsp_real J1 = R(2) * x * y * dr + R(2) * c->p1 * x + R(2) * c->p2 * y;
        cdsp_real J3 = radial + R(2) * y * y * dr + R(6) * c->p1 * y + R(2) * c->p2 * x;
        cdsp_real ex = c->fx * xd + c->cx - u, ey = c->fy * yd + c->cy - v, det;
        /* pixel Jacobian: diag(f) J diag(1/f) */
        Jp[0] = J0;
        Jp[1] = J1 * c->fx / c->fy;
        Jp[2] = J1 * c->fy / c->fx;
        Jp[3] = J3;
        if (R_FABS(ex) <= R(CDSP_UNDISTORT_TOL_PX) && R_FABS(ey) <= R(CDSP_UNDISTORT_TOL_PX))
            return 1;
        det = Jp[0] * Jp[3] - Jp[1] * Jp[2];
        if (!(det > R(1e-6)))
            return 0;
        q[0] -= (Jp[3] * ex - Jp[1] * ey) / det;
        q[1] -= (-Jp[2] * ex + Jp[0] * ey) / det;
    }
    return 0;
}

static void blur_line(float *data, size_t n, size_t stride, const float *kern, int rad, float *tmp)
{
    size_t i;
    for (i = 0; i < n; i++)
        tmp[i] = data[i * stride];
    for (i = 0; i < n; i++) {
        float acc = 0.0f;
        int j;
        for (j = -rad; j <= rad; j++) {
            long idx = (long)i + j;
            if (idx < 0)
                idx = 0; /* clamp: replicate the border */
            if (idx >= (long)n)
                idx = (long)n - 1;
            acc += kern[j + rad] * tmp[idx];
        }
        data[i * stride] = acc;
    }
}

/* One output pixel: sensor noise, rounding to the output's levels, clamping. */
static void store(const cdsp_scene *s, cdsp_rng *rng, cdsp_real val, cdsp_real full, void *out,
                  size_t stride, size_t bpp, int x, int y)
{
    long qv;
    if (s->noise_sigma > R(0))
        val += s->noise_sigma * cdsp_rng_normal(rng);
    /* clamp before the conversion: a level far outside [0, 1] (or noise on
     * it) must not reach (long) out of its range */
    if (!(val > R(0)))
        qv = 0;
    else if (val >= R(1))
        qv = (long)full;
    else
        qv = (long)(val * full + R(0.5));
    if (bpp == 1)
        ((unsigned char *)out)[(size_t)y * stride + (size_t)x] = (unsigned char)qv;
    else
        ((uint16_t *)(void *)((unsigned char *)out + (size_t)y * stride))[x] = (uint16_t)qv;
}

#define RENDER_MAX_KERNEL 25 /* radius: 3 sigma up to sigma = CDSP_RENDER_MAX_BLUR_PX */

/* Every real of the scene is finite (the header's CDSP_E_NONFINITE). */
static int scene_finite(const cdsp_scene *s)
{
    int i;
    if (!v3_finite(s->axis_point) || !v3_finite(s->axis_dir) || !v3_finite(s->light) ||
        !R_FINITE(s->radius) || !R_FINITE(s->half_length) || !R_FINITE(s->pipe_level) ||
        !R_FINITE(s->cap_level) || !R_FINITE(s->background_level) || !R_FINITE(s->ambient) ||
        !R_FINITE(s->texture) || !R_FINITE(s->texture_scale_px) || !R_FINITE(s->blur_sigma_px) ||
        !R_FINITE(s->noise_sigma) || !R_FINITE(s->background_ramp[0]) ||
        !R_FINITE(s->background_ramp[1]) || !R_FINITE(s->specular) ||
        !R_FINITE(s->specular_exp) || !R_FINITE(s->motion_px[0]) || !R_FINITE(s->motion_px[1]))
        return 0;
    for (i = 0; i < s->n_extra_pipes && i < CDSP_RENDER_MAX_PIPES - 1; i++) {
        const cdsp_scene_pipe *e = &s->extra_pipe[i];
        if (!v3_finite(e->axis_point) || !v3_finite(e->axis_dir) || !R_FINITE(e->radius) ||
            !R_FINITE(e->half_length))
            return 0;
    }
    for (i = 0; i < s->n_clutter && i < CDSP_RENDER_MAX_CLUTTER; i++) {
        const cdsp_clutter *c = &s->clutter[i];
        if (!v3_finite(c->p0) || !v3_finite(c->p1) || !R_FINITE(c->half_width) ||
            !R_FINITE(c->level))
            return 0;
    }
    return 1;
}

/* Bilinear sample of a W x H float frame at (x, y), borders replicated. */
static float bilinear(const float *f, int W, int H, cdsp_real x, cdsp_real y)
{
    cdsp_real fx, fy, tx, ty;
    int x0, y0, x1, y1;
    if (x < R(0))
        x = R(0);
    if (y < R(0))
        y = R(0);
    if (x > (cdsp_real)(W - 1))
        x = (cdsp_real)(W - 1);
    if (y > (cdsp_real)(H - 1))
        y = (cdsp_real)(H - 1);
    fx = R_FLOOR(x);
    fy = R_FLOOR(y);
    tx = x - fx;
    ty = y - fy;
    x0 = (int)fx;
    y0 = (int)fy;
    x1 = x0 + 1 < W ? x0 + 1 : x0;
    y1 = y0 + 1 < H ? y0 + 1 : y0;
    return (float)((R(1) - ty) * ((R(1) - tx) * (cdsp_real)f[(size_t)y0 * (size_t)W + (size_t)x0] +
                                  tx * (cdsp_real)f[(size_t)y0 * (size_t)W + (size_t)x1]) +
                   ty * ((R(1) - tx) * (cdsp_real)f[(size_t)y1 * (size_t)W + (size_t)x0] +
                         tx * (cdsp_real)f[(size_t)y1 * (size_t)W + (size_t)x1]));
}

/* Linear motion blur: each pixel the mean of the frame over the segment
 * +-motion/2 through it (a box exposure), sampled at N points spaced at
 * most half a pixel apart (midpoint rule), from src into dst. */
static void motion_blur(const float *src, float *dst, int W, int H, const cdsp_real m[2])
{
    cdsp_real len = R_SQRT(m[0] * m[0] + m[1] * m[1]);
    int n = (int)R_CEIL(R(2) * len), x, y, i;
    if (n < 2)
        n = 2;
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++) {
            cdsp_real acc = R(0);
            for (i = 0; i < n; i++) {
                cdsp_real t = ((cdsp_real)i + R(0.5)) / (cdsp_real)n - R(0.5);
                acc += (cdsp_real)bilinear(src, W, H, (cdsp_real)x + t * m[0], (cdsp_real)y + t * m[1]);
            }
            dst[(size_t)y * (size_t)W + (size_t)x] = (float)(acc / (cdsp_real)n);
        }
}

cdsp_status cdsp_render(const cdsp_scene *s, const cdsp_camera *cam, void *out, size_t stride,
                        int out_bits, float *scratch, size_t scratch_len, cdsp_rng *rng)
{
    ctx k;
    int x, y, i, b, W, H, use_scratch, moving;
    cdsp_status st;
    cdsp_real q[2], Jp[4];
    size_t bpp;

    if (!s || !cam || !out)
        return CDSP_E_ARG;
    st = cdsp_camera_check(cam);
    if (st != CDSP_OK)
        return st;
    if (out_bits < 1 || out_bits > 16)
        return CDSP_E_FORMAT;
    W = cam->width;
    H = cam->height;
    bpp = out_bits <= 8 ? 1u : 2u;
    if (stride == 0)
        stride = (size_t)W * bpp;
    if (stride < (size_t)W * bpp)
        return CDSP_E_FORMAT;
    if (!scene_finite(s))
        return CDSP_E_NONFINITE;
    if (s->specular < R(0) || (s->specular > R(0) && s->specular_exp < R(1)) ||
        s->motion_px[0] * s->motion_px[0] + s->motion_px[1] * s->motion_px[1] >
            R(CDSP_RENDER_MAX_MOTION_PX) * R(CDSP_RENDER_MAX_MOTION_PX))
        return CDSP_E_ARG;
    if (!(s->radius > R(0)) || s->n_clutter < 0 || s->n_clutter > CDSP_RENDER_MAX_CLUTTER ||
        s->n_extra_pipes < 0 || s->n_extra_pipes > CDSP_RENDER_MAX_PIPES - 1 ||
        s->blur_sigma_px < R(0) || s->blur_sigma_px > R(CDSP_RENDER_MAX_BLUR_PX) ||
        s->noise_sigma < R(0))
        return CDSP_E_ARG;
    if (s->noise_sigma > R(0) && !rng)
        return CDSP_E_ARG;
    moving = s->motion_px[0] != R(0) || s->motion_px[1] != R(0);
    use_scratch = s->blur_sigma_px > R(0) || moving;
    if (use_scratch && (!scratch || scratch_len < cdsp_render_scratch_size(W, H)))
        return CDSP_E_CAPACITY;

    k.s = s;
    k.cam = cam;
    k.full = (cdsp_real)((1L << out_bits) - 1);
    k.npipes = 1 + s->n_extra_pipes;
    for (b = 0; b < k.npipes; b++) {
        const cdsp_real *P = b ? s->extra_pipe[b - 1].axis_point : s->axis_point;
        const cdsp_real *V = b ? s->extra_pipe[b - 1].axis_dir : s->axis_dir;
        cdsp_real r = b ? s->extra_pipe[b - 1].radius : s->radius;
        cdsp_real hl = b ? s->extra_pipe[b - 1].half_length : s->half_length;
        cyl *c = &k.pipes[b].c;
        for (i = 0; i < 3; i++) {
            c->p0[i] = P[i];
            c->v[i] = V[i];
        }
        if (!(v3_normalize(c->v) > R(0)) || !(r > R(0)))
            return CDSP_E_ARG;
        c->r = r;
        c->half = hl > R(0) ? hl : R(0);
    }
    for (i = 0; i < 3; i++)
        k.light[i] = s->light[i];
    v3_normalize(k.light);
    k.nbars = s->n_clutter;
    for (b = 0; b < s->n_clutter; b++) {
        const cdsp_clutter *c = &s->clutter[b];
        cdsp_real len;
        for (i = 0; i < 3; i++) {
            k.bars[b].p0[i] = (c->p0[i] + c->p1[i]) / R(2);
            k.bars[b].v[i] = c->p1[i] - c->p0[i];
        }
        len = v3_normalize(k.bars[b].v);
        if (!(len > R(0)) || !(c->half_width > R(0)))
            return CDSP_E_ARG;
        k.bars[b].half = len / R(2);
        k.bars[b].r = c->half_width;
    }
    for (b = 0; b < k.npipes; b++) {
        pipe_geo *g = &k.pipes[b];
        cdsp_real foot[3], pin[2];
        g->have_contours = contour_planes(g->c.p0, g->c.v, g->c.r, g->n, foot) == CDSP_OK &&
                           cdsp_cylinder_contours(cam, g->c.p0, g->c.v, g->c.r, 1, g->l[0],
                                                  g->l[1], pin) == CDSP_OK;
    }

    for (y = 0; y < H; y++) {
        /* Newton starts from the distorted position at the row's start, then
         * from the left neighbour's solution one pixel on. */
        q[0] = R(0);
        q[1] = (cdsp_real)y;
        for (x = 0; x < W; x++) {
            cdsp_real val;
            if (!undistort_px(cam, (cdsp_real)x, (cdsp_real)y, q, Jp)) {
                /* outside the model's invertible field: plain background */
                q[0] = (cdsp_real)x;
                q[1] = (cdsp_real)y;
                val = s->background_level;
                Jp[0] = Jp[3] = R(1);
                Jp[1] = Jp[2] = R(0);
            } else {
                val = pixel(&k, q, Jp);
            }
            if (use_scratch)
                scratch[(size_t)y * (size_t)W + (size_t)x] = (float)val;
            else
                store(s, rng, val, k.full, out, stride, bpp, x, y);
            q[0] += Jp[0] > R(0) ? R(1) / Jp[0] : R(1); /* next pixel's guess */
        }
    }
    if (!use_scratch)
        return CDSP_OK;

    if (s->blur_sigma_px > R(0)) {
        float kern[2 * RENDER_MAX_KERNEL + 1], sum = 0.0f, *line = scratch + 2 * (size_t)W * (size_t)H;
        int rad = (int)R_CEIL(R(3) * s->blur_sigma_px);
        if (rad > RENDER_MAX_KERNEL)
            rad = RENDER_MAX_KERNEL;
        for (i = -rad; i <= rad; i++) {
            cdsp_real z = (cdsp_real)i / s->blur_sigma_px;
            kern[i + rad] = (float)R_EXP(R(-0.5) * z * z);
            sum += kern[i + rad];
        }
        for (i = 0; i < 2 * rad + 1; i++)
            kern[i] /= sum;
        for (y = 0; y < H; y++)
            blur_line(scratch + (size_t)y * (size_t)W, (size_t)W, 1, kern, rad, line);
        for (x = 0; x < W; x++)
            blur_line(scratch + x, (size_t)H, (size_t)W, kern, rad, line);
    }
    if (moving) {
        float *second = scratch + (size_t)W * (size_t)H;
        size_t j, np = (size_t)W * (size_t)H;
        motion_blur(scratch, second, W, H, s->motion_px);
        for (j = 0; j < np; j++)
            scratch[j] = second[j];
    }
    for (y = 0; y < H; y++)
        for (x = 0; x < W; x++)
            store(s, rng, (cdsp_real)scratch[(size_t)y * (size_t)W + (size_t)x], k.full, out, stride,
                  bpp, x, y);
    return CDSP_OK;
}

/* ---- the paper's simulated set-up (docs/method.md §9) ---------------------
 * One definition for the tests, cdsp_tool's sim and bench, and the
 * benchmarks: the camera, its pose and the four pipes. */

void cdsp_render_paper_camera(cdsp_camera *cam)
{
    zero_bytes(cam, sizeof *cam); /* no distortion */
    cam->fx = cam->fy = R(12.0 / 3.45e-3); /* f / pixel pitch = 3478.26 px */
    cam->width = 2448;
    cam->height = 2048;
    /* the centre of the pixel grid: pixel centres are integers */
    cam->cx = R((2448 - 1) / 2.0);
    cam->cy = R((2048 - 1) / 2.0);
}

void cdsp_render_paper_pose(cdsp_real Rm[9], cdsp_real C[3])
{
    /* Looking from C at the world origin with Z_W up: forward = -C / |C|;
     * image down = world down (0, 0, -1) made perpendicular to forward
     * (Gram-Schmidt); image right = down x forward (a right-handed camera,
     * x right, y down, z forward). */
    cdsp_real fwd[3], down[3] = {R(0), R(0), R(-1)}, right[3], t;
    int i;
    C[0] = R(150);
    C[1] = R(200);
    C[2] = R(300);
    for (i = 0; i < 3; i++)
        fwd[i] = -C[i];
    v3_normalize(fwd);
    t = v3_dot(down, fwd);
    for (i = 0; i < 3; i++)
        down[i] -= t * fwd[i];
    v3_normalize(down);
    v3_cross(down, fwd, right);
    for (i = 0; i < 3; i++) {
        Rm[i] = right[i];
        Rm[3 + i] = down[i];
        Rm[6 + i] = fwd[i];
    }
}

cdsp_status cdsp_render_paper_pipe(int k, cdsp_real point[3], cdsp_real dir[3],
                                   cdsp_real *half_length)
{
    /* world: pipes in Z_W = 0; p1 along X_W through the origin, p2 = p1
     * moved -100 mm along Y_W (away from the camera), p3 along Y_W, p4 = p3
     * moved -100 mm along X_W; 500 mm long */
    static const cdsp_real pw[4][3] = {{0, 0, 0}, {0, -100, 0}, {0, 0, 0}, {-100, 0, 0}};
    static const cdsp_real dw[4][3] = {{1, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 1, 0}};
    cdsp_real Rm[9], C[3], rel[3];
    int i;
    if (k < 0 || k > 3)
        return CDSP_E_ARG;
    cdsp_render_paper_pose(Rm, C);
    for (i = 0; i < 3; i++)
        rel[i] = pw[k][i] - C[i];
    for (i = 0; i < 3; i++) {
        point[i] = v3_dot(&Rm[3 * i], rel);
        dir[i] = v3_dot(&Rm[3 * i], dw[k]);
    }
    if (half_length)
        *half_length = R(250);
    return CDSP_OK;
}
