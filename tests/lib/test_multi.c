/*
 * test_multi.c - every pipe in view (lib/multi.c) on rendered racks: 2 to 5
 * parallel pipes, equal and different radii, gaps narrower than the pipes
 * (so every dark gap is itself a plausible band: the case where a gap could
 * be taken for a pipe), shaded and flat, with a bar in front of the rack or
 * a support column behind it crossing every pipe. Checked: every pipe is
 * found once, nothing else is reported (no gap, no column), the spacing of
 * neighbours (the paper's Eq. 17-21 measure, cdsp_result_axis_spacing)
 * within the tolerance derived below; a rack panning across the frame keeps
 * each pipe's track id; the spacing measure on exact poses; hostile
 * arguments.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <math.h>
#include <string.h>
#include <stdio.h>
#include <cmocka.h>
#include "support.h"

static cdsp_frame_all_ws ws;

#define W 640
#define H 480
#define F 800.0
#define Z0 420.0 /* depth of the rack's middle, mm */
#define RADIUS 8.0

enum { CROSS_NONE, CROSS_BAR, CROSS_COLUMN };

typedef struct {
    const char *name;
    int n;
    double radius[5];   /* mm; the solver is given RADIUS */
    double gap;         /* gap between neighbours / their mean diameter */
    int shaded;
    int cross;
    double tol_mm;      /* spacing tolerance, derived in the table's comment */
} rack_case;

/* The rack's geometry: pipes along v, side by side along s (perpendicular
 * to v and to the line of sight to the middle), centres c[i]. */
typedef struct {
    double v[3], s[3], c[5][3];
} rack_geo;

static void unit(double a[3])
{
    double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    a[0] /= n;
    a[1] /= n;
    a[2] /= n;
}

static void cross3(const double a[3], const double b[3], double c[3])
{
    c[0] = a[1] * b[2] - a[2] * b[1];
    c[1] = a[2] * b[0] - a[0] * b[2];
    c[2] = a[0] * b[1] - a[1] * b[0];
}

/* Centres along s, the rack's middle at (dx, 0, Z0). */
static void rack_layout(const rack_case *rc, double dx, rack_geo *g)
{
    double ray[3] = {dx, 0, Z0}, pos[5], total;
    int i, k;
    g->v[0] = 0.12;
    g->v[1] = 1;
    g->v[2] = 0.08;
    unit(g->v);
    cross3(g->v, ray, g->s);
    unit(g->s);
    pos[0] = 0;
    for (i = 1; i < rc->n; i++)
        pos[i] = pos[i - 1] + (rc->radius[i - 1] + rc->radius[i]) * (1 + rc->gap);
    total = pos[rc->n - 1];
    for (i = 0; i < rc->n; i++)
        for (k = 0; k < 3; k++)
            g->c[i][k] = ray[k] + (pos[i] - total / 2) * g->s[k];
}

static void rack_scene(const rack_case *rc, const rack_geo *g, cdsp_scene *s)
{
    int i, k;
    cdsp_scene_default(s);
    for (k = 0; k < 3; k++) {
        s->axis_point[k] = (cdsp_real)g->c[0][k];
        s->axis_dir[k] = (cdsp_real)g->v[k];
    }
    s->radius = (cdsp_real)rc->radius[0];
    s->n_extra_pipes = rc->n - 1;
    for (i = 1; i < rc->n; i++) {
        for (k = 0; k < 3; k++) {
            s->extra_pipe[i - 1].axis_point[k] = (cdsp_real)g->c[i][k];
            s->extra_pipe[i - 1].axis_dir[k] = (cdsp_real)g->v[k];
        }
        s->extra_pipe[i - 1].radius = (cdsp_real)rc->radius[i];
    }
    if (!rc->shaded)
        s->ambient = 1;
    s->texture = 0.01;
    if (rc->cross != CROSS_NONE) {
        /* across the rack along s: a bar 60 mm in front, or a support
         * column (12.68 mm, the paper's) 40 mm behind */
        double depth = rc->cross == CROSS_BAR ? -60 : 40, mid[3], half = 400;
        cdsp_clutter *b = &s->clutter[s->n_clutter++];
        for (k = 0; k < 3; k++)
            mid[k] = (g->c[0][k] + g->c[rc->n - 1][k]) / 2 + 30 * g->v[k];
        mid[2] += depth;
        for (k = 0; k < 3; k++) {
            b->p0[k] = (cdsp_real)(mid[k] - half * g->s[k]);
            b->p1[k] = (cdsp_real)(mid[k] + half * g->s[k]);
        }
        b->half_width = (cdsp_real)(rc->cross == CROSS_BAR ? 5 : 6.34);
        b->level = (cdsp_real)(rc->cross == CROSS_BAR ? 0.45 : 0.55);
    }
}

static void camera(cdsp_camera *cam)
{
    sup_camera(cam, W, H, F, 0, 0);
}

/* Index of the found pipe matching true pipe i (direction within 1 degree,
 * the image of the true axis foot within 3 px of its contours' middle), or
 * -1. The 3D comparison is the spacing check's job. */
static int match(const cdsp_camera *cam, const cdsp_result *out, size_t n, const rack_geo *g, int i,
                 double r_true)
{
    size_t k;
    int best = -1;
    double lt[2][3], pin[2], bestd = 3;
    if (!sup_contour_lines(cam, g->c[i], g->v, r_true, lt, pin))
        return -1;
    for (k = 0; k < n; k++) {
        double d[3], P[3], e = 0;
        int c;
        sup_result_pose(&out[k], P, d, NULL);
        if (sup_axis_angle(d, g->v) > SUP_PI / 180)
            continue;
        /* both found contours at pin against the true ones (either order) */
        for (c = 0; c < 2; c++) {
            const cdsp_real *l = out[k].lines[c];
            double f = (double)l[0] * pin[0] + (double)l[1] * pin[1] + (double)l[2], q[2], e0, e1;
            q[0] = pin[0] - f * (double)l[0];
            q[1] = pin[1] - f * (double)l[1];
            e0 = fabs(lt[0][0] * q[0] + lt[0][1] * q[1] + lt[0][2]);
            e1 = fabs(lt[1][0] * q[0] + lt[1][1] * q[1] + lt[1][2]);
            e = fmax(e, fmin(e0, e1));
        }
        if (e < bestd) {
            bestd = e;
            best = (int)k;
        }
    }
    return best;
}

/* As solve_rack, with only the first `shown` pipes of the layout rendered
 * (the others hidden: g still holds every pipe's axis). */
