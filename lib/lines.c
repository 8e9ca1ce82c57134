/*
 * lines.c - straight contour lines from edge points.
 *
 * Fit: total least squares, i.e. the right singular vector of the smallest
 * singular value of the N x 3 matrix [u v 1] (docs/method.md §3). With the
 * points centred on their centroid the 3x3 normal matrix is block diagonal,
 * diag(C, 1) with C the 2x2 scatter (covariance) matrix, so the line's normal
 * is the eigenvector of C's smallest eigenvalue and the line passes through
 * the centroid: computed directly in closed form (mom_fit), from moments
 * gathered in one pass about a nearby origin. The eigenvalues are the
 * spread along the line and the residual across it (squared); the normal is
 * accurate to about eps * spread^2 / (spread^2 - residual^2) (the
 * eigenvector's condition number, Golub & Van Loan, Matrix Computations,
 * 4th ed., Thm. 8.1.12), i.e. to eps for any line worth the name, in float
 * too.
 *
 * Robust extraction: sequential RANSAC (Fischler & Bolles 1981). Two points
 * define a hypothesis, which is kept only if both points' gradients agree
 * with its normal (same polarity, within normal_tol_deg): with opposite
 * polarities on the two contours of a pipe, nearly every surviving sample
 * is all-inlier. Hypotheses are scored on a fixed subsample
 * (preemptive scoring, Nister 2005) and only the best is scored on all
 * points; the iteration count adapts to the best inlier ratio w found:
 * N = log(1 - confidence) / log(1 - w^2). The winner is refined by alternating
 * inlier selection and TLS fit. Each found line's inliers are labelled and
 * removed before the next line is sought.
 *
 * Guided samples (issue 10): with uniform pairs, a contour holding a
 * fraction w of the points is drawn with probability w^2 per hypothesis, so
 * among long clutter edges a short pipe contour (w = 0.04: 1 in 600) is
 * easily missed within max_iterations. Every other hypothesis therefore
 * takes its second point near the first in the array (edge points come in
 * scan order, so neighbours in the array are neighbours in the frame, for
 * the row and the column families alike): the farthest of the free points
 * within +-GUIDE_SPAN indices whose gradient and position agree with the
 * first point's edge direction. Such a pair lies on one contour with
 * probability ~w, not w^2. For input in no particular order the guided
 * samples are merely as good as uniform ones, which the other half stay.
 *
 * Seeds (issue 17): tracking knows where the contours were a frame ago, and
 * the points it reads lie in bands around them. Each line search therefore
 * scores the seed lines it was given (the prior's two contours) on the
 * subsample first, both orientations, and the best seed becomes the best
 * hypothesis so far. It is confirmed, and no sample is drawn, when it holds
 * more of the free subsample than lies on no seed at all: a line other
 * than the seeds holds only those points and the few of each seed's where
 * it crosses it, so the random search would find none with more (the
 * points on no seed are counted when two seeds could share some); the
 * refinement then fits the seed's inliers as it would the winner of the
 * draws. A pipe moves a few pixels between frames, more than the inlier
 * distance: when the seeds as given are not confirmed, each is moved onto
 * its contour (fitted to the subsample's points within SEED_REACH inlier
 * distances of it, then half that, down to twice the inlier distance) and
 * tried again. A seed with nothing of its contour in reach is not
 * confirmed: the draws run as without seeds (the seed the best to beat).
 * When every seed was confirmed and taken as the first lines, the search
 * for more stops once the points left are fewer than a quarter of the
 * weakest seed line's: what is left of a tracked band is its contours'
 * stray points (19-32 on the paper's frames, against 611 per contour), and
 * a line of them is too short to count among the pair tests' interior and
 * neighbouring contours (lib/pair.c: band_split, edge_of_neighbour) or to
 * outscore the tracked pair on its weaker contour's evidence. Not a
 * proof: such a line could still end a contour's corner test (lib/pair.c,
 * flips_on; without it a track may fall back to a full search) or be a
 * weak rival pair's side. Measured on bench_frame's 18 tracked solves
 * (`bench_frame DIR hash` with n_lines left out of the hash): every other
 * field the same, n_lines 2 instead of 3 on 6 of them (12-15 stray points
 * along one contour).
 */
#include "internal.h"

#define LABEL_FREE 0u
#define LABEL_TRIAL 255u
#define SUBSAMPLE 160u          /* points a hypothesis is scored on first */
/* The subsample visits i_k = k * G mod n with G ~ 0.618 n made coprime to
 * n: distinct indices (G coprime) spread evenly over the whole set (the
 * golden-ratio sequence has the lowest discrepancy), whatever the order of
 * the points. A plain stride aliases with ordered input, e.g. points that
 * alternate between two lines. */
