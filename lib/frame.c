/*
 * frame.c - frame in, pose out: edges -> undistortion -> line pair -> axis.
 *
 * Tracking: a pipe moves little between frames, so with the previous result
 * as a prior only short scanline segments of +-track_band_px around each
 * predicted contour are read (the prior's undistorted line, distorted back
 * into the frame), far fewer pixels than a full search. If the band search
 * finds no pipe, or too few inliers on either contour, a full search runs.
 */
#include "internal.h"

/* Distorted-frame position where the prior's undistorted line l crosses
 * scanline `line` (a row when horizontal, else a column): fixed point on the
 * across-coordinate, 4 rounds (distortion moves a point by a small fraction
 * of a pixel per pixel, so each round gains more than a digit). */
static int crossing(const cdsp_camera *cam, const cdsp_real l[3], int horizontal, int line,
                    cdsp_real *s_out)
{
    cdsp_real target = (cdsp_real)line, t = target, und[2], dist[2];
    int it;
    for (it = 0; it < 4; it++) {
        if (horizontal) { /* row v = t: u from a u + b v + c = 0 */
            und[1] = t;
            und[0] = -(l[1] * t + l[2]) / l[0];
        } else {
            und[0] = t;
            und[1] = -(l[0] * t + l[2]) / l[1];
        }
        if (cdsp_camera_distort(cam, und, dist) != CDSP_OK)
            return 0;
        t += target - (horizontal ? dist[1] : dist[0]);
    }
    *s_out = horizontal ? dist[0] : dist[1];
    return R_FINITE(*s_out);
}

static size_t track_bands(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                          int step, const cdsp_result *prior, cdsp_edge *out, size_t cap)
{
    int x0 = 0, y0 = 0, x1 = img->width, y1 = img->height, k, h = p->edge.half_window;
    int band = (int)R_CEIL(p->track_band_px);
    size_t n = 0;
    if (p->edge.roi.w > 0 && p->edge.roi.h > 0) {
        x0 = p->edge.roi.x > 0 ? p->edge.roi.x : 0;
        y0 = p->edge.roi.y > 0 ? p->edge.roi.y : 0;
        x1 = p->edge.roi.x + p->edge.roi.w < img->width ? p->edge.roi.x + p->edge.roi.w : img->width;
        y1 = p->edge.roi.y + p->edge.roi.h < img->height ? p->edge.roi.y + p->edge.roi.h : img->height;
    }
    for (k = 0; k < 2; k++) {
        const cdsp_real *l = prior->lines[k];
        /* near-vertical contour (|a| >= |b|): scan rows; else columns */
        int horizontal = R_FABS(l[0]) >= R_FABS(l[1]);
        int lo = horizontal ? y0 : x0, hi = horizontal ? y1 : x1;
        int ext = horizontal ? img->width : img->height;     /* along the scan */
        int other = horizontal ? img->height : img->width;   /* across */
        int smin = horizontal ? x0 : y0, smax = horizontal ? x1 : y1;
        int t;
        for (t = (lo > 1 ? lo : 1) + step / 2; t < hi - 1 && t < other - 1; t += step) {
            cdsp_real sc;
            int from, to;
            if (!crossing(cam, l, horizontal, t, &sc))
                continue;
            if (sc < (cdsp_real)(smin - band) || sc > (cdsp_real)(smax + band))
                continue;
            from = (int)R_FLOOR(sc) - band;
            to = (int)R_FLOOR(sc) + band + 1;
            if (from < smin)
                from = smin;
            if (to > smax)
                to = smax;
            if (from < h + 1)
                from = h + 1;
            if (to > ext - h - 1)
                to = ext - h - 1;
            n += cdsp__edges_scan_segment(img, &p->edge, horizontal, t, from, to, out + n, cap - n);
            if (n == cap)
                return n;
        }
    }
    return n;
}

/* The bands around both contours; when they hold more edges than cap, both
 * are read again at twice the step until they fit, so the first contour's
 * band never fills the buffer before the second is read (*truncated set). */
static size_t track_edges(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                          const cdsp_result *prior, cdsp_edge *out, size_t cap, int *truncated)
{
    int step = p->edge.step, extent = img->width > img->height ? img->width : img->height;
    size_t n;
    *truncated = 0;
    while ((n = track_bands(img, cam, p, step, prior, out, cap)) == cap && step <= extent / 2) {
        step *= 2;
        *truncated = 1;
    }
    return n;
}

static cdsp_status solve_edges(const cdsp_camera *cam, cdsp_real radius, cdsp_frame_ws *ws,
                               size_t n, const cdsp_params *p, const cdsp_result *prior,
                               cdsp_rng *rng, cdsp_result *out)
{
    cdsp_status st = cdsp_camera_undistort_edges(cam, ws->edge, &n);
    if (st != CDSP_OK)
        return st;
    return cdsp__pair_solve(cam, radius, ws->edge, n, ws->label, p, prior, rng, out);
}

cdsp_status cdsp_frame_solve(const cdsp_image *img, const cdsp_camera *cam, cdsp_real radius,
                             const cdsp_params *p, const cdsp_result *prior, cdsp_frame_ws *ws,
                             cdsp_rng *rng, cdsp_result *out)
{
    cdsp_status st;
    size_t n = 0;
    uint32_t flags = CDSP_FLAG_FULL_SEARCH;
    if (!img || !cam || !p || !ws || !rng || !out)
        return CDSP_E_ARG;
    st = cdsp_image_check(img);
    if (st != CDSP_OK)
        return st;
    st = cdsp__solve_args_check(cam, radius, p);
    if (st != CDSP_OK)
        return st;
    if (img->width != cam->width || img->height != cam->height)
        return CDSP_E_ARG;

    if (prior && v3_finite(prior->lines[0]) && v3_finite(prior->lines[1])) {
        int truncated;
        n = track_edges(img, cam, p, prior, ws->edge, CDSP_MAX_EDGES, &truncated);
        st = solve_edges(cam, radius, ws, n, p, prior, rng, out);
        if (st == CDSP_OK && out->inliers[0] >= (uint32_t)p->track_min_inliers &&
            out->inliers[1] >= (uint32_t)p->track_min_inliers) {
            out->flags = CDSP_FLAG_TRACKED | (truncated ? CDSP_FLAG_TRUNCATED : 0u);
            return CDSP_OK;
        }
    }
    st = cdsp_edges_detect(img, &p->edge, ws->edge, CDSP_MAX_EDGES, &n);
    if (st == CDSP_E_CAPACITY)
        flags |= CDSP_FLAG_TRUNCATED;
    else if (st != CDSP_OK)
        return st;
    st = solve_edges(cam, radius, ws, n, p, prior, rng, out);
    if (st != CDSP_OK)
        return st;
    out->flags = flags;
    return CDSP_OK;
}