static void solve_rack_any(const rack_case *rc, int shown, double dx, uint64_t seed, int ranged,
                           cdsp_tracker *trk, cdsp_result *out, size_t *n, rack_geo *g, cdsp_status *st)
{
    cdsp_camera cam;
    cdsp_scene s;
    cdsp_image img;
    cdsp_params prm;
    cdsp_rng rng;
    void *buf;
    camera(&cam);
    rack_layout(rc, dx, g);
    rack_scene(rc, g, &s);
    s.n_extra_pipes = shown - 1;
    buf = sup_render(&s, &cam, 8, seed, &img);
    assert_non_null(buf);
    cdsp_params_default(&prm);
    if (ranged) {
        /* where the pipes solve with the radius RADIUS (Z0 RADIUS / r_i, up
         * to 5 % more off the optical axis), widened by 10 %: this excludes
         * the crossing (the bar or the column solved as an 8 mm pipe lands
         * at 576-580 mm, beyond 1.1 x the farthest pipe's 480 mm) */
        double rmin = rc->radius[0], rmax = rc->radius[0];
        int i;
        for (i = 1; i < rc->n; i++) {
            rmin = fmin(rmin, rc->radius[i]);
            rmax = fmax(rmax, rc->radius[i]);
        }
        prm.pair.min_distance = (cdsp_real)(0.9 * Z0 * RADIUS / rmax);
        prm.pair.max_distance = (cdsp_real)(1.1 * Z0 * RADIUS / rmin);
    }
    cdsp_rng_seed(&rng, seed, 3);
    *st = cdsp_frame_solve_all(&img, &cam, RADIUS, &prm, trk, &ws, &rng, out, CDSP_MAX_PIPES, n);
    free(buf);
}

static void solve_rack(const rack_case *rc, double dx, uint64_t seed, int ranged, cdsp_tracker *trk,
                       cdsp_result *out, size_t *n, rack_geo *g, cdsp_status *st)
{
    solve_rack_any(rc, rc->n, dx, seed, ranged, trk, out, n, g, st);
}

static void solve_rack_shown(const rack_case *rc, int shown, double dx, uint64_t seed, cdsp_tracker *trk,
                             cdsp_result *out, size_t *n, rack_geo *g, cdsp_status *st)
{
    solve_rack_any(rc, shown, dx, seed, 0, trk, out, n, g, st);
}

static void debug_print(const cdsp_result *out, size_t n)
{
    size_t k;
    if (!getenv("MULTI_DEBUG"))
        return;
    for (k = 0; k < n; k++) {
        double P[3], d[3];
        sup_result_pose(&out[k], P, d, NULL);
        printf("  #%zu dist %.1f dir %.3f %.3f %.3f conf %.3f score %.1f inliers %u %u id %u\n", k,
               (double)out[k].distance, d[0], d[1], d[2], (double)out[k].confidence,
               (double)out[k].score, out[k].inliers[0], out[k].inliers[1], out[k].track_id);
    }
}

/* Frames where taking the scored pairs best score first (each contour
 * once) gives fewer pipes than the rack holds: a gap outscored the pipes
 * beside it, and only the matching's augmenting paths find them all. */
static int greedy_short;

static int greedy_pairs(const cdsp_pair_set *set)
{
    uint8_t used[CDSP_MAX_LINES] = {0};
    int k, n = 0;
    for (k = 0; k < set->npairs; k++)
        if (!used[set->pair[k].i] && !used[set->pair[k].j]) {
            used[set->pair[k].i] = used[set->pair[k].j] = 1;
            n++;
        }
    return n;
}

/* One frame of the case, with or without the distance range: every pipe
 * found once (idx), and nothing else parallel to the rack (no gap); without
 * the range the crossing may be reported too (a real object solved as a
 * pipe of the wrong radius), with it nothing but the pipes. */
static void rack_found(const rack_case *rc, uint64_t seed, int ranged, cdsp_result *out, size_t *n,
                       rack_geo *g, int idx[5])
{
    cdsp_camera cam;
    cdsp_status st;
    size_t k;
    int i, j;
    camera(&cam);
    solve_rack(rc, 0, seed, ranged, NULL, out, n, g, &st);
    debug_print(out, *n);
    if (st != CDSP_OK)
        fail_msg("%s: %s", rc->name, cdsp_strerror(st));
    if (greedy_pairs(&ws.frame.pairs) < rc->n)
        greedy_short++;
    for (i = 0; i < rc->n; i++) {
        idx[i] = match(&cam, out, *n, g, i, rc->radius[i]);
        if (idx[i] < 0)
            fail_msg("%s%s: pipe %d of %d not found (%zu reported)", rc->name,
                     ranged ? " (range)" : "", i, rc->n, *n);
        for (j = 0; j < i; j++)
            if (idx[j] == idx[i])
                fail_msg("%s: pipes %d and %d reported as one", rc->name, j, i);
    }
    for (k = 0; k < *n; k++) {
        double P[3], d[3];
        int mine = 0;
        for (i = 0; i < rc->n; i++)
            mine |= idx[i] == (int)k;
        if (mine)
            continue;
        sup_result_pose(&out[k], P, d, NULL);
        if (ranged || rc->cross == CROSS_NONE || sup_axis_angle(d, g->s) > 2 * SUP_PI / 180)
            fail_msg("%s%s: reported pipe %zu (distance %.1f) is neither a pipe nor the crossing: "
                     "a gap taken for a pipe", rc->name, ranged ? " (range)" : "", k,
                     (double)out[k].distance);
    }
}

/* Contour bias of the edge detector allowed per contour, px: flat-lit
 * edges are exact up to the noise (the partial-area estimate, docs/method.md
 * §2: test_edges measures a few 1e-3 px); a shaded limb keeps a bias the
 * second pass does not remove (issue 12: 0.07-0.44 % of the distance on
 * shaded frames, i.e. 0.01-0.07 px on the 30 px bands here). */
#define DELTA_FLAT_PX 0.005
#define DELTA_SHADED_PX 0.03

/* The spacing tolerance of neighbours a, b (mm). Random part: 6 sigma of
 * the spacing, each pipe's P_C covariance projected on the rack's side
 * direction s (the spacing is lateral; the large depth variance is along
 * the line of sight and hardly moves it). Systematic part, for a bias of
 * delta px on each contour: both contours moved inward by delta make the
 * band 2 delta narrower, the distance d (1 + 2 delta / w) (w the band's
 * width, px), and that moves the axis along its line of sight, which has
 * the component x / d along s (x: the pipe's offset from the optical axis
 * along s): |x| 2 delta / w per pipe; a bias that differs between the two
 * contours shifts the axis sideways by up to d delta / F per pipe.
 * Measured (test_racks prints each case's worst pair): shaded cases 0.33-
 * 0.64 of the tolerance (double and float), where the bias allowance
 * dominates and the error is mostly that bias; flat cases 0.02-0.17, where
 * the 6-sigma random part dominates: one draw per pair, at a fraction of a
 * sigma, is what a 6-sigma band (2e-9 per check) leaves room for, not a
 * tolerance to shrink to the sample. */