/* floor(0.618034 n), exactly, without overflow where size_t is 32 bits
 * (n * 618034 wraps past n = 6949, below the Cortex-M builds' 16384
 * edges): with n = 10^6 a + 10^3 b + c (b, c < 1000),
 *   0.618034 n = 618034 a + 618 b + (34000 b + 618034 c) / 10^6,
 * the first two terms integers and the last numerator below 6.6e8. */
size_t cdsp__golden_start(size_t n)
{
    size_t a = n / 1000000u, b = (n / 1000u) % 1000u, c = n % 1000u;
    return 618034u * a + 618u * b + (34000u * b + 618034u * c) / 1000000u;
}

static size_t golden_stride(size_t n)
{
    size_t g, a, b;
    if (n < 2)
        return 0;
    for (g = cdsp__golden_start(n); g < n; g++) {
        for (a = n, b = g; b;) { /* gcd(n, g) */
            size_t t = a % b;
            a = b;
            b = t;
        }
        if (a == 1)
            return g;
    }
    return 1;
}
#define MIN_SAMPLE_DIST_PX 4.0  /* closer sample pairs give a poorly defined angle */
#define GUIDE_SPAN 96           /* array neighbours a guided second point is sought among */
/* a guided second point lies within this angle of the first point's edge
 * direction (sin 10 deg: the partial-area slope of a faint edge is good to a
 * few degrees) */
#define GUIDE_SIN 0.17
#define REFINE_PASSES 4

/* Moments of a point set about a nearby origin (o), enough for the TLS fit
 * and the polarity of the set. */
typedef struct {
    cdsp_real ox, oy;
    cdsp_real n, sx, sy, sxx, syy, sxy;
    cdsp_real sgx, sgy;
} moments;

static void mom_init(moments *m, cdsp_real ox, cdsp_real oy)
{
    m->ox = ox;
    m->oy = oy;
    m->n = m->sx = m->sy = m->sxx = m->syy = m->sxy = R(0);
    m->sgx = m->sgy = R(0);
}

static void mom_add(moments *m, const cdsp_edge *e)
{
    cdsp_real dx = e->x - m->ox, dy = e->y - m->oy;
    m->n += R(1);
    m->sx += dx;
    m->sy += dy;
    m->sxx += dx * dx;
    m->syy += dy * dy;
    m->sxy += dx * dy;
    m->sgx += e->gx;
    m->sgy += e->gy;
}

/* TLS line from moments: fills l, centroid, dir (count, extent, residual
 * and strength are the stats pass's job).
 *
 * The normal (a, b) is the eigenvector of the smaller eigenvalue of the
 * centred scatter C = [cxx cxy; cxy cyy]. With d = (cxx - cyy) / 2 and
 * r = hypot(d, cxy), the eigenvalues are (cxx + cyy) / 2 +- r and the
 * larger one's eigenvector is (d + r, cxy) = (cxy, r - d) up to scale
 * (C - lambda I annihilates it: (d - r)(d + r) + cxy^2 = 0). Of the two
 * forms we take the one that adds numbers of one sign, (d + r, cxy) for
 * d >= 0 and (cxy, r - d) for d < 0, so no digits cancel (the reasoning of
 * the symmetric 2x2 Schur step, Golub & Van Loan, Alg. 8.5.1, which picks
 * the rotation's root the same way); the normal is its perpendicular. r = 0 (the points spread
 * alike in every direction) leaves no line: CDSP_E_DEGENERATE. Scaling C
 * leaves its eigenvectors alone, so no normalization is needed. */
