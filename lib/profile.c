/*
 * profile.c - the edge-profile model: a contour's silhouette from the
 * intensity profile across it, accumulated along the whole contour.
 *
 * Why. The partial-area detector (edges.c) is exact for a step between two
 * flat sides seen through a symmetric blur narrower than its window. Real
 * pipes have neither: a Lambertian limb's intensity changes like the square
 * root of the distance from the limb, a motion blur can be wider than the
 * window, and at 45 degrees the window's rows meet the shading at other
 * distances than at 0. Each bias is a fraction of a pixel that the line
 * fit cannot average away, because it is the same at every point.
 *
 * The profile. Every scanline (a row when the contour is nearer vertical,
 * else a column) through a reference point q on the fitted line, with the
 * line's unit normal n toward the pipe, gives pixels at signed distances
 * u = n.(x - q) from the line. Pixel centres of hundreds of scanlines at
 * their exact u, binned at 1/4 px (the mean u of each bin is kept, so a bin
 * is a sample at a known abscissa), are the edge-spread function O(u)
 * sampled far finer than a pixel (the slanted-edge method; at 0 and 90
 * degrees all rows share one phase and the bins are 1 px apart, which is
 * still exact for the integral below, as for the partial-area effect).
 *
 * The model. The scene across the contour is S(u) = bg(u) = D + E (u - d)
 * for u < d and P(s) = A + B s + C sqrt(s (2 Rc - s)), s = u - d, for
 * u > d, d the silhouette and Rc the pipe's image radius (a Lambertian
 * cylinder: cos(phi) linear in the distance from the limb, sin(phi) ~ its
 * square root; see sides below; E and B also take vignetting). What the camera sees is O = S * K with K symmetric of
 * variance s2 (optical blur, motion blur, the pixel's footprint projected
 * on n, whose variance is 1/12 at any angle). The blur only moves
 * intensity across u, so over a window [a, b] = [d - W, d + W] wider than K
 *     int_a^b O du = int_a^b S du + (s2 / 2) (S'(b) - S'(a))         (1)
 * (the second term is what K carries over the window's ends where S has a
 * slope; O(K's fourth moment x S''') neglected). With the sides fitted to
 * the bins outside the blur zone (|u - d| >= z = 3.5 sqrt(s2) + 1.5), (1) is
 * one equation in d: Newton, from the line (d = 0). The blur itself comes
 * from the first moment over the blur zone, int (u - d)(O - S) du =
 * -J s2 / 2 for a jump J at d (exact for a step; the limb's curvature is
 * accounted for in model_solve). Fit, solve, measure the blur, adapt z
 * and W, repeat.
 *
 * A limb in shadow (light from behind it) is flat up to the terminator
 * St and lit beyond: P = A + B (s - St)_+ + C (sq(s) - sq(St))_+, St
 * searched (fit_sides); the window then ends before the kink.
 *
 * A blur wider than the detector's window (sigma > 1 px): the blurred
 * scene itself fitted to every bin (the forward model, fwd_* below) in
 * place of (1), whose pipe side is extrapolated over the blur zone; a
 * shadow ending inside the blur zone as a terminator fitted with it
 * (fwd_terminator). Where the area balance's rounds fail (faint limbs, a
 * terminator's step outweighing the silhouette's), the forward model alone
 * (fwd_alone).
 *
 * Limits (measured in make bench's accuracy study): a shadow ending inside
 * the blur zone under a blur of at most 1 px, or on 8-bit frames (the
 * rounding hides the kink), a specular stripe or a saturation plateau
 * inside the fit zone break the side model; the window must stay inside
 * the pipe (0.9 of its half-width is used).
 */
#include "internal.h"

#define BPP CDSP_PROFILE_BINS_PER_PX
#define NB CDSP_PROFILE_NBINS
#ifndef PROFILE_FIT_ZONE
#define PROFILE_FIT_ZONE 30
#endif
/* fit_chi2 of a pipe side with no bins to check (cdsp_profile) */
#define PROFILE_CHI2_UNCHECKED 1e6
/* fit_chi2's residuals are averaged over groups this wide in u, px
 * (model_solve) */
#define PROFILE_CHI2_GROUP 1

void cdsp_profile_params_default(cdsp_profile_params *p)
{
    p->enable = 0; /* opt-in until it beats the detector everywhere (make bench's study) */
    p->max_rows = 2048;
    p->max_half_width_px = R(20);
    p->max_fit_chi2 = R(0.25);
}

cdsp_status cdsp__profile_params_check(const cdsp_profile_params *p)
{
    if (!p || p->max_rows < 16 || p->max_rows > 4096 || !(p->max_half_width_px >= R(6)) ||
        !(p->max_half_width_px <= R(CDSP_PROFILE_RANGE_PX)) || !(p->max_fit_chi2 > R(0)))
        return CDSP_E_ARG;
    return CDSP_OK;
}

static void ws_clear(cdsp_profile_ws *ws)
{
    int b;
    for (b = 0; b < NB; b++) {
        ws->count[b] = 0;
        ws->sum[b] = 0;
        ws->sumsq[b] = 0;
        ws->sum_u[b] = R(0);
    }
}

/* One scanline through q (frame px) across the contour, unit normal n
 * toward the pipe: the pixels with |u| <= half into the bins. Returns 0
 * (nothing added) when the window leaves the frame. */
static int accumulate(const cdsp_image *img, cdsp_profile_ws *ws, const cdsp_real q[2],
                      const cdsp_real n[2], cdsp_real half)
{
    int horizontal = R_FABS(n[0]) >= R_FABS(n[1]);
    int s_ax = horizontal ? 0 : 1, t_ax = 1 - s_ax, t, s, lo, hi, ext;
    cdsp_real ns = n[s_ax], ct, slo, shi, u;
    if (!(R_FABS(ns) > R(0.5)))
        return 0;
    t = (int)R_FLOOR(q[t_ax] + R(0.5));
    if (t < 0 || t >= (horizontal ? img->height : img->width))
        return 0;
    ct = ((cdsp_real)t - q[t_ax]) * n[t_ax];
    /* u(s) = (s - q_s) ns + ct covers [-half, half] for s in [slo, shi] */
    slo = q[s_ax] + (-half - ct) / ns;
    shi = q[s_ax] + (half - ct) / ns;
    if (slo > shi) {
        cdsp_real tmp = slo;
        slo = shi;
        shi = tmp;
    }
    lo = (int)R_CEIL(slo);
    hi = (int)R_FLOOR(shi);
    ext = horizontal ? img->width : img->height;
    if (lo < 0 || hi >= ext || hi - lo < 4)
        return 0;
    {
        /* the scanline's pixels by pointer steps (a row: 1 pixel, a column:
         * the stride), not img_px's multiply per pixel: the fit's cost is
         * mostly here and in fit_pipe */
        const unsigned char *base = (const unsigned char *)img->data;
        size_t bpp = img->bits <= 8 ? 1 : 2, step = horizontal ? bpp : img->stride, o;
        o = horizontal ? (size_t)t * img->stride + (size_t)lo * bpp : (size_t)lo * img->stride + (size_t)t * bpp;
        if (bpp == 1 && half <= R(CDSP_PROFILE_RANGE_PX) - R(0.01)) {
            /* the common case, 8 bit and a window inside the bins' range
             * (the default half-width 20 px of 24): every pixel's |u| is
             * at most half (to rounding, far below the 0.01 px margin),
             * so its bin is in range and the test below is not needed;
             * s counted in cdsp_real (exact: integers) */
            cdsp_real sr = (cdsp_real)lo, qs = q[s_ax];
            uint32_t *cnt = ws->count, *sum = ws->sum;
            uint64_t *sumsq = ws->sumsq;
            cdsp_real *sum_u = ws->sum_u;
            const unsigned char *px = base + o;
#define ACC_PX(px, sr)                                              \
    do {                                                            \
        uint32_t v = *(px);                                         \
        int b;                                                      \
        u = ((sr) - qs) * ns + ct;                                  \
        b = (int)((u + R(CDSP_PROFILE_RANGE_PX)) * R(BPP));         \
        cnt[b]++;                                                   \
        sum[b] += v;                                                \
        sumsq[b] += (uint64_t)(v * v);                              \
        sum_u[b] += u;                                              \
    } while (0)
            /* two pixels a round (the loop's test and steps were 4 of
             * ~25 instructions a pixel), in order: the same sums */
            for (s = hi - lo + 1; s > 1; s -= 2, px += 2 * step, sr += R(2)) {
                ACC_PX(px, sr);
                ACC_PX(px + step, sr + R(1));
            }
            if (s > 0)
                ACC_PX(px, sr);
#undef ACC_PX
            return 1;
        }
        for (s = lo; s <= hi; s++, o += step) {
            int v = bpp == 1 ? base[o] : *(const uint16_t *)(const void *)(base + o), b;
            cdsp_real x;
            u = ((cdsp_real)s - q[s_ax]) * ns + ct;
            /* the bin floor((u + RANGE) BPP), by truncation where that is
             * >= 0 (floor's library call was a third of this loop) */
            x = (u + R(CDSP_PROFILE_RANGE_PX)) * R(BPP);
            if (!(x >= R(0)) || x >= R(NB))
                continue;
            b = (int)x;
            ws->count[b]++;
            ws->sum[b] += (uint32_t)v;
            ws->sumsq[b] += (uint64_t)v * (uint64_t)v;
            ws->sum_u[b] += u;
        }
    }
    return 1;
}

/* Small dense least squares by normal equations: solves N x = r in place
 * (m <= 5 unknowns; N's rows ld apart) by Gauss-Jordan with partial
 * pivoting; 0 when singular. */
static int gj_solve(cdsp_real *N, int ld, cdsp_real *r, int m)
{
    int i, j, k;
    for (i = 0; i < m; i++) {
        int piv = i;
        for (j = i + 1; j < m; j++)
            if (R_FABS(N[j * ld + i]) > R_FABS(N[piv * ld + i]))
                piv = j;
        if (!(R_FABS(N[piv * ld + i]) > R(0)))
            return 0;
        if (piv != i) {
            for (k = 0; k < m; k++) {
                cdsp_real t = N[i * ld + k];
                N[i * ld + k] = N[piv * ld + k];
                N[piv * ld + k] = t;
            }
            {
                cdsp_real t = r[i];
                r[i] = r[piv];
                r[piv] = t;
            }
        }
        for (j = 0; j < m; j++) {
            cdsp_real f;
            if (j == i)
                continue;
            f = N[j * ld + i] / N[i * ld + i];
            for (k = i; k < m; k++)
                N[j * ld + k] -= f * N[i * ld + k];
            r[j] -= f * r[i];
        }
    }
    for (i = 0; i < m; i++)
        r[i] /= N[i * ld + i];
    return 1;
}

/* m <= 3 unknowns */
static int solve_small(cdsp_real N[3][3], cdsp_real r[3], int m)
{
    return gj_solve(&N[0][0], 3, r, m);
}

/* The sides' models about the silhouette d. The pipe side is a Lambertian
 * cylinder of image radius Rc seen side on: at the angle phi from the limb,
 * s = Rc (1 - cos phi) from it, its normal is cos(phi) n_out + sin(phi) v,
 * so the shading is linear in cos(phi) = 1 - s/Rc and in
 * sin(phi) = sqrt(s (2 Rc - s)) / Rc: exactly A + B s + C sq(s) with
 * sq(s) = sqrt(s (2 Rc - s)) (~ sqrt(2 Rc s) near the limb). */
typedef struct {
    cdsp_real D, E;    /* background: D + E (u - d) */
    cdsp_real A, B, C; /* pipe: A + B s + C sq(s), s = u - d (St = 0) */
    cdsp_real Rc;      /* the limb's radius, px */
    cdsp_real St;      /* the shadow's end (terminator), px from the
                          silhouette; 0: no shadow in the fit zone */
} sides;

static cdsp_real sq_at(const sides *m, cdsp_real s)
{
    cdsp_real v = s * (R(2) * m->Rc - s);
    return v > R(0) ? R_SQRT(v) : R(0);
}

/* The pipe side with a limb in shadow: where the light grazes the limb
 * from behind (l_n < 0 in ambient + (1 - ambient) max(0, l_n cos phi +
 * l_v sin phi)) the Lambertian term is clipped to 0 up to the terminator
 * tan(phi_t) = -l_n / l_v, s_t = Rc (1 - cos phi_t): the side is flat
 * (ambient only) on [0, St] and the lit model beyond, continuous at St:
 *     P(s) = A + B (s - St)_+ + C (sq(s) - sq(St))_+.
 * St = 0 is the unclipped model A + B s + C sq(s). */
static cdsp_real pipe_at(const sides *m, cdsp_real s)
{
    if (s <= m->St)
        return m->A;
    return m->A + m->B * (s - m->St) + m->C * (sq_at(m, s) - sq_at(m, m->St));
}

/* sq'' (the curvature that the blur turns into a bias of the fit; the
 * basis uses it only beyond the shadow, pipe_basis_h) */
static cdsp_real sq_curv(const sides *m, cdsp_real s)
{
    cdsp_real v = s * (R(2) * m->Rc - s);
    return v > R(0) ? -m->Rc * m->Rc / (v * R_SQRT(v)) : R(0);
}

/* int_0^X sq (the circular segment's area) */
static cdsp_real sq_int(const sides *m, cdsp_real X)
{
    cdsp_real R0 = m->Rc, t = X - R0, r2 = R0 * R0 - t * t, c;
    c = r2 > R(0) ? R_SQRT(r2) : R(0);
    return t * c / R(2) + R0 * R0 / R(2) * (R_ATAN2(t, c) + R_PI / R(2));
}

/* int_0^X of the pipe model */
static cdsp_real pipe_int(const sides *m, cdsp_real X)
{
    cdsp_real acc = m->A * X, e = X - m->St;
    if (e > R(0))
        acc += m->B * e * e / R(2) + m->C * (sq_int(m, X) - sq_int(m, m->St) - sq_at(m, m->St) * e);
    return acc;
}

/* d/dX of the pipe model at X > 0 */
static cdsp_real pipe_slope(const sides *m, cdsp_real X)
{
    cdsp_real q = sq_at(m, X);
    if (X <= m->St)
        return R(0);
    return m->B + (q > R(0) ? m->C * (m->Rc - X) / q : R(0));
}

/* Phi(t), the standard normal distribution, by Abramowitz and Stegun
 * 7.1.26 (|error| < 1.5e-7; exp only, which every libm the library is
 * built for has), given g = exp(-t^2 / 2) (the caller has it for the
 * density: one exp per blurred kink's bin, not two) */
