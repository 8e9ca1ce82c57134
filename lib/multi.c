/*
 * multi.c - every pipe in view: the pipes of a rack as a matching of the
 * candidate contour lines, and their track ids from frame to frame.
 *
 * pair.c scores every pair of candidate lines that passes the pair tests.
 * A contour belongs to one pipe, so the pipes are a matching in the graph
 * whose nodes are the lines and whose edges are the scored pairs. The
 * single-pipe path ranks bands; here the question is which set of bands
 * explains the contours, and the answer is the matching with the most
 * pairs: across a rack of k bright pipes the edges alternate in polarity,
 * and pairing them as the k pipes uses all 2k contours, whereas pairing
 * them as the k - 1 dark gaps leaves the two outer ones over. Maximum
 * cardinality is found from the greedy best-score matching by augmenting
 * paths (Berge 1957: a matching is maximum iff no augmenting path exists;
 * the search below is Kuhn's, exact on bipartite graphs, and the pair graph
 * is bipartite whenever the contours are near-parallel, since a pair joins
 * a line whose normal points one way to one whose normal points the other;
 * on other graphs it may stop short, never with an invalid matching). Edges
 * are tried in score order, so among the augmentations the strongest pairs
 * come in. With a tracker the pairs near a live track are tried first
 * (their score weighted as in the single path's tracking, 1 + 2 exp(-e^2/2)).
 *
 * Tracking: each pipe is matched to the live track whose predicted
 * contours are nearest to its own (the largest of the two contours'
 * distances, at the pipe's middle, undistorted px), within the tracker's
 * gate, greedily by distance; it keeps the track's id and its direction's
 * sign. The prediction moves each contour by its last shift per frame
 * (constant velocity, times the frames since it was seen): without it a
 * rack panning by about a gap's width per frame puts the gap where a pipe
 * was, and the gap would inherit the pipe's track. A track not seen for
 * more than max_missed frames is dropped. When every live track was seen
 * the frame before, the frame path reads only the bands around the
 * tracks' predicted contours (tracked_all below) and falls back to the
 * full search when a track is not found there.
 */
#include "internal.h"

void cdsp_tracker_init(cdsp_tracker *t)
{
    if (!t)
        return;
    zero_bytes(t, sizeof *t);
    t->next_id = 1u;
    t->gate_px = R(24);
    t->max_missed = 2;
    t->full_every = 10;
}

size_t cdsp_frame_all_ws_size(void)
{
    return sizeof(cdsp_frame_all_ws);
}

size_t cdsp_points_all_ws_size(void)
{
    return sizeof(cdsp_points_all_ws);
}

/* A matching: mate[line] = index of its pair in the pair list, or -1. */
typedef struct {
    const cdsp_pair_set *set;
    const uint8_t *order;    /* pair indices in the order they are tried */
    int mate[CDSP_MAX_LINES];
    uint8_t seen[CDSP_MAX_LINES];
    int width, height;       /* the frame, undistorted px (the camera's size) */
} matching;

static void link_pair(matching *m, int k)
{
    const cdsp_pair_eval *e = &m->set->pair[k];
    m->mate[e->i] = k;
    m->mate[e->j] = k;
}

static int other_end(const cdsp_pair_eval *e, int v)
{
    return e->i == v ? e->j : e->j == v ? e->i : -1;
}

/* Kuhn's search for an augmenting path from the free line root, depth
 * first, iterative (no recursion: the stack bound stays known): level l
 * holds a line v_l and the pair via[l] = (v_l, w_l) it tries; w_l's
 * partner x opens level l + 1; a free w ends the path, and linking every
 * level's pair flips it (each w_l leaves its old pair for v_l). */
static int augment(matching *m, int root)
{
    const cdsp_pair_set *set = m->set;
    int line[CDSP_MAX_LINES], next[CDSP_MAX_LINES], via[CDSP_MAX_LINES], top = 1;
    line[0] = root;
    next[0] = 0;
    m->seen[root] = 1;
    while (top > 0) {
        int v = line[top - 1], opened = 0;
        while (next[top - 1] < set->npairs && !opened) {
            int k = m->order[next[top - 1]++], w = other_end(&set->pair[k], v), x, l;
            if (w < 0 || m->seen[w] || m->mate[v] == k)
                continue;
            m->seen[w] = 1;
            via[top - 1] = k;
            if (m->mate[w] < 0) {
                for (l = 0; l < top; l++)
                    link_pair(m, via[l]);
                return 1;
            }
            x = other_end(&set->pair[m->mate[w]], w);
            if (x < 0 || m->seen[x] || top == CDSP_MAX_LINES)
                continue;
            m->seen[x] = 1;
            line[top] = x;
            next[top] = 0;
            top++;
            opened = 1;
        }
        if (!opened)
            top--;
    }
    return 0;
}

/* +1 when pair e's band lies on its lines' normal side (a band brighter
 * than its surroundings: the normals, toward the bright side, point into
 * it), -1 for a darker band. */
static int pair_sign(const cdsp_pair_set *set, const cdsp_pair_eval *e)
{
    const cdsp_line *A = &set->lines[e->i], *B = &set->lines[e->j];
    return A->l[0] * B->centroid[0] + A->l[1] * B->centroid[1] + A->l[2] > R(0) ? 1 : -1;
}

/* Line v left over with bands of sign s: explained when its band would
 * reach out of the frame within `reach` px (the pipe whose other contour is
 * beyond the edge), from its centroid across it, on the band's side. */
static int frame_explains(const matching *m, int v, int s, cdsp_real reach)
{
    const cdsp_line *L = &m->set->lines[v];
    cdsp_real x = L->centroid[0] + (cdsp_real)s * reach * L->l[0];
    cdsp_real y = L->centroid[1] + (cdsp_real)s * reach * L->l[1];
    return !(x >= R(0) && y >= R(0) && x <= (cdsp_real)(m->width - 1) && y <= (cdsp_real)(m->height - 1));
}

/* Among matchings of the same size, the one whose left-over lines the
 * frame's edge explains (see the top): from a left-over line root that the
 * frame does not explain, an alternating path root - w1 = x1 - w2 = ... =
 * x_m of new pairs of one sign s (the pairs (w_k, x_k) in the matching),
 * ending at a line x_m that the frame explains for bands of sign s, is
 * flipped when the new pairs score at least as much as the old ones: root
 * is matched, x_m left over, the size unchanged. (The greedy start took
 * the best pair first, so a gap scoring a little above the pipe beside it
 * locked both pipes out.) Depth first, iterative, as augment. */