static cdsp_status mom_fit(const moments *m, cdsp_line *out)
{
    cdsp_real mx, my, cxx, cyy, cxy, rms2, d, r, a, b, norm;
    if (m->n < R(2))
        return CDSP_E_FEW_POINTS;
    mx = m->sx / m->n;
    my = m->sy / m->n;
    /* centred second moments */
    cxx = m->sxx / m->n - mx * mx;
    cyy = m->syy / m->n - my * my;
    cxy = m->sxy / m->n - mx * my;
    if (cxx < R(0))
        cxx = R(0);
    if (cyy < R(0))
        cyy = R(0);
    rms2 = cxx + cyy;
    if (!(rms2 > R(0)) || !R_FINITE(rms2))
        return CDSP_E_DEGENERATE;
    d = (cxx - cyy) / R(2);
    r = R_SQRT(d * d + cxy * cxy);
    if (d >= R(0)) { /* major axis (d + r, cxy), normal (-cxy, d + r) */
        a = -cxy;
        b = d + r;
    } else { /* major axis (cxy, r - d), normal (d - r, cxy) */
        a = d - r;
        b = cxy;
    }
    norm = R_SQRT(a * a + b * b);
    if (!(norm > R(0)) || !R_FINITE(norm))
        return CDSP_E_DEGENERATE;
    a /= norm;
    b /= norm;
    /* back to pixels: a (x - mx - ox) + b (y - my - oy) = 0 */
    out->l[0] = a;
    out->l[1] = b;
    out->l[2] = -a * (mx + m->ox) - b * (my + m->oy);
    /* polarity: (a, b) toward the brighter side = along the mean gradient */
    if (a * m->sgx + b * m->sgy < R(0) ||
        (a * m->sgx + b * m->sgy == R(0) && (b < R(0) || (b == R(0) && a < R(0))))) {
        out->l[0] = -out->l[0];
        out->l[1] = -out->l[1];
        out->l[2] = -out->l[2];
    }
    out->centroid[0] = mx + m->ox;
    out->centroid[1] = my + m->oy;
    out->dir[0] = -out->l[1];
    out->dir[1] = out->l[0];
    return CDSP_OK;
}

/* Residual RMS, extent and spread along the line, mean gradient length and
 * count over the selected points (idx, or label == want, or all); with a
 * label array, the selected points are relabelled `relabel` on the way. */
static void line_stats(const cdsp_edge *pts, size_t n, const uint32_t *idx, uint8_t *label,
                       uint8_t want, uint8_t relabel, cdsp_line *ln)
{
    size_t i;
    cdsp_real ss = R(0), tmin = R_MAX, tmax = -R_MAX, spread = R(0), cnt = R(0), sg = R(0);
    for (i = 0; i < n; i++) {
        const cdsp_edge *e;
        cdsp_real d, t;
        if (idx) {
            e = &pts[idx[i]];
        } else if (label) {
            if (label[i] != want)
                continue;
            label[i] = relabel;
            e = &pts[i];
        } else {
            e = &pts[i];
        }
        d = ln->l[0] * e->x + ln->l[1] * e->y + ln->l[2];
        t = ln->dir[0] * (e->x - ln->centroid[0]) + ln->dir[1] * (e->y - ln->centroid[1]);
        ss += d * d;
        spread += t * t;
        sg += R_SQRT(e->gx * e->gx + e->gy * e->gy);
        if (t < tmin)
            tmin = t;
        if (t > tmax)
            tmax = t;
        cnt += R(1);
    }
    ln->count = (uint32_t)cnt;
    ln->rms = cnt > R(0) ? R_SQRT(ss / cnt) : R(0);
    ln->spread = spread;
    ln->t_min = cnt > R(0) ? tmin : R(0);
    ln->t_max = cnt > R(0) ? tmax : R(0);
    ln->strength = cnt > R(0) ? sg / cnt : R(0);
}

cdsp_status cdsp_line_fit(const cdsp_edge *pts, const uint32_t *idx, size_t n, cdsp_line *out)
{
    moments m;
    size_t i;
    cdsp_status st;
    if (!pts || !out)
        return CDSP_E_ARG;
    if (n < 2)
        return CDSP_E_FEW_POINTS;
    for (i = 0; i < n; i++) {
        const cdsp_edge *e = idx ? &pts[idx[i]] : &pts[i];
        if (!R_FINITE(e->x) || !R_FINITE(e->y) || !R_FINITE(e->gx) || !R_FINITE(e->gy))
            return CDSP_E_NONFINITE;
    }
    {
        const cdsp_edge *e0 = idx ? &pts[idx[0]] : &pts[0];
        mom_init(&m, e0->x, e0->y);
    }
    for (i = 0; i < n; i++)
        mom_add(&m, idx ? &pts[idx[i]] : &pts[i]);
    st = mom_fit(&m, out);
    if (st != CDSP_OK)
        return st;
    line_stats(pts, n, idx, NULL, 0, 0, out);
    return CDSP_OK;
}

/* Is e an inlier of oriented line l? Distance within thr and gradient
 * within the angular tolerance on the positive side: (g.n)^2 >= cos^2 |g|^2. */
static inline int is_inlier(const cdsp_edge *e, const cdsp_real l[3], cdsp_real thr, cdsp_real cos2)
{
    cdsp_real d = l[0] * e->x + l[1] * e->y + l[2];
    cdsp_real gn;
    if (d > thr || d < -thr)
        return 0;
    gn = l[0] * e->gx + l[1] * e->gy;
    return gn > R(0) && gn * gn >= cos2 * (e->gx * e->gx + e->gy * e->gy);
}