static double spacing_tol(const cdsp_result *ra, const cdsp_result *rb, const rack_geo *g, int a,
                          int b, const double radius[5], double delta)
{
    double var = 0, sys = 0;
    int k, r, c, which;
    for (which = 0; which < 2; which++) {
        const cdsp_result *res = which ? rb : ra;
        int i = which ? b : a;
        double x = 0, d = sqrt(g->c[i][0] * g->c[i][0] + g->c[i][2] * g->c[i][2]), w;
        for (r = 0; r < 3; r++)
            for (c = 0; c < 3; c++)
                var += g->s[r] * (double)res->cov[r][c] * g->s[c];
        for (k = 0; k < 3; k++)
            x += g->c[i][k] * g->s[k];
        w = 2 * F * radius[i] / d;
        sys += fabs(x) * 2 * delta / w + d * delta / F;
    }
    return 6 * sqrt(var) + sys;
}

/* Every neighbours' spacing against its tolerance; returns the worst ratio
 * error / tolerance. The found pipes' 3D poses are scaled by r_i / RADIUS:
 * a wrong radius moves P_C and the segment by exactly (dr / r) d
 * (docs/method.md §9). */
static double rack_check(const rack_case *rc, uint64_t seed, double *worst_err)
{
    cdsp_result out[CDSP_MAX_PIPES];
    size_t n = 0;
    rack_geo g;
    int idx[5], i, k;
    double worst = 0;
    rack_found(rc, seed, 0, out, &n, &g, idx);
    rack_found(rc, seed, 1, out, &n, &g, idx);
    if (n != (size_t)rc->n)
        fail_msg("%s: %zu pipes reported for %d with the range", rc->name, n, rc->n);
    for (i = 0; i < rc->n; i++) {
        cdsp_result *r = &out[idx[i]];
        cdsp_real sc = (cdsp_real)(rc->radius[i] / RADIUS);
        for (k = 0; k < 3; k++) {
            r->point[k] *= sc;
            r->segment[0][k] *= sc;
            r->segment[1][k] *= sc;
        }
    }
    *worst_err = 0;
    for (i = 0; i + 1 < rc->n; i++) {
        cdsp_real mean, spread;
        double truth = sup_line_dist(g.c[i], g.v, g.c[i + 1]), err, tol;
        assert_int_equal(cdsp_result_axis_spacing(&out[idx[i]], &out[idx[i + 1]], 64, &mean, &spread),
                         CDSP_OK);
        err = fabs((double)mean - truth);
        tol = spacing_tol(&out[idx[i]], &out[idx[i + 1]], &g, i, i + 1, rc->radius,
                          rc->shaded ? DELTA_SHADED_PX : DELTA_FLAT_PX);
        if (getenv("MULTI_DEBUG"))
            printf("   pair %d: error %.4f mm, tolerance %.4f mm\n", i, err, tol);
        if (err > tol)
            fail_msg("%s: spacing %d-%d off by %.4f mm (tolerance %.4f mm)", rc->name, i, i + 1, err,
                     tol);
        worst = fmax(worst, err / tol);
        *worst_err = fmax(*worst_err, err);
    }
    return worst;
}

static const rack_case cases[] = {
    {"2 equal, flat", 2, {8, 8}, 0.6, 0, CROSS_NONE, 0},
    {"2 equal, shaded", 2, {8, 8}, 0.6, 1, CROSS_NONE, 0},
    {"3 equal, shaded, bar", 3, {8, 8, 8}, 0.5, 1, CROSS_BAR, 0},
    {"3 different, flat, column", 3, {8, 7, 9}, 0.6, 0, CROSS_COLUMN, 0},
    {"4 equal, flat, column", 4, {8, 8, 8, 8}, 0.5, 0, CROSS_COLUMN, 0},
    {"4 different, shaded, bar", 4, {7, 9, 8, 7.5}, 0.6, 1, CROSS_BAR, 0},
    {"5 equal, shaded", 5, {8, 8, 8, 8, 8}, 0.45, 1, CROSS_NONE, 0},
    {"5 different, shaded, column", 5, {8, 7, 9, 7.5, 8.5}, 0.5, 1, CROSS_COLUMN, 0},
};

static void test_racks(void **state)
{
    size_t c;
    (void)state;
    for (c = 0; c < sizeof cases / sizeof cases[0]; c++) {
        double e, ratio = rack_check(&cases[c], 11 + c, &e);
        printf("%-30s spacing error %.4f mm, %.2f of its tolerance\n", cases[c].name, e, ratio);
    }
    printf("frames where best-score-first pairing would have taken a gap: %d of %d\n", greedy_short,
           (int)(2 * (sizeof cases / sizeof cases[0])));
    /* the table holds the case the matching exists for (measured: 1 of 16) */
    assert_true(greedy_short >= 1);
}

/* Whether pipe i of g has both contours inside the frame (6 px in) at its
 * middle row and, on the side the racks leave by, at its top row. */
static int in_full_view(const cdsp_camera *cam, const rack_geo *g, int i)
{
    double lt[2][3], pin[2], u0, u1;
    assert_true(sup_contour_lines(cam, g->c[i], g->v, 8, lt, pin));
    u0 = -(lt[0][1] * (H / 2.0) + lt[0][2]) / lt[0][0];
    u1 = -(lt[1][1] * (H / 2.0) + lt[1][2]) / lt[1][0];
    return u0 > 6 && u0 < W - 7 && u1 > 6 && u1 < W - 7 && -(lt[0][1] * 0 + lt[0][2]) / lt[0][0] < W - 7 &&
           -(lt[1][1] * 0 + lt[1][2]) / lt[1][0] < W - 7;
}

/* A rack of three pipes panning across the frame, 10 mm (19 px) per
 * frame, within the tracker's 24 px gate: every pipe keeps its id, and
 * the ids are distinct. */
static void test_tracking_pan(void **state)
{
    static const rack_case rc = {"pan", 3, {8, 8, 8}, 0.5, 1, CROSS_NONE, 0};
    cdsp_tracker trk;
    cdsp_camera cam;
    uint32_t ids[3] = {0, 0, 0};
    int f, i;
    (void)state;
    camera(&cam);
    cdsp_tracker_init(&trk);
    for (f = 0; f < 13; f++) {
        cdsp_result out[CDSP_MAX_PIPES];
        size_t n;
        rack_geo g;
        cdsp_status st;
        solve_rack(&rc, -60 + 10.0 * f, 100 + (uint64_t)f, 0, &trk, out, &n, &g, &st);
        debug_print(out, n);
        assert_int_equal(st, CDSP_OK);
        assert_int_equal(n, 3);
        for (i = 0; i < 3; i++) {
            int k = match(&cam, out, n, &g, i, 8);
            if (k < 0)
                fail_msg("frame %d: pipe %d not found", f, i);
            if (out[k].track_id == 0)
                fail_msg("frame %d: pipe %d has no track id", f, i);
            if (f == 0)
                ids[i] = out[k].track_id;
            else if (out[k].track_id != ids[i])
                fail_msg("frame %d: pipe %d has id %u, was %u", f, i, out[k].track_id, ids[i]);
        }
    }
    assert_true(ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2]);
}