static int rebalance(matching *m, int root, int s_now, cdsp_real reach)
{
    const cdsp_pair_set *set = m->set;
    int line[CDSP_MAX_LINES], next[CDSP_MAX_LINES], via[CDSP_MAX_LINES], was[CDSP_MAX_LINES];
    int top = 1, sign = 0;
    if (frame_explains(m, root, s_now, reach))
        return 0;
    line[0] = root;
    next[0] = 0;
    m->seen[root] = 1;
    while (top > 0) {
        int v = line[top - 1], opened = 0;
        while (next[top - 1] < set->npairs && !opened) {
            int k = m->order[next[top - 1]++], w = other_end(&set->pair[k], v), x, l;
            if (w < 0 || m->seen[w] || m->mate[v] == k || m->mate[w] < 0)
                continue;
            if (top == 1)
                sign = pair_sign(set, &set->pair[k]);
            else if (pair_sign(set, &set->pair[k]) != sign)
                continue;
            x = other_end(&set->pair[m->mate[w]], w);
            if (x < 0 || m->seen[x])
                continue;
            via[top - 1] = k;
            was[top - 1] = m->mate[w];
            if (frame_explains(m, x, sign, reach)) {
                cdsp_real gain = R(0);
                for (l = 0; l < top; l++)
                    gain += set->pair[via[l]].score - set->pair[was[l]].score;
                if (gain < R(0))
                    continue;
                for (l = 0; l < top; l++)
                    link_pair(m, via[l]);
                m->mate[x] = -1;
                return 1;
            }
            if (top == CDSP_MAX_LINES)
                continue;
            m->seen[w] = m->seen[x] = 1;
            line[top] = x;
            next[top] = 0;
            top++;
            opened = 1;
        }
        if (!opened)
            top--;
    }
    return 0;
}

/* The width (px) of a contour pair at q: from q's foot on a to line b. */
static cdsp_real pair_width(const cdsp_real *a, const cdsp_real *b, const cdsp_real q[2])
{
    cdsp_real d = a[0] * q[0] + a[1] * q[1] + a[2];
    return R_FABS(b[0] * (q[0] - d * a[0]) + b[1] * (q[1] - d * a[1]) + b[2]);
}

/* A pipe's apparent width may change by this fraction of the track's from
 * one frame to the next: its distance changing by a quarter in a frame
 * (a crawler or drone closing 1 m/s at 0.45 m and 30 frames/s changes it
 * by 7 %). A pair within the gate but of another width is another band:
 * a pipe half in view, paired in its track's bands with an edge beside
 * it, solved at 754 mm for 458 (17 px wide for 28) and took the track of
 * the pipe it was (test_tracking_entering_edge). */
#define TRACK_WIDTH_CHANGE 0.25

/* Distance (px) of pipe contours l (at their foot from point q) from the
 * nearer contour of track t: the larger of the two; beyond any gate when
 * their widths differ by more than TRACK_WIDTH_CHANGE. */
static cdsp_real track_offset(const cdsp_real *l0, const cdsp_real *l1, const cdsp_real q[2],
                              const cdsp_real *t0, const cdsp_real *t1)
{
    cdsp_real worst = R(0), wt = pair_width(t0, t1, q);
    int c;
    if (!(R_FABS(pair_width(l0, l1, q) - wt) <= R(TRACK_WIDTH_CHANGE) * wt))
        return R(1e30);
    for (c = 0; c < 2; c++) {
        const cdsp_real *l = c ? l1 : l0;
        cdsp_real d = l[0] * q[0] + l[1] * q[1] + l[2], f[2], e0, e1;
        f[0] = q[0] - d * l[0];
        f[1] = q[1] - d * l[1];
        e0 = R_FABS(t0[0] * f[0] + t0[1] * f[1] + t0[2]);
        e1 = R_FABS(t1[0] * f[0] + t1[1] * f[1] + t1[2]);
        e0 = e1 < e0 ? e1 : e0;
        worst = e0 > worst ? e0 : worst;
    }
    return worst;
}

/* Undistorted pixel of the middle of a result's visible segment (its foot
 * point when the segment is behind the camera). */
static void result_mid(const cdsp_camera *cam, const cdsp_result *r, cdsp_real q[2])
{
    cdsp_real X[3];
    int i;
    for (i = 0; i < 3; i++)
        X[i] = (r->segment[0][i] + r->segment[1][i]) / R(2);
    if (!(X[2] > R(0)))
        for (i = 0; i < 3; i++)
            X[i] = r->point[i];
    q[0] = cam->fx * X[0] / X[2] + cam->cx;
    q[1] = cam->fy * X[1] / X[2] + cam->cy;
}

/* Where track t's contours are expected this frame: each moved along its
 * normal by its velocity times the frames since it was seen (a line
 * a u + b v + c = 0 with a^2 + b^2 = 1 moved by s along (a, b) has c - s). */
static void track_predict(const cdsp_track *t, cdsp_real out[2][3])
{
    cdsp_real k = (cdsp_real)(t->missed + 1u);
    int c;
    for (c = 0; c < 2; c++) {
        out[c][0] = t->lines[c][0];
        out[c][1] = t->lines[c][1];
        out[c][2] = t->lines[c][2] - k * t->velocity[c];
    }
}

/* The pair's contours' offset from track t's prediction, px, at p_in. */
static cdsp_real pair_track_offset(const cdsp_pair_set *set, const cdsp_pair_eval *e,
                                   const cdsp_track *t)
{
    cdsp_real pr[2][3];
    track_predict(t, pr);
    return track_offset(set->lines[e->i].l, set->lines[e->j].l, e->p_in, pr[0], pr[1]);
}