/* Hypothesis through a and b, oriented by a's gradient; 0 when the pair is
 * too close or the gradients disagree with the normal. */
static int hypothesis(const cdsp_edge *a, const cdsp_edge *b, cdsp_real cos2, cdsp_real l[3])
{
    cdsp_real dx = b->x - a->x, dy = b->y - a->y, len2 = dx * dx + dy * dy, len, ga, gb;
    if (len2 < R(MIN_SAMPLE_DIST_PX * MIN_SAMPLE_DIST_PX))
        return 0;
    len = R_SQRT(len2);
    l[0] = -dy / len;
    l[1] = dx / len;
    ga = l[0] * a->gx + l[1] * a->gy;
    if (ga < R(0)) {
        l[0] = -l[0];
        l[1] = -l[1];
        ga = -ga;
    }
    l[2] = -(l[0] * a->x + l[1] * a->y);
    gb = l[0] * b->gx + l[1] * b->gy;
    return ga * ga >= cos2 * (a->gx * a->gx + a->gy * a->gy) && gb > R(0) &&
           gb * gb >= cos2 * (b->gx * b->gx + b->gy * b->gy);
}

/* Iterations needed for the given confidence when a fraction w of the free
 * points are inliers (2-point samples). */
static long needed_iterations(cdsp_real w, cdsp_real confidence, long cap)
{
    cdsp_real w2 = w * w, den;
    if (w2 >= R(1))
        return 1;
    if (w2 <= R(0))
        return cap;
    den = R_LOG(R(1) - w2);
    if (!(den < R(0)))
        return cap;
    {
        cdsp_real k = R_LOG(R(1) - confidence) / den;
        return k >= (cdsp_real)cap ? cap : (long)k + 1;
    }
}

/* Select inliers of l among free points into the LABEL_TRIAL set while
 * accumulating their moments; returns the count. */
static uint32_t select_inliers(const cdsp_edge *pts, size_t n, uint8_t *label, const cdsp_real l[3],
                               cdsp_real thr, cdsp_real cos2, moments *m)
{
    size_t i;
    uint32_t cnt = 0;
    for (i = 0; i < n; i++) {
        if (label[i] != LABEL_FREE && label[i] != LABEL_TRIAL)
            continue;
        if (is_inlier(&pts[i], l, thr, cos2)) {
            label[i] = LABEL_TRIAL;
            mom_add(m, &pts[i]);
            cnt++;
        } else {
            label[i] = LABEL_FREE;
        }
    }
    return cnt;
}

/* Guided second sample for a (see the top): the farthest free point within
 * GUIDE_SPAN array positions that lies along a's edge direction with a
 * gradient of the same polarity within the angular tolerance; n when none. */
static size_t guided_partner(const cdsp_edge *pts, size_t n, const uint8_t *label, size_t a,
                             cdsp_real cos2)
{
    const cdsp_edge *e = &pts[a];
    cdsp_real g2 = e->gx * e->gx + e->gy * e->gy, best = R(MIN_SAMPLE_DIST_PX * MIN_SAMPLE_DIST_PX);
    size_t lo = a > GUIDE_SPAN ? a - GUIDE_SPAN : 0, hi = a + GUIDE_SPAN < n ? a + GUIDE_SPAN : n - 1, i,
           pick = n;
    if (!(g2 > R(0)))
        return n;
    for (i = lo; i <= hi; i++) {
        const cdsp_edge *b = &pts[i];
        cdsp_real dx, dy, d2, along, dot;
        if (label[i] != LABEL_FREE || i == a)
            continue;
        dx = b->x - e->x;
        dy = b->y - e->y;
        d2 = dx * dx + dy * dy;
        if (d2 <= best)
            continue;
        /* across a's edge: (d . g)^2 <= sin^2 |d|^2 |g|^2 */
        along = dx * e->gx + dy * e->gy;
        if (along * along > R(GUIDE_SIN * GUIDE_SIN) * d2 * g2)
            continue;
        dot = b->gx * e->gx + b->gy * e->gy;
        if (!(dot > R(0)) || dot * dot < cos2 * g2 * (b->gx * b->gx + b->gy * b->gy))
            continue;
        best = d2;
        pick = i;
    }
    return pick;
}

/* One line search's state: the subsample (the golden-stride one, or the
 * list of the free points once fewer than SUBSAMPLE are left) and the best
 * hypothesis so far. */
typedef struct {
    const cdsp_edge *pts;
    const uint8_t *label;
    size_t n, nsub, sstep;
    const uint32_t *list; /* free points when listed, else NULL */
    size_t nlist;
    cdsp_real thr, cos2, confidence;
    long cap, need;
    uint32_t sub_free, best_sub;
    cdsp_real best[3], origin[2];
} search;