static cdsp_real norm_cdf_g(cdsp_real t, cdsp_real g)
{
    cdsp_real x = R_FABS(t) / R(1.4142135623730951), k = R(1) / (R(1) + R(0.3275911) * x), e;
    e = R(1.061405429);
    e = R(-1.453152027) + k * e;
    e = R(1.421413741) + k * e;
    e = R(-0.284496736) + k * e;
    e = R(0.254829592) + k * e;
    e *= k * g; /* erfc(x), exp(-x^2) = g */
    return t >= R(0) ? R(1) - e / R(2) : e / R(2);
}

/* The pipe side's basis at x (px from the silhouette), blurred as the bins
 * are (variance s2): f[0] = 1, f[1] ~ (x - St)_+, f[2] ~ (h(x) - h(St))_+
 * with h = sq + (s2/2) sq''. At a terminator the kink is blurred too: the
 * ramp (x - St)_+ seen through a Gaussian is sigma phi(t) + (x - St) Phi(t),
 * t = (x - St) / sigma; the sq term is its tangent there times that ramp
 * plus the (smooth, second-order) rest. The model's value is
 * A + B f[1] + C f[2]. */
typedef struct {
    cdsp_real sig, sig4, hs, q; /* sqrt(s2), 4 sqrt(s2), h(St) = sq(St), sq'(St) */
} pipe_kink;

static void pipe_kink_at(const sides *m, cdsp_real s2, pipe_kink *k)
{
    k->sig = R_SQRT(s2);
    k->sig4 = R(4) * k->sig;
    k->hs = sq_at(m, m->St);
    k->q = k->hs > R(0) ? (m->Rc - m->St) / k->hs : R(0);
}

/* pipe_basis with h(x) = sq(x) + (s2/2) sq''(x) given (fit_pipe's zone
 * holds it per bin: it does not depend on St, so the terminator's search
 * computes its square roots once, not once per trial) */
static inline void pipe_basis_h(const sides *m, cdsp_real x, cdsp_real hx, const pipe_kink *k, cdsp_real f[3])
{
    cdsp_real d, t;
    f[0] = R(1);
    if (!(m->St > R(0))) {
        f[1] = x;
        f[2] = hx;
        return;
    }
    /* t = (x - St) / sigma, whose branch |x - St| >= 4 sigma decides
     * without the division (4 sigma is exact, a power of 2 times sigma,
     * and rounding is monotone: x - St >= 4 sigma gives a quotient >= 4):
     * the same f, one division less on the bins outside the kink's
     * blur (the paper frame's full search: 7 552 of the 10 236 bins a
     * terminator's basis is evaluated on; fit_pipe 743 972 -> 741 415
     * instructions, callgrind: a division is one instruction there, but
     * ~4 cycles of the divider's throughput and 13-15 of latency) */
    d = x - m->St;
    t = d >= k->sig4 ? R(4) : d <= -k->sig4 ? R(-4) : d / k->sig;
    if (t >= R(4)) {
        f[1] = d;
        f[2] = hx - k->hs;
    } else if (t <= R(-4)) {
        f[1] = f[2] = R(0);
    } else {
        cdsp_real g = R_EXP(-t * t / R(2)), ramp = k->sig * R(0.3989422804014327) * g + d * norm_cdf_g(t, g);
        f[1] = ramp;
        f[2] = k->q * ramp + (x > m->St ? hx - k->hs - k->q * d : R(0));
    }
}

/* h(x) of the basis (pipe_basis) */
static cdsp_real pipe_h(const sides *m, cdsp_real x, cdsp_real s2)
{
    return sq_at(m, x) + s2 / R(2) * sq_curv(m, x);
}

/* (inline: out of line, as area_sigma's third caller made it, the full
 * search cost 9 K instructions more, callgrind) */
static inline void pipe_basis(const sides *m, cdsp_real x, cdsp_real s2, cdsp_real f[3])
{
    pipe_kink k;
    pipe_kink_at(m, s2, &k);
    pipe_basis_h(m, x, pipe_h(m, x, s2), &k, f);
}

static cdsp_real pipe_fitted(const sides *m, cdsp_real x, cdsp_real s2)
{
    cdsp_real f[3];
    pipe_basis(m, x, s2, f);
    return m->A + m->B * f[1] + m->C * f[2];
}

/* The pipe side's weighted fit over the bins with z <= u - d <= W for the
 * terminator St (0: none): basis 1, (x - St)_+ and (h(x) - h(St))_+ with
 * h = sq + (s2/2) sq'' (what the bins hold is the blurred scene,
 * S + (s2/2) S'' + ...: near the limb sq'' is large, and fitting S itself
 * to the blurred bins put the extrapolated limb 0.03 px off at blur
 * 1 px). The basis is centred on the zone's middle and the values on the
 * zone's first bin, so that the normal equations stay well conditioned in
 * float too (1, x and sqrt are nearly collinear over a zone of a few px
 * and the levels reach 65535). Returns the weighted residual sum of
 * squares, or -1 when the zone holds too few bins. */
/* The pipe side's zone z <= u - d <= W of one fit_sides call (d and s2
 * fixed there): its bins with counts, in order, packed once per call
 * with what every trial terminator reads of them (x, count, the mean
 * less the first bin's, h(x) for pipe_basis_h), so that fit_pipe's
 * trials loop over the zone alone (the same values in the same order as
 * when each trial picked them out of the bins: bench_frame's hash
 * unchanged; the sums that do not depend on the terminator once, in
 * the same order). zbuf is the workspace's fwd_r, the forward model's
 * residuals, not live while the area balance iterates. */
typedef struct {
    const cdsp_real *zx, *zw, *zy, *zh;
    cdsp_real mp0, z, W, s2;
    cdsp_real sw, swy, swyy; /* the sums of w, w y and w y y, which no
                                terminator changes */
    int nz;
} pipe_zone;

static cdsp_real fit_pipe(const pipe_zone *zn, cdsp_real St, sides *m)
{
    cdsp_real Np[3][3], rp[3], r0[3], yy = zn->swyy, fc[3], mp0 = zn->mp0;
    const cdsp_real *zx = zn->zx, *zw = zn->zw, *zy = zn->zy, *zh = zn->zh, z = zn->z, W = zn->W;
    /* the normal equations' sums in scalars (kept in registers: Np's
     * address goes to solve_small), Np[i][j] += w f[i] f[j] and
     * rp[i] += w f[i] y with f[0] = 1 spelled out: the same products in
     * the same order (N01 = N10 and N02 = N20 are one sum each) */
    cdsp_real s00 = zn->sw, s01 = R(0), s02 = R(0), s11 = R(0), s12 = R(0), s21 = R(0), s22 = R(0);
    cdsp_real q0 = zn->swy, q1 = R(0), q2 = R(0);
    pipe_kink k;
    int b, i, npp = zn->nz;
    m->St = St;
    pipe_kink_at(m, zn->s2, &k);
    pipe_basis(m, (z + W) / R(2), zn->s2, fc);
    for (b = 0; b < npp; b++) {
        cdsp_real w = zw[b], f[3], y = zy[b], w1, w2;
        pipe_basis_h(m, zx[b], zh[b], &k, f);
        f[1] -= fc[1];
        f[2] -= fc[2];
        w1 = w * f[1];
        w2 = w * f[2];
        s01 += w1;
        s02 += w2;
        s11 += w1 * f[1];
        s12 += w1 * f[2];
        s21 += w2 * f[1];
        s22 += w2 * f[2];
        q1 += w1 * y;
        q2 += w2 * y;
    }
    Np[0][0] = s00;
    Np[0][1] = Np[1][0] = s01;
    Np[0][2] = Np[2][0] = s02;
    Np[1][1] = s11;
    Np[1][2] = s12;
    Np[2][1] = s21;
    Np[2][2] = s22;
    rp[0] = q0;
    rp[1] = q1;
    rp[2] = q2;
    for (i = 0; i < 3; i++)
        r0[i] = rp[i];
    if (npp < 4 || !solve_small(Np, rp, 3))
        return R(-1);
    /* back to A + B f[1] + C f[2] (pipe_basis) */
    m->B = rp[1];
    m->C = rp[2];
    m->A = mp0 + rp[0] - rp[1] * fc[1] - rp[2] * fc[2];
    yy -= rp[0] * r0[0] + rp[1] * r0[1] + rp[2] * r0[2];
    return yy > R(0) ? yy : R(0);
}

/* What fit_pipe(zn, St, m) writes into m, from a fit of the same St on
 * the same zone held in f (fit_sides) */
static void pipe_take(sides *m, const sides *f)
{
    m->St = f->St;
    m->A = f->A;
    m->B = f->B;
    m->C = f->C;
}

/* fit_sides's grid skips a trial whose RSS's lower bound exceeds the
 * best by this many R_EPS of the zone's sum of squares (below) */
#define PRUNE_MARGIN 1e9

/* Weighted fits of both sides over the bins with z <= |u - d| <= W: the
 * background D + E x, the pipe side (fit_pipe) with its terminator. A
 * shadowed limb is the unclipped model's misfit (its chi-square reached
 * 0.6-1.2 on the paper's and the rack's scenes, with offsets of 0.2 px
 * and more); the terminator is searched on a 1 px grid over the zone
 * (search = 1; 2: +- 1 px about the last one; 0: +- 1/4 px about it)
 * and kept when it is
 * significant: F = (RSS_0 - RSS_t) / (RSS_t / dof) > 10, as
 * the limb term's test in model_solve. */
static int fit_sides(const cdsp_profile_ws *ws, const cdsp_real *ub, const cdsp_real *mb, cdsp_real *hb,
                     cdsp_real (*zbuf)[NB], cdsp_real d, cdsp_real z, cdsp_real W, cdsp_real s2, int search,
                     sides *m, int *improved)
{
    cdsp_real Nb[3][3] = {{0}}, rb[3] = {0}, xb = -(z + W) / R(2), mb0 = R(0), rss0, best, bestSt, lo, hi, t;
    int b, i, j, nbg = 0, npp = 0;
    /* the pipe side's fits kept as they are computed: the one without a
     * terminator (s0), the best so far (sb) and the golden section's two
     * (k1, k2). The fit the call ends with is one of them, at the same
     * St on the same zone: the same numbers as fitting it once more (as
     * until issue 17's third pass: one fit_pipe in every ~8, callgrind) */
    sides trial = *m, s0, sb, k1 = *m, k2 = *m;
    pipe_zone zn;
    zn.zx = zbuf[0];
    zn.zw = zbuf[1];
    zn.zy = zbuf[2];
    zn.zh = zbuf[3];
    zn.mp0 = zn.sw = zn.swy = zn.swyy = R(0);
    zn.z = z;
    zn.W = W;
    zn.s2 = s2;
    for (b = 0; b < NB; b++) {
        cdsp_real w, x = ub[b] - d, f[2];
        if (!ws->count[b])
            continue;
        if (x >= z && x <= W) {
            /* the pipe side's zone, packed (pipe_zone) */
            if (!npp)
                zn.mp0 = mb[b];
            hb[b] = pipe_h(m, x, s2);
            zbuf[0][npp] = x;
            zbuf[1][npp] = (cdsp_real)ws->count[b];
            zbuf[2][npp] = mb[b] - zn.mp0;
            zbuf[3][npp] = hb[b];
            zn.sw += zbuf[1][npp];
            zn.swy += zbuf[1][npp] * zbuf[2][npp];
            zn.swyy += zbuf[1][npp] * zbuf[2][npp] * zbuf[2][npp];
            npp++;
        }
        if (!(x <= -z && x >= -W))
            continue;
        if (!nbg)
            mb0 = mb[b];
        w = (cdsp_real)ws->count[b];
        f[0] = R(1);
        f[1] = x - xb;
        for (i = 0; i < 2; i++) {
            for (j = 0; j < 2; j++)
                Nb[i][j] += w * f[i] * f[j];
            rb[i] += w * f[i] * (mb[b] - mb0);
        }
        nbg++;
    }
    zn.nz = npp;
    if (nbg < 3 || npp < 4 || !solve_small(Nb, rb, 2))
        return 0;
    m->E = rb[1];
    m->D = mb0 + rb[0] - rb[1] * xb;
    rss0 = fit_pipe(&zn, R(0), &trial);
    if (rss0 < R(0))
        return 0;
    s0 = sb = trial;
    best = rss0;
    bestSt = R(0);
    *improved = 0;
    if ((!search && !(m->St > R(0))) || npp < 8) { /* a terminator wants 8 bins at least */
        pipe_take(m, &s0);
        return 1;
    }
    lo = z;
    hi = W - R(1.5); /* 6 bins beyond it at least */
    if (search == 1) {
        /* the whole zone on a 1 px grid first. A trial whose RSS cannot
         * fall below the best so far is not fitted: where x - St <= -4
         * sigma the basis is 0 (pipe_basis_h), the model a constant, so
         * the trial's RSS is at least those bins' weighted scatter about
         * their mean (lb, Welford's running sums over the zone's bins in
         * order while they qualify: St only grows). Fitted, such a trial
         * would not be taken (r < best false) as long as its computed RSS
         * is within the margin of its true value, PRUNE_MARGIN R_EPS of
         * the zone's sum of squares: the normal equations' RSS was never
         * more than 1.9e-13 of it below the residuals' weighted sum at the
         * computed fit (summed in long double, which is at least the true
         * least squares RSS; all 2 219 fits of bench_frame's hash run), nor
         * more than 6.1e-11 on test_profile.c's 37 497, against 2.2e-7
         * here in double; in float the margin exceeds every RSS and
         * nothing is skipped. On the paper frame 5-6 of a grid's 14-16
         * trials are fitted, the rest skipped once St is ~4 px into the
         * zone: the same results
         * (bench_frame's hash), the full search's fit_pipe calls 171 -> 133,
         * instructions 4 667 950 -> 4 437 417 (callgrind). */
        cdsp_real sig4 = R(4) * R_SQRT(s2), margin = R(PRUNE_MARGIN) * R_EPS * zn.swyy;
        cdsp_real pw = R(0), pmean = R(0), lb = R(0);
        int kp = 0;
        for (t = lo; t <= hi; t += R(1)) {
            cdsp_real r;
            for (; kp < npp && zn.zx[kp] - t <= -sig4; kp++) {
                cdsp_real w = zn.zw[kp], dy = zn.zy[kp] - pmean;
                pw += w;
                pmean += dy * w / pw;
                lb += w * dy * (zn.zy[kp] - pmean);
            }
            if (lb > best + margin)
                continue;
            r = fit_pipe(&zn, t, &trial);
            if (r >= R(0) && r < best) {
                best = r;
                bestSt = t;
                sb = trial;
            }
        }
        *improved = bestSt > R(0);
    } else {
        best = fit_pipe(&zn, m->St, &trial);
        bestSt = m->St;
        sb = trial;
        if (best < R(0)) {
            best = rss0;
            bestSt = R(0);
            sb = s0;
        }
    }
    if (bestSt > R(0)) {
        /* between the grid's points: golden-section search of the RSS on
         * bestSt +- 1 px after the grid, +- 1/4 px about the last
         * iteration's terminator, to 0.01 px (the level of the shadow, A,
         * follows the terminator through the continuity there: on the
         * rendered limbs a 0.05 px error in St moved the silhouette by
         * 0.01 px; parabolic steps went astray on the binned RSS) */
        const cdsp_real g = R(0.3819660112501051);
        cdsp_real xa = bestSt - (search ? R(1) : R(0.25)), xd = bestSt + (search ? R(1) : R(0.25)), x1, x2, f1, f2;
        if (xa < lo)
            xa = lo;
        if (xd > hi)
            xd = hi;
        x1 = xa + g * (xd - xa);
        x2 = xd - g * (xd - xa);
        f1 = fit_pipe(&zn, x1, &k1);
        f2 = fit_pipe(&zn, x2, &k2);
        while (xd - xa > R(0.01) && f1 >= R(0) && f2 >= R(0)) {
            if (f1 < f2) {
                xd = x2;
                x2 = x1;
                f2 = f1;
                k2 = k1;
                x1 = xa + g * (xd - xa);
                f1 = fit_pipe(&zn, x1, &k1);
            } else {
                xa = x1;
                x1 = x2;
                f1 = f2;
                k1 = k2;
                x2 = xd - g * (xd - xa);
                f2 = fit_pipe(&zn, x2, &k2);
            }
        }
        if (f1 >= R(0) && f1 < best) {
            best = f1;
            bestSt = x1;
            sb = k1;
        }
        if (f2 >= R(0) && f2 < best) {
            best = f2;
            bestSt = x2;
            sb = k2;
        }
    }
    /* Hysteresis: a terminator an earlier round found significant (m->St)
     * is kept at F > 4, the 95 % level of F(1, ~60) for one parameter
     * whose place is given; 10 is for one found by searching. A short
     * shadow (terminator 0.3-0.6 px beyond the blur zone, bench frame 0
     * and the paper's scene at 256 scanlines) gave F 7.4, 96, 9.0 in
     * successive rounds and flipped off in the third: bound 1.9 px where
     * the 2048-scanline fit (F 230-380) gave 0.02 */
    if (!(bestSt > R(0) && rss0 - best > (m->St > R(0) ? R(4) : R(10)) * best / (cdsp_real)(npp - 4)))
        bestSt = R(0);
    /* (every kept fit succeeded: best >= 0, and rss0 >= 0) */
    pipe_take(m, bestSt > R(0) ? &sb : &s0);
    return 1;
}