/* Order of trial: by score, weighted near a live track (see the top). */
static void trial_order(const cdsp_pair_set *set, const cdsp_tracker *trk, cdsp_real gate,
                        uint8_t *order)
{
    cdsp_real w[CDSP_MAX_PAIRS];
    int k, a;
    for (k = 0; k < set->npairs; k++) {
        w[k] = set->pair[k].score;
        if (trk) {
            cdsp_real best = R_MAX;
            int t;
            for (t = 0; t < CDSP_MAX_TRACKS; t++) {
                cdsp_real e;
                if (!trk->track[t].id)
                    continue;
                e = pair_track_offset(set, &set->pair[k], &trk->track[t]);
                best = e < best ? e : best;
            }
            if (best < R_MAX) {
                cdsp_real z = best / gate;
                w[k] *= R(1) + R(2) * R_EXP(R(-0.5) * z * z);
            }
        }
        order[k] = (uint8_t)k;
    }
    /* insertion sort, descending weight (at most CDSP_MAX_PAIRS) */
    for (k = 1; k < set->npairs; k++)
        for (a = k; a > 0 && w[order[a - 1]] < w[order[a]]; a--) {
            uint8_t t = order[a];
            order[a] = order[a - 1];
            order[a - 1] = t;
        }
}

/* The matching (see the top): chosen[] receives pair indices, best score
 * first; returns their number (<= CDSP_MAX_LINES / 2). */
static int select_pipes(const cdsp_pair_set *set, const cdsp_camera *cam, const cdsp_tracker *trk,
                        cdsp_real gate, int *chosen)
{
    matching m;
    uint8_t order[CDSP_MAX_PAIRS];
    int v, k, o, n = 0, grew = 1, signs = 0;
    cdsp_real reach = R(0);
    m.set = set;
    m.order = order;
    m.width = cam->width;
    m.height = cam->height;
    trial_order(set, trk, gate, order);
    for (v = 0; v < set->nlines; v++)
        m.mate[v] = -1;
    for (o = 0; o < set->npairs; o++) {
        const cdsp_pair_eval *e = &set->pair[order[o]];
        if (m.mate[e->i] < 0 && m.mate[e->j] < 0)
            link_pair(&m, order[o]);
    }
    /* each augmentation adds one pair; at most nlines / 2 rounds */
    while (grew) {
        grew = 0;
        for (v = 0; v < set->nlines && !grew; v++) {
            if (m.mate[v] >= 0)
                continue;
            for (k = 0; k < set->nlines; k++)
                m.seen[k] = 0;
            grew = augment(&m, v);
        }
    }
    /* the matching's band sign (most pairs') and the widest band: how far
     * beyond a left-over line the frame's edge may hide its partner */
    for (k = 0; k < set->npairs; k++) {
        const cdsp_pair_eval *e = &set->pair[k];
        const cdsp_line *A = &set->lines[e->i];
        cdsp_real wd;
        if (m.mate[e->i] != k || m.mate[e->j] != k)
            continue;
        signs += pair_sign(set, e);
        wd = R(2) * R_FABS(A->l[0] * e->p_in[0] + A->l[1] * e->p_in[1] + A->l[2]);
        reach = wd > reach ? wd : reach;
    }
    reach *= R(1.5);
    for (v = 0; v < set->nlines && signs != 0; v++) {
        if (m.mate[v] >= 0)
            continue;
        for (k = 0; k < set->nlines; k++)
            m.seen[k] = 0;
        (void)rebalance(&m, v, signs > 0 ? 1 : -1, reach);
    }
    /* the pairs of the matching, in score order (the pair list's own) */
    for (k = 0; k < set->npairs; k++) {
        const cdsp_pair_eval *e = &set->pair[k];
        if (m.mate[e->i] == k && m.mate[e->j] == k)
            chosen[n++] = k;
    }
    return n;
}

/* Tracks: match, keep ids and signs, start new tracks, age the rest. */
static void track_update(cdsp_tracker *trk, const cdsp_camera *cam, cdsp_result *out, size_t n)
{
    uint8_t taken_t[CDSP_MAX_TRACKS], taken_r[CDSP_MAX_PIPES];
    cdsp_real mid[CDSP_MAX_PIPES][2];
    size_t i;
    int t, k;
    for (t = 0; t < CDSP_MAX_TRACKS; t++)
        taken_t[t] = 0;
    for (i = 0; i < n; i++) {
        taken_r[i] = 0;
        result_mid(cam, &out[i], mid[i]);
    }
    /* greedy by distance: the closest (pipe, track) first */
    for (;;) {
        cdsp_real best = trk->gate_px;
        int bt = -1;
        size_t bi = 0;
        for (i = 0; i < n; i++) {
            if (taken_r[i])
                continue;
            for (t = 0; t < CDSP_MAX_TRACKS; t++) {
                cdsp_real e, pr[2][3];
                if (!trk->track[t].id || taken_t[t])
                    continue;
                track_predict(&trk->track[t], pr);
                e = track_offset(out[i].lines[0], out[i].lines[1], mid[i], pr[0], pr[1]);
                if (e <= best) {
                    best = e;
                    bt = t;
                    bi = i;
                }
            }
        }
        if (bt < 0)
            break;
        taken_t[bt] = 1;
        taken_r[bi] = 1;
        out[bi].track_id = trk->track[bt].id;
        if (v3_dot(out[bi].direction, trk->track[bt].direction) < R(0))
            cdsp__axis_swap(&out[bi]);
    }
    /* unseen tracks age; new pipes take a free slot (or the oldest unseen) */
    for (t = 0; t < CDSP_MAX_TRACKS; t++)
        if (trk->track[t].id && !taken_t[t] && ++trk->track[t].missed > (uint32_t)trk->max_missed)
            trk->track[t].id = 0;
    for (i = 0; i < n; i++) {
        int slot = -1;
        if (taken_r[i])
            continue;
        for (t = 0; t < CDSP_MAX_TRACKS && slot < 0; t++)
            if (!trk->track[t].id)
                slot = t;
        for (t = 0; t < CDSP_MAX_TRACKS && slot < 0; t++)
            if (!taken_t[t] && trk->track[t].missed > 0)
                slot = t;
        if (slot < 0)
            continue; /* every slot holds a pipe seen this frame: no id */
        trk->track[slot].id = trk->next_id++;
        if (trk->next_id == 0u)
            trk->next_id = 1u; /* wrapped after 2^32 pipes: 0 means none */
        taken_t[slot] = 1;
        out[i].track_id = trk->track[slot].id;
        trk->track[slot].missed = 0;
        trk->track[slot].velocity[0] = trk->track[slot].velocity[1] = R(0);
        for (k = 0; k < 3; k++) { /* no motion known yet: the velocity below stays 0 */
            trk->track[slot].lines[0][k] = out[i].lines[0][k];
            trk->track[slot].lines[1][k] = out[i].lines[1][k];
        }
    }
    /* what every matched or new track saw this frame */
    for (i = 0; i < n; i++) {
        cdsp_track *tr = NULL;
        if (!out[i].track_id)
            continue;
        for (t = 0; t < CDSP_MAX_TRACKS; t++)
            if (trk->track[t].id == out[i].track_id)
                tr = &trk->track[t];
        if (!tr)
            continue;
        /* each new contour's shift from the old one of its polarity (the
         * one whose normal points the same way; the order of a result's
         * two lines may change), per frame since it was seen */
        for (k = 0; k < 2; k++) {
            const cdsp_real *nl = out[i].lines[k];
            int m = nl[0] * tr->lines[0][0] + nl[1] * tr->lines[0][1] >=
                            nl[0] * tr->lines[1][0] + nl[1] * tr->lines[1][1]
                        ? 0
                        : 1;
            cdsp_real dot = nl[0] * tr->lines[m][0] + nl[1] * tr->lines[m][1];
            tr->velocity[k] = dot > R(0) ? (tr->lines[m][2] - nl[2]) / (cdsp_real)(tr->missed + 1u)
                                         : R(0);
        }
        tr->missed = 0;
        for (k = 0; k < 3; k++) {
            tr->lines[0][k] = out[i].lines[0][k];
            tr->lines[1][k] = out[i].lines[1][k];
            tr->direction[k] = out[i].direction[k];
        }
        tr->mid[0] = mid[i][0];
        tr->mid[1] = mid[i][1];
    }
}