/* Score the sample (a, b) on the subsample and keep it if it beats the best
 * so far, shrinking the iteration count to what the new inlier ratio needs. */
static void search_try(search *s, uint32_t a, uint32_t b)
{
    const cdsp_edge *pts = s->pts;
    cdsp_real l[3];
    uint32_t sc = 0;
    size_t i, j;
    if (!hypothesis(&pts[a], &pts[b], s->cos2, l))
        return;
    if (s->list) {
        /* stops once even all the points left could not beat the best:
         * only a higher count replaces it, so the choice is the same */
        for (j = 0; j < s->nlist && sc + (s->nlist - j) > s->best_sub; j++)
            sc += (uint32_t)is_inlier(&pts[s->list[j]], l, s->thr, s->cos2);
    } else {
        for (i = 0, j = 0; j < s->nsub; j++, i = i + s->sstep >= s->n ? i + s->sstep - s->n : i + s->sstep)
            sc += s->label[i] == LABEL_FREE && is_inlier(&pts[i], l, s->thr, s->cos2);
    }
    if (sc > s->best_sub) {
        long nn;
        s->best_sub = sc;
        s->best[0] = l[0];
        s->best[1] = l[1];
        s->best[2] = l[2];
        s->origin[0] = pts[a].x; /* moments are taken about a point on the data */
        s->origin[1] = pts[a].y;
        nn = needed_iterations((cdsp_real)sc / (cdsp_real)s->sub_free, s->confidence, s->cap);
        if (nn < s->need)
            s->need = nn;
    }
}

/* Inliers of l within distance thr among the search's free subsample (or
 * list), all of them, their moments added to m (unless NULL); *first: the
 * first one (the moments' origin), when any. */
static uint32_t search_count(const search *s, const cdsp_real l[3], cdsp_real thr, moments *m, size_t *first)
{
    const cdsp_edge *pts = s->pts;
    uint32_t sc = 0;
    size_t i, j;
    if (s->list) {
        for (j = 0; j < s->nlist; j++)
            if (is_inlier(&pts[s->list[j]], l, thr, s->cos2)) {
                if (sc++ == 0)
                    *first = s->list[j];
                if (m)
                    mom_add(m, &pts[s->list[j]]);
            }
    } else {
        for (i = 0, j = 0; j < s->nsub; j++, i = i + s->sstep >= s->n ? i + s->sstep - s->n : i + s->sstep)
            if (s->label[i] == LABEL_FREE && is_inlier(&pts[i], l, thr, s->cos2)) {
                if (sc++ == 0)
                    *first = i;
                if (m)
                    mom_add(m, &pts[i]);
            }
    }
    return sc;
}

#define SEED_REACH 8 /* inlier distances: how far a seed is moved from (seed_fit) */
/* Seed states (lines_find's state[]): not yet looked at; oriented (its
 * line in sl[]); oriented and moved onto its contour; confirmed (its
 * search ends in its line or in none); not a line. */
#define SEED_NEW 0u
#define SEED_READY 1u
#define SEED_MOVED 2u
#define SEED_USED 3u
#define SEED_BAD 4u

/* A seed's orientation: of the free subsample's (or list's) points within
 * SEED_REACH inlier distances of the unit line l whose gradient is within
 * the angular tolerance of one of its two normals, the side with more
 * (ties: l as given); l oriented so, *sc its inliers (the first: *first)
 * and *at the first of its points in reach. */
static void seed_orient(const search *s, cdsp_real l[3], uint32_t *sc, size_t *first, size_t *at)
{
    const cdsp_edge *pts = s->pts;
    cdsp_real wide = R(SEED_REACH) * s->thr;
    uint32_t nr[2] = {0, 0}, ni[2] = {0, 0};
    size_t fr[2] = {0, 0}, fi[2] = {0, 0}, i, j, k;
    int sg;
    for (i = 0, j = 0; j < (s->list ? s->nlist : s->nsub); j++) {
        const cdsp_edge *e;
        cdsp_real d, gn;
        k = s->list ? s->list[j] : i;
        if (!s->list)
            i = i + s->sstep >= s->n ? i + s->sstep - s->n : i + s->sstep;
        if (!s->list && s->label[k] != LABEL_FREE)
            continue;
        e = &pts[k];
        d = l[0] * e->x + l[1] * e->y + l[2];
        if (d > wide || d < -wide)
            continue;
        gn = l[0] * e->gx + l[1] * e->gy;
        if (gn == R(0) || gn * gn < s->cos2 * (e->gx * e->gx + e->gy * e->gy))
            continue;
        sg = gn < R(0);
        if (nr[sg]++ == 0)
            fr[sg] = k;
        if (!(d > s->thr || d < -s->thr) && ni[sg]++ == 0) /* is_inlier at thr, of l or -l */
            fi[sg] = k;
    }
    sg = nr[1] > nr[0];
    if (sg) {
        l[0] = -l[0];
        l[1] = -l[1];
        l[2] = -l[2];
    }
    *sc = ni[sg];
    *first = fi[sg];
    *at = fr[sg];
}