/* Trapezoid integral over [a, b] of the bins' (u, value) samples, the
 * pieces before the first and after the last sample from the side models;
 * with moment != 0, of (u - d)(O - S) instead (S the model). */
static cdsp_real integrate(const cdsp_profile_ws *ws, const cdsp_real *ub, const cdsp_real *mb,
                           const sides *m, cdsp_real d0, cdsp_real d, cdsp_real a, cdsp_real b,
                           int moment)
{
    cdsp_real acc = R(0), pu = R(0), pv = R(0);
    int k, first = 1;
    for (k = 0; k < NB; k++) {
        cdsp_real v, u = ub[k];
        if (!ws->count[k] || u < a || u > b)
            continue;
        v = mb[k];
        if (moment) {
            cdsp_real sv = u < d ? m->D + m->E * (u - d0) : pipe_at(m, u - d);
            v = (u - d) * (v - sv);
        }
        if (first) {
            /* from a to the first sample: the background model (moment: 0) */
            if (!moment)
                acc += (u - a) * (m->D + m->E * ((a + u) / R(2) - d0));
            first = 0;
        } else {
            acc += (u - pu) * (v + pv) / R(2);
        }
        pu = u;
        pv = v;
    }
    if (first)
        return R(0);
    if (!moment) {
        /* from the last sample to b: the pipe model (exact integral) */
        cdsp_real s0 = pu - d;
        acc += pipe_int(m, b - d) - pipe_int(m, s0 > R(0) ? s0 : R(0));
    }
    return acc;
}

/*
 * The forward model (a blur wider than the detector's window). The area
 * balance (1) needs the pipe side's model over the blur zone, where it has
 * no data of its own: extrapolated from beyond z = 3.5 sigma + 1.5 (12 px
 * at sigma 3) to the silhouette, the limb term's curvature is poorly held
 * (the fit zone is a few px of gentle slope; on 8-bit frames the rounding's
 * steps are as large as the curvature left there) and the extrapolated
 * limb misfits. Here the blurred scene itself is fitted to every bin of
 * the window, the blur zone included:
 *     O(x) = D + E x + (A - D) p0(x) + (B - E) p1(x) + C p2(x),
 * x = u - d, p_f = K * (f 1_{s > 0}) for f = 1, s, sq(s) (K * 1 = 1 and
 * K * x = x for a symmetric K), K a Gaussian of sd sg convolved with a box
 * of width w (a motion blur across the contour; the pixel's footprint and
 * the optics are the Gaussian). Linear in D, E, A, B, C for given
 * (d, sg, w): variable projection, Levenberg-Marquardt on (d, sg, w) with
 * a Jacobian by differences. The p_f come from a grid of 1/FWD_SUB px in
 * x (exact cell masses of K from its distribution function, the pipe
 * side's cell means of f, so the step itself is exact at the grid's
 * origin) interpolated linearly at the bins.
 */
#define FWD_SUB CDSP_PROFILE_FWD_SUB
#define FWD_NX CDSP_PROFILE_FWD_NX
#define FWD_NK CDSP_PROFILE_FWD_NK
#define FWD_IX ((FWD_NX - 1) / 2) /* the grid's index of x = 0 */
/* the forward model replaces the area balance above this blur (px): the
 * detector's window spans sigma <= 0.97 px at h = 4 (cdsp_profile_applies) */
#define FWD_MIN_BLUR 1.0
/* the area balance's fit zone that can tell a straight pipe side, px */
#define FWD_AREA_ZONE 6
/* a forward fit worse than this replaces only a worse area balance */
#define FWD_MISFIT_CHI2 5
/* rounds of fwd_lm from each start before the better one goes on */
#ifndef FWD_START_ROUNDS
#define FWD_START_ROUNDS 3
#endif
/* the terminator is searched where the forward fit without one misfits
 * beyond this fit_chi2 (fwd_chi2): noise-free 16-bit lit limbs in make
 * bench-accuracy reach 0.0027, a shadow ending 3.2 px from the silhouette
 * under 3 px of blur 0.0106 (test_shadow_in_blur), 5.03 px 0.10-0.18; the
 * search is 5-7 times the fit's cost */
#ifndef FWD_TERM_CHI2
#define FWD_TERM_CHI2 5e-3
#endif
#ifndef FWD_TERM_ROUNDS
#define FWD_TERM_ROUNDS 4
#endif
#ifndef FWD_TERM_RMS
#define FWD_TERM_RMS 1e-4
#endif
#ifndef FWD_LIMB_RMS
#define FWD_LIMB_RMS 3e-4
#endif

typedef struct {
    cdsp_real d, sg, w; /* silhouette, the kernel's Gaussian sd and box width */
    cdsp_real T, Rc;    /* the terminator (px from d; 0: none) and the limb's radius */
    cdsp_real c[5];     /* D, E, A - D, B - E, C (T > 0: D, E, A - D, B, C) */
    cdsp_real rss, Wf;  /* residual sum of squares over |x + dw| <= Wf */
    cdsp_real dw;       /* d less the window's centre: 0 but in fwd_sigma's
                           steps in d, which hold the window */
    int i0, i1, J;      /* the grid's range, the kernel's half-width in cells */
} fwd_state;

/* Psi(t) = t Phi(t) + phi(t), the antiderivative of Phi */
static cdsp_real fwd_psi(cdsp_real t)
{
    cdsp_real g = R_EXP(-t * t / R(2));
    return t * norm_cdf_g(t, g) + R(0.3989422804014327) * g;
}

/* the kernel's distribution function at y: a Gaussian's through a box of
 * width w, (sg / w) (Psi((y + w/2) / sg) - Psi((y - w/2) / sg)); a box
 * narrower than sg / 20 as the Gaussian of the same variance (the
 * difference of Psi loses its digits there) */
static cdsp_real fwd_cdf(cdsp_real y, cdsp_real sg, cdsp_real w)
{
    if (w < sg / R(20)) {
        cdsp_real s = R_SQRT(sg * sg + w * w / R(12)), t = y / s;
        return norm_cdf_g(t, R_EXP(-t * t / R(2)));
    }
    return sg / w * (fwd_psi((y + w / R(2)) / sg) - fwd_psi((y - w / R(2)) / sg));
}

/* The blurred basis p0, p1, p2 on the grid for (sg, w), and the kernel's
 * cell masses: cell j of K is [(j - J) / SUB, (j - J + 1) / SUB] */
static void fwd_basis(cdsp_profile_ws *ws, fwd_state *fs)
{
    cdsp_real tot = R(0), prev;
    int j, i, J = (int)R_CEIL((fs->w / R(2) + R(4) * fs->sg) * R(FWD_SUB));
    if (J > FWD_NK / 2)
        J = FWD_NK / 2;
    if (J < 1)
        J = 1;
    fs->J = J;
    prev = fwd_cdf(-(cdsp_real)J / R(FWD_SUB), fs->sg, fs->w);
    for (j = 0; j < 2 * J; j++) {
        cdsp_real c = fwd_cdf((cdsp_real)(j - J + 1) / R(FWD_SUB), fs->sg, fs->w);
        ws->fwd_k[j] = c - prev;
        tot += c - prev;
        prev = c;
    }
    for (j = 0; j < 2 * J; j++)
        ws->fwd_k[j] /= tot;
    /* p_f(x_i) = sum over the pipe's cells k (s in [k, k + 1] / SUB) of
     * f_k times K's mass over x_i - that cell: cell i - k - 1 of K */
    /* p0 and p1 by running sums over K's cells j <= rel - 1 (cell j is
     * [j, j + 1] / SUB): p0 = sum M_j, p1 = sum (rel - j - 1/2) M_j / SUB;
     * p2 by the convolution with the cell means of sq */
    {
        cdsp_real S0 = R(0), S1 = R(0), sqT = R(0), qT = R(0);
        int jc = -J - 1, kT = 0;
        if (fs->T > R(0)) {
            sides geo;
            cdsp_real e;
            geo.Rc = fs->Rc;
            geo.St = R(0);
            kT = (int)R_FLOOR(fs->T * R(FWD_SUB));
            sqT = sq_at(&geo, fs->T);
            e = (cdsp_real)(kT + 1) / R(FWD_SUB);
            qT = (sq_int(&geo, e) - sq_int(&geo, fs->T) - sqT * (e - fs->T)) * R(FWD_SUB);
        }
        for (i = fs->i0; i <= fs->i1; i++) {
            int rel = i - FWD_IX, k0 = rel - J, k1 = rel + J - 1, k, jm = rel - 1 < J - 1 ? rel - 1 : J - 1;
            cdsp_real a2 = R(0);
            while (jc < jm) {
                jc++;
                S0 += ws->fwd_k[jc + J];
                S1 += (cdsp_real)jc * ws->fwd_k[jc + J];
            }
            if (k0 < 0)
                k0 = 0;
            if (fs->T > R(0)) {
                /* the lit part beyond the terminator, (sq(s) - sq(T))_+:
                 * the cells before T hold 0, the one across T its part */
                if (k0 < kT)
                    k0 = kT;
                for (k = k0; k <= k1; k++)
                    a2 += ws->fwd_k[rel - k - 1 + J] * (k == kT ? qT : ws->fwd_q[k] - sqT);
            } else {
                for (k = k0; k <= k1; k++)
                    a2 += ws->fwd_k[rel - k - 1 + J] * ws->fwd_q[k];
            }
            ws->fwd_p[0][i] = S0;
            ws->fwd_p[1][i] = (((cdsp_real)rel - R(0.5)) * S0 - S1) / R(FWD_SUB);
            ws->fwd_p[2][i] = a2;
        }
    }
}

/* the forward model's n <= 5 coefficients */
static int fwd_solve(cdsp_real N[5][5], cdsp_real r[5], int n)
{
    return gj_solve(&N[0][0], 5, r, n);
}

/* the basis row at bin position x (relative to d): 1, x, p0, p1, p2 */
static void fwd_row(const cdsp_profile_ws *ws, const fwd_state *fs, cdsp_real x, cdsp_real f[5])
{
    cdsp_real t = x * R(FWD_SUB) + R(FWD_IX), fr;
    int ii = (int)R_FLOOR(t), j;
    if (ii < fs->i0)
        ii = fs->i0;
    if (ii > fs->i1 - 1)
        ii = fs->i1 - 1;
    fr = t - (cdsp_real)ii;
    f[0] = R(1);
    f[1] = x;
    for (j = 0; j < 3; j++)
        f[2 + j] = ws->fwd_p[j][ii] + fr * (ws->fwd_p[j][ii + 1] - ws->fwd_p[j][ii]);
    if (fs->T > R(0)) {
        /* a limb in shadow: the background's slope E on the background
         * only (x - K * s_+), the lit part's ramp K * (s - T)_+ (p1 at
         * x - T; 0 below the grid) */
        f[1] = x - f[3];
        t = (x - fs->T) * R(FWD_SUB) + R(FWD_IX);
        ii = (int)R_FLOOR(t);
        if (ii < fs->i0) {
            f[3] = R(0);
        } else {
            fr = t - (cdsp_real)ii;
            f[3] = ws->fwd_p[1][ii] + fr * (ws->fwd_p[1][ii + 1] - ws->fwd_p[1][ii]);
        }
    }
}

/* The linear coefficients and the weighted residuals (into fwd_r[slot])
 * for fs's (d, sg, w); fs->rss. 0 when singular. basis 0: the grid
 * already holds fs's basis (the same sg, w and T as the last call's: a
 * step in d alone). */
