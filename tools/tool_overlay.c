/*
 * tool_overlay.c - the picture a user checks first: the frame in gray with
 * the edge points, the inliers of each contour, the two fitted contour
 * lines and the projected visible axis drawn over it, as an RGB PNG.
 * The contours and the axis live in undistorted coordinates; they are
 * drawn through the camera's distortion, so they bend exactly as the
 * pipe's image does. Marks scale with the frame (1 px up to 1000 px wide).
 */
#include "tool_internal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

typedef struct {
    uint8_t *rgb;
    int w, h;
} canvas;

/* (x, y) rounded to the nearest pixel when it lies within reach px of the
 * canvas: 1, else 0 (also NaN). A projection can land far outside the
 * frame, beyond what an int holds, so the test is made in doubles first. */
static int near_canvas(const canvas *c, double x, double y, int reach, int *cx, int *cy)
{
    if (!(x > -1.0 - reach && x < (double)c->w + reach && y > -1.0 - reach &&
          y < (double)c->h + reach))
        return 0;
    *cx = (int)floor(x + 0.5);
    *cy = (int)floor(y + 0.5);
    return 1;
}

/* A small '+' (arm length arm px): edge points stay visible on the lines. */
static void mark(canvas *c, double x, double y, int arm, const uint8_t col[3])
{
    int cx, cy, k;
    if (!near_canvas(c, x, y, arm, &cx, &cy))
        return;
    for (k = -arm; k <= arm; k++) {
        int px[2] = {cx + k, cx}, py[2] = {cy, cy + k}, i;
        for (i = 0; i < 2; i++) {
            uint8_t *p;
            if (px[i] < 0 || py[i] < 0 || px[i] >= c->w || py[i] >= c->h)
                continue;
            p = c->rgb + 3 * ((size_t)py[i] * (size_t)c->w + (size_t)px[i]);
            memcpy(p, col, 3);
        }
    }
}

static void plot(canvas *c, double x, double y, int rad, const uint8_t col[3])
{
    int cx, cy, dx, dy;
    if (!near_canvas(c, x, y, rad, &cx, &cy))
        return;
    for (dy = -rad; dy <= rad; dy++)
        for (dx = -rad; dx <= rad; dx++) {
            int px = cx + dx, py = cy + dy;
            uint8_t *p;
            if (px < 0 || py < 0 || px >= c->w || py >= c->h || dx * dx + dy * dy > rad * rad + rad)
                continue;
            p = c->rgb + 3 * ((size_t)py * (size_t)c->w + (size_t)px);
            p[0] = col[0];
            p[1] = col[1];
            p[2] = col[2];
        }
}

/* Undistorted pixel -> frame pixel; 0 when the distortion model fails. */
static int to_frame(const cdsp_camera *cam, double u, double v, double out[2])
{
    cdsp_real und[2] = {(cdsp_real)u, (cdsp_real)v}, dist[2];
    if (cdsp_camera_distort(cam, und, dist) != CDSP_OK)
        return 0;
    out[0] = (double)dist[0];
    out[1] = (double)dist[1];
    return isfinite(out[0]) && isfinite(out[1]);
}

/* The undistorted line a u + b v + c = 0 over the frame, sampled every
 * half pixel and bent by the distortion. Only the part whose undistorted
 * position lies within a margin of the image is drawn: far outside, the
 * polynomial distortion model folds back and means nothing. */
static void draw_line(canvas *c, const cdsp_camera *cam, const cdsp_real l[3], int rad,
                      const uint8_t col[3])
{
    double a = (double)l[0], b = (double)l[1], cc = (double)l[2];
    double margin = 0.1 * (c->w > c->h ? c->w : c->h);
    double t, tmax = 2.0 * (c->w + c->h), u0, v0;
    double n = sqrt(a * a + b * b);
    if (!(n > 0))
        return;
    a /= n;
    b /= n;
    cc /= n;
    /* the point of the line nearest the image centre, then along (-b, a) */
    u0 = (double)cam->cx - a * (a * (double)cam->cx + b * (double)cam->cy + cc);
    v0 = (double)cam->cy - b * (a * (double)cam->cx + b * (double)cam->cy + cc);
    for (t = -tmax; t <= tmax; t += 0.5) {
        double u = u0 - b * t, v = v0 + a * t, p[2];
        if (u < -margin || v < -margin || u > c->w + margin || v > c->h + margin)
            continue;
        if (to_frame(cam, u, v, p))
            plot(c, p[0], p[1], rad, col);
    }
}