/* A seed moved onto its contour: the oriented line l fitted to the free
 * subsample's points within SEED_REACH inlier distances, then half that,
 * down to twice the inlier distance, each time about the fit before
 * (moments about a point in reach, *at, the first of the pass before); l
 * is left as it was when a fit fails. A pipe moves a few pixels a frame
 * (the tracking tests' sequences: 1-7 of the 80 subsample points of a
 * contour within the inlier distance of the prior's line), and the band's
 * points are its two contours of opposite polarity, so the points of a
 * contour within reach are mostly that contour's. */
static void seed_fit(const search *s, cdsp_real l[3], size_t *at)
{
    cdsp_real reach;
    for (reach = R(SEED_REACH) * s->thr; reach >= R(2) * s->thr; reach /= R(2)) {
        moments m;
        cdsp_line fit;
        size_t next = *at;
        mom_init(&m, s->pts[*at].x, s->pts[*at].y);
        if (search_count(s, l, reach, &m, &next) < 2 || mom_fit(&m, &fit) != CDSP_OK ||
            !(fit.l[0] * l[0] + fit.l[1] * l[1] > R(0)))
            return;
        l[0] = fit.l[0];
        l[1] = fit.l[1];
        l[2] = fit.l[2];
        *at = next;
    }
}

/* How many of the free subsample (or list) are inliers of at least one of
 * the seeds' lines sl that are not used and have any (sc): their sum when
 * no point can be an inlier of two (one such seed, or normals more than
 * twice the angular tolerance apart, as a pipe's two contours' are: cos of
 * the angle below cos(2 tol) = 2 cos^2(tol) - 1), else counted. */
static uint32_t seeds_union(const search *s, cdsp_real (*sl)[3], const uint32_t *sc, const uint8_t *state,
                            int nseed)
{
    uint32_t u = 0;
    size_t i, j, k;
    int q, m = 0;
    for (q = 0; q < nseed; q++)
        if (state[q] < SEED_USED && sc[q]) {
            u += sc[q];
            m++;
        }
    if (m < 2 || (nseed == 2 && sl[0][0] * sl[1][0] + sl[0][1] * sl[1][1] < R(2) * s->cos2 - R(1)))
        return u;
    u = 0;
    for (i = 0, j = 0; j < (s->list ? s->nlist : s->nsub); j++) {
        k = s->list ? s->list[j] : i;
        if (s->list || s->label[k] == LABEL_FREE)
            for (q = 0; q < nseed; q++)
                if (state[q] < SEED_USED && sc[q] && is_inlier(&s->pts[k], sl[q], s->thr, s->cos2)) {
                    u++;
                    break;
                }
        if (!s->list)
            i = i + s->sstep >= s->n ? i + s->sstep - s->n : i + s->sstep;
    }
    return u;
}

/* The seeds not used yet (see the top; sl, state: lines_find's, kept from
 * one line's search to the next): the best one becomes the search's best
 * hypothesis when it beats it; 1 when it is confirmed (then SEED_USED), 0
 * when the draws must run. The seeds as they are first; when the best is
 * not confirmed, those not moved yet are moved onto their contours
 * (seed_fit) and tried again. */