static int fwd_eval_b(cdsp_profile_ws *ws, fwd_state *fs, int slot, int nc, int basis)
{
    cdsp_real N[5][5], r[5], y0 = R(0), f[5];
    const cdsp_real *ub = ws->mean_u, *mb = ws->mean_v;
    int b, i, j, first = 1;
    for (i = 0; i < 5; i++) {
        r[i] = R(0);
        for (j = 0; j < 5; j++)
            N[i][j] = R(0);
    }
    if (basis)
        fwd_basis(ws, fs);
    for (b = 0; b < NB; b++) {
        cdsp_real x = ub[b] - fs->d, w = (cdsp_real)ws->count[b], y;
        if (!ws->count[b] || R_FABS(x + fs->dw) > fs->Wf)
            continue;
        if (first) {
            y0 = mb[b]; /* the levels about the first bin's: conditioning */
            first = 0;
        }
        fwd_row(ws, fs, x, f);
        y = mb[b] - y0;
        for (i = 0; i < nc; i++) {
            for (j = 0; j < nc; j++)
                N[i][j] += w * f[i] * f[j];
            r[i] += w * f[i] * y;
        }
    }
    if (first || !fwd_solve(N, r, nc))
        return 0;
    r[0] += y0;
    fs->rss = R(0);
    for (b = 0; b < NB; b++) {
        cdsp_real x = ub[b] - fs->d, e = R(0);
        if (ws->count[b] && R_FABS(x + fs->dw) <= fs->Wf) {
            fwd_row(ws, fs, x, f);
            e = mb[b];
            for (i = 0; i < nc; i++)
                e -= r[i] * f[i];
            e *= R_SQRT((cdsp_real)ws->count[b]);
            fs->rss += e * e;
        }
        ws->fwd_r[slot][b] = e;
    }
    for (i = 0; i < 5; i++)
        fs->c[i] = i < nc ? r[i] : R(0);
    return 1;
}

static int fwd_eval_n(cdsp_profile_ws *ws, fwd_state *fs, int slot, int nc)
{
    return fwd_eval_b(ws, fs, slot, nc, 1);
}

static int fwd_eval(cdsp_profile_ws *ws, fwd_state *fs, int slot)
{
    return fwd_eval_n(ws, fs, slot, 5);
}

/* Levenberg-Marquardt on (d, sg, w^2 / 12) from cur (its Wf, grid and
 * the limb term's cell means set; slot 0 and cur.rss are the result's) */
static int fwd_lm(cdsp_profile_ws *ws, cdsp_real d0, cdsp_real half, int maxit, fwd_state *io)
{
    /* the steps of d, sg and the box's variance w^2 / 12 (px, px, px^2:
     * the variance, not w, whose derivative vanishes at w = 0) */
    static const cdsp_real step[3] = {R(0.01), R(0.01), R(0.01)};
    fwd_state cur = *io, trial;
    cdsp_real vb;
    cdsp_real lambda = R(1e-3);
    int k, it;
    if (!fwd_eval(ws, &cur, 0))
        return 0;
    for (it = 0; it < maxit; it++) {
        cdsp_real JJ[3][3], Jr[3], del[3] = {R(0), R(0), R(0)};
        int i, j, b, tries, acc = 0;
        /* the Jacobian by forward differences: slot 1 + k holds the
         * residuals at the step in d, sg, w (the step in d on cur's
         * basis, the grid's since the last accepted step) */
        for (k = 0; k < 3; k++) {
            trial = cur;
            if (k == 0)
                trial.d += step[0];
            else if (k == 1)
                trial.sg += step[1];
            else
                trial.w = R_SQRT(cur.w * cur.w + R(12) * step[2]);
            if (!fwd_eval_b(ws, &trial, 1 + k, 5, k != 0))
                return 0;
        }
        for (i = 0; i < 3; i++) {
            Jr[i] = R(0);
            for (j = 0; j < 3; j++)
                JJ[i][j] = R(0);
        }
        for (b = 0; b < NB; b++) {
            cdsp_real g[3], r0 = ws->fwd_r[0][b];
            for (i = 0; i < 3; i++)
                g[i] = (ws->fwd_r[1 + i][b] - r0) / step[i];
            for (i = 0; i < 3; i++) {
                Jr[i] += g[i] * r0;
                for (j = 0; j < 3; j++)
                    JJ[i][j] += g[i] * g[j];
            }
        }
        for (tries = 0; tries < 8 && !acc; tries++) {
            cdsp_real N[3][3], rr[3];
            for (i = 0; i < 3; i++) {
                for (j = 0; j < 3; j++)
                    N[i][j] = JJ[i][j];
                N[i][i] += lambda * (JJ[i][i] > R(0) ? JJ[i][i] : R(1));
                rr[i] = -Jr[i];
            }
            if (!solve_small(N, rr, 3))
                return 0;
            for (i = 0; i < 3; i++)
                del[i] = rr[i];
            trial = cur;
            trial.d += del[0];
            trial.sg += del[1];
            if (trial.sg < R(0.25))
                trial.sg = R(0.25);
            vb = cur.w * cur.w / R(12) + del[2];
            trial.w = vb > R(0) ? R_SQRT(R(12) * vb) : R(0);
            /* the window must hold the blurred edge and 3 px of each
             * side beyond it: a kernel wider than that makes the step's
             * columns collinear with the sides' (a 15 px motion blur at
             * 45 degrees went to a 18 px box and the contrast x 4) */
            if (R_FABS(trial.d - d0) > half / R(4) || trial.w / R(2) + R(3) * trial.sg > cur.Wf - R(3)) {
                lambda *= R(4);
                continue;
            }
            if (fwd_eval(ws, &trial, 1) && trial.rss < cur.rss) {
                acc = 1;
                cur = trial;
                for (b = 0; b < NB; b++)
                    ws->fwd_r[0][b] = ws->fwd_r[1][b];
                lambda /= R(3);
            } else {
                lambda *= R(4);
            }
        }
        if (!acc || R_FABS(del[0]) < R(1e-5))
            break;
    }
    *io = cur;
    return 1;
}

/* The forward model from the area balance's d and blur s2 over the window
 * |x| <= Wf (half - |d| - 1/4): from two starts, a Gaussian of that
 * variance and a box of it through a 0.8 px Gaussian (the optics and the
 * pixel's footprint), where the window holds them (fwd_lm); the better
 * fit. Returns 1 with *out fitted and its residuals in fwd_r[0]. */
static int fwd_fit(cdsp_profile_ws *ws, cdsp_real d0, cdsp_real s2, cdsp_real half, cdsp_real Rc,
                   fwd_state *out)
{
    fwd_state cur;
    sides geo;
    int k, kmax, start, have = 0;
    geo.Rc = Rc;
    geo.St = R(0);
    cur.d = d0;
    cur.dw = R(0);
    cur.T = R(0);
    cur.Rc = Rc;
    cur.Wf = half - R_FABS(d0) - R(0.25);
    if (!(cur.Wf >= R(4)))
        return 0;
    cur.i0 = FWD_IX - (int)R_CEIL((cur.Wf + R(1)) * R(FWD_SUB));
    cur.i1 = FWD_IX + (int)R_CEIL((cur.Wf + R(1)) * R(FWD_SUB));
    if (cur.i0 < 0 || cur.i1 >= FWD_NX)
        return 0;
    /* the limb term's cell means, sq's integral over each cell */
    kmax = cur.i1 - FWD_IX + FWD_NK / 2 + 1;
    if (kmax > CDSP_PROFILE_FWD_NQ)
        return 0;
    {
        cdsp_real prev = R(0);
        for (k = 0; k < kmax; k++) {
            cdsp_real c = sq_int(&geo, (cdsp_real)(k + 1) / R(FWD_SUB));
            ws->fwd_q[k] = (c - prev) * R(FWD_SUB);
            prev = c;
        }
    }
    for (start = 0; start < 2; start++) {
        fwd_state t = cur;
        t.d = d0;
        if (start == 0) {
            t.sg = R_SQRT(s2);
            t.w = R(0);
        } else {
            if (!(s2 > R(2) * R(0.64)))
                continue;
            t.sg = R(0.8);
            t.w = R_SQRT(R(12) * (s2 - R(0.64)));
        }
        /* a few rounds from each start, then on from the better */
        if (t.w / R(2) + R(3) * t.sg > t.Wf - R(3) || !fwd_lm(ws, d0, half, FWD_START_ROUNDS, &t))
            continue;
        if (!have || t.rss < out->rss) {
            *out = t;
            have = 1;
        }
    }
    if (have && !fwd_lm(ws, d0, half, 20, out))
        return 0;
    /* the better fit's residuals in slot 0 */
    return have && fwd_eval(ws, out, 0);
}


/* The forward model with a limb in shadow (a terminator T px beyond the
 * silhouette, the pipe side flat up to it: pipe_at's model, blurred):
 * from the fit without one (fs), T on a grid of 1/2 px over the window
 * with (d, sg, w) held, then by turns fwd_lm on (d, sg, w) with T held
 * and T on a finer grid about the best, T0 > 0 (the area balance's
 * terminator) on the grid too. Replaces *fs when the terminator lowers
 * the residuals beyond chance (F > 10 for its one parameter, as
 * fwd_limb) and beyond the 8-bit rounding's floor (fwd_limb's). */
static int fwd_terminator_fit(cdsp_profile_ws *ws, cdsp_real d0, cdsp_real half, cdsp_real T0, fwd_state *fs)
{
    /* three states (an MCU's stack): the best, and the trials lo, hi */
    fwd_state best = *fs, lo, hi;
    cdsp_real T, h, wsum = R(0), floor2, J = fs->c[2];
    int b, n = 0;
    for (b = 0; b < NB; b++)
        if (ws->count[b] && R_FABS(ws->mean_u[b] - fs->d) <= fs->Wf) {
            n++;
            wsum += (cdsp_real)ws->count[b];
        }
    if (n < 16)
        return 0;
    best.rss = R(-1);
    for (T = R(1); T <= fs->Wf - R(3); T += T < R(6) ? R(1) : R(2)) {
        lo = *fs;
        lo.T = T;
        if (fwd_lm(ws, d0, half, FWD_START_ROUNDS, &lo) && (best.rss < R(0) || lo.rss < best.rss))
            best = lo;
    }
    if (T0 > R(0) && T0 <= fs->Wf - R(3)) {
        lo = *fs;
        lo.T = T0;
        if (fwd_lm(ws, d0, half, FWD_START_ROUNDS, &lo) && (best.rss < R(0) || lo.rss < best.rss))
            best = lo;
    }
    if (!(best.rss >= R(0)) || !(best.rss < fs->rss))
        return 0;
    /* T and d are nearly collinear over the blur (moving T alone moves
     * the fit's d): each trial T with a few rounds of fwd_lm, and the
     * parabola through T - h, T, T + h */
    for (h = R(0.5); h > R(0.01); h /= R(2.5)) {
        cdsp_real den, Tn, r0, r2;
        lo = best;
        lo.T = best.T - h;
        hi = best;
        hi.T = best.T + h;
        if (!(lo.T > R(0)) || hi.T > fs->Wf - R(3) || !fwd_lm(ws, d0, half, FWD_TERM_ROUNDS, &lo) ||
            !fwd_lm(ws, d0, half, FWD_TERM_ROUNDS, &hi))
            continue;
        r0 = lo.rss;
        r2 = hi.rss;
        if (hi.rss < lo.rss)
            lo = hi; /* lo: the better trial; hi free for the parabola's */
        den = r0 - R(2) * best.rss + r2;
        if (den > R(0)) {
            Tn = best.T - h * (r2 - r0) / (R(2) * den);
            hi = best;
            hi.T = Tn;
            if (R_FABS(Tn - best.T) < h && fwd_lm(ws, d0, half, FWD_TERM_ROUNDS, &hi) && hi.rss < best.rss)
                best = hi;
        }
        if (lo.rss < best.rss)
            best = lo;
    }
    if (!fwd_lm(ws, d0, half, 20, &best) || !fwd_eval(ws, &best, 0))
        return 0;
    floor2 = R(FWD_TERM_RMS) * R(FWD_TERM_RMS) * J * J;
    if (floor2 < R(1) / R(12) / R(16))
        floor2 = R(1) / R(12) / R(16);
    if (!(fs->rss - best.rss > R(10) * best.rss / (cdsp_real)(n - 9) && fs->rss - best.rss > floor2 * wsum))
        return 0;
    *fs = best;
    return 1;
}

/* fwd_terminator_fit, and slot 0 back to fs's residuals when it keeps fs
 * (its trials overwrite slot 0) */
static void fwd_terminator(cdsp_profile_ws *ws, cdsp_real d0, cdsp_real half, cdsp_real T0, fwd_state *fs)
{
    if (!fwd_terminator_fit(ws, d0, half, T0, fs))
        (void)fwd_eval(ws, fs, 0);
}


/* Whether the forward model's limb term is significant: F-test of its fit
 * against the same kernel and silhouette without C (a straight pipe
 * side: there the area balance is exact whatever the kernel, and the
 * forward model's kernel only near the true one), F > 10 as model_solve's
 * test of the limb term, and the term explains a mean square of more
 * than (FWD_LIMB_RMS J)^2 (noise-free 16-bit flat sides under 15 px of
 * motion pass the F-test on the kernel's shape alone; a dark pipe's limb
 * there explained (0.06 % J)^2 and its area balance was 0.012 px off) and
 * than a sixteenth of a pixel's rounding, 1/12 / 16 gray levels^2 (on
 * noise-free 8-bit frames the rounding repeats along the contour and is
 * no noise: a flat side at 10 gray levels, optical blur 1.5, gave F 10-13
 * for 4e-4 gray levels^2, shaded ones 0.06-0.2, make bench-accuracy; the
 * pixels' noise is the F-test's: averaged over the rows, a sixteenth of
 * it had rejected the paper's shaded limbs at blur 2.5 px, 0.034 gray
 * levels^2 against a noise of 3.6).
 * Leaves fwd_r[0] with fs's residuals. */
static int fwd_limb(cdsp_profile_ws *ws, const fwd_state *fs)
{
    fwd_state t = *fs;
    cdsp_real wsum = R(0), J = fs->c[2], floor2;
    int b, n = 0;
    for (b = 0; b < NB; b++)
        if (ws->count[b] && R_FABS(ws->mean_u[b] - fs->d) <= fs->Wf) {
            n++;
            wsum += (cdsp_real)ws->count[b];
        }
    if (n < 12 || !fwd_eval_n(ws, &t, 1, 4))
        return 0;
    floor2 = R(FWD_LIMB_RMS) * R(FWD_LIMB_RMS) * J * J;
    if (floor2 < R(1) / R(12) / R(16))
        floor2 = R(1) / R(12) / R(16);
    return t.rss - fs->rss > R(10) * fs->rss / (cdsp_real)(n - 8) && t.rss - fs->rss > floor2 * wsum;
}