/*
 * Crossing members (issue 13: the support columns of the paper's rack).
 * A pipe of radius r and a bar or column of radius r' < r at r' / r of its
 * distance give the same two contours: one frame cannot tell them apart
 * alone (docs/method.md §9), and a column solved as a pipe of radius r
 * lands at r / r' of its distance (the paper's 12.68 mm columns under its
 * 16 mm pipes: 1.26 x, inside a distance range of x [0.8, 1.25] about the
 * pipes). Where it crosses a pipe in the image, though, the two must agree
 * on which is in front. In the image, the one behind has no edge points on
 * its contours within the other's band (occluded), the one in front keeps
 * them. In 3D, at the axes' closest approach X_C (on C) and X_P (on P),
 * the one in front is nearer the camera. So C, crossing P at more than
 * 30 degrees and seen in front of P, but solved farther than P, is not a
 * pipe of radius r (a thinner bar in front, solved too far); and, with a
 * distance range (the caller says where the pipes are: a rack), C seen
 * behind P but solved more than CROSS_GAP r beyond touching it (axes more
 * than 2 r + CROSS_GAP r apart) is taken for a support of the rack, not a
 * pipe of radius r floating behind it: such a member touches the pipes it
 * carries, and a column of radius r' touching P solves r / r' of its
 * distance away (the paper's: about 160 mm behind a 16 mm pipe at 600 mm),
 * where a pipe of radius r lying on the rack solves touching it (axes 2 r
 * apart, within its sigma: a fraction of r at the rack's distances). */
#define CROSS_COS 0.8660254 /* cos 30 degrees */
#define CROSS_GAP 1
/* below this fraction of a contour's mean inlier density over the other's
 * band (edge points on its line there), the contour is taken as occluded */
#define CROSS_HIDDEN 0.25

/* Parameters along line L (from its centroid, along dir) where it meets
 * lines a and b, ordered; 0 when L is near parallel to either. */
static int line_span(const cdsp_line *L, const cdsp_real a[3], const cdsp_real b[3], cdsp_real *t0,
                     cdsp_real *t1)
{
    cdsp_real da = a[0] * L->dir[0] + a[1] * L->dir[1], db = b[0] * L->dir[0] + b[1] * L->dir[1];
    cdsp_real ta, tb;
    if (R_FABS(da) < R(0.2) || R_FABS(db) < R(0.2))
        return 0;
    ta = -(a[0] * L->centroid[0] + a[1] * L->centroid[1] + a[2]) / da;
    tb = -(b[0] * L->centroid[0] + b[1] * L->centroid[1] + b[2]) / db;
    *t0 = ta < tb ? ta : tb;
    *t1 = ta < tb ? tb : ta;
    return 1;
}

/* The contours of result c that cross the band of result q with edge
 * points there (*vis) and without (*hid: occluded); a contour that ends
 * in the band or runs along it counts in neither. Any edge point on the
 * contour's line counts, of either polarity and not only its inliers: a
 * contour crossing something brighter than itself flips its step there
 * (the bar's against a lit pipe), and one seen in front still has its
 * points. The margin (EDGE_MARGIN px inside the band's edges) keeps the
 * other's own contour points out. Expected over the band: the contour's
 * inlier density along its extent. */
#define CROSS_NEAR_PX 1.5
#define CROSS_NORMAL_COS 0.94 /* cos 20 degrees, the line finder's default tolerance */
#define CROSS_MARGIN_PX 5
static void contours_over(const cdsp_pair_set *set, const cdsp_edge *pts, size_t n,
                          const cdsp_result *c, const cdsp_result *q, int *vis, int *hid)
{
    int k;
    *vis = *hid = 0;
    for (k = 0; k < 2; k++) {
        const cdsp_line *L;
        cdsp_real t0, t1, inside = R(0), dens;
        size_t i;
        if (c->label[k] == 0 || c->label[k] > set->nlines)
            continue;
        L = &set->lines[c->label[k] - 1];
        if (!line_span(L, q->lines[0], q->lines[1], &t0, &t1) || t0 < L->t_min || t1 > L->t_max ||
            !(L->t_max > L->t_min))
            continue;
        t0 += R(CROSS_MARGIN_PX);
        t1 -= R(CROSS_MARGIN_PX);
        if (!(t1 > t0))
            continue;
        for (i = 0; i < n; i++) {
            const cdsp_edge *e = &pts[i];
            cdsp_real d = L->l[0] * e->x + L->l[1] * e->y + L->l[2], g, t;
            if (R_FABS(d) > R(CROSS_NEAR_PX))
                continue;
            g = L->l[0] * e->gx + L->l[1] * e->gy;
            if (g * g < R(CROSS_NORMAL_COS) * R(CROSS_NORMAL_COS) * (e->gx * e->gx + e->gy * e->gy))
                continue;
            t = (e->x - L->centroid[0]) * L->dir[0] + (e->y - L->centroid[1]) * L->dir[1];
            inside += t >= t0 && t <= t1 ? R(1) : R(0);
        }
        dens = (cdsp_real)L->count / (L->t_max - L->t_min);
        if (inside < R(CROSS_HIDDEN) * dens * (t1 - t0))
            ++*hid;
        else
            ++*vis;
    }
}