#define MAX_SEEDS 2
static int search_seeds(search *s, const cdsp_real (*seed)[3], cdsp_real (*sl)[3], uint8_t *state, int nseed)
{
    uint32_t sc[MAX_SEEDS], total;
    size_t first[MAX_SEEDS], at[MAX_SEEDS];
    int q, b, round;
    for (q = 0; q < nseed; q++) {
        sc[q] = 0;
        first[q] = at[q] = 0;
        if (state[q] == SEED_NEW) {
            cdsp_real norm = R_SQRT(seed[q][0] * seed[q][0] + seed[q][1] * seed[q][1]);
            if (!(norm > R(0)) || !R_FINITE(norm) || !R_FINITE(seed[q][2])) {
                state[q] = SEED_BAD;
                continue;
            }
            sl[q][0] = seed[q][0] / norm;
            sl[q][1] = seed[q][1] / norm;
            sl[q][2] = seed[q][2] / norm;
            state[q] = SEED_READY;
            seed_orient(s, sl[q], &sc[q], &first[q], &at[q]);
        } else if (state[q] < SEED_USED) {
            sc[q] = search_count(s, sl[q], s->thr, NULL, &first[q]);
            at[q] = first[q];
        }
    }
    for (round = 0; round < 2; round++) {
        int moved = 0;
        total = 0;
        b = -1;
        for (q = 0; q < nseed; q++) {
            if (state[q] >= SEED_USED)
                continue;
            if (round && state[q] == SEED_READY) {
                state[q] = SEED_MOVED;
                moved = 1;
                seed_fit(s, sl[q], &at[q]);
                sc[q] = search_count(s, sl[q], s->thr, NULL, &first[q]);
            }
            total += sc[q];
            if (sc[q] > 0 && (b < 0 || sc[q] > sc[b]))
                b = q;
        }
        if ((round && !moved) || b < 0)
            continue;
        if (sc[b] > s->best_sub) {
            long nn;
            s->best_sub = sc[b];
            s->best[0] = sl[b][0];
            s->best[1] = sl[b][1];
            s->best[2] = sl[b][2];
            s->origin[0] = s->pts[first[b]].x;
            s->origin[1] = s->pts[first[b]].y;
            nn = needed_iterations((cdsp_real)sc[b] / (cdsp_real)s->sub_free, s->confidence, s->cap);
            if (nn < s->need)
                s->need = nn;
        }
        /* the points on no seed: the seeds' counts summed, or when that
         * would confirm, counted (two seeds may share points: both moved
         * onto one contour) */
        if (total <= s->sub_free && sc[b] > s->sub_free - total &&
            sc[b] > s->sub_free - seeds_union(s, sl, sc, state, nseed)) {
            state[b] = SEED_USED;
            return 1;
        }
    }
    return 0;
}

/* At line nseed: whether every seed was confirmed, so the lines so far are
 * the seeds' (a confirmed seed's search ends in its line or in none), and
 * the nfree points left are fewer than a quarter of the weakest's. */
static int seeds_found(const uint8_t *state, const cdsp_line *lines, int nseed, size_t nfree)
{
    uint32_t weakest = lines[0].count;
    int q;
    for (q = 0; q < nseed; q++) {
        if (state[q] != SEED_USED)
            return 0;
        weakest = lines[q].count < weakest ? lines[q].count : weakest;
    }
    return nfree < (size_t)(weakest / 4u);
}

/* Free points listed (indices into pts) once at most this many are left:
 * drawing from the list makes every draw a sample of free points (drawing
 * from all n, with 19 free points left among the paper frame's tracked
 * points, took 6000 tries for 32 samples, and with none in the subsample
 * the search stopped), and the list is the subsample. With at most
 * max_iterations distinct pairs (25 points at the default 300) each pair is
 * tried once. 32: above that bound at the defaults, and only 128 bytes of
 * stack (the Cortex-M budgets, docs/mcu.md). */
#define FREE_LIST 32u