/* fit_chi2 of the forward model: its residuals over the whole window
 * (the blur zone included, where a kernel of the wrong shape shows), by
 * 1 px groups of x, against the bins' noise with the pixel's rounding and
 * the 0.2 % floor of model_solve's test */
static cdsp_real fwd_chi2(const cdsp_profile_ws *ws, const fwd_state *fs, cdsp_real var_pix)
{
    cdsp_real chi = R(0), gr = R(0), gc = R(0), J = fs->c[2];
    int b, g = -1, ng = 0;
    for (b = 0; b <= NB; b++) {
        cdsp_real x = b < NB ? ws->mean_u[b] - fs->d : R(0);
        int in = b < NB && ws->count[b] && R_FABS(x) <= fs->Wf, gb = in ? (int)R_FLOOR(x) : -1000;
        if (g != -1000 && gc > R(0) && (b == NB || (in && gb != g))) {
            cdsp_real r = gr / gc;
            chi += r * r / ((var_pix + R(1) / R(12)) / gc + R(4e-6) * J * J);
            ng++;
            gr = gc = R(0);
        }
        if (in) {
            cdsp_real w = (cdsp_real)ws->count[b];
            gr += R_SQRT(w) * ws->fwd_r[0][b]; /* w e: fwd_r holds sqrt(w) e */
            gc += w;
            g = gb;
        }
    }
    return ng > 8 ? chi / (cdsp_real)(ng - 8) : R(PROFILE_CHI2_UNCHECKED);
}

/* fwd_sigma's step in parameter k of fs (0 d, 1 sg, 2 the box's variance
 * w^2 / 12, 3 T; fwd_lm's steps) into fwd_r[slot], turned in place into
 * the derivative of the weighted residuals there against fwd_r[0], fs's.
 * basis 0: the grid holds fs's basis (a step in d). 0 when singular. */
static int fwd_deriv(cdsp_profile_ws *ws, const fwd_state *fs, int k, int slot, int basis)
{
    const cdsp_real h = R(0.01);
    fwd_state t = *fs;
    int b;
    if (k == 0) {
        t.d += h;
        t.dw = h; /* the same bins as fs's */
    } else if (k == 1) {
        t.sg += h;
    } else if (k == 2) {
        t.w = R_SQRT(fs->w * fs->w + R(12) * h);
    } else {
        t.T += h;
    }
    if (!fwd_eval_b(ws, &t, slot, 5, basis))
        return 0;
    for (b = 0; b < NB; b++)
        ws->fwd_r[slot][b] = (ws->fwd_r[slot][b] - ws->fwd_r[0][b]) / h;
    return 1;
}

/* sum over the bins of fwd_r[i] fwd_r[j] */
static cdsp_real fwd_dot(const cdsp_profile_ws *ws, int i, int j)
{
    cdsp_real s = R(0);
    int b;
    for (b = 0; b < NB; b++)
        s += ws->fwd_r[i][b] * ws->fwd_r[j][b];
    return s;
}

/* The forward fit's silhouette noise (its sigma_offset): the Gauss-Newton
 * covariance of its nonlinear parameters at the solution,
 * var_pix (J^T J)^-1, J the weighted residuals' derivatives in d, sg,
 * w^2 / 12 and, with a limb in shadow, T (fwd_deriv). The linear
 * coefficients are solved again at each step (variable projection), so
 * J^T J is the Schur complement of the full problem's normal matrix: the
 * nonlinear parameters' covariance with the linear ones free (Golub and
 * Pereyra 1973). d's variance is marginal over the rest: T and d are
 * nearly collinear over the blur. The window's end held (dw): a bin
 * crossing it in a 0.01 px step would be a jump of its residual (the
 * noise over 0.01 px), not a derivative. Until this the forward fit
 * reported the window's part alone (the area balance's varM), 2.5 times
 * too small under 3 px of blur (test_noise: z-scores' RMS 2.32, now
 * 0.88). The slots hold up to three
 * derivatives beside fs's residuals, so T's products come in a second
 * pass. 0 when J^T J is singular; fwd_r[0] keeps fs's residuals. */
static cdsp_real fwd_sigma(cdsp_profile_ws *ws, const fwd_state *fs, cdsp_real var_pix)
{
    cdsp_real N[4][4], r[4] = {R(1), R(0), R(0), R(0)};
    fwd_state t = *fs;
    int m = fs->T > R(0) ? 4 : 3, i, j;
    if (!fwd_eval(ws, &t, 0))
        return R(0);
    for (i = 0; i < 3; i++)
        if (!fwd_deriv(ws, fs, i, 1 + i, i != 0))
            return R(0);
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++)
            N[i][j] = fwd_dot(ws, 1 + i, 1 + j);
    if (m == 4) {
        /* T into slot 1 (d's), its products with sg and w; d again */
        if (!fwd_deriv(ws, fs, 3, 1, 1))
            return R(0);
        N[3][3] = fwd_dot(ws, 1, 1);
        N[1][3] = N[3][1] = fwd_dot(ws, 1, 2);
        N[2][3] = N[3][2] = fwd_dot(ws, 1, 3);
        if (!fwd_deriv(ws, fs, 0, 2, 1))
            return R(0);
        N[0][3] = N[3][0] = fwd_dot(ws, 1, 2);
    }
    if (!gj_solve(&N[0][0], 4, r, m) || !(r[0] > R(0)))
        return R(0);
    return R_SQRT(var_pix * r[0]);
}

/* The pixels' noise from the sides' bins: those at least z from the
 * silhouette d and within W (u[] the bins' positions), the per-pixel
 * variance pooled over them (c sumsq - sum^2 exact in 64 bits: c <= 4096
 * rows x 1 per bin); *varM that of the trapezoid sum over the window
 * (weights ~ the bin spacing). */
static cdsp_real side_noise(const cdsp_profile_ws *ws, const cdsp_real *u, cdsp_real d, cdsp_real z,
                            cdsp_real W, cdsp_real *varM)
{
    cdsp_real var_pix = R(0), dof = R(0);
    int b;
    for (b = 0; b < NB; b++) {
        cdsp_real x = u[b] - d;
        if (ws->count[b] > 1 && R_FABS(x) >= z && R_FABS(x) <= W) {
            uint64_t c = ws->count[b], sm = ws->sum[b], q = c * ws->sumsq[b] - sm * sm;
            var_pix += (cdsp_real)q / (cdsp_real)c;
            dof += (cdsp_real)c - R(1);
        }
    }
    if (dof > R(0))
        var_pix /= dof;
    *varM = R(0);
    for (b = 0; b < NB; b++)
        if (ws->count[b] && R_FABS(u[b] - d) <= W)
            *varM += var_pix / (cdsp_real)ws->count[b] / (cdsp_real)(BPP * BPP);
    return var_pix;
}

/* One round of the area balance as its last round left it, for
 * area_sigma: the sides fitted about d0 over z <= |u - d0| <= W with the
 * blur s2, the window [a, bb] of (1), the silhouette d it gave, and the
 * first moment's window [mlo, mhi] and step Jeff that gave the next blur */
typedef struct {
    cdsp_real d0, d, z, W, s2, a, bb, mlo, mhi, Jeff;
} area_round;

/* A bin's trapezoid weight in a sum over the samples in [lo, hi]: half the
 * gap to each neighbour there (prev, next: the neighbouring non-empty
 * bins, -1 / NB for none; the bins' u rise with their index) */
static cdsp_real trap_weight(const cdsp_real *ub, int prev, int b, int next, cdsp_real lo, cdsp_real hi)
{
    cdsp_real t = R(0);
    if (ub[b] < lo || ub[b] > hi)
        return t;
    if (prev >= 0 && ub[prev] >= lo)
        t += (ub[b] - ub[prev]) / R(2);
    if (next < NB && ub[next] <= hi)
        t += (ub[next] - ub[b]) / R(2);
    return t;
}

/* The noise of the area balance's silhouette, px (docs/method.md 2a). At
 * its solution F(d; y) = 0, with y the bins' means,
 *     F = int_uf^d (D + E x) du + int_0^(ul - d) P(s) ds
 *         + (s2/2)(P'(bb - d) - E) - trap(y; uf .. ul),
 * uf and ul the first and last bins in the window [a, bb] (the trapezoid
 * sum's end pieces are the models' own and cancel), so to first order
 *     dd = -(sum_i F_i dy_i + F_s2 ds2) / F_d,
 * F_d = D - P(bb - d) (the Newton step's derivative),
 *     F_i = -t_i + w_i f_i' Nb^-1 cb + w_i f_i' Np^-1 cp,
 * t_i the bin's trapezoid weight, f_i its basis in the side's fit (weights
 * w_i = counts, normal matrices Nb, Np as fit_sides forms them) and cb, cp
 * F's derivatives in the fits' coefficients: the sides' noise enters d
 * through their extrapolation to the silhouette, which the trapezoid
 * sum's weights alone (the estimate before) leave out (6 times too small
 * on test_profile.c's flat edge). The blur is measured on the same bins,
 * s2 = -2 mom / Jeff with mom = trap((u - d)(y - S)) over [mlo, mhi] (S
 * the sides' models, so their noise too), and enters through the blur
 * term and the pipe basis's (s2/2) sq'' (F_s2 below; small: -0.012 to
 * -0.016 px per px^2 of s2 on test_noise's lit limbs). Held: the
 * terminator, Jeff's noise (1 % of it at contrast 100 and noise 2), the
 * zones' edges. Independent bins (each pixel is in one) of variance
 * var_pix / count. This is one round's response, the sides fitted about
 * d0; area_solve divides it by 1 - rho, the rounds' contraction. */
static cdsp_real area_sigma(const cdsp_profile_ws *ws, const cdsp_real *ub, const cdsp_real *hb, const sides *m,
                            const area_round *rd, cdsp_real var_pix)
{
    const cdsp_real d0 = rd->d0, d = rd->d, z = rd->z, W = rd->W, s2 = rd->s2;
    cdsp_real Nb[3][3] = {{0}}, Np[3][3] = {{0}}, Nb2[3][3], Np2[3][3], vb[3], vp[3], fc[3], xb = -(z + W) / R(2), cm;
    cdsp_real momb[3] = {0, 0, 0}, momp[3] = {0, 0, 0};
    cdsp_real uf = R(0), ul = R(0), var = R(0), Fd, Fs2, X, e, q;
    pipe_kink k;
    int b, i, j, prev, nbg = 0, npp = 0, have = 0;
    pipe_kink_at(m, s2, &k);
    pipe_basis(m, (z + W) / R(2), s2, fc);
    cm = sq_curv(m, (z + W) / R(2));
    for (b = 0; b < NB; b++) {
        cdsp_real x = ub[b] - d0, f[3], w = (cdsp_real)ws->count[b];
        if (!ws->count[b])
            continue;
        if (ub[b] >= rd->a && ub[b] <= rd->bb) {
            if (!have)
                uf = ub[b];
            ul = ub[b];
            have = 1;
        }
        if (x >= z && x <= W) {
            pipe_basis_h(m, x, hb[b], &k, f);
            f[1] -= fc[1];
            f[2] -= fc[2];
            for (i = 0; i < 3; i++)
                for (j = 0; j < 3; j++)
                    Np[i][j] += w * f[i] * f[j];
            npp++;
        } else if (x <= -z && x >= -W) {
            f[0] = R(1);
            f[1] = x - xb;
            for (i = 0; i < 2; i++)
                for (j = 0; j < 2; j++)
                    Nb[i][j] += w * f[i] * f[j];
            nbg++;
        }
    }
    if (!have || nbg < 3 || npp < 4 || !(R_FABS(rd->Jeff) > R(0)))
        return R(0);
    /* cb: dF/dD, dF/dE (the background D + E x), in the fit's basis
     * (1, x - xb): D = c0 - c1 xb, E = c1 */
    vb[0] = d - uf;
    vb[1] = ((d - d0) * (d - d0) - (uf - d0) * (uf - d0)) / R(2) - s2 / R(2);
    vb[1] -= vb[0] * xb;
    /* cp: dF/dA, dB, dC (pipe_int to ul - d, pipe_slope at bb - d), in
     * the fit's basis (1, f1 - fc1, f2 - fc2): A = c0 - c1 fc1 - c2 fc2 */
    X = ul - d > R(0) ? ul - d : R(0);
    e = X - m->St;
    vp[0] = X;
    vp[1] = e > R(0) ? e * e / R(2) : R(0);
    vp[2] = e > R(0) ? sq_int(m, X) - sq_int(m, m->St) - sq_at(m, m->St) * e : R(0);
    X = rd->bb - d;
    q = sq_at(m, X);
    if (X > m->St) {
        vp[1] += s2 / R(2);
        vp[2] += q > R(0) ? s2 / R(2) * (m->Rc - X) / q : R(0);
    }
    vp[1] -= vp[0] * fc[1];
    vp[2] -= vp[0] * fc[2];
    /* the moment's model part: mom holds -sum_i tm_i (u_i - d) S(u_i)
     * over its window, S the background's (basis as in its fit) or the
     * pipe's (unblurred: pipe_at, in the fit's basis less its centre) */
    for (b = 0, prev = -1; b < NB; b++) {
        cdsp_real t, f[3], s_;
        int nx;
        if (!ws->count[b])
            continue;
        for (nx = b + 1; nx < NB && !ws->count[nx]; nx++)
            ;
        t = trap_weight(ub, prev, b, nx, rd->mlo, rd->mhi) * (ub[b] - d);
        prev = b;
        if (t == R(0))
            continue;
        if (ub[b] < d) {
            momb[0] += t;
            momb[1] += t * (ub[b] - d0 - xb);
            continue;
        }
        s_ = ub[b] - d;
        f[1] = s_ > m->St ? s_ - m->St : R(0);
        f[2] = s_ > m->St ? sq_at(m, s_) - sq_at(m, m->St) : R(0);
        momp[0] += t;
        momp[1] += t * (f[1] - fc[1]);
        momp[2] += t * (f[2] - fc[2]);
    }
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) {
            Nb2[i][j] = Nb[i][j];
            Np2[i][j] = Np[i][j];
        }
    if (!solve_small(Nb, vb, 2) || !solve_small(Np, vp, 3) || !solve_small(Nb2, momb, 2) ||
        !solve_small(Np2, momp, 3))
        return R(0);
    Fd = m->D + m->E * (d - d0) - pipe_at(m, rd->bb - d);
    if (!(R_FABS(Fd) > R(0)))
        return R(0);
    /* F_s2: the blur term's (P'(bb - d) - E) / 2, and through the pipe
     * fit, whose basis holds (s2/2) sq'' beyond the terminator: d theta /
     * d s2 = -Np^-1 sum_j w_j f_j (C/2)(sq''(x_j) - sq''(mid)) (the
     * residuals' part is noise times noise) */
    Fs2 = (pipe_slope(m, rd->bb - d) - m->E) / R(2);
    for (b = 0; b < NB; b++) {
        cdsp_real x = ub[b] - d0, f[3];
        if (!ws->count[b] || !(x >= z && x <= W && x > m->St))
            continue;
        pipe_basis_h(m, x, hb[b], &k, f);
        Fs2 -= (cdsp_real)ws->count[b] * (vp[0] + (f[1] - fc[1]) * vp[1] + (f[2] - fc[2]) * vp[2]) * m->C / R(2) *
               (sq_curv(m, x) - cm);
    }
    /* the sum over the bins of (dd/dy_i)^2 / count, with
     * ds2/dy_i = -2 tm_i (u_i - d) / Jeff, tm_i the moment's weight */
    for (b = 0, prev = -1; b < NB; b++) {
        cdsp_real g, gm, x = ub[b] - d0, f[3], w = (cdsp_real)ws->count[b];
        int nx;
        if (!ws->count[b])
            continue;
        for (nx = b + 1; nx < NB && !ws->count[nx]; nx++)
            ;
        g = -trap_weight(ub, prev, b, nx, uf, ul);
        gm = trap_weight(ub, prev, b, nx, rd->mlo, rd->mhi) * (ub[b] - d); /* d mom / d y_b */
        if (x >= z && x <= W) {
            pipe_basis_h(m, x, hb[b], &k, f);
            g += w * (vp[0] + (f[1] - fc[1]) * vp[1] + (f[2] - fc[2]) * vp[2]);
            gm -= w * (momp[0] + (f[1] - fc[1]) * momp[1] + (f[2] - fc[2]) * momp[2]);
        } else if (x <= -z && x >= -W) {
            g += w * (vb[0] + (x - xb) * vb[1]);
            gm -= w * (momb[0] + (x - xb) * momb[1]);
        }
        g -= Fs2 * R(2) * gm / rd->Jeff;
        var += g * g / w;
        prev = b;
    }
    return R_SQRT(var * var_pix) / R_FABS(Fd);
}

