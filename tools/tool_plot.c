/*
 * tool_plot.c - `cdsp_tool plot`: a run's records as a picture, drawn with
 * cairo into a PNG: the distance |P_C|, the lateral offset of P_C (its X
 * and Y) and the direction (its angle in the image plane and out of it)
 * over the frame number or the camera time, each with its +-1 sigma band,
 * the frames without a pipe marked as red bands across every panel, and,
 * given the ground truth, the truth as dashed lines and two more panels of
 * errors (the paper's axis RMSE and the distance error; the angle error).
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <cairo.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PI 3.14159265358979323846

static const char plot_description[] =
    "    Reads the records of `cdsp_tool solve` (JSON Lines or --csv; \"-\" is\n"
    "    standard input) or of `cdspd --format json`, and draws FILE.png, one\n"
    "    panel above the other, sharing the horizontal axis (the record's place\n"
    "    in the file, or with --x time the camera time in seconds from the first\n"
    "    record):\n"
    "      distance   |P_C|, the distance of the axis from the optical centre\n"
    "      lateral    P_C's X (right) and Y (down): where the axis passes\n"
    "      direction  the axis direction's angle in the image plane,\n"
    "                 atan2(d_y, d_x), and out of it, asin(d_z), degrees\n"
    "    Each curve has a band of +-1 standard deviation (the record's sigma,\n"
    "    propagated to the angles to first order). A record without a pipe\n"
    "    (any error record) breaks the curves and is marked by a red band\n"
    "    across all panels. With --truth, the true values are dashed lines and\n"
    "    two panels are added: the errors against the truth (the paper's axis\n"
    "    RMSE and the distance error, as `cdsp_tool compare` computes them) and\n"
    "    the angle between the found and the true direction.\n"
    "\n"
    "    Lengths are in the unit of the radius (mm in the examples).\n\n";

static const char plot_after[] =
    "EXAMPLES\n"
    "    cdsp_tool sim --out seq --frames 50 --move 0.5,0,0 --turn 0.2 --noise 0.01\n"
    "    cdsp_tool solve --calib seq/camera.yaml --radius 8 --track seq > seq.jsonl\n"
    "    cdsp_tool plot --out seq.png --truth seq/truth.json seq.jsonl\n"
    "    cdsp_tool listen --json -n 300 > live.jsonl && \\\n"
    "        cdsp_tool plot --x time --out live.png live.jsonl\n";

static const char plot_exit[] =
    "    0  the picture was written\n"
    "    1  the picture was written, but no record holds a pipe (nothing to plot)\n"
    "    2  usage error, a records or truth file that cannot be read (the message\n"
    "       names the file and line), --x time without times in the records, or\n"
    "       the picture cannot be written\n";

/* Colours as bytes, so that the picture's pixels have exactly these values
 * where a curve covers them (the tests look for them). */
typedef struct {
    int r, g, b;
} rgb;
static const rgb c_curve[2] = {{0, 90, 200}, {230, 120, 0}};
static const rgb c_band[2] = {{200, 220, 245}, {250, 225, 195}};
static const rgb c_gap = {255, 215, 215};
static const rgb c_grid = {225, 225, 225};

static void set_rgb(cairo_t *cr, rgb c)
{
    cairo_set_source_rgb(cr, c.r / 255.0, c.g / 255.0, c.b / 255.0);
}

/* One panel: up to two series, each value and sigma per record (NAN: no
 * value), and the truth per record (NAN: none). */
typedef struct {
    const char *title, *unit;
    const char *name[2];
    int nseries;
    double *v[2], *s[2], *t[2];
} panel;

typedef struct {
    double x0, x1, y0, y1;       /* data range */
    double left, right, top, bottom; /* pixels */
} frame;

static double px_x(const frame *f, double x)
{
    return f->left + (x - f->x0) / (f->x1 - f->x0) * (f->right - f->left);
}

static double px_y(const frame *f, double y)
{
    return f->bottom - (y - f->y0) / (f->y1 - f->y0) * (f->bottom - f->top);
}