cdsp_status cdsp__lines_find(const cdsp_edge *pts, size_t n, uint8_t *label,
                             const cdsp_pair_params *p, cdsp_real cos_tol, const cdsp_real (*seed)[3],
                             cdsp_rng *rng, cdsp_line *lines, int *nlines, int *capped)
{
    int nseed = seed ? MAX_SEEDS : 0;
    uint8_t state[MAX_SEEDS] = {SEED_NEW, SEED_NEW};
    cdsp_real sl[MAX_SEEDS][3]; /* the seeds' lines, oriented, moved (search_seeds) */
    cdsp_real cos2 = cos_tol * cos_tol, thr = p->inlier_px;
    size_t i, j, nfree = n;
    int k, max_lines = p->max_lines < CDSP_MAX_LINES ? p->max_lines : CDSP_MAX_LINES;
    uint32_t list[FREE_LIST];
    search s;

    *nlines = 0;
    *capped = 0;
    for (i = 0; i < n; i++)
        label[i] = LABEL_FREE;
    s.pts = pts;
    s.label = label;
    s.n = n;
    s.nsub = n < SUBSAMPLE ? n : SUBSAMPLE;
    s.sstep = golden_stride(n);
    s.thr = thr;
    s.cos2 = cos2;
    s.confidence = p->confidence;
    s.cap = p->max_iterations;

    for (k = 0; k < max_lines; k++) {
        long it, tries = 0, max_tries = 20L * p->max_iterations;
        uint32_t cnt = 0, draw_n, draw_t;
        int pass;
        moments m;

        if (nfree < (size_t)p->min_inliers || nfree < 2)
            break;
        /* every seed confirmed and found: the rest are strays (see the top) */
        if (nseed && k == nseed && seeds_found(state, lines, nseed, nfree))
            break;
        s.need = p->max_iterations;
        s.best_sub = 0;
        s.sub_free = 0;
        s.best[0] = s.best[1] = s.best[2] = R(0);
        s.origin[0] = s.origin[1] = R(0);
        s.list = NULL;
        s.nlist = 0;
        if (nfree <= FREE_LIST) {
            for (i = 0; i < n && s.nlist < FREE_LIST; i++)
                if (label[i] == LABEL_FREE)
                    list[s.nlist++] = (uint32_t)i;
            s.list = list;
            s.sub_free = (uint32_t)s.nlist;
        } else {
            for (i = 0, j = 0; j < s.nsub; j++, i = i + s.sstep >= n ? i + s.sstep - n : i + s.sstep)
                s.sub_free += label[i] == LABEL_FREE;
        }
        if (s.sub_free == 0 || (s.list && s.nlist < (size_t)p->min_inliers))
            break;

        if (nseed && search_seeds(&s, seed, sl, state, nseed)) {
            /* confirmed: no draws */
        } else if (s.list && (long)(s.nlist * (s.nlist - 1) / 2) <= p->max_iterations) {
            /* No more distinct samples than iterations: try each once. */
            for (i = 0; i < s.nlist; i++)
                for (j = i + 1; j < s.nlist; j++)
                    search_try(&s, list[i], list[j]);
        } else {
            draw_n = s.list ? (uint32_t)s.nlist : (uint32_t)n;
            draw_t = cdsp__rng_threshold(draw_n);
            for (it = 0; it < s.need && tries < max_tries; tries++) {
                uint32_t a = cdsp__rng_below_t(rng, draw_n, draw_t), b;
                if (s.list)
                    a = list[a];
                if (tries & 1) {
                    size_t g;
                    if (label[a] != LABEL_FREE)
                        continue;
                    g = guided_partner(pts, n, label, a, cos2);
                    if (g == n)
                        continue; /* a has no partner in reach: not a sample */
                    b = (uint32_t)g;
                } else {
                    b = cdsp__rng_below_t(rng, draw_n, draw_t);
                    if (s.list)
                        b = list[b];
                }
                if (label[a] != LABEL_FREE || label[b] != LABEL_FREE || a == b)
                    continue; /* not a sample of the free points: does not count */
                it++;
                search_try(&s, a, b);
            }
        }
        if (s.best_sub == 0)
            break;

        /* Refine: inliers of the current line -> TLS fit -> inliers again,
         * until the inlier count settles. The line kept is the fit of the
         * last inlier set. */
        cnt = 0;
        for (pass = 0; pass < REFINE_PASSES; pass++) {
            cdsp_line fit;
            uint32_t prev = cnt;
            mom_init(&m, s.origin[0], s.origin[1]);
            cnt = select_inliers(pts, n, label, s.best, thr, cos2, &m);
            if (cnt < 2 || mom_fit(&m, &fit) != CDSP_OK) {
                cnt = 0;
                break;
            }
            s.best[0] = fit.l[0];
            s.best[1] = fit.l[1];
            s.best[2] = fit.l[2];
            lines[*nlines] = fit;
            if (cnt == prev)
                break;
        }
        if (cnt < (uint32_t)p->min_inliers || cnt < 2) {
            for (i = 0; i < n; i++)
                if (label[i] == LABEL_TRIAL)
                    label[i] = LABEL_FREE;
            break;
        }
        line_stats(pts, n, NULL, label, LABEL_TRIAL, (uint8_t)(k + 1), &lines[*nlines]);
        nfree -= cnt;
        (*nlines)++;
    }
    /* stopped by the cap while another line's worth of points was left */
    if (*nlines == max_lines && nfree >= (size_t)(2 * p->min_inliers))
        *capped = 1;
    return *nlines > 0 ? CDSP_OK : CDSP_E_FEW_POINTS;
}

void cdsp_pair_params_default(cdsp_pair_params *p)
{
    p->inlier_px = R(1.0);
    p->normal_tol_deg = R(20);
    p->confidence = R(0.999);
    p->max_iterations = 300;
    p->max_lines = 24;
    p->min_inliers = 12;
    p->min_overlap = R(0.5);
    p->max_contour_angle_deg = R(60);
    p->polarity = 0;
    p->min_distance = R(0);
    p->max_distance = R(0);
    p->min_support = R(0.35);
}