/* The same rack panning faster (12 mm, 23 px, a gap's width per frame)
 * until its pipes leave the frame: when one contour of the first pipe is
 * out of view, the five lines left pair as two pipes or as two gaps (the
 * same count), and the gaps score higher here (their contours are the
 * pipes' brighter ones); without the tracker's constant-velocity
 * prediction the gap beside a pipe sits where the pipe was a frame before
 * and took its track (measured: two gaps at 657 mm reported, and ids
 * swapped after). Checked: every pipe reported is a true one (never a
 * gap), each true pipe keeps one id over the whole run, and a pipe in view
 * with both contours is reported. The same frames solved on their own (no
 * tracker) must not report a gap either: there the tie between as many
 * pipes as gaps goes to the matching whose left-over contour the frame's
 * edge explains (measured: without that, frame 10 reports a gap at 734 mm). */
static void test_tracking_leaving(void **state)
{
    static const rack_case rc = {"leaving", 3, {8, 8, 8}, 0.6, 1, CROSS_NONE, 0};
    cdsp_tracker trk;
    cdsp_camera cam;
    uint32_t ids[3] = {0, 0, 0};
    int f, i, reported = 0;
    (void)state;
    camera(&cam);
    cdsp_tracker_init(&trk);
    for (f = 0; f < 16; f++) {
        cdsp_result out[CDSP_MAX_PIPES];
        size_t n, k;
        rack_geo g;
        cdsp_status st;
        int seen[CDSP_MAX_PIPES] = {0};
        solve_rack(&rc, 20.0 + 12.0 * f, 300 + (uint64_t)f, 0, &trk, out, &n, &g, &st);
        debug_print(out, n);
        if (st != CDSP_OK)
            continue; /* every pipe out of view */
        for (i = 0; i < 3; i++) {
            k = (size_t)match(&cam, out, n, &g, i, 8);
            if ((int)k < 0) {
                if (in_full_view(&cam, &g, i))
                    fail_msg("frame %d: pipe %d in view but not reported", f, i);
                continue;
            }
            seen[k] = 1;
            reported++;
            if (!ids[i])
                ids[i] = out[k].track_id;
            else if (out[k].track_id != ids[i])
                fail_msg("frame %d: pipe %d has id %u, was %u", f, i, out[k].track_id, ids[i]);
        }
        for (k = 0; k < n; k++)
            if (!seen[k])
                fail_msg("frame %d: reported pipe %zu (distance %.1f) is no true pipe (a gap)", f, k,
                         (double)out[k].distance);
        /* on its own */
        solve_rack(&rc, 20.0 + 12.0 * f, 300 + (uint64_t)f, 0, NULL, out, &n, &g, &st);
        assert_int_equal(st, CDSP_OK);
        for (k = 0; k < n; k++) {
            int mine = 0;
            for (i = 0; i < 3; i++)
                mine |= match(&cam, out, n, &g, i, 8) == (int)k;
            if (!mine)
                fail_msg("frame %d, no tracker: reported pipe %zu (distance %.1f) is a gap", f, k,
                         (double)out[k].distance);
        }
    }
    /* the run saw the rack whole and leaving (measured: 38 reports of 48
     * pipe-frames, the rest out of view; 2 fewer allowed for the float build) */
    if (getenv("MULTI_DEBUG"))
        printf("leaving: %d pipe reports\n", reported);
    assert_true(reported >= 36);
    assert_true(ids[0] && ids[1] && ids[2] && ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2]);
}

/* A pipe coming into view while every track holds: a rack of three
 * panning by 5 mm (9.5 px) per frame, inside the bands, whose third pipe
 * is hidden (not rendered) for the first 3 frames, as when it comes out
 * from behind an occluder. The bands read only the two tracks' contours,
 * so it must be found by the full search every full_every frames (the
 * default 10: by frame 10, 8 frames after it appeared) and keep its id
 * after; the two tracked pipes keep theirs through that search. With
 * full_every 0 (a full search only when a track is lost) the same run
 * must miss it to the end (18 frames), or the run would not test the
 * rule. Returns the frames the third pipe waited (18 - 3 + 1 when never
 * reported). */
static int entering_run(int full_every, uint32_t ids[3])
{
    static const rack_case rc = {"entering", 3, {8, 8, 8}, 0.5, 1, CROSS_NONE, 0};
    cdsp_tracker trk;
    cdsp_camera cam;
    int f, i, wait = 18 - 3 + 1;
    camera(&cam);
    cdsp_tracker_init(&trk);
    if (full_every >= 0)
        trk.full_every = full_every;
    for (i = 0; i < 3; i++)
        ids[i] = 0;
    for (f = 0; f < 18; f++) {
        cdsp_result out[CDSP_MAX_PIPES];
        size_t n;
        rack_geo g;
        cdsp_status st;
        int shown = f < 3 ? 2 : 3;
        solve_rack_shown(&rc, shown, -20 + 5.0 * f, 900 + (uint64_t)f, &trk, out, &n, &g, &st);
        debug_print(out, n);
        assert_int_equal(st, CDSP_OK);
        for (i = 0; i < shown; i++) {
            int k = match(&cam, out, n, &g, i, 8);
            if (k < 0) {
                if (i < 2)
                    fail_msg("full_every %d, frame %d: tracked pipe %d lost", full_every, f, i);
                continue;
            }
            if (!ids[i])
                ids[i] = out[k].track_id;
            else if (out[k].track_id != ids[i])
                fail_msg("full_every %d, frame %d: pipe %d has id %u, was %u", full_every, f, i,
                         out[k].track_id, ids[i]);
            if (i == 2 && f - 3 + 1 < wait)
                wait = f - 3 + 1;
        }
    }
    if (getenv("MULTI_DEBUG"))
        printf("entering, full_every %d: ids %u %u %u, the third pipe waited %d frames\n", full_every,
               ids[0], ids[1], ids[2], wait);
    return wait;
}

/* test_tracking_leaving's rack coming into view from the frame's edge
 * (12 mm, 23 px per frame): a pipe half in view is tracked, and on the
 * next frame its bands held one of its contours and an edge beside it,
 * a pair within the gate but 17 px wide for 28, solved at 754 mm for 458;
 * it took the track, and the pipe got a new id the frame after (measured
 * before lib/multi.c's TRACK_WIDTH_CHANGE). Checked: every pipe reported
 * is a true one, and each keeps one id from the first frame it is
 * reported in full view. */