/* Closest points of the axes of a and b (X_a on a, X_b on b); 0 when they
 * are near parallel. */
static int axes_closest(const cdsp_result *a, const cdsp_result *b, cdsp_real Xa[3], cdsp_real Xb[3])
{
    cdsp_real w[3], d = v3_dot(a->direction, b->direction), e, f, den, s, t;
    int i;
    for (i = 0; i < 3; i++)
        w[i] = a->point[i] - b->point[i];
    e = v3_dot(a->direction, w);
    f = v3_dot(b->direction, w);
    den = R(1) - d * d;
    if (!(den > R(0.25))) /* within 30 degrees: not a crossing */
        return 0;
    s = (d * f - e) / den;
    t = (f - d * e) / den;
    for (i = 0; i < 3; i++) {
        Xa[i] = a->point[i] + s * a->direction[i];
        Xb[i] = b->point[i] + t * b->direction[i];
    }
    return 1;
}

/* Whether result c, crossing result q, is no pipe of radius r (see above). */
static int crossing_inconsistent(const cdsp_pair_set *set, const cdsp_edge *pts, size_t n,
                                 const cdsp_result *c, const cdsp_result *q, cdsp_real radius, int ranged)
{
    cdsp_real Xc[3], Xq[3], dv[3], behind;
    int i, vis_c, hid_c, vis_q, hid_q;
    if (R_FABS(v3_dot(c->direction, q->direction)) > R(CROSS_COS) || !axes_closest(c, q, Xc, Xq))
        return 0;
    /* in front: a contour seen over the other's band, and both of the
     * other's hidden there (one contour of the one in front may be missing
     * too: a shaded limb against a brighter member behind has no step) */
    contours_over(set, pts, n, c, q, &vis_c, &hid_c);
    contours_over(set, pts, n, q, c, &vis_q, &hid_q);
    for (i = 0; i < 3; i++)
        dv[i] = Xc[i] - Xq[i];
    behind = v3_norm(Xc) - v3_norm(Xq); /* > 0: c solved farther than q */
    if (vis_c >= 1 && hid_q == 2) /* c in front in the image */
        return behind > R(0);
    if (hid_c == 2 && vis_q >= 1) /* c behind q in the image */
        return ranged && behind > R(0) && v3_norm(dv) > (R(2) + R(CROSS_GAP)) * radius;
    return 0;
}

/* Drops every result that crosses a result of a parallel family at least
 * as large inconsistently (the crossing member, not the rack's pipes: a
 * smaller family never removes a larger one's member; in a tie the rules
 * above name at most one of the two). */
static size_t drop_crossing(const cdsp_pair_set *set, const cdsp_edge *pts, size_t n, cdsp_real radius,
                            int ranged, cdsp_result *out, size_t m)
{
    uint8_t drop[CDSP_MAX_PIPES], fam[CDSP_MAX_PIPES];
    cdsp_real par = R(CROSS_COS);
    size_t i, j, k = 0;
    for (i = 0; i < m; i++) {
        fam[i] = 0;
        for (j = 0; j < m; j++)
            fam[i] += R_FABS(v3_dot(out[i].direction, out[j].direction)) > par;
    }
    for (i = 0; i < m; i++) {
        drop[i] = 0;
        for (j = 0; j < m && !drop[i]; j++)
            drop[i] = j != i && fam[j] >= fam[i] &&
                      crossing_inconsistent(set, pts, n, &out[i], &out[j], radius, ranged);
    }
    for (i = 0; i < m; i++)
        if (!drop[i]) {
            if (k != i)
                out[k] = out[i];
            k++;
        }
    return k;
}

/* Pipes select_pipes chooses at most. */
#define MAX_CHOSEN (CDSP_MAX_LINES / 2 + 1)

/* From the pairs select_pipes chose (chosen[0..nc-1]) to results (both
 * paths); ref: per chosen pair, what the frame path's edge-profile model
 * did to its lines (NULL on the points path, which so does not link
 * lib/profile.c); fws: the frame path's workspace (its pair set is set),
 * sigma the frame's noise, for the single path's scatter rule (NULL on
 * the points path: points carry no noise measure). */
static cdsp_status solve_all(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts,
                             size_t n, const cdsp_pair_set *set, const int *chosen, int nc,
                             const cdsp__pair_refined *ref, const cdsp_frame_ws *fws, cdsp_real sigma,
                             const cdsp_params *p, cdsp_real min_step, cdsp_result *out,
                             size_t cap, size_t *n_out)
{
    int k;
    size_t m = 0, i;
    if (cap > CDSP_MAX_PIPES)
        cap = CDSP_MAX_PIPES;
    for (k = 0; k < nc && m < cap; k++) {
        const cdsp_pair_eval *e = &set->pair[chosen[k]];
        /* a narrow band with a flipping contour out of the >= 0.9 bin, as
         * on the single path (test_multi's test_flip_cap_all: 0.998
         * without) */
        cdsp_real conf = cdsp__pair_flip_cap(cam, radius, set, e, cdsp__pair_evidence(e, min_step > R(0)));
        cdsp_result *r = &out[m];
        if (conf < p->min_confidence)
            continue;
        if (cdsp__pair_result(cam, radius, n, set, e, ref ? &ref[k] : NULL, r) != CDSP_OK)
            continue; /* the refined lines turned degenerate: not a pose */
        /* the edge-profile model moves the lines after the pair's range
         * test: with a range given, nothing outside it, ever (issue 10) */
        if (!cdsp__pair_in_range(&p->pair, r->distance))
            continue;
        /* a contour whose points are too scattered to be one edge says
         * nothing reliable about the silhouette (lib/frame.c, issue 12):
         * as on the single path the pose has no bound and its confidence
         * is capped; below min_confidence then, the slot is reused (its
         * contours stay free for no other pair, the matching is not
         * redone) */
        if (fws && cdsp__frame_scatter_mark(fws, r, sigma, &conf) && conf < p->min_confidence)
            continue;
        r->confidence = conf;
        if (cdsp__axis_wants_swap(r->direction))
            cdsp__axis_swap(r);
        m++;
    }
    m = drop_crossing(set, pts, n, radius, p->pair.min_distance > R(0) || p->pair.max_distance > R(0),
                      out, m);
    for (i = 0; i < m; i++)
        out[i].n_candidates = (uint32_t)m;
    *n_out = m;
    return m ? CDSP_OK : CDSP_E_NO_PIPE;
}