/* The model on the bins: silhouette d (px from the line toward the pipe),
 * blur, contrast, noise of d. *s2_start receives the first blur (from the
 * profile's slope) before the area balance's rounds, which can fail. */
static cdsp_status area_solve(cdsp_profile_ws *ws, cdsp_real half, cdsp_real radius_px, int forward,
                              cdsp_profile *out, cdsp_real *s2_start)
{
    cdsp_real *ub = ws->mean_u, *mb = ws->mean_v;
    /* start from a wide blur (fit zones at the window's ends), then adapt */
    cdsp_real d = R(0), s2 = (half / R(6)) * (half / R(6)), var_pix = R(0), varM = R(0);
    sides m;
    int b, it, ok = 0, clamped = 0, search, grid_seen = 0, grid_improved = 0, improved, nmv = 0;
    cdsp_real mv[2] = {0, 0};
    cdsp_real grid_d = R(0), grid_sig = R(0), s2_first, s2f;
    area_round rd = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0}; /* the last round, for area_sigma */
    fwd_state fs;
    m.Rc = radius_px;
    m.St = R(0);
    cdsp_real z = R(0), W = R(0), J = R(0);
    for (b = 0; b < NB; b++)
        if (ws->count[b]) {
            ub[b] = ws->sum_u[b] / (cdsp_real)ws->count[b];
            mb[b] = (cdsp_real)ws->sum[b] / (cdsp_real)ws->count[b];
        } else {
            ub[b] = mb[b] = R(0);
        }
    {
        /* A first blur from the profile's slope: the edge is where the
         * bins' differences peak, and their full width at half that peak
         * is 2.355 sigma for a Gaussian (1.5 sigma too wide for a motion
         * blur's box, the safe side: the iteration below narrows the blur
         * zone from there). The wide start (sigma = half / 6) stays when
         * that is wider. */
        cdsp_real peak = R(0), xl = R(0), xr = R(0), pu = R(0), pv = R(0), ppos = R(0), sgn = R(0);
        int prev = -1, pk = -1, k, have_l = 0, have_r = 0;
        /* the step's sign from either side of the line (within 3 px): a
         * limb's shading can slope the other way, and more steeply, next
         * to a dark pipe's silhouette (a 15 px motion blur's first blur
         * came out 1.5 px from that slope's peak, and the fit diverged) */
        for (b = 0; b < NB; b++)
            if (ws->count[b] && R_FABS(ub[b]) >= R(0.5) && R_FABS(ub[b]) <= R(3))
                sgn += ub[b] > R(0) ? mb[b] : -mb[b];
        for (k = 0; k < 2; k++)
            for (b = 0, prev = -1; b < NB; b++) {
                cdsp_real dv, xm;
                if (!ws->count[b])
                    continue;
                if (prev < 0 || !(ub[b] > pu)) {
                    prev = b;
                    pu = ub[b];
                    pv = mb[b];
                    continue;
                }
                dv = (mb[b] - pv) / (ub[b] - pu);
                xm = (ub[b] + pu) / R(2);
                if (k == 0 && R_FABS(xm) < half / R(2) && dv * sgn > R(0) && R_FABS(dv) > R_FABS(peak)) {
                    peak = dv;
                    ppos = xm;
                    pk = b;
                }
                /* k = 1: the half-peak crossings nearest the peak */
                if (k == 1 && xm < ppos && dv * peak < peak * peak / R(2)) {
                    xl = xm;
                    have_l = 1;
                }
                if (k == 1 && xm > ppos && dv * peak < peak * peak / R(2) && !have_r) {
                    xr = xm;
                    have_r = 1;
                }
                prev = b;
                pu = ub[b];
                pv = mb[b];
            }
        if (pk >= 0 && have_l && have_r) {
            cdsp_real v = (xr - xl) / R(2.355);
            v *= v;
            if (v < R(1) / R(12))
                v = R(1) / R(12);
            if (v < s2)
                s2 = v;
        }
    }
    s2_first = s2;
    *s2_start = s2;
    for (it = 0; it < 8; it++) {
        cdsp_real a, bb, bm, M, dn = d, d_prev = d, mom;
        int k;
        /* the blur zone: 3.5 sigma (a Gaussian's tail there is 2e-4 of the
         * step) plus the pixel footprint */
        z = R(3.5) * R_SQRT(s2) + R(1.5);
        W = half - R_FABS(d) - R(0.25);
        if (z > W - R(3))
            z = W - R(3);
        if (W > z + R(PROFILE_FIT_ZONE))
            W = z + R(PROFILE_FIT_ZONE);
        /* (ws->sum_u, read into ub above, holds fit_sides's h(x) per bin).
         * The terminator's grid in the first three rounds, but not again
         * where the last grid lowered the lit model's RSS nowhere and the
         * silhouette and the blur have since moved by less than 0.02 px:
         * the same zone, the same bins, the same outcome (the flat sides
         * of the paper's scene; a grid is ~16 fits, 2/3 of the fit's
         * cost). Not on its first outcome alone: on noise-free shadowed
         * limbs (make bench-accuracy) the first round's wide blur hid the
         * terminator that the second found. */
        search = it < 3;
        if (search && grid_seen && !grid_improved && R_FABS(d - grid_d) < R(0.02) &&
            R_FABS(R_SQRT(s2) - grid_sig) < R(0.02))
            search = 0;
        /* a terminator found in an earlier round: searched again +- 1 px
         * about it, not on the grid again */
        if (search && m.St > R(0))
            search = 2;
        if (!(z >= R(1)) || !fit_sides(ws, ub, mb, ws->sum_u, ws->fwd_r, d, z, W, s2, search, &m, &improved))
            return CDSP_E_NOCONVERGE;
        if (search == 1) {
            grid_improved = improved;
            grid_seen = 1;
            grid_d = d;
            grid_sig = R_SQRT(s2);
        }
        a = d - W;
        /* a limb in shadow: the window ends on its flat part, clear of the
         * terminator's blurred kink (3.5 sigma), so that (1) and the
         * moment see a flat pipe side; the lit part beyond only placed
         * the terminator. A shadow too short for that keeps the whole
         * window: (1) holds with the kink's blur inside it too */
        bb = d + (m.St > R(0) && m.St - R(3.5) * R_SQRT(s2) >= z ? m.St - R(3.5) * R_SQRT(s2) : W);
        M = integrate(ws, ub, mb, &m, d, d, a, bb, 0);
        rd.d0 = d;
        rd.s2 = s2;
        rd.z = z;
        rd.W = W;
        rd.a = a;
        rd.bb = bb;
        /* Newton on G(dn) = M, (1) with the sides fixed about d:
         * G = int_a^dn bg + int_0^(bb-dn) P + (s2/2)(P'(bb - dn) - E) */
        for (k = 0; k < 6; k++) {
            cdsp_real X = bb - dn, G, dG;
            if (!(X > R(0)))
                return CDSP_E_NOCONVERGE;
            G = m.D * (dn - a) + m.E * ((dn - d) * (dn - d) - (a - d) * (a - d)) / R(2) +
                pipe_int(&m, X) + s2 / R(2) * (pipe_slope(&m, X) - m.E);
            dG = m.D + m.E * (dn - d) - pipe_at(&m, X);
            if (!(R_FABS(dG) > R(0)))
                return CDSP_E_NOCONVERGE;
            dn -= (G - M) / dG;
            if (!R_FINITE(dn) || R_FABS(dn) > half / R(2))
                return CDSP_E_NOCONVERGE;
        }
        d = dn;
        J = m.A - (m.D + m.E * (d - d_prev));
        /* the blur from the first moment about the new silhouette, over
         * |u - d| <= zm = 4.5 sigma + 2 (the blur zone and a margin: a
         * Gaussian's moment beyond 4.5 sigma is 1e-4 of it): beyond, O - S
         * is only noise, weighted by (u - d); over the whole window the
         * noise of the blur was ~6 times larger (the weights' cube,
         * (20 / 6)^3 at blur 0.85 px) */
        {
            cdsp_real zm = R(4.5) * R_SQRT(s2) + R(2);
            if (zm > bb - d)
                zm = bb - d;
            if (zm > d - a)
                zm = d - a;
            /* the window's pipe end on the last sample in it, so that
             * the trapezoid sum covers it exactly (O - S is not 0 there on
             * a limb; at 0 degrees the samples are 1 px apart) */
            bm = d;
            for (k = 0; k < NB; k++)
                if (ws->count[k] && ub[k] <= d + zm && ub[k] > bm)
                    bm = ub[k];
            mom = integrate(ws, ub, mb, &m, d_prev, d, d - zm, bm, 1);
            rd.d = d;
            rd.mlo = d - zm;
            rd.mhi = bm;
        }
        {
            /* int (u - d)(O - S) = -s2/2 (J - int_0^X s S''(s) ds), the
             * second part from the limb's curvature: X P'(X) - (P(X) - P(0));
             * still inflated by ~20 % on a strongly shaded limb (the
             * Taylor form of the blur is poor next to the square root) */
            cdsp_real X = bm - d, Jeff = J - (X * pipe_slope(&m, X) - (pipe_at(&m, X) - m.A));
            if (!(R_FABS(Jeff) > R(0)))
                return CDSP_E_NOCONVERGE;
            rd.Jeff = Jeff;
            s2 = R(-2) * mom / Jeff;
            if (!(s2 >= R(1) / R(12)))
                s2 = R(1) / R(12);
            clamped = s2 > (half / R(4)) * (half / R(4));
            if (clamped)
                s2 = (half / R(4)) * (half / R(4));
        }
        if (!search) {
            /* the rounds' moves once the terminator is held: their ratio
             * is the rounds' contraction (area_sigma's rho) */
            mv[0] = mv[1];
            mv[1] = d - d_prev;
            nmv++;
        }
        if (it >= 2 && R_FABS(d - d_prev) < R(1e-4)) {
            ok = 1;
            break;
        }
    }
    (void)ok; /* the last iterate stands: at most 1e-3 px from converged in the study
                 (faint 8-bit edges whose rounds do not settle are caught by
                 cdsp_profile_applies's bound on the move) */
    /* noise: per-pixel variance from the sides' bins, then that of the
     * trapezoid sum (weights ~ bin spacing) */
    var_pix = side_noise(ws, ub, d, z, W, &varM);
    out->offset = d;
    out->blur = R_SQRT(s2);
    out->contrast = J;
    /* sigma_offset: the propagation through the sides (area_sigma) where
     * the move may be used (forward: cdsp_profile_fit, the frame path with
     * the model on); the frame path's bound alone (model off) reads no
     * sigma and keeps the window's part, at 1/40 of the cost (area_sigma:
     * ~41 K instructions a contour on the paper's frame, callgrind) */
    out->sigma_offset = R(0);
    if (forward) {
        /* area_sigma is one round's response to the bins' noise, the
         * sides fitted about the last d. The rounds are a fixed point
         * d = Phi(d, y) whose contraction rho = dPhi/dd is not 0 on a
         * shaded limb (the sides refitted about a moved silhouette, the
         * blur measured about it): 0.3 on test_noise's lit limbs, from the
         * ratio of successive moves, so the solution's noise is the
         * round's over 1 - rho (test_noise's lit limb at 0 degrees: 0.66
         * -> 1.01 of the offset's scatter over 64 seeds). The
         * ratio is read where the moves are clear of rounding (1e-6 px)
         * and kept within [0, 0.8] (the zones' bins make it jump); rounds
         * that did not settle add their last move (a cycle between two
         * zones' bins, d's spread along it). A negative ratio is that
         * cycle, moves alternating as d crosses a bin, not the fixed
         * point's contraction: over test_noise's rows it came on 157 of
         * 226 seeds whose rounds did not settle, 10 of 303 that did, and
         * read as rho it shrank their sigma by up to 1.8 (z-scores' RMS
         * 1.87 on those seeds of the lit limb at 5 degrees, 0.99 on the
         * others). */
        cdsp_real rho = R(0), sg = area_sigma(ws, ub, ws->sum_u, &m, &rd, var_pix);
        if (nmv >= 2 && R_FABS(mv[0]) > R(1e-6))
            rho = mv[1] / mv[0];
        if (rho > R(0.8))
            rho = R(0.8);
        if (rho < R(0))
            rho = R(0);
        sg /= R(1) - rho;
        if (!ok)
            sg = R_SQRT(sg * sg + mv[1] * mv[1]);
        out->sigma_offset = sg;
    }
    if (!(out->sigma_offset > R(0))) /* or too few bins for the sides' part */
        out->sigma_offset = R_FABS(J) > R(0) ? R_SQRT(varM) / R_FABS(J) : R(0);
    out->half_width = W;
    out->shadow = m.St;
    out->noise = R_SQRT(var_pix);
    out->blur_clamped = clamped;
    {
        /* the pipe side's fit quality: chi-square per bin against the
         * bins' own noise (var_pix / count) */
        cdsp_real chi = R(0), gr = R(0), gc = R(0);
        int nb = 0, ng = 0, g = -1;
        for (b = 0; b <= NB; b++) {
            cdsp_real x = b < NB ? ub[b] - d : R(0);
            int in = b < NB && ws->count[b] && x >= z && x <= W, gb = in ? (int)R_FLOOR(x / R(PROFILE_CHI2_GROUP)) : -1;
            if (g >= 0 && (b == NB || (in && gb != g))) {
                /* the group's mean residual against its noise, with a
                 * pixel's rounding (1/12 of a gray level squared, which a
                 * bin whose pixels share one phase does not show in
                 * var_pix), floored at 0.2 % of the step: a model error
                 * that small is not a misfit. (Noise-free frames, var_pix
                 * 0: before issue 12's bound a misfit there came out as
                 * fit_chi2 0.) */
                cdsp_real r = gr / gc;
                chi += r * r / ((var_pix + R(1) / R(12)) / gc + R(4e-6) * J * J);
                ng++;
                gr = gc = R(0);
                g = -1;
            }
            if (in) {
                /* the residuals by PROFILE_CHI2_GROUP px of u, count
                 * weighted: near a rational slope the contour's pixel
                 * phases drift slowly along it, each bin takes its pixels
                 * from a few stretches of the contour, and the limb's
                 * shading that changes along a pipe in perspective
                 * (directional light) is a ripple from bin to bin at the
                 * pixel lattice's spacing (0.71 px at 45 degrees), not a
                 * misfit of the model: +-0.3 gray levels on the paper's
                 * scene at ambient 0.85 (fit_chi2 0.98 per bin with a
                 * line 0.012 px off that the model moved to 0.002). A
                 * misfit of the side model (a terminator, a plateau's
                 * kink, a stripe) spans the blur at least and stays. */
                cdsp_real w = (cdsp_real)ws->count[b];
                gr += w * (mb[b] - pipe_fitted(&m, x, s2));
                gc += w;
                g = gb;
                nb++;
            }
        }
        /* fewer than 4 bins beyond the blur zone: the pipe side is not
         * checked at all, which is no evidence of a fit (a 15 px motion
         * blur's zone filling the window had fit_chi2 0 and moved the
         * line 6.6 px off, make bench-accuracy) */
        out->fit_chi2 = nb > 3 ? chi / (cdsp_real)(ng > 4 ? ng - 3 : 1) : R(PROFILE_CHI2_UNCHECKED);
    }
    {
        /* Is the pipe side's limb term significant? F-test of the model
         * against a straight pipe side A + B s (the detector's second pass
         * is exact for straight sides): F = (RSS_line - RSS_model) /
         * (RSS_model / dof); 10 is far beyond chance for one parameter. */
        cdsp_real S0 = 0, S1 = 0, S2 = 0, T0 = 0, T1 = 0, T2 = 0, rss_m = 0, det, bl, al;
        int nbin = 0;
        for (b = 0; b < NB; b++) {
            cdsp_real x = ub[b] - d, w = (cdsp_real)ws->count[b], r, y;
            if (!ws->count[b] || x < z || x > W)
                continue;
            y = mb[b] - mb[NB / 2 + (int)(z * R(BPP))]; /* a level near the zone: conditioning */
            S0 += w;
            S1 += w * x;
            S2 += w * x * x;
            T0 += w * y;
            T1 += w * x * y;
            T2 += w * y * y;
            r = mb[b] - pipe_fitted(&m, x, s2);
            rss_m += w * r * r;
            nbin++;
        }
        det = S0 * S2 - S1 * S1;
        out->flat = 1;
        if (nbin > 4 && det > R(0)) {
            cdsp_real rss_l;
            bl = (S0 * T1 - S1 * T0) / det;
            al = (T0 - bl * S1) / S0;
            rss_l = T2 - al * T0 - bl * T1; /* residual of the weighted line fit */
            if (rss_m > R(0) && rss_l - rss_m > R(10) * rss_m / (cdsp_real)(nbin - 3))
                out->flat = 0;
        }
    }
    /* the first moment's blur at its floor (1/12, the pixel's footprint)
     * under a wide edge: on a faint limb under strong shading (10 gray
     * levels, ambient 0.3) the moment went negative; the profile's slope
     * (s2_first) still says how wide the edge is */
    if (s2 <= R(1) / R(12) && s2_first > s2)
        s2f = s2_first;
    else
        s2f = s2;
    if (forward && R_SQRT(s2f) > R(FWD_MIN_BLUR) && !(m.St > R(0)) && !clamped &&
        fwd_fit(ws, d, s2f, half, radius_px, &fs) &&
        (fwd_chi2(ws, &fs, var_pix) <= R(FWD_TERM_CHI2) || (fwd_terminator(ws, d, half, m.St, &fs), 1)) &&
        fwd_limb(ws, &fs)) {
        /* a blur wider than the detector's window on a lit, shaded limb:
         * the forward model (fwd_fit) in place of the area balance, whose
         * pipe side is extrapolated over the blur zone. A straight pipe
         * side that fits at least as well keeps the area balance, exact
         * there whatever the kernel (noise-free 8-bit flat sides at 45
         * degrees under 7 px of motion: the footprint's trapezoid is no
         * Gaussian, the limb term took up the difference with fit_chi2
         * 0.29 and the area balance's line, 0.003 px off, was lost), when
         * its fit zone is wide enough to tell a limb (FWD_AREA_ZONE px;
         * under 15 px of motion 3 px are left, and shaded limbs there
         * passed for straight with the line 0.013-0.06 px off). Nor does
         * a forward fit that misfits (fit_chi2 > FWD_MISFIT_CHI2, 20 x
         * max_fit_chi2's default) replace an area balance that misfits
         * less (limbs in shadow whose terminator the detector took, 7-9 px
         * off: the bound's |offset| and blur are the better fit's) */
        cdsp_real chi_f = fwd_chi2(ws, &fs, var_pix);
        if (!(out->flat && out->fit_chi2 <= chi_f && W - z >= R(FWD_AREA_ZONE)) &&
            (chi_f <= R(FWD_MISFIT_CHI2) || chi_f <= out->fit_chi2)) {
            out->offset = fs.d;
            out->blur = R_SQRT(fs.sg * fs.sg + fs.w * fs.w / R(12));
            out->contrast = fs.c[2];
            out->half_width = fs.Wf;
            out->fit_chi2 = chi_f;
            out->shadow = fs.T;
            out->flat = 0;
            out->sigma_offset = fwd_sigma(ws, &fs, var_pix);
            if (!(out->sigma_offset > R(0)) && R_FABS(fs.c[2]) > R(0))
                out->sigma_offset = R_SQRT(varM) / R_FABS(fs.c[2]);
        }
    }
    return CDSP_OK;
}