/* A tick step of 1, 2 or 5 x 10^k giving about n ticks over span. */
static double nice_step(double span, int n)
{
    double raw = span / n, p = pow(10, floor(log10(raw))), m = raw / p;
    return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

static void text_at(cairo_t *cr, double x, double y, const char *s, double ax, double ay)
{
    cairo_text_extents_t e;
    cairo_text_extents(cr, s, &e);
    cairo_move_to(cr, x - ax * e.width - e.x_bearing, y + ay * e.height - (e.height + e.y_bearing));
    cairo_show_text(cr, s);
    cairo_new_path(cr); /* show_text leaves a current point a line_to would start from */
}

static void draw_panel(cairo_t *cr, const panel *p, const double *x, const int *gap, size_t n,
                       double dx, frame f)
{
    size_t i;
    int k;
    double lo = HUGE_VAL, hi = -HUGE_VAL, step, y;
    char buf[64];
    for (k = 0; k < p->nseries; k++)
        for (i = 0; i < n; i++) {
            double v = p->v[k][i], s = p->s[k] ? p->s[k][i] : NAN, t = p->t[k] ? p->t[k][i] : NAN;
            if (isfinite(v)) {
                double w = isfinite(s) ? s : 0;
                lo = fmin(lo, v - w);
                hi = fmax(hi, v + w);
            }
            if (isfinite(t)) {
                lo = fmin(lo, t);
                hi = fmax(hi, t);
            }
        }
    if (!(lo <= hi)) {
        lo = -1;
        hi = 1;
    }
    if (hi - lo < 1e-9 * (1 + fabs(hi))) {
        double m = 0.5 * (hi + lo), w = fmax(1e-3 * fabs(m), 1e-6);
        lo = m - w;
        hi = m + w;
    }
    f.y0 = lo - 0.05 * (hi - lo);
    f.y1 = hi + 0.05 * (hi - lo);

    /* no-pipe records: red bands one record wide */
    set_rgb(cr, c_gap);
    for (i = 0; i < n; i++)
        if (gap[i]) {
            double a = px_x(&f, x[i] - 0.5 * dx), b = px_x(&f, x[i] + 0.5 * dx);
            a = fmax(a, f.left);
            b = fmin(b, f.right);
            cairo_rectangle(cr, a, f.top, fmax(b - a, 1), f.bottom - f.top);
        }
    cairo_fill(cr);
    /* grid and labels */
    cairo_set_font_size(cr, 12);
    step = nice_step(f.y1 - f.y0, 5);
    for (y = ceil(f.y0 / step) * step; y <= f.y1; y += step) {
        set_rgb(cr, c_grid);
        cairo_set_line_width(cr, 1);
        cairo_move_to(cr, f.left, floor(px_y(&f, y)) + 0.5);
        cairo_line_to(cr, f.right, floor(px_y(&f, y)) + 0.5);
        cairo_stroke(cr);
        cairo_set_source_rgb(cr, 0, 0, 0);
        snprintf(buf, sizeof buf, "%.6g", fabs(y) < 1e-12 * step ? 0.0 : y);
        text_at(cr, f.left - 6, px_y(&f, y), buf, 1, 0.5);
    }
    /* sigma bands, then curves, each series broken at records without a value */
    for (k = 0; k < p->nseries; k++) {
        if (p->s[k]) {
            set_rgb(cr, c_band[k]);
            for (i = 0; i < n; i++) {
                size_t j = i;
                if (!isfinite(p->v[k][i]) || !isfinite(p->s[k][i]))
                    continue;
                while (j + 1 < n && isfinite(p->v[k][j + 1]) && isfinite(p->s[k][j + 1]))
                    j++;
                {
                    size_t m;
                    for (m = i; m <= j; m++)
                        cairo_line_to(cr, px_x(&f, x[m]), px_y(&f, p->v[k][m] + p->s[k][m]));
                    for (m = j + 1; m-- > i;)
                        cairo_line_to(cr, px_x(&f, x[m]), px_y(&f, p->v[k][m] - p->s[k][m]));
                    if (i == j) { /* a lone record: a bar one pixel either side */
                        cairo_new_path(cr);
                        cairo_rectangle(cr, px_x(&f, x[i]) - 1, px_y(&f, p->v[k][i] + p->s[k][i]),
                                        2, px_y(&f, p->v[k][i] - p->s[k][i]) -
                                               px_y(&f, p->v[k][i] + p->s[k][i]));
                    }
                    cairo_close_path(cr);
                    cairo_fill(cr);
                }
                i = j;
            }
        }
    }
    for (k = 0; k < p->nseries; k++) {
        set_rgb(cr, c_curve[k]);
        cairo_set_line_width(cr, 2);
        for (i = 0; i < n; i++) {
            if (!isfinite(p->v[k][i]))
                continue;
            if (i == 0 || !isfinite(p->v[k][i - 1]))
                cairo_move_to(cr, px_x(&f, x[i]), px_y(&f, p->v[k][i]));
            else
                cairo_line_to(cr, px_x(&f, x[i]), px_y(&f, p->v[k][i]));
            if (i + 1 == n || !isfinite(p->v[k][i + 1])) {
                /* a lone point stays visible: a short dash */
                if (i == 0 || !isfinite(p->v[k][i - 1]))
                    cairo_rel_line_to(cr, 0.01, 0);
                cairo_stroke(cr);
            }
        }
        if (p->t[k]) { /* the truth, dashed and thin */
            static const double dash[2] = {6, 4};
            cairo_set_source_rgb(cr, 0, 0, 0);
            cairo_set_line_width(cr, 1);
            cairo_set_dash(cr, dash, 2, 0);
            for (i = 0; i < n; i++) {
                if (!isfinite(p->t[k][i]))
                    continue;
                if (i == 0 || !isfinite(p->t[k][i - 1]))
                    cairo_move_to(cr, px_x(&f, x[i]), px_y(&f, p->t[k][i]));
                else
                    cairo_line_to(cr, px_x(&f, x[i]), px_y(&f, p->t[k][i]));
            }
            cairo_stroke(cr);
            cairo_set_dash(cr, NULL, 0, 0);
        }
    }
    /* frame, title, legend */
    cairo_set_source_rgb(cr, 0, 0, 0);
    cairo_set_line_width(cr, 1);
    cairo_rectangle(cr, floor(f.left) + 0.5, floor(f.top) + 0.5, floor(f.right - f.left),
                    floor(f.bottom - f.top));
    cairo_stroke(cr);
    cairo_set_font_size(cr, 13);
    snprintf(buf, sizeof buf, "%s (%s)", p->title, p->unit);
    text_at(cr, f.left, f.top - 6, buf, 0, 0);
    {
        double lx = f.right;
        for (k = p->nseries; k-- > 0;) {
            cairo_text_extents_t e;
            cairo_text_extents(cr, p->name[k], &e);
            lx -= e.width + 8;
            set_rgb(cr, c_curve[k]);
            text_at(cr, lx, f.top - 6, p->name[k], 0, 0);
            lx -= 14;
            cairo_rectangle(cr, lx, f.top - 14, 10, 8);
            cairo_fill(cr);
            lx -= 10;
        }
    }
}

int tool_plot_main(int argc, char **argv)
{
    static const tool_doc doc = {
        "plot", "distance, offset and direction of a run over time, as a PNG",
        "--out FILE.png [OPTIONS] RECORDS.jsonl|RECORDS.csv|-", plot_description, plot_after,
        plot_exit};
    const char *out = NULL, *truth_path = NULL, *title = NULL;
    int width = 1200, height = 0, xtime = 0, npos = 0, rc, np, k, solved = 0;
    char **pos = NULL;
    tool_records rs;
    tool_truth t;
    size_t n, i;
    double *buf = NULL, *x, dx;
    int *gap = NULL;
    panel P[5];
    cairo_surface_t *surf;
    cairo_t *cr;
    cairo_status_t st;
    const tool_opt opts[] = {
        {"out", 'o', OPT_STR, &out, 0, 0, "FILE.png", "The picture to write (required).", NULL, 1},
        {"truth", 0, OPT_STR, &truth_path, 0, 0, "TRUTH.json",
         "The ground truth (sim's truth.json): dashed truth lines and error panels.", NULL, 1},
        {"x", 0, OPT_CHOICE, &xtime, 0, 0, NULL,
         "Horizontal axis: the record's place in the file (frame), or the camera time "
         "t_camera_us (else t_host_us) of cdspd's records in seconds from the first (time).",
         "frame|time", 0},
        {"width", 0, OPT_INT, &width, 320, 8192, "W", "Picture width, px.", NULL, 0},
        {"height", 0, OPT_INT, &height, 0, 8192, "H",
         "Picture height, px; 0: 240 px per panel plus 70.", NULL, 0},
        {"title", 0, OPT_STR, &title, 0, 0, "TEXT", "Title line. Default: the records file and "
         "its counts.", NULL, 1},
        {NULL, 0, OPT_FLAG, NULL, 0, 0, NULL, NULL, NULL, 0},
    };
    rc = tool_parse_alloc("plot", &doc, opts, argc, argv, &pos, &npos);
    if (rc)
        return rc - 1;
    if (!out) {
        free(pos);
        return tool_usage_error("plot", "--out FILE.png is required (see --help)");
    }
    if (npos != 1) {
        free(pos);
        return tool_usage_error("plot", "expected one RECORDS file (see --help)");
    }
    rc = tool_records_read("plot", pos[0], &rs);
    if (rc) {
        free(pos);
        return rc;
    }
    memset(&t, 0, sizeof t);
    if (truth_path && (rc = tool_truth_read("plot", truth_path, &t)) != 0)
        goto out;
    rc = TOOL_EXIT_USAGE;
    n = rs.n;
    if (n == 0) {
        tool_usage_error("plot", "%s: no records", pos[0]);
        goto out;
    }
    /* per record: x, then 3 panels x 2 series x (value, sigma, truth) and
     * 2 error panels x 2 series */
    buf = malloc(sizeof *buf * n * 32);
    gap = calloc(n, sizeof *gap);
    if (!buf || !gap) {
        tool_usage_error("plot", "out of memory");
        goto out;
    }
    for (i = 0; i < n * 32; i++)
        buf[i] = NAN;
    x = buf;
    memset(P, 0, sizeof P);
    np = truth_path ? 5 : 3;
    P[0] = (panel){"distance |P_C|", "unit of R", {"distance", NULL}, 1, {buf + n}, {buf + 2 * n},
                   {truth_path ? buf + 3 * n : NULL}};
    P[1] = (panel){"lateral offset", "unit of R", {"X", "Y"}, 2, {buf + 4 * n, buf + 5 * n},
                   {buf + 6 * n, buf + 7 * n},
                   {truth_path ? buf + 8 * n : NULL, truth_path ? buf + 9 * n : NULL}};
    P[2] = (panel){"direction", "deg", {"in image plane", "out of it"}, 2,
                   {buf + 10 * n, buf + 11 * n}, {buf + 12 * n, buf + 13 * n},
                   {truth_path ? buf + 14 * n : NULL, truth_path ? buf + 15 * n : NULL}};
    P[3] = (panel){"error against the truth", "unit of R", {"axis RMSE", "distance error"}, 2,
                   {buf + 16 * n, buf + 17 * n}, {NULL, NULL}, {NULL, NULL}};
    P[4] = (panel){"direction error", "deg", {"angle", NULL}, 1, {buf + 18 * n}, {NULL},
                   {NULL}};
    for (i = 0; i < n; i++) {
        const tool_record *r = &rs.r[i];
        if (xtime) {
            if (!isfinite(r->t_us)) {
                tool_usage_error("plot", "%s: record %zu has no time (t_camera_us or t_host_us): "
                                 "use --x frame", pos[0], i + 1);
                goto out;
            }
            x[i] = (r->t_us - rs.r[0].t_us) * 1e-6;
        } else {
            x[i] = (double)i;
        }
        gap[i] = !r->ok;
        if (r->ok) {
            const double *d = r->direction, *sd = r->sigma_direction;
            double nd = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), h2 = d[0] * d[0] + d[1] * d[1];
            solved++;
            P[0].v[0][i] = r->distance;
            P[0].s[0][i] = r->sigma_distance;
            P[1].v[0][i] = r->point[0];
            P[1].v[1][i] = r->point[1];
            P[1].s[0][i] = r->sigma_point[0];
            P[1].s[1][i] = r->sigma_point[1];
            /* azimuth atan2(dy, dx): d az = (dx d(dy) - dy d(dx)) / (dx^2 + dy^2);
             * elevation asin(dz / |d|): d el = d(dz) / sqrt(|d|^2 - dz^2) */
            P[2].v[0][i] = atan2(d[1], d[0]) * 180 / PI;
            P[2].v[1][i] = asin(d[2] / nd) * 180 / PI;
            P[2].s[0][i] = h2 > 0 ? sqrt(d[0] * d[0] * sd[1] * sd[1] + d[1] * d[1] * sd[0] * sd[0]) /
                                        h2 * 180 / PI
                                  : NAN;
            P[2].s[1][i] = h2 > 0 ? sd[2] / sqrt(h2) * 180 / PI : NAN;
        }
        if (truth_path) {
            const tool_truth_frame *tf = tool_truth_match(&t, r, i);
            if (tf) {
                const double *d = tf->direction;
                P[0].t[0][i] = tf->distance;
                P[1].t[0][i] = tf->point[0];
                P[1].t[1][i] = tf->point[1];
                P[2].t[0][i] = atan2(d[1], d[0]) * 180 / PI;
                P[2].t[1][i] = asin(d[2] / sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])) * 180 / PI;
                if (r->ok)
                    tool_record_errors(r, tf, 100, &P[3].v[0][i], &P[4].v[0][i], &P[3].v[1][i]);
            }
        }
    }
    /* the band of a missing record spans the typical spacing */
    dx = n > 1 ? (x[n - 1] - x[0]) / (double)(n - 1) : 1;
    if (!(dx > 0))
        dx = 1;
    if (height == 0)
        height = 240 * np + 70;
    surf = cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height);
    cr = cairo_create(surf);
    cairo_set_source_rgb(cr, 1, 1, 1);
    cairo_paint(cr);
    cairo_select_font_face(cr, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    {
        char head[600];
        double ph = (height - 40.0 - 36.0) / np, step, xv;
        frame f;
        f.x0 = x[0] - (n > 1 ? 0 : 1);
        f.x1 = x[n - 1] + (n > 1 ? 0 : 1);
        f.left = 80;
        f.right = width - 16;
        if (title)
            snprintf(head, sizeof head, "%s", title);
        else
            snprintf(head, sizeof head, "%s: %zu records, %d with a pipe, %zu without (red)",
                     pos[0], n, solved, n - (size_t)solved);
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_font_size(cr, 15);
        text_at(cr, 0.5 * width, 22, head, 0.5, 0);
        for (k = 0; k < np; k++) {
            f.top = 40 + k * ph + 22;
            f.bottom = 40 + (k + 1) * ph - 8;
            draw_panel(cr, &P[k], x, gap, n, dx, f);
        }
        /* the shared horizontal axis under the last panel */
        cairo_set_source_rgb(cr, 0, 0, 0);
        cairo_set_font_size(cr, 12);
        step = nice_step(f.x1 - f.x0, 10);
        if (!xtime && step < 1)
            step = 1;
        for (xv = ceil(f.x0 / step) * step; xv <= f.x1 + 1e-9 * step; xv += step) {
            char lab[32];
            double px = px_x(&f, xv);
            cairo_move_to(cr, floor(px) + 0.5, f.bottom);
            cairo_line_to(cr, floor(px) + 0.5, f.bottom + 4);
            cairo_stroke(cr);
            snprintf(lab, sizeof lab, "%.6g", xv);
            text_at(cr, px, f.bottom + 6, lab, 0.5, 1);
        }
        text_at(cr, 0.5 * (f.left + f.right), height - 4.0,
                xtime ? "time from the first record (s)" : "record (frame number)", 0.5, 0);
    }
    cairo_destroy(cr);
    st = cairo_surface_write_to_png(surf, out);
    cairo_surface_destroy(surf);
    tool_cairo_done();
    if (st != CAIRO_STATUS_SUCCESS) {
        tool_usage_error("plot", "%s: cannot write the picture: %s", out,
                         cairo_status_to_string(st));
        goto out;
    }
    rc = solved ? TOOL_EXIT_OK : TOOL_EXIT_PARTIAL;
    if (!solved)
        tool_warn("plot", "%s: no record holds a pipe", pos[0]);
out:
    free(buf);
    free(gap);
    tool_records_free(&rs);
    tool_truth_free(&t);
    free(pos);
    return rc;
}