static cdsp_status tracker_check(const cdsp_tracker *trk)
{
    if (trk && (!(trk->gate_px > R(0)) || !R_FINITE(trk->gate_px) || trk->max_missed < 0 ||
                trk->full_every < 0))
        return CDSP_E_ARG;
    return CDSP_OK;
}

/* cdsp_params.refine_step (lib/rescan.c) on the pipes solve_all returned
 * (out[0..m)): each one's lines refitted to a finer scan of their bands
 * and its pose solved again from them, its confidence, its place and the
 * scatter rule's verdict on the new lines as solve_all gives them. After
 * solve_all, not before it: the crossing rule (drop_crossing) compares a
 * contour's inlier density with the search's edges, at the search's step.
 * A pipe whose lines do not refit keeps the search's pose. */
static void rescan_pipes(const cdsp_image *img, const cdsp_camera *cam, cdsp_real radius,
                         const cdsp_params *p, cdsp_frame_all_ws *ws, size_t n, cdsp_real sigma,
                         cdsp_real min_step, const int *chosen, int nc, cdsp__pair_refined *ref,
                         cdsp_result *out, size_t m)
{
    cdsp_pair_set *set = &ws->frame.pairs;
    cdsp__profile_src src;
    size_t i;
    src.pts = ws->frame.edge;
    src.n = n;
    src.label = ws->frame.label;
    src.pws = &ws->frame.profile;
    src.noise = sigma;
    for (i = 0; i < m; i++) {
        cdsp_result *r = &out[i];
        cdsp_real conf = r->confidence;
        uint32_t ncand = r->n_candidates;
        int k;
        for (k = 0; k < nc; k++) {
            const cdsp_pair_eval *e = &set->pair[chosen[k]];
            /* either order: cdsp__axis_swap exchanges the contours */
            if ((r->label[0] == e->i + 1 && r->label[1] == e->j + 1) ||
                (r->label[1] == e->i + 1 && r->label[0] == e->j + 1))
                break;
        }
        if (k == nc || cdsp__rescan_pair(img, cam, p, min_step, set, &set->pair[chosen[k]], &src, &ref[k]) != CDSP_OK ||
            cdsp__pair_result(cam, radius, n, set, &set->pair[chosen[k]], &ref[k], r) != CDSP_OK)
            continue;
        (void)cdsp__frame_scatter_mark(&ws->frame, r, sigma, &conf);
        r->confidence = conf;
        r->n_candidates = ncand;
        if (cdsp__axis_wants_swap(r->direction))
            cdsp__axis_swap(r);
    }
}

/* The frame path's pipes from the pair set scored on ws->frame.edge[0..n):
 * the matching, the edge-profile model on every chosen pair solve_all may
 * return (the pairs share no line, so the order does not matter; beyond
 * cap the model runs for nothing, which a caller asking for all
 * CDSP_MAX_PIPES never sees), the results. */
static cdsp_status frame_pipes(const cdsp_image *img, const cdsp_camera *cam, cdsp_real radius,
                               const cdsp_params *p, const cdsp_tracker *trk, cdsp_frame_all_ws *ws,
                               size_t n, cdsp_real sigma, cdsp_real min_step, cdsp_result *out,
                               size_t cap, size_t *n_out)
{
    cdsp_pair_set *set = &ws->frame.pairs;
    cdsp__pair_refined ref[MAX_CHOSEN];
    int chosen[MAX_CHOSEN], nc, k;
    cdsp_status st;
    nc = select_pipes(set, cam, trk, trk ? trk->gate_px : R(1), chosen);
    for (k = 0; k < nc; k++) {
        const cdsp_pair_eval *e = &set->pair[chosen[k]];
        if (cdsp__pair_evidence(e, min_step > R(0)) >= p->min_confidence)
            cdsp__frame_refine(img, cam, ws->frame.edge, n, ws->frame.label, set, e, p, sigma,
                               &ws->frame.profile, &ref[k]);
    }
    st = solve_all(cam, radius, ws->frame.edge, n, set, chosen, nc, ref, &ws->frame, sigma, p, min_step,
                   out, cap, n_out);
    if (st == CDSP_OK && p->refine_step > 0) {
        size_t i, m = 0;
        rescan_pipes(img, cam, radius, p, ws, n, sigma, min_step, chosen, nc, ref, out, *n_out);
        /* the refitted lines may move a pose out of the range solve_all
         * held it to: with a range given, nothing outside it, ever */
        for (i = 0; i < *n_out; i++)
            if (cdsp__pair_in_range(&p->pair, out[i].distance)) {
                if (m != i)
                    out[m] = out[i];
                m++;
            }
        for (i = 0; i < m; i++)
            out[i].n_candidates = (uint32_t)m;
        *n_out = m;
        st = m ? CDSP_OK : CDSP_E_NO_PIPE;
    }
    return st;
}

/*
 * The tracked solve (cdsp_frame_solve_all with live tracks): as the single
 * path's tracking (lib/frame.c), only scanline segments of +-track_band_px
 * around each track's predicted contours are read, at the full search's
 * step and on its scanlines (so a contour's points are the ones the full
 * search would have found on it), all tracks' bands in one buffer. On one
 * scanline the bands of neighbouring contours may overlap (a gap or a
 * pipe narrower than 2 track_band_px): they are merged, so that no edge is
 * read twice (a duplicated point would count twice in its line's fit and
 * halve its variance). When the bands hold more than cap edges, all are
 * read again at twice the step until they fit (*truncated set), as in
 * lib/frame.c. Returns the edges written.
 */