static void test_tracking_entering_edge(void **state)
{
    static const rack_case rc = {"entering edge", 3, {8, 8, 8}, 0.6, 1, CROSS_NONE, 0};
    cdsp_tracker trk;
    cdsp_camera cam;
    uint32_t ids[3] = {0, 0, 0};
    int f, i;
    (void)state;
    camera(&cam);
    cdsp_tracker_init(&trk);
    for (f = 0; f < 18; f++) {
        cdsp_result out[CDSP_MAX_PIPES];
        size_t n, k;
        rack_geo g;
        cdsp_status st;
        int seen[CDSP_MAX_PIPES] = {0};
        solve_rack(&rc, 20.0 + 12.0 * (17 - f), 700 + (uint64_t)f, 0, &trk, out, &n, &g, &st);
        debug_print(out, n);
        if (st != CDSP_OK)
            continue; /* nothing in view yet */
        for (i = 0; i < 3; i++) {
            int m = match(&cam, out, n, &g, i, 8);
            if (m < 0)
                continue;
            seen[m] = 1;
            if (!in_full_view(&cam, &g, i))
                continue;
            if (!ids[i])
                ids[i] = out[m].track_id;
            else if (out[m].track_id != ids[i])
                fail_msg("frame %d: pipe %d has id %u, was %u", f, i, out[m].track_id, ids[i]);
        }
        for (k = 0; k < n; k++)
            if (!seen[k])
                fail_msg("frame %d: reported pipe %zu (distance %.1f) is no true pipe", f, k,
                         (double)out[k].distance);
    }
    assert_true(ids[0] && ids[1] && ids[2] && ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2]);
}

static void test_tracking_entering(void **state)
{
    static const rack_case rc = {"entering", 3, {8, 8, 8}, 0.5, 1, CROSS_NONE, 0};
    uint32_t ids[3];
    cdsp_tracker t;
    cdsp_result out[CDSP_MAX_PIPES];
    size_t n;
    rack_geo g;
    cdsp_status st;
    int wait;
    (void)state;
    cdsp_tracker_init(&t);
    assert_int_equal(t.full_every, 10);
    wait = entering_run(-1, ids);
    if (wait > t.full_every)
        fail_msg("the pipe coming into view waited %d frames, more than full_every = %d", wait,
                 t.full_every);
    assert_true(ids[0] && ids[1] && ids[2] && ids[0] != ids[1] && ids[1] != ids[2] && ids[0] != ids[2]);
    wait = entering_run(0, ids);
    if (!(wait > t.full_every))
        fail_msg("with full_every 0 the pipe was found after %d frames: the run does not test the rule",
                 wait);
    t.full_every = -1;
    solve_rack_shown(&rc, 3, 0, 1, &t, out, &n, &g, &st);
    assert_int_equal(st, CDSP_E_ARG);
}

/* Perpendicular distance (px) of undistorted point (x, y) from the
 * nearest contour the tracker predicts for this frame (its lines moved by
 * their velocity, as lib/multi.c's track_predict). */
static double band_offset(const cdsp_tracker *trk, double x, double y)
{
    double best = 1e30;
    int t, c;
    for (t = 0; t < CDSP_MAX_TRACKS; t++)
        for (c = 0; c < 2 && trk->track[t].id; c++) {
            const cdsp_real *l = trk->track[t].lines[c];
            double k = (double)trk->track[t].missed + 1;
            double d = fabs((double)l[0] * x + (double)l[1] * y + (double)l[2] -
                            k * (double)trk->track[t].velocity[c]);
            best = fmin(best, d);
        }
    return best;
}

/* The tracked multi-pipe solve reads only the bands of its tracks: a
 * rack panning by 5 mm (9.5 px) per frame, inside the 12 px bands even
 * before the tracks have a velocity, with a bar across it (edges outside
 * every band). From the second frame on every pipe is flagged TRACKED
 * (not FULL_SEARCH) and every edge point the solve considered lies within
 * track_band_px + 2 px of a predicted contour (the band's floor and
 * rounding, 1 px, and the partial-area position within its candidate
 * pixel, 1 px; a perpendicular distance, at most the distance along the
 * scanline); the full search of the same frame considers more. The poses
 * are the full search's: the bands are read on the full search's scanlines
 * at its step, so each contour gets the same inliers and the same fit, up
 * to the rounding of sums taken in another order (measured: 2e-11 of each
 * pose's own sigma in double, 0.009 in float; tolerance 1e-9 and 0.02; one
 * inlier taken by one search and not the other would move a pose by ~0.1
 * sigma, a point's scatter / ~120 inliers). Then the rack jumps by more
 * than the gate (40 mm, 76 px): the bands lose every pipe, a full search
 * runs (FULL_SEARCH) and finds all three, with new ids. */
static void test_tracking_bands(void **state)
{
    static const rack_case rc = {"bands", 3, {8, 8, 8}, 0.5, 1, CROSS_BAR, 0};
    cdsp_tracker trk;
    cdsp_camera cam;
    cdsp_params prm;
    int f, i, tracked = 0;
    double worst_z = 0, tol = sizeof(cdsp_real) < sizeof(double) ? 0.02 : 1e-9;
    (void)state;
    camera(&cam);
    cdsp_params_default(&prm);
    cdsp_tracker_init(&trk);
    for (f = 0; f < 7; f++) {
        cdsp_result out[CDSP_MAX_PIPES], ref[CDSP_MAX_PIPES];
        cdsp_tracker before = trk;
        size_t n, m, e;
        rack_geo g;
        cdsp_status st;
        double dx = f < 6 ? -20 + 5.0 * f : -20 + 5.0 * 5 + 40;
        solve_rack(&rc, dx, 500 + (uint64_t)f, 0, &trk, out, &n, &g, &st);
        assert_int_equal(st, CDSP_OK);
        debug_print(out, n);
        if (f > 0 && f < 6) {
            for (i = 0; i < (int)n; i++)
                if ((out[i].flags & (CDSP_FLAG_TRACKED | CDSP_FLAG_FULL_SEARCH)) != CDSP_FLAG_TRACKED)
                    fail_msg("frame %d: pipe %d not from the bands (flags 0x%x)", f, i, out[i].flags);
            for (e = 0; e < out[0].n_edges; e++) {
                double d = band_offset(&before, (double)ws.frame.edge[e].x, (double)ws.frame.edge[e].y);
                if (d > (double)prm.track_band_px + 2)
                    fail_msg("frame %d: edge %zu read %.1f px from every band", f, e, d);
            }
            tracked++;
        } else {
            for (i = 0; i < (int)n; i++)
                assert_true(out[i].flags & CDSP_FLAG_FULL_SEARCH);
        }
        /* the same frame by the full search */
        solve_rack(&rc, dx, 500 + (uint64_t)f, 0, NULL, ref, &m, &g, &st);
        assert_int_equal(st, CDSP_OK);
        if (f > 0 && f < 6 && !(out[0].n_edges < ref[0].n_edges))
            fail_msg("frame %d: the bands held %u edges, the whole frame %u", f, out[0].n_edges,
                     ref[0].n_edges);
        for (i = 0; i < 3; i++) {
            int a = match(&cam, out, n, &g, i, 8), b = match(&cam, ref, m, &g, i, 8), k;
            double Pa[3], da[3], Pb[3], db[3], zd, zp = 0;
            if (a < 0 || b < 0)
                fail_msg("frame %d: pipe %d not found (tracked %d, full %d)", f, i, a, b);
            sup_result_pose(&out[a], Pa, da, NULL);
            sup_result_pose(&ref[b], Pb, db, NULL);
            zd = sup_axis_angle(da, db) / sqrt((double)(ref[b].sigma_direction[0] * ref[b].sigma_direction[0] +
                                                        ref[b].sigma_direction[1] * ref[b].sigma_direction[1] +
                                                        ref[b].sigma_direction[2] * ref[b].sigma_direction[2]));
            for (k = 0; k < 3; k++)
                zp = fmax(zp, fabs(Pa[k] - Pb[k]) / (double)ref[b].sigma_point[k]);
            if (getenv("MULTI_DEBUG"))
                printf("  frame %d pipe %d: tracked - full: direction %.3g sigma, point %.3g sigma\n", f, i,
                       zd, zp);
            worst_z = fmax(worst_z, fmax(zd, zp));
            if (zd > tol || zp > tol)
                fail_msg("frame %d, pipe %d: tracked pose %.3f sigma from the full search's", f, i,
                         fmax(zd, zp));
        }
    }
    printf("tracked rack frames: %d of 7, poses at most %.3g sigma from the full search's\n", tracked,
           worst_z);
    assert_int_equal(tracked, 5);
}