/* Where the area balance's rounds fail (a faint limb under strong
 * shading, a shadow whose terminator outweighs the silhouette's step:
 * Newton's G' vanished or d ran off), the forward model alone, from the
 * line (d = 0) and the profile's first blur s2, with its terminator
 * search; the pipe side's noise from the bins beyond its blur zone
 * (3.5 sigma + 1.5 px, as the area balance's). Its fit_chi2 decides
 * whether the line moves (cdsp_profile_applies). */
static cdsp_status fwd_alone(cdsp_profile_ws *ws, cdsp_real half, cdsp_real radius_px, cdsp_real s2,
                             cdsp_profile *out)
{
    fwd_state fs;
    cdsp_real var_pix = R(0), varM = R(0), z, blur;
    int b;
    if (!fwd_fit(ws, R(0), s2, half, radius_px, &fs))
        return CDSP_E_NOCONVERGE;
    {
        /* an edge at all: the step lowers the residuals of the sides'
         * line D + E x beyond chance and the 8-bit rounding's floor (a
         * frame without an edge must not report one) */
        cdsp_real wsum = R(0), rss = fs.rss;
        int n = 0;
        for (b = 0; b < NB; b++)
            if (ws->count[b] && R_FABS(ws->mean_u[b] - fs.d) <= fs.Wf) {
                n++;
                wsum += (cdsp_real)ws->count[b];
            }
        /* fs itself for the line's fit, then back (one state less on an
         * MCU's stack) */
        if (n < 16 || !fwd_eval_n(ws, &fs, 1, 2) || !(fs.rss - rss > R(10) * rss / (cdsp_real)(n - 8)) ||
            !(fs.rss - rss > wsum / R(12) / R(16)) || !fwd_eval(ws, &fs, 0))
            return CDSP_E_NOCONVERGE;
    }
    fwd_terminator(ws, R(0), half, R(0), &fs);
    blur = R_SQRT(fs.sg * fs.sg + fs.w * fs.w / R(12));
    z = R(3.5) * blur + R(1.5) + fs.w / R(2);
    var_pix = side_noise(ws, ws->mean_u, fs.d, z, fs.Wf, &varM);
    out->offset = fs.d;
    out->blur = blur;
    out->contrast = fs.c[2];
    out->sigma_offset = fwd_sigma(ws, &fs, var_pix);
    if (!(out->sigma_offset > R(0)))
        out->sigma_offset = R_FABS(fs.c[2]) > R(0) ? R_SQRT(varM) / R_FABS(fs.c[2]) : R(0);
    out->half_width = fs.Wf;
    out->shadow = fs.T;
    out->noise = R_SQRT(var_pix);
    out->blur_clamped = 0;
    out->flat = 0;
    out->fit_chi2 = fwd_chi2(ws, &fs, var_pix);
    return CDSP_OK;
}

static cdsp_status model_solve(cdsp_profile_ws *ws, cdsp_real half, cdsp_real radius_px, int forward,
                               cdsp_profile *out)
{
    cdsp_real s2 = R(0);
    cdsp_status st = area_solve(ws, half, radius_px, forward, out, &s2);
    if (st == CDSP_E_NOCONVERGE && forward)
        st = fwd_alone(ws, half, radius_px, s2, out);
    return st;
}

/* Any bin within a gray level of full scale (255, 4095, 65535): a
 * saturation plateau, which no side model here describes. */
static int saturated(const cdsp_profile_ws *ws, const cdsp_image *img)
{
    uint32_t full = (1u << img->bits) - 1u;
    int b;
    for (b = 0; b < NB; b++)
        if (ws->count[b] && ws->sum[b] >= (full - 1u) * ws->count[b])
            return 1;
    return 0;
}

/* Whether the fitted model describes the edge (cdsp_profile_applies and
 * cdsp_profile_bound): it fits (not a shadowed limb, a highlight, a
 * plateau, an edge spread wider than the window holds), and its move is
 * one a blur explains: the detector's line is off by at most ~0.7 blur
 * sigma on a shaded limb (0.3-0.5 px at 0.76 px) and ~1 sigma under a
 * motion blur wider than its window (4.2 px at 4.4 px); the model moved
 * faint 8-bit lines by 1.4-10 px where its rounds had not settled (make
 * bench's accuracy study). */
static int model_describes(const cdsp_profile *pr, const cdsp_profile_params *pp)
{
    return pr->fit_chi2 <= pp->max_fit_chi2 && !pr->saturated && !pr->blur_clamped &&
           R_FABS(pr->offset) <= R(2) * pr->blur + R(0.5);
}

/* The partial-area detector's regime (cdsp_profile_applies): a straight
 * pipe side, or one flat in the limb's shadow over the window (its pixel
 * centres reach h + 1/2 from the silhouette), and a blur the window spans
 * (below). h + 1/2, not h + 1: with the terminator at 4.6-5.0 px (h = 4,
 * blur 0.5-0.76 px) the detector's line was within 0.002 px while the
 * model, its window ending 3.5 sigma before the terminator, moved it
 * 0.001-0.012 px off (test_short_shadow; make bench-accuracy's six
 * shadowed-limb cells at s_t 4.94-5.0; the paper's p1 at ambient 0.85,
 * s_t 4.7: the scene's axis RMSE 0.0163 -> 0.0150 mm). Shorter shadows
 * (s_t 4.2-4.4) keep the detector exact too, but there the model does
 * not find the terminator, so shadow says nothing. */
static int detector_exact(const cdsp_profile *pr, int detector_h)
{
    return (pr->flat || pr->shadow >= (cdsp_real)detector_h + R(0.5)) &&
           R(2.33) * pr->blur <= ((cdsp_real)detector_h + R(0.5)) / R(2);
}

int cdsp_profile_applies(const cdsp_profile *pr, const cdsp_profile_params *pp, int detector_h)
{
    if (!pr || !pp || !model_describes(pr, pp))
        return 0;
    /* a straight pipe side (or one flat in the limb's shadow over the
     * detector's window, h + 1/2: detector_exact) and a blur the detector's
     * window spans: the partial-area estimate is exact there and less
     * noisy than the model's wider window. Its second pass samples each
     * side D = (h + 1/2)/2 from the edge; a blur leaks T = Phi(-D/sigma)
     * of the step into both samples, which scales the offset e (<= 1/2 px
     * from the window's centre) by 1/(1 - 2T): a bias of at most T px, so
     * the detector's line stays while T <= 0.01 (D >= 2.33 sigma: sigma
     * <= 0.97 px at h = 4) */
    if (detector_exact(pr, detector_h))
        return 0;
    return 1;
}