static void draw_axis(canvas *c, const cdsp_camera *cam, const cdsp_result *r, int rad,
                      const uint8_t col[3])
{
    const cdsp_real *s0 = r->segment[0], *s1 = r->segment[1];
    double len = 0, steps, k;
    cdsp_real pix[2], X[3];
    int i;
    for (i = 0; i < 3; i++)
        len += (double)((s1[i] - s0[i]) * (s1[i] - s0[i]));
    len = sqrt(len);
    if (!(len > 0)) {
        /* no extent known: mark the foot of the perpendicular only */
        if (cdsp_camera_project(cam, r->point, pix) == CDSP_OK)
            plot(c, (double)pix[0], (double)pix[1], 3 * rad + 2, col);
        return;
    }
    /* enough samples for half-pixel spacing along the projected segment */
    steps = 4.0 * (c->w + c->h);
    for (k = 0; k <= steps; k++) {
        double f = k / steps;
        for (i = 0; i < 3; i++)
            X[i] = s0[i] + (cdsp_real)f * (s1[i] - s0[i]);
        if (cdsp_camera_project(cam, X, pix) == CDSP_OK)
            plot(c, (double)pix[0], (double)pix[1], rad, col);
    }
    for (i = 0; i < 2; i++)
        if (cdsp_camera_project(cam, r->segment[i], pix) == CDSP_OK)
            plot(c, (double)pix[0], (double)pix[1], 2 * rad + 2, col);
}

int tool_overlay_write(const char *path, const cdsp_host_image *img, const cdsp_camera *cam,
                       const cdsp_edge *edges, const uint8_t *label, size_t n,
                       const cdsp_result *r, size_t nr, const cdsp_roi *roi,
                       const char *const *caption, int ncaption, cdsp_host_err *err)
{
    static const uint8_t blue[3] = {40, 120, 255}, green[3] = {0, 230, 0},
                         magenta[3] = {255, 0, 255}, yellow[3] = {255, 230, 0},
                         red[3] = {255, 30, 30};
    canvas c;
    tool_tag tags[CDSP_MAX_PIPES];
    int ntags = 0;
    size_t i, k, npx;
    int rc, rad = (img->width > img->height ? img->width : img->height) / 1000;
    c.w = img->width;
    c.h = img->height;
    npx = (size_t)c.w * (size_t)c.h;
    c.rgb = malloc(npx * 3u);
    if (!c.rgb) {
        snprintf(err->msg, sizeof err->msg, "%s: out of memory for the overlay", path);
        return CDSP_HOST_E_NOMEM;
    }
    /* the frame, slightly darkened so the marks stand out */
    for (i = 0; i < npx; i++) {
        int x = (int)(i % (size_t)c.w), y = (int)(i / (size_t)c.w);
        uint8_t g = (uint8_t)(cdsp_host_image_at(img, x, y) * 200.0 + 0.5);
        c.rgb[3 * i] = c.rgb[3 * i + 1] = c.rgb[3 * i + 2] = g;
    }
    if (!r)
        nr = 0;
    for (k = 0; k < nr; k++) {
        draw_line(&c, cam, r[k].lines[0], rad, yellow);
        draw_line(&c, cam, r[k].lines[1], rad, yellow);
    }
    for (i = 0; i < n; i++)
        mark(&c, (double)edges[i].x, (double)edges[i].y, 2 * rad + 1,
             label[i] == 0 ? blue : label[i] % 2 ? green : magenta);
    for (k = 0; k < nr; k++) {
        cdsp_real mid[3], pix[2];
        draw_axis(&c, cam, &r[k], rad, red);
        if (nr < 2 || k >= CDSP_MAX_PIPES)
            continue;
        /* the rank beside the axis' middle */
        for (i = 0; i < 3; i++)
            mid[i] = (r[k].segment[0][i] + r[k].segment[1][i]) / 2;
        if (cdsp_camera_project(cam, mid, pix) == CDSP_OK && pix[0] > -1e6 && pix[0] < 1e6 &&
            pix[1] > -1e6 && pix[1] < 1e6) {
            tags[ntags].x = (double)pix[0] + 4.0 * (rad + 1);
            tags[ntags].y = (double)pix[1];
            snprintf(tags[ntags].text, sizeof tags[ntags].text, "#%zu", k + 1);
            ntags++;
        }
    }
    /* the ROI and the caption, in words (cairo: tool_caption.c) */
    if (tool_overlay_annotate(c.rgb, c.w, c.h, roi, caption, ncaption, tags, ntags) != 0) {
        free(c.rgb);
        snprintf(err->msg, sizeof err->msg, "%s: out of memory for the overlay's caption", path);
        return CDSP_HOST_E_NOMEM;
    }
    rc = cdsp_host_png_write_rgb(path, c.rgb, c.w, c.h, err);
    free(c.rgb);
    return rc;
}