/* The points path: exact contour points of three parallel pipes (0.1 px
 * noise), one of them with half the points: all three found, each once. */
static void test_points_rack(void **state)
{
    static cdsp_points_all_ws pws;
    static const rack_case rc = {"points", 3, {8, 8, 8}, 0.6, 0, CROSS_NONE, 0};
    cdsp_edge pts[CDSP_MAX_POINTS];
    cdsp_result out[CDSP_MAX_PIPES];
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng;
    rack_geo g;
    size_t n = 0, m;
    int i, k, seen[3] = {-1, -1, -1};
    (void)state;
    camera(&cam);
    rack_layout(&rc, 0, &g);
    cdsp_rng_seed(&rng, 5, 1);
    for (i = 0; i < 3; i++)
        n += sup_contour_points(&cam, g.c[i], g.v, 8, -150, 150, i == 1 ? 100 : 200, 0.1, 80, &rng,
                                pts + n, CDSP_MAX_POINTS - n, NULL);
    cdsp_params_default(&prm);
    assert_int_equal(cdsp_points_solve_all(&cam, 8, pts, n, &prm, NULL, &pws, &rng, out, CDSP_MAX_PIPES,
                                           &m),
                     CDSP_OK);
    assert_int_equal(m, 3);
    for (i = 0; i < 3; i++) {
        seen[i] = match(&cam, out, m, &g, i, 8);
        assert_true(seen[i] >= 0);
        for (k = 0; k < i; k++)
            assert_true(seen[k] != seen[i]);
    }
    /* cap: the best two only, in rank order */
    assert_int_equal(cdsp_points_solve_all(&cam, 8, pts, n, &prm, NULL, &pws, &rng, out, 2, &m), CDSP_OK);
    assert_int_equal(m, 2);
    assert_true(out[0].score >= out[1].score);
}

/* The spacing measure on exact results: two parallel axes 100 mm apart
 * give exactly 100 with no spread; axes at an angle give the mean of the
 * distances at the segment's part midpoints, computed here directly. */
static void test_axis_spacing(void **state)
{
    cdsp_result a, b;
    cdsp_real mean, spread;
    double sum = 0, sum2 = 0, m;
    int k;
    (void)state;
    memset(&a, 0, sizeof a);
    memset(&b, 0, sizeof b);
    a.point[2] = 500;
    a.direction[0] = 1;
    a.segment[0][0] = -150;
    a.segment[1][0] = 150;
    a.segment[0][2] = a.segment[1][2] = 500;
    b = a;
    b.point[1] = 100;
    assert_int_equal(cdsp_result_axis_spacing(&a, &b, 16, &mean, &spread), CDSP_OK);
    /* a few rounding steps per distance (cross product, norm), summed
     * over 16 points: 64 ulps of 100 bounds it; measured 0 (every
     * operation exact: y = 100, z = 0, unit direction) */
    assert_true(fabs((double)mean - 100) < 64 * T_EPS * 100);
    assert_true((double)spread < 64 * T_EPS * 100);
    /* b turned by 0.1 rad about the spacing direction: d(x) = sqrt(100^2 +
     * (x sin 0.1)^2), mean and spread computed here in double, the spread
     * in two passes (sum2 / 8 - m^2 cancels 1e4 against 0.1: it was off by
     * 70 eps x 100 in double, more than the library). Bound: each distance
     * is a few roundings of ~100 (the point on a's segment, the difference,
     * the cross product, the norm: ~2.5 eps x 100 at worst), the mean of 8
     * adds ~4 more at worst, and the spread's deviations d_k - m carry the
     * same absolute error: 8 eps x 100 for both. Measured: 0 / 0 (double:
     * the roundings of the library and of this reference agree), 0.52 /
     * 0.017 eps x 100 (float: rounding errors of one sign partly cancel in
     * the sum, and in the deviations almost wholly, the 8 distances being
     * rounded alike). It was 1e4 and 1e5 eps x 100 (0.12 and 1.2 mm in
     * float, for a spread of 0.32 mm). */
    b.direction[0] = (cdsp_real)cos(0.1);
    b.direction[2] = (cdsp_real)sin(0.1);
    b.point[0] = 0;
    assert_int_equal(cdsp_result_axis_spacing(&a, &b, 8, &mean, &spread), CDSP_OK);
    for (k = 0; k < 8; k++) {
        double x = -150 + 300 * (k + 0.5) / 8, d = sqrt(100.0 * 100 + x * x * sin(0.1) * sin(0.1));
        sum += d;
    }
    m = sum / 8;
    for (k = 0; k < 8; k++) {
        double x = -150 + 300 * (k + 0.5) / 8, d = sqrt(100.0 * 100 + x * x * sin(0.1) * sin(0.1));
        sum2 += (d - m) * (d - m);
    }
    if (getenv("CDSP_TEST_VERBOSE"))
        print_message("axis spacing: mean off by %.3g eps x 100, spread by %.3g (spread %.4g mm)\n",
                      fabs((double)mean - m) / (T_EPS * 100),
                      fabs((double)spread - sqrt(sum2 / 8)) / (T_EPS * 100), sqrt(sum2 / 8));
    assert_true(fabs((double)mean - m) < 8 * T_EPS * 100);
    assert_true(fabs((double)spread - sqrt(sum2 / 8)) < 8 * T_EPS * 100);
    assert_int_equal(cdsp_result_axis_spacing(NULL, &b, 8, &mean, &spread), CDSP_E_ARG);
    assert_int_equal(cdsp_result_axis_spacing(&a, &b, 0, &mean, &spread), CDSP_E_ARG);
    b.direction[1] = (cdsp_real)NAN;
    assert_int_equal(cdsp_result_axis_spacing(&a, &b, 8, &mean, &spread), CDSP_E_NONFINITE);
}