/*
 * The systematic bound (issue 12). What the profile says about where the
 * silhouette is, turned into a bound on the line's offset from it:
 * - the model describes the edge (fitted, pipe side within max_fit_chi2,
 *   not saturated, spread not at its clamp, a move a blur explains): the
 *   silhouette is at the model's line or the detector's, give or take
 *   BOUND_A0 + BOUND_A1 blur: B = |offset| + A0 + A1 blur, for either
 *   line. The |offset| stays in the bound of the moved line too: on a dark
 *   pipe's shadowed limb the model fits (fit_chi2 1e-5) and moves a
 *   detector's line that was right to 0.27-0.37 px off (make
 *   bench-accuracy), so a fit is no proof of which line is right.
   Where the edge is in the detector's regime (a straight or shadowed
 *   pipe side and a blur its window spans: cdsp_profile_applies keeps its
 *   line) the floor is what the detector's own error is there, not the
 *   study-wide A0 + A1 blur: B = |offset| + F0 + T + FQ / |J|, T =
 *   Phi(-D / blur) the step's leak into the window's side samples (the
 *   bias cdsp_profile_applies accepts, D = (h + 1/2) / 2), FQ / |J| the
 *   gray level's rounding (noise-free 8-bit steps of 10 gray levels
 *   biased the line by 0.017 px, 0.2 / 10 covers it) and F0 the rest: the
 *   detector's phase ripple at 45 degrees, 0.0016 px at most beyond the
 *   other terms on make bench-accuracy's cells of that regime (16 bit,
 *   noise-free), F0 = 0.002. On the paper's scene in flat light
 *   (blur 0.76 px, J 114) the floor is 0.0053 px where A0 + A1 blur was
 *   0.018, against line errors of 0.0000-0.0031 px.
 * - it does not (a limb in shadow the detector took the terminator of, a
 *   plateau, a stripe): B = |offset| + B0 + B1 blur, the blur zone the
 *   silhouette may hide in;
 * - it was not fitted: half the profile's half-width, the farthest the
 *   model would have looked.
 * Since fit_chi2 averages the residuals over 1 px groups (model_solve:
 * the bin-to-bin ripple of a near-rational slope is no misfit), a
 * wide-blurred 8-bit edge whose model misfits smoothly passes the chi-square
 * test where its rounding ripple failed it before: the misfit's share,
 * AK blur sqrt(fit_chi2) (the misfit's rms in units of the 0.2 % floor,
 * spread over the blur), keeps those cells covered (AK = 0.3, the
 * smallest of 0.05..0.3 covering as many cells as before; 0.046-0.065 px
 * on the paper's directional scene).
 * A0, A1, B0, B1 are the smallest of a grid (A0 0.01..0.03, A1 0..0.1,
 * B0 0.25..1, B1 0.5..2) covering the measured bias in >= 95 % of the
 * study's cells both for the detector's line and for the moved one; the
 * line's residual rms above the noise's expectation was tried as a
 * further term and was not needed (its best weight on the grid was 0).
 */
#define BOUND_A0 0.01
#define BOUND_A1 0.01
#define BOUND_AK 0.3
#define BOUND_B0 1.0
#define BOUND_B1 1.5
#define BOUND_F0 0.002
#define BOUND_FQ 0.2

cdsp_real cdsp_profile_bound(const cdsp_profile *pr, const cdsp_profile_params *pp, int detector_h)
{
    cdsp_real d;
    if (!pp)
        return R(0);
    if (!pr || pr->rows == 0 || !R_FINITE(pr->offset) || !R_FINITE(pr->blur))
        return pp->max_half_width_px / R(2);
    d = R_FABS(pr->offset);
    if (model_describes(pr, pp)) {
        if (detector_exact(pr, detector_h) && R_FABS(pr->contrast) > R(0) && pr->blur > R(0)) {
            cdsp_real t = -((cdsp_real)detector_h + R(0.5)) / R(2) / pr->blur;
            return d + R(BOUND_F0) + norm_cdf_g(t, R_EXP(-t * t / R(2))) + R(BOUND_FQ) / R_FABS(pr->contrast);
        }
        return d + R(BOUND_A0) + R(BOUND_A1) * pr->blur + R(BOUND_AK) * pr->blur * R_SQRT(pr->fit_chi2);
    }
    return d + R(BOUND_B0) + R(BOUND_B1) * pr->blur;
}

cdsp_status cdsp_profile_fit(const cdsp_image *img, const cdsp_real line[3], const cdsp_real p_in[2],
                             const cdsp_real ends[2][2], const cdsp_profile_params *pp,
                             cdsp_profile_ws *ws, cdsp_profile *out)
{
    cdsp_real a, b, len, side, n[2], q0[2], q1[2], L, half;
    int rows, i, used = 0;
    cdsp_status st;
    if (!line || !p_in || !ends || !ws || !out)
        return CDSP_E_ARG;
    st = cdsp_image_check(img);
    if (st != CDSP_OK)
        return st;
    st = cdsp__profile_params_check(pp);
    if (st != CDSP_OK)
        return st;
    len = R_SQRT(line[0] * line[0] + line[1] * line[1]);
    if (!R_FINITE(len) || !(len > R(0)) || !R_FINITE(line[2]))
        return CDSP_E_ARG;
    a = line[0] / len;
    b = line[1] / len;
    side = a * p_in[0] + b * p_in[1] + line[2] / len;
    if (!R_FINITE(side) || side == R(0))
        return CDSP_E_ARG;
    n[0] = side > R(0) ? a : -a;
    n[1] = side > R(0) ? b : -b;
    for (i = 0; i < 2; i++) {
        const cdsp_real *e = ends[i];
        cdsp_real dd = a * e[0] + b * e[1] + line[2] / len;
        cdsp_real *q = i ? q1 : q0;
        q[0] = e[0] - dd * a;
        q[1] = e[1] - dd * b;
    }
    L = R_SQRT((q1[0] - q0[0]) * (q1[0] - q0[0]) + (q1[1] - q0[1]) * (q1[1] - q0[1]));
    if (!R_FINITE(L))
        return CDSP_E_ARG;
    half = pp->max_half_width_px;
    if (half > R(0.9) * R_FABS(side))
        half = R(0.9) * R_FABS(side);
    if (half < R(6))
        return CDSP_E_FEW_POINTS;
    /* one sample per scanline: accumulate reads the row (or column) at
     * the sample's rounded coordinate, so samples 1 px apart along a
     * contour at 45 degrees read 24 of 57 scanlines twice, bins that are
     * not independent, their noise 1.26 times what sigma_offset says
     * (test_noise's row at 45 degrees); the scanlines k between the
     * ends, each at the line's point on it, evenly thinned to max_rows */
    {
        int t_ax = R_FABS(n[0]) >= R_FABS(n[1]) ? 1 : 0, k0, k1, nk, k, acc;
        cdsp_real lo = q0[t_ax] < q1[t_ax] ? q0[t_ax] : q1[t_ax], hi = q0[t_ax] < q1[t_ax] ? q1[t_ax] : q0[t_ax];
        cdsp_real dq = q1[t_ax] - q0[t_ax], last = (cdsp_real)((t_ax ? img->height : img->width) - 1);
        /* the scanlines in the frame (beyond, accumulate reads nothing) */
        if (lo < R(0))
            lo = R(0);
        if (hi > last)
            hi = last;
        if (!(hi >= lo))
            return CDSP_E_FEW_POINTS;
        k0 = (int)R_CEIL(lo);
        k1 = (int)R_FLOOR(hi);
        nk = k1 - k0 + 1;
        rows = nk < pp->max_rows ? nk : pp->max_rows;
        ws_clear(ws);
        /* k = k0 + floor(i nk / rows) by a running remainder: no product
         * to overflow, no 64-bit division (a library call on Cortex-M,
         * which tests/mcu/stack.py cannot bound) */
        for (i = 0, k = k0, acc = 0; i < rows && dq != R(0); i++) {
            cdsp_real t = ((cdsp_real)k - q0[t_ax]) / dq, q[2];
            q[0] = q0[0] + t * (q1[0] - q0[0]);
            q[1] = q0[1] + t * (q1[1] - q0[1]);
            q[t_ax] = (cdsp_real)k;
            used += accumulate(img, ws, q, n, half);
            for (acc += nk; acc >= rows; acc -= rows)
                k++;
        }
    }
    if (used < 16)
        return CDSP_E_FEW_POINTS;
    st = model_solve(ws, half, R_FABS(side), 1, out);
    out->rows = (uint32_t)used;
    out->saturated = saturated(ws, img);
    return st;
}

/*
 * Frame path: refine contour line ln (undistorted px) from its inliers
 * (label[i] == lab). Each sampled inlier's foot on the line is distorted
 * into the frame, with the line's local normal there (the normal of the
 * distorted tangent) and the scale between undistorted and distorted
 * normal displacements (from the distortion's Jacobian by differences of
 * half a pixel). The silhouette's offset d (frame px) is carried back as
 * d / mean(scale) and the line moved by it. Returns CDSP_OK and fills
 * *prof and *moved (undistorted px toward the pipe) when the model fitted.
 */
cdsp_status cdsp__profile_refine(const cdsp_image *img, const cdsp_camera *cam, const cdsp_edge *pts,
                                 size_t n, const uint8_t *label, uint8_t lab, cdsp_line *ln,
                                 const cdsp_real p_in[2], const cdsp_profile_params *pp,
                                 int detector_h, cdsp_real noise, cdsp_profile_ws *ws, cdsp_profile *prof,
                                 cdsp_real *moved, cdsp_real *sigma_moved)
{
    const cdsp_real eps = R(0.5);
    cdsp_real side, nu[2], tu[2], half, scale_sum = R(0), du;
    size_t i, cnt = 0, stride, k = 0;
    int used = 0;
    cdsp_status st;
    zero_bytes(prof, sizeof *prof); /* rows stays 0 unless the model is fitted */
    *moved = *sigma_moved = R(0);
    side = ln->l[0] * p_in[0] + ln->l[1] * p_in[1] + ln->l[2];
    if (!R_FINITE(side) || side == R(0))
        return CDSP_E_ARG;
    nu[0] = side > R(0) ? ln->l[0] : -ln->l[0];
    nu[1] = side > R(0) ? ln->l[1] : -ln->l[1];
    tu[0] = -nu[1];
    tu[1] = nu[0];
    half = pp->max_half_width_px;
    if (half > R(0.9) * R_FABS(side))
        half = R(0.9) * R_FABS(side);
    if (half < R(6))
        return CDSP_E_FEW_POINTS;
    for (i = 0; i < n; i++)
        cnt += label[i] == lab;
    if (cnt < 16)
        return CDSP_E_FEW_POINTS;
    /* three scanlines per sampled inlier (below) */
    stride = (3 * cnt + (size_t)pp->max_rows - 1) / (size_t)pp->max_rows;
    ws_clear(ws);
    for (i = 0; i < n; i++) {
        cdsp_real d, f[2], p2[2], q[2], qt[2], qn[2], nd[2], nl, g[2], sc;
        if (label[i] != lab || (k++ % stride) != 0)
            continue;
        d = ln->l[0] * pts[i].x + ln->l[1] * pts[i].y + ln->l[2];
        f[0] = pts[i].x - d * ln->l[0];
        f[1] = pts[i].y - d * ln->l[1];
        if (cdsp_camera_distort(cam, f, q) != CDSP_OK)
            continue;
        p2[0] = f[0] + eps * tu[0];
        p2[1] = f[1] + eps * tu[1];
        if (cdsp_camera_distort(cam, p2, qt) != CDSP_OK)
            continue;
        p2[0] = f[0] + eps * nu[0];
        p2[1] = f[1] + eps * nu[1];
        if (cdsp_camera_distort(cam, p2, qn) != CDSP_OK)
            continue;
        nd[0] = qt[1] - q[1];
        nd[1] = -(qt[0] - q[0]);
        nl = R_SQRT(nd[0] * nd[0] + nd[1] * nd[1]);
        if (!(nl > R(0)))
            continue;
        nd[0] /= nl;
        nd[1] /= nl;
        g[0] = (qn[0] - q[0]) / eps;
        g[1] = (qn[1] - q[1]) / eps;
        sc = nd[0] * g[0] + nd[1] * g[1];
        if (sc < R(0)) {
            nd[0] = -nd[0];
            nd[1] = -nd[1];
            sc = -sc;
        }
        if (!(sc > R(0.1)))
            continue;
        {
            /* this scanline and its two neighbours (the detector reads one
             * line in step; the profile's noise wants them all): along the
             * distorted tangent, one scanline per step */
            cdsp_real td[2] = {-nd[1], nd[0]}, ta = R_FABS(nd[0]) >= R_FABS(nd[1]) ? td[1] : td[0];
            int j;
            if (!(R_FABS(ta) > R(0.5)))
                continue;
            for (j = -1; j <= 1; j++) {
                cdsp_real qj[2];
                qj[0] = q[0] + (cdsp_real)j * td[0] / R_FABS(ta);
                qj[1] = q[1] + (cdsp_real)j * td[1] / R_FABS(ta);
                if (accumulate(img, ws, qj, nd, half * sc)) {
                    used++;
                    scale_sum += sc;
                }
            }
        }
    }
    if (used < 16)
        return CDSP_E_FEW_POINTS;
    /* the forward model (a blur wider than the detector's window) only
     * where the line may move: its 10-20 fits cost ~6-10 M instructions
     * a contour (15 px of motion, optical 3 px; the area balance 0.5 M),
     * and with the model off the bound keeps the area balance's offset */
    st = model_solve(ws, half * scale_sum / (cdsp_real)used, R_FABS(side) * scale_sum / (cdsp_real)used, pp->enable,
                     prof);
    if (st != CDSP_OK) {
        prof->rows = 0;
        return st;
    }
    prof->rows = (uint32_t)used;
    prof->saturated = saturated(ws, img);
    if (!cdsp_profile_applies(prof, pp, detector_h)) {
        *moved = R(0);
        return prof->fit_chi2 <= pp->max_fit_chi2 ? CDSP_OK : CDSP_E_NOCONVERGE;
    }
    du = prof->offset * (cdsp_real)used / scale_sum;
    /* move the line du toward the pipe: l.(p + du nu) = du (nu . l) */
    ln->l[2] -= du * (nu[0] * ln->l[0] + nu[1] * ln->l[1]);
    ln->centroid[0] += du * nu[0];
    ln->centroid[1] += du * nu[1];
    *moved = du;
    /* the bins' pooled variance holds, beside the pixels' noise, how the
     * scene varies along the contour (the background's texture, shading
     * in perspective, columns crossing: 2.3-12.7 gray levels on the
     * paper's rack, whose noise is 2.0), a variation of the bins' means
     * that is neither independent from bin to bin nor the pixels' noise:
     * the frame's measured noise, when smaller, is the one scaled */
    *sigma_moved = prof->sigma_offset * (cdsp_real)used / scale_sum;
    if (noise > R(0) && noise < prof->noise)
        *sigma_moved *= noise / prof->noise;
    return CDSP_OK;
}