#define BAND_LINES (2 * CDSP_MAX_TRACKS)
static size_t bands_at(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                       const cdsp_edge_params *edge, const cdsp_real (*lines)[3], int nl, int step,
                       cdsp_edge *out, size_t cap)
{
    int x0, y0, x1, y1, fam, h = p->edge.half_window, nodist = cdsp__camera_no_distortion(cam);
    /* a real until clipped (track_band_px may exceed INT_MAX), as lib/frame.c */
    cdsp_real band = R_CEIL(p->track_band_px);
    size_t n = 0;
    cdsp__edges_clip_roi(img, &p->edge.roi, &x0, &y0, &x1, &y1);
    for (fam = 0; fam < 2; fam++) {
        /* fam 0: rows, for near-vertical contours (|a| >= |b|); 1: columns */
        int horizontal = fam == 0, lo = horizontal ? y0 : x0, hi = horizontal ? y1 : x1;
        int ext = horizontal ? img->width : img->height, other = horizontal ? img->height : img->width;
        int smin = horizontal ? x0 : y0, smax = horizontal ? x1 : y1, t, k, any = 0;
        for (k = 0; k < nl; k++)
            any |= (R_FABS(lines[k][0]) >= R_FABS(lines[k][1])) == horizontal;
        if (!any)
            continue;
        for (t = (lo > 1 ? lo : 1) + step / 2; t < hi - 1 && t < other - 1; t += step) {
            int from[BAND_LINES], to[BAND_LINES], ns = 0, a, b;
            for (k = 0; k < nl; k++) {
                int fr, tt;
                if ((R_FABS(lines[k][0]) >= R_FABS(lines[k][1])) != horizontal ||
                    !cdsp__frame_band(cam, nodist, lines[k], horizontal, t, band, smin, smax, h, ext, &fr, &tt))
                    continue;
                /* insertion by start (at most BAND_LINES segments) */
                for (a = ns; a > 0 && from[a - 1] > fr; a--) {
                    from[a] = from[a - 1];
                    to[a] = to[a - 1];
                }
                from[a] = fr;
                to[a] = tt;
                ns++;
            }
            /* a segment [f, t] tests the candidates f + 1 .. t - 2 (lib/edges.c):
             * two whose candidates meet or overlap (f' <= t - 2) are read as
             * one, [f, max(t, t')], which tests exactly their union */
            for (a = 0; a < ns; a = b) {
                int tt = to[a];
                for (b = a + 1; b < ns && from[b] <= tt - 2; b++)
                    tt = to[b] > tt ? to[b] : tt;
                n += cdsp__edges_scan_segment(img, edge, horizontal, t, from[a], tt, out + n, cap - n);
                if (n == cap)
                    return n;
            }
        }
    }
    return n;
}

static size_t band_edges(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                         const cdsp_edge_params *edge, const cdsp_real (*lines)[3], int nl,
                         cdsp_edge *out, size_t cap, int *truncated)
{
    int step = p->edge.step, extent = img->width > img->height ? img->width : img->height;
    size_t n;
    *truncated = 0;
    while ((n = bands_at(img, cam, p, edge, lines, nl, step, out, cap)) == cap && step <= extent / 2) {
        step *= 2;
        *truncated = 1;
    }
    return n;
}

/* Whether every live track has a pipe among out[0..n): within the gate of
 * its prediction, with track_min_inliers on each contour (the single
 * path's test of a tracked pose), each pipe for one track. */
static int tracks_found(const cdsp_tracker *trk, const cdsp_camera *cam, const cdsp_params *p,
                        const cdsp_result *out, size_t n)
{
    uint8_t taken[CDSP_MAX_PIPES];
    size_t i;
    int t;
    for (i = 0; i < n; i++)
        taken[i] = 0;
    for (t = 0; t < CDSP_MAX_TRACKS; t++) {
        cdsp_real pr[2][3], best = trk->gate_px;
        size_t bi = n;
        if (!trk->track[t].id)
            continue;
        track_predict(&trk->track[t], pr);
        for (i = 0; i < n; i++) {
            cdsp_real q[2], e;
            if (taken[i] || out[i].inliers[0] < (uint32_t)p->track_min_inliers ||
                out[i].inliers[1] < (uint32_t)p->track_min_inliers)
                continue;
            result_mid(cam, &out[i], q);
            e = track_offset(out[i].lines[0], out[i].lines[1], q, pr[0], pr[1]);
            if (e <= best) {
                best = e;
                bi = i;
            }
        }
        if (bi == n)
            return 0;
        taken[bi] = 1;
    }
    return 1;
}

/* The tracked solve (above): 1 with the pipes in out when every live track
 * was found in the bands; 0 when a full search must run (a track lost,
 * one seen last frame no more, or no live track). The frame's noise is
 * measured every frame (cdsp_frame_prepare: the tracker keeps no noise
 * figure, which the single path takes from its prior). */
static int tracked_all(const cdsp_image *img, const cdsp_camera *cam, cdsp_real radius,
                       const cdsp_params *p, const cdsp_tracker *trk, cdsp_frame_all_ws *ws,
                       cdsp_rng *rng, cdsp_result *out, size_t cap, size_t *n_out, cdsp_real *sigma,
                       cdsp_real *min_step, uint32_t *flags)
{
    cdsp_real lines[BAND_LINES][3];
    cdsp_frame_edges fe;
    int nl = 0, t, k, truncated;
    size_t n;
    for (t = 0; t < CDSP_MAX_TRACKS; t++) {
        cdsp_real pr[2][3];
        if (!trk->track[t].id)
            continue;
        if (trk->track[t].missed != 0)
            return 0;
        track_predict(&trk->track[t], pr);
        for (k = 0; k < 3; k++) {
            lines[nl][k] = pr[0][k];
            lines[nl + 1][k] = pr[1][k];
        }
        nl += 2;
    }
    if (nl == 0 || cdsp_frame_prepare(img, p, &fe) != CDSP_OK)
        return 0;
    n = band_edges(img, cam, p, &fe.edge, (const cdsp_real(*)[3])lines, nl, ws->frame.edge,
                   CDSP_MAX_EDGES, &truncated);
    if (cdsp_camera_undistort_edges(cam, ws->frame.edge, &n) != CDSP_OK ||
        cdsp__pair_score_all(cam, radius, ws->frame.edge, n, ws->frame.label, p, fe.min_step, NULL, rng,
                             &ws->frame.pairs) != CDSP_OK ||
        frame_pipes(img, cam, radius, p, trk, ws, n, fe.sigma, fe.min_step, out, cap, n_out) != CDSP_OK ||
        !tracks_found(trk, cam, p, out, *n_out))
        return 0;
    *sigma = fe.sigma;
    *min_step = fe.min_step;
    *flags = CDSP_FLAG_TRACKED | (truncated ? CDSP_FLAG_TRUNCATED : 0u);
    return 1;
}