/*
 * The single path's scatter rule (issue 12, lib/frame.c
 * cdsp__frame_scatter_mark) applies to every pipe of cdsp_frame_solve_all:
 * test_frame's paper scene (2448 x 2048, noise 0.5 gray level, pipes
 * p1..p4, radius 8 mm, half length 250 mm). At ambient 0.4 the shadowed
 * limb is nearly the background's level, and a pose from its scattered
 * line was 13-170 mm off while claiming sigma plus bound far below that;
 * every pose reported with CDSP_FLAG_BOUND must hold its distance error
 * within 3 sigma plus the bound (measured without the rule: p1 twice, 20.1
 * and 18.0 mm off within its wide 23.9 and 47.2 mm, then p2 48.5 mm off
 * against 10.1 mm, a failure). A marked pose claims no bound (flag clear,
 * bound fields 0: its error is not checked) and has its confidence capped
 * at 0.78 (measured: 4 such poses at ambient 0.4, one bounded pose of p4
 * 0.21 mm off against 1.29 mm). At ambient 0.85 (clean contours) the rule
 * must not mark the pipe: it is reported with its bound, within it
 * (measured: 0.015-0.051 mm off against 0.22-0.33).
 */
static void test_scatter_refusal(void **state)
{
    static const double ambients[] = {0.4, 0.85};
    cdsp_camera cam;
    int a, i, reported[2] = {0, 0}, unbounded = 0;
    (void)state;
    sup_paper_camera(&cam, 0, 0);
    for (a = 0; a < 2; a++)
        for (i = 0; i < 4; i++) {
            cdsp_scene s;
            cdsp_image img;
            cdsp_result out[CDSP_MAX_PIPES];
            cdsp_params prm;
            cdsp_rng rng;
            size_t n = 0, k;
            double P[3], v[3], t, f[3], dtrue;
            int q, found = 0;
            void *px;
            sup_paper_bound_scene(&s, i, ambients[a], P, v);
            px = sup_render(&s, &cam, 8, (uint64_t)(50 + i), &img);
            assert_non_null(px);
            cdsp_params_default(&prm);
            cdsp_rng_seed(&rng, 3, (uint64_t)i);
            if (cdsp_frame_solve_all(&img, &cam, 8, &prm, NULL, &ws, &rng, out, CDSP_MAX_PIPES, &n) != CDSP_OK)
                n = 0;
            free(px);
            t = P[0] * v[0] + P[1] * v[1] + P[2] * v[2];
            for (q = 0; q < 3; q++)
                f[q] = P[q] - t * v[q];
            dtrue = sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
            for (k = 0; k < n; k++) {
                double Pk[3], d[3], err, allowed;
                sup_result_pose(&out[k], Pk, d, NULL);
                if (sup_axis_angle(d, v) > 2 * SUP_PI / 180)
                    continue; /* not this pipe (the scene has nothing else, but a band is possible) */
                found = 1;
                if (!(out[k].flags & CDSP_FLAG_BOUND)) {
                    /* scattered: no bound claimed, confidence capped
                     * (lib/frame.c SCATTER_CONF), bound fields 0 */
                    if (a == 1)
                        fail_msg("ambient 0.85 p%d: a clean pipe reported without a bound", i + 1);
                    assert_true((double)out[k].confidence <= 0.78);
                    assert_true(out[k].bound_distance == 0 && out[k].edge_bound[0] == 0);
                    unbounded++;
                    continue;
                }
                err = fabs((double)out[k].distance - dtrue);
                allowed = 3 * (double)out[k].sigma_distance + (double)out[k].bound_distance;
                if (getenv("MULTI_DEBUG"))
                    printf("ambient %.2f p%d: distance error %.3f mm, 3 sigma + bound %.3f mm\n",
                           ambients[a], i + 1, err, allowed);
                if (!(err <= allowed))
                    fail_msg("ambient %.2f p%d: reported %.3f mm off, beyond 3 sigma + bound %.3f mm",
                             ambients[a], i + 1, err, allowed);
            }
            reported[a] += found;
            if (a == 1 && !found)
                fail_msg("ambient 0.85 p%d: a clean pipe was not reported", i + 1);
        }
    if (getenv("MULTI_DEBUG"))
        printf("scatter: reported %d of 4 at ambient 0.4 (%d poses without a bound), %d of 4 at 0.85\n",
               reported[0], unbounded, reported[1]);
    assert_true(unbounded >= 1); /* the rule is exercised: the checks above are not vacuous */
}

/*
 * Support columns (the paper's rack: 12.68 mm columns under 16 mm pipes,
 * touching them from behind, across the rack): solved as pipes of radius
 * 8 they land at (Z0 + 8 + 6.34) 8 / 6.34 = 548 mm, 1.30 x the rack's
 * 420 mm, inside a distance range of x [0.8, 1.35] about the rack, so the
 * range alone lets them in. Seen behind the pipes (their contours hidden
 * over the pipes' bands) and solved about 120 mm beyond touching them,
 * they are not reported (lib/multi.c, crossing members); every pipe is.
 * Without the cue both columns were reported (measured: frame 0, at 549
 * and 562 mm, five results).
 */
static void test_support_columns(void **state)
{
    static const rack_case rc = {"supports", 3, {8, 8, 8}, 0.6, 1, CROSS_NONE, 0};
    cdsp_camera cam;
    int f;
    (void)state;
    camera(&cam);
    for (f = 0; f < 3; f++) {
        cdsp_scene s;
        cdsp_image img;
        cdsp_params prm;
        cdsp_rng rng;
        cdsp_result out[CDSP_MAX_PIPES];
        rack_geo g;
        size_t n = 0;
        double back[3], mid[3];
        int i, k, c, idx[3];
        void *buf;
        rack_layout(&rc, -20.0 + 20 * f, &g);
        rack_scene(&rc, &g, &s);
        cross3(g.v, g.s, back);
        unit(back);
        if (back[2] < 0)
            for (k = 0; k < 3; k++)
                back[k] = -back[k];
        for (k = 0; k < 3; k++)
            mid[k] = (g.c[0][k] + g.c[rc.n - 1][k]) / 2;
        for (c = 0; c < 2; c++) {
            cdsp_clutter *b = &s.clutter[s.n_clutter++];
            for (k = 0; k < 3; k++) {
                double o = mid[k] + (c ? 70 : -70) * g.v[k] + (8 + 6.34) * back[k];
                b->p0[k] = (cdsp_real)(o - 60 * g.s[k]);
                b->p1[k] = (cdsp_real)(o + 60 * g.s[k]);
            }
            b->half_width = (cdsp_real)6.34;
            b->level = (cdsp_real)0.45;
        }
        buf = sup_render(&s, &cam, 8, 700 + (uint64_t)f, &img);
        assert_non_null(buf);
        cdsp_params_default(&prm);
        prm.pair.min_distance = (cdsp_real)(0.8 * Z0);
        prm.pair.max_distance = (cdsp_real)(1.35 * Z0);
        cdsp_rng_seed(&rng, 9, (uint64_t)f);
        assert_int_equal(cdsp_frame_solve_all(&img, &cam, RADIUS, &prm, NULL, &ws, &rng, out, CDSP_MAX_PIPES, &n),
                         CDSP_OK);
        free(buf);
        debug_print(out, n);
        for (i = 0; i < 3; i++) {
            idx[i] = match(&cam, out, n, &g, i, 8);
            if (idx[i] < 0)
                fail_msg("frame %d: pipe %d not found (%zu reported)", f, i, n);
        }
        if (n != 3)
            fail_msg("frame %d: %zu reported for 3 pipes (a column taken for a pipe)", f, n);
    }
}

static void test_hostile(void **state)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng;
    cdsp_tracker trk;
    cdsp_result out[2];
    size_t n = 7;
    unsigned char px[W * H];
    cdsp_image img = {px, W, H, W, 8};
    cdsp_edge e[4] = {{0, 0, 1, 0}, {1, 0, 1, 0}, {2, 0, 1, 0}, {3, 0, 1, 0}};
    static cdsp_points_all_ws pws;
    (void)state;
    memset(px, 60, sizeof px);
    camera(&cam);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 1);
    cdsp_tracker_init(&trk);
    assert_int_equal(cdsp_frame_solve_all(NULL, &cam, 8, &prm, NULL, &ws, &rng, out, 2, &n), CDSP_E_ARG);
    assert_int_equal(cdsp_frame_solve_all(&img, &cam, 8, &prm, NULL, &ws, &rng, out, 0, &n), CDSP_E_ARG);
    assert_int_equal(cdsp_frame_solve_all(&img, &cam, 8, &prm, NULL, &ws, &rng, out, 2, NULL), CDSP_E_ARG);
    assert_int_equal(cdsp_frame_solve_all(&img, &cam, -1, &prm, NULL, &ws, &rng, out, 2, &n), CDSP_E_ARG);
    trk.gate_px = 0;
    assert_int_equal(cdsp_frame_solve_all(&img, &cam, 8, &prm, &trk, &ws, &rng, out, 2, &n), CDSP_E_ARG);
    cdsp_tracker_init(&trk);
    /* a blank frame: no pipe, nothing written, the tracker still usable */
    assert_int_equal(cdsp_frame_solve_all(&img, &cam, 8, &prm, &trk, &ws, &rng, out, 2, &n),
                     CDSP_E_FEW_POINTS);
    assert_int_equal(n, 0);
    img.width = W - 1;
    assert_int_equal(cdsp_frame_solve_all(&img, &cam, 8, &prm, NULL, &ws, &rng, out, 2, &n), CDSP_E_ARG);
    e[2].x = (cdsp_real)INFINITY;
    assert_int_equal(cdsp_points_solve_all(&cam, 8, e, 4, &prm, NULL, &pws, &rng, out, 2, &n),
                     CDSP_E_NONFINITE);
    assert_int_equal(cdsp_points_solve_all(&cam, 8, e, CDSP_MAX_POINTS + 1, &prm, NULL, &pws, &rng, out,
                                           2, &n),
                     CDSP_E_CAPACITY);
    assert_int_equal(cdsp_points_solve_all(&cam, 8, NULL, 4, &prm, NULL, &pws, &rng, out, 2, &n), CDSP_E_ARG);
    assert_true(cdsp_frame_all_ws_size() == sizeof(cdsp_frame_all_ws));
    assert_true(cdsp_points_all_ws_size() == sizeof(cdsp_points_all_ws));
}

/* The multi-pipe path caps a flipping narrow band's confidence as the
 * single path does (lib/pair.c, cdsp__pair_flip_cap): a pipe 20 px wide
 * (radius 5 at 400 mm, f 800) whose contrast flips halfway along both
 * contours (the background crossing its level), so each contour is two
 * lines of opposite polarity and each half is a band of its own. A half's
 * direction in depth turns by degrees for a 0.3 px drift of its contours'
 * ends; its evidence (support alone on the points path) is near 1, and
 * before the cap the multi-pipe path reported it at that. */
static void test_flip_cap_all(void **state)
{
    static cdsp_points_all_ws pws;
    static cdsp_points_ws sws;
    static cdsp_edge pts[800];
    double P[3] = {10, -5, 400}, v[3] = {0.05, 1, 0.1};
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng;
    cdsp_result out[CDSP_MAX_PIPES], one;
    size_t n = 0, m = 0, i;
    (void)state;
    unit(v);
    sup_camera(&cam, W, H, F, 0, 0);
    cdsp_rng_seed(&rng, 7, 1);
    n += sup_contour_points(&cam, P, v, 5, -100, 0, 150, 0.15, 60, &rng, pts, 800, NULL);
    n += sup_contour_points(&cam, P, v, 5, 0, 100, 150, 0.15, -60, &rng, pts + n, 800 - n, NULL);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 2);
    assert_int_equal(cdsp_points_solve(&cam, 5, pts, n, &prm, NULL, &sws, &rng, &one), CDSP_OK);
    cdsp_rng_seed(&rng, 1, 2);
    assert_int_equal(cdsp_points_solve_all(&cam, 5, pts, n, &prm, NULL, &pws, &rng, out, CDSP_MAX_PIPES, &m),
                     CDSP_OK);
    if (getenv("CDSP_TEST_VERBOSE")) {
        print_message("single path: distance %.1f confidence %.3f\n", (double)one.distance,
                      (double)one.confidence);
        for (i = 0; i < m; i++)
            print_message("multi-pipe path %u: distance %.1f confidence %.3f\n", (unsigned)i,
                          (double)out[i].distance, (double)out[i].confidence);
    }
    assert_true((double)one.confidence < 0.9);
    for (i = 0; i < m; i++)
        assert_true((double)out[i].confidence < 0.9);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_racks),
        cmocka_unit_test(test_tracking_pan),
        cmocka_unit_test(test_tracking_leaving),
        cmocka_unit_test(test_tracking_entering),
        cmocka_unit_test(test_tracking_entering_edge),
        cmocka_unit_test(test_tracking_bands),
        cmocka_unit_test(test_points_rack),
        cmocka_unit_test(test_scatter_refusal),
        cmocka_unit_test(test_support_columns),
        cmocka_unit_test(test_axis_spacing),
        cmocka_unit_test(test_hostile),
        cmocka_unit_test(test_flip_cap_all),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