cdsp_status cdsp_frame_solve_all(const cdsp_image *img, const cdsp_camera *cam, cdsp_real radius,
                                 const cdsp_params *p, cdsp_tracker *trk, cdsp_frame_all_ws *ws,
                                 cdsp_rng *rng, cdsp_result *out, size_t cap, size_t *n_out)
{
    cdsp_status st;
    size_t n = 0, i;
    uint32_t flags = 0;
    int tracked = 0;
    cdsp_real sigma = R(0), min_step = R(0);
    if (!img || !cam || !p || !ws || !rng || !out || !n_out || cap == 0)
        return CDSP_E_ARG;
    *n_out = 0;
    st = cdsp_image_check(img);
    if (st != CDSP_OK)
        return st;
    st = cdsp__solve_args_check(cam, radius, p);
    if (st == CDSP_OK)
        st = tracker_check(trk);
    if (st != CDSP_OK)
        return st;
    if (img->width != cam->width || img->height != cam->height)
        return CDSP_E_ARG;
    /* every full_every-th frame a full search whatever the tracks: the
     * bands read only the tracks' contours, and a pipe coming into view
     * would wait for a track to be lost */
    if (trk && !(trk->full_every > 0 && trk->since_full + 1u >= (uint32_t)trk->full_every)) {
        /* the generator's state on entry: a fallback full search starts
         * from it again, so it gives exactly what a search without the
         * band attempt gives */
        cdsp_rng rng0 = *rng;
        tracked = tracked_all(img, cam, radius, p, trk, ws, rng, out, cap, n_out, &sigma, &min_step, &flags);
        if (!tracked) {
            *rng = rng0;
            *n_out = 0;
        }
    }
    if (!tracked) {
        st = cdsp__frame_edges(img, cam, p, &ws->frame, &n, &sigma, &min_step, &flags);
        if (st == CDSP_OK)
            st = cdsp__pair_score_all(cam, radius, ws->frame.edge, n, ws->frame.label, p, min_step, NULL,
                                      rng, &ws->frame.pairs);
        if (st == CDSP_OK)
            st = frame_pipes(img, cam, radius, p, trk, ws, n, sigma, min_step, out, cap, n_out);
    }
    if (trk) {
        track_update(trk, cam, out, *n_out); /* with no pipe (n_out 0) every track ages */
        trk->since_full = tracked ? trk->since_full + 1u : 0u;
    }
    for (i = 0; i < *n_out; i++) {
        out[i].flags |= flags;
        out[i].noise = sigma;
        out[i].min_step = min_step;
    }
    return st;
}

cdsp_status cdsp_points_solve_all(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts,
                                  size_t n, const cdsp_params *p, cdsp_tracker *trk,
                                  cdsp_points_all_ws *ws, cdsp_rng *rng, cdsp_result *out,
                                  size_t cap, size_t *n_out)
{
    cdsp_status st;
    if (!cam || !p || !ws || !rng || !out || !n_out || cap == 0 || (!pts && n))
        return CDSP_E_ARG;
    *n_out = 0;
    st = cdsp__solve_args_check(cam, radius, p);
    if (st == CDSP_OK)
        st = tracker_check(trk);
    if (st != CDSP_OK)
        return st;
    if (n > CDSP_MAX_POINTS)
        return CDSP_E_CAPACITY;
    if (!cdsp__points_finite(pts, n))
        return CDSP_E_NONFINITE;
    st = cdsp__pair_score_all(cam, radius, pts, n, ws->points.label, p, R(0), NULL, rng,
                              &ws->points.pairs);
    if (st == CDSP_OK) {
        int chosen[MAX_CHOSEN];
        int nc = select_pipes(&ws->points.pairs, cam, trk, trk ? trk->gate_px : R(1), chosen);
        st = solve_all(cam, radius, pts, n, &ws->points.pairs, chosen, nc, NULL, NULL, R(0), p, R(0),
                       out, cap, n_out);
        if (trk)
            track_update(trk, cam, out, *n_out);
        return st;
    }
    if (trk)
        track_update(trk, cam, out, 0);
    return st;
}

/* Two passes (mean, then the spread about it): a spread a millionth of
 * the spacing survives in float, where sum(d^2)/n - mean^2 would not. */
static cdsp_real spacing_at(const cdsp_result *a, const cdsp_result *b, int k, int n)
{
    cdsp_real t = ((cdsp_real)k + R(0.5)) / (cdsp_real)n, X[3];
    int i;
    for (i = 0; i < 3; i++)
        X[i] = a->segment[0][i] + t * (a->segment[1][i] - a->segment[0][i]);
    return cdsp_result_point_distance(b, X);
}

cdsp_status cdsp_result_axis_spacing(const cdsp_result *a, const cdsp_result *b, int n,
                                     cdsp_real *mean, cdsp_real *spread)
{
    cdsp_real sum = R(0), m;
    int k;
    if (!a || !b || !mean || !spread || n < 1)
        return CDSP_E_ARG;
    if (!v3_finite(a->segment[0]) || !v3_finite(a->segment[1]) || !v3_finite(b->point) ||
        !v3_finite(b->direction) || !(v3_norm(b->direction) > R(0)))
        return CDSP_E_NONFINITE;
    for (k = 0; k < n; k++)
        sum += spacing_at(a, b, k, n);
    m = sum / (cdsp_real)n;
    sum = R(0);
    for (k = 0; k < n; k++) {
        cdsp_real e = spacing_at(a, b, k, n) - m;
        sum += e * e;
    }
    *mean = m;
    *spread = R_SQRT(sum / (cdsp_real)n);
    return CDSP_OK;
}
