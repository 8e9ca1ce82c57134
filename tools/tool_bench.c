/*
 * tool_bench.c - `cdsp_tool bench`: the accuracy study of the paper
 * (Yao et al. 2024, section 4; docs/method.md) on simulated data, with the
 * paper's figures printed beside ours:
 *   1. axis RMSE against Gaussian noise of 0..3 px on the contour points,
 *      10 trials per level, the paper's four pipes p1..p4;
 *   2. axis RMSE when the assumed radius is off by 0.02 / 0.05 / 0.10 mm;
 *   3. time per reconstruction: the points path (what the paper timed) and
 *      the whole frame path on a rendered 2448 x 2048 frame.
 * Contour points are sampled on the exact image contours of each finite
 * pipe, computed here from the tangent planes (independently of libcdsp),
 * about one per pixel of contour length as in the paper; the metric is the
 * paper's (Eq. 17-21): RMSE of the distances from points along the
 * reconstructed visible segment to the true axis.
 * Writes DIR/bench_noise.csv, bench_radius.csv, bench_time.csv and
 * bench_noise.svg (the plot, SVG written directly).
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define N_PIPES 4

typedef struct {
    const char *out;
    int trials, points, samples, frame_runs, no_frames, quiet, rack, rack_frames, rack_refine, rack_point_fit;
    tool_list levels;
    uint64_t seed;
    double rack_noise;
} bench_opts;

typedef struct {
    double A[3], v[3], half; /* axis point, unit direction, half length */
    double foot[3], dist;
    cdsp_edge pts[CDSP_MAX_POINTS]; /* exact contour points, undistorted px */
    size_t n;
    double length_px; /* visible length of the longer contour, px */
} pipe_case;

/* ---- the paper's pipes and their exact contours ---------------------------- */

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static int project(const cdsp_camera *cam, const double X[3], double p[2])
{
    if (!(X[2] > 0))
        return 0;
    p[0] = (double)cam->fx * X[0] / X[2] + (double)cam->cx;
    p[1] = (double)cam->fy * X[1] / X[2] + (double)cam->cy;
    return 1;
}

static int in_image(const cdsp_camera *cam, const double p[2])
{
    return p[0] >= 0 && p[1] >= 0 && p[0] <= cam->width - 1 && p[1] <= cam->height - 1;
}

/* Both contours of the finite pipe: a generator line G(t) = A + t v - r n
 * for each tangent plane normal n (n.v = 0, n.F = r with F the foot of the
 * axis), n = (r/d) e1 +- sqrt(1 - r^2/d^2) e2, e1 = F/d, e2 = v x e1.
 * Its image is a straight segment; the visible part is found by sampling
 * t, and `per_line` points are spread evenly over it (fewer if shorter
 * than that many pixels). Gradients point into the pipe (brighter), as
 * the edge detector would report them, with a step of 115 gray levels. */
static int make_case(const cdsp_camera *cam, int k, double r, int per_line, pipe_case *pc)
{
    double dir[3], e1[3], e2[3], c, s, inside[2], mid[3];
    int side, i;
    tool_paper_pipe(k, pc->A, dir, &pc->half);
    tool_axis_truth(pc->A, dir, pc->foot, pc->v, &pc->dist);
    for (i = 0; i < 3; i++)
        e1[i] = pc->foot[i] / pc->dist;
    cross3(pc->v, e1, e2);
    c = r / pc->dist;
    s = sqrt(1 - c * c);
    /* a pixel inside the pipe's image: the axis' midpoint of visibility is
     * found below; start from the foot's projection as a reference */
    pc->n = 0;
    pc->length_px = 0;
    for (side = 0; side < 2; side++) {
        double n[3], p0[2] = {0, 0}, p1[2] = {0, 0}, len, g[2], nn;
        int found = 0, steps = 20000, m;
        for (i = 0; i < 3; i++)
            n[i] = c * e1[i] + (side ? -s : s) * e2[i];
        for (i = 0; i <= steps; i++) {
            double t = -pc->half + 2 * pc->half * i / steps, X[3], p[2];
            int j;
            for (j = 0; j < 3; j++)
                X[j] = pc->A[j] + t * pc->v[j] - r * n[j];
            if (!project(cam, X, p) || !in_image(cam, p))
                continue;
            if (!found)
                p0[0] = p[0], p0[1] = p[1];
            p1[0] = p[0], p1[1] = p[1];
            found = 1;
        }
        if (!found)
            return -1;
        len = hypot(p1[0] - p0[0], p1[1] - p0[1]);
        if (len > pc->length_px)
            pc->length_px = len;
        m = per_line < (int)len ? per_line : (int)len;
        if (m < 20)
            return -1;
        /* the inward normal: toward the axis' image at the same place */
        for (i = 0; i < 3; i++)
            mid[i] = pc->foot[i];
        if (!project(cam, mid, inside))
            return -1;
        g[0] = -(p1[1] - p0[1]);
        g[1] = p1[0] - p0[0];
        nn = hypot(g[0], g[1]);
        g[0] /= nn;
        g[1] /= nn;
        if (g[0] * (inside[0] - p0[0]) + g[1] * (inside[1] - p0[1]) < 0)
            g[0] = -g[0], g[1] = -g[1];
        for (i = 0; i < m; i++) {
            double f = (i + 0.5) / m;
            cdsp_edge *e = &pc->pts[pc->n++];
            e->x = (cdsp_real)(p0[0] + f * (p1[0] - p0[0]));
            e->y = (cdsp_real)(p0[1] + f * (p1[1] - p0[1]));
            e->gx = (cdsp_real)(115 * g[0]);
            e->gy = (cdsp_real)(115 * g[1]);
        }
    }
    return 0;
}

/* Paper Eq. 17-21: RMSE of the distances of `samples` points along the
 * reconstructed visible segment to the true axis (d = 0). */
static double axis_rmse(const cdsp_result *res, const pipe_case *pc, int samples)
{
    double a[3], b[3];
    int j;
    for (j = 0; j < 3; j++) {
        a[j] = (double)res->segment[0][j];
        b[j] = (double)res->segment[1][j];
    }
    if (hypot(hypot(b[0] - a[0], b[1] - a[1]), b[2] - a[2]) < 1e-9)
        for (j = 0; j < 3; j++) { /* extent unknown: the true visible length */
            a[j] = (double)res->point[j] - pc->half * (double)res->direction[j];
            b[j] = (double)res->point[j] + pc->half * (double)res->direction[j];
        }
    return tool_segment_rmse(a, b, pc->A, pc->v, samples);
}

/* ---- output helpers ------------------------------------------------------ */

static FILE *open_csv(const bench_opts *B, const char *name, char *path, size_t cap)
{
    FILE *f;
    snprintf(path, cap, "%s/%s", B->out, name);
    f = fopen(path, "w");
    if (!f)
        tool_warn("bench", "%s: cannot create: %s", path, strerror(errno));
    return f;
}

static int close_file(FILE *f, const char *path)
{
    int bad = ferror(f);
    if ((fclose(f) != 0) | bad) {
        tool_warn("bench", "%s: write failed: %s", path, strerror(errno));
        return -1;
    }
    return 0;
}

/* The paper's figures for table 1 (0 where it gives none). */
static double paper_noise(double sigma)
{
    if (fabs(sigma - 0.1) < 1e-9)
        return 0.013;
    if (fabs(sigma - 1.5) < 1e-9)
        return 0.2;
    if (fabs(sigma - 3.0) < 1e-9)
        return 0.4;
    return 0;
}

static int write_svg(const bench_opts *B, const double *mean, int n)
{
    char path[4200], b[4][32];
    FILE *f;
    const double W = 640, H = 420, L = 70, R = 20, T = 40, Bm = 50;
    double xmax = 0, ymax = 0, tick;
    int i;
    for (i = 0; i < n; i++) {
        if (B->levels.v[i] > xmax)
            xmax = B->levels.v[i];
        if (mean[i] > ymax)
            ymax = mean[i];
    }
    if (xmax < 3)
        xmax = 3;
    if (ymax < 0.45)
        ymax = 0.45;
    ymax *= 1.1;
    snprintf(path, sizeof path, "%s/bench_noise.svg", B->out);
    f = fopen(path, "w");
    if (!f) {
        tool_warn("bench", "%s: cannot create: %s", path, strerror(errno));
        return -1;
    }
#define SX(x) (L + (x) / xmax * (W - L - R))
#define SY(y) (H - Bm - (y) / ymax * (H - T - Bm))
    fprintf(f, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
               "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
               "viewBox=\"0 0 %.0f %.0f\" font-family=\"sans-serif\" font-size=\"12\">\n"
               "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n"
               "<text x=\"%.0f\" y=\"22\" font-size=\"14\">Axis RMSE against contour point "
               "noise (paper pipes p1..p4, mean)</text>\n",
            W, H, W, H, L);
    for (tick = 0; tick <= xmax + 1e-9; tick += 0.5)
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                   "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">%g</text>\n",
                SX(tick), SY(0), SX(tick), SY(ymax), SX(tick), SY(0) + 16, tick);
    for (tick = 0; tick <= ymax + 1e-9; tick += 0.1)
        fprintf(f, "<line x1=\"%.1f\" y1=\"%.1f\" x2=\"%.1f\" y2=\"%.1f\" stroke=\"#ddd\"/>\n"
                   "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"end\">%.1f</text>\n",
                SX(0), SY(tick), SX(xmax), SY(tick), SX(0) - 6, SY(tick) + 4, tick);
    fprintf(f, "<text x=\"%.1f\" y=\"%.1f\" text-anchor=\"middle\">Gaussian noise on contour "
               "points (px)</text>\n"
               "<text transform=\"translate(18 %.1f) rotate(-90)\" text-anchor=\"middle\">RMSE "
               "(mm)</text>\n",
            (SX(0) + SX(xmax)) / 2, H - 12, (SY(0) + SY(ymax)) / 2);
    fprintf(f, "<polyline fill=\"none\" stroke=\"#1f5fd0\" stroke-width=\"2\" points=\"");
    for (i = 0; i < n; i++)
        fprintf(f, "%s,%s ", cdsp_host_fmt_real(b[0], floor(SX(B->levels.v[i]) * 10) / 10),
                cdsp_host_fmt_real(b[1], floor(SY(mean[i]) * 10) / 10));
    fprintf(f, "\"/>\n");
    for (i = 0; i < n; i++)
        fprintf(f, "<circle cx=\"%.1f\" cy=\"%.1f\" r=\"3\" fill=\"#1f5fd0\"/>\n",
                SX(B->levels.v[i]), SY(mean[i]));
    {
        static const double px[3] = {0.1, 1.5, 3.0}, py[3] = {0.013, 0.2, 0.4};
        for (i = 0; i < 3; i++)
            fprintf(f, "<rect x=\"%.1f\" y=\"%.1f\" width=\"8\" height=\"8\" fill=\"none\" "
                       "stroke=\"#d02020\" stroke-width=\"2\"/>\n",
                    SX(px[i]) - 4, SY(py[i]) - 4);
    }
    fprintf(f, "<circle cx=\"%.0f\" cy=\"%.0f\" r=\"3\" fill=\"#1f5fd0\"/>"
               "<text x=\"%.0f\" y=\"%.0f\">cdsp (this run)</text>\n"
               "<rect x=\"%.0f\" y=\"%.0f\" width=\"8\" height=\"8\" fill=\"none\" "
               "stroke=\"#d02020\" stroke-width=\"2\"/>"
               "<text x=\"%.0f\" y=\"%.0f\">paper (Yao et al. 2024)</text>\n</svg>\n",
            L + 20, T + 14, L + 30, T + 18, L + 16, T + 30, L + 30, T + 38);
#undef SX
#undef SY
    (void)b[2];
    (void)b[3];
    return close_file(f, path);
}

/* ---- the study ---------------------------------------------------------------- */

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

static const char bench_description[] =
    "    Repeats the accuracy study of the paper (Yao et al. 2024, section 4;\n"
    "    figures restated in docs/method.md) with libcdsp on simulated data\n"
    "    and prints each table beside the paper's figures:\n"
    "\n"
    "    1. Axis RMSE against Gaussian noise of 0..3 px added to the contour\n"
    "       points, --trials trials per level, for the paper's four pipes p1..p4\n"
    "       (see cdsp_tool sim --preset paper) and their mean. Contour points are\n"
    "       sampled evenly on the exact image contours of each 500 mm pipe, about\n"
    "       one per pixel of visible contour (--points per line at most), and\n"
    "       solved by the points path (RANSAC, total least squares, closed form);\n"
    "       the RANSAC inlier distance is max(1 px, 3 sigma). The metric is the\n"
    "       paper's (Eq. 17-21): RMSE of the distances of --samples points along\n"
    "       the reconstructed visible axis segment to the true axis.\n"
    "    2. Axis RMSE without noise when the radius assumed is off by +-0.02,\n"
    "       0.05 and 0.10 mm, beside the exact value (dr / r) x distance.\n"
    "    3. Time per reconstruction: the points path (what the paper timed), and\n"
    "       the whole frame path (subpixel edges, undistortion, RANSAC, closed\n"
    "       form) on rendered 2448 x 2048 8-bit frames of p1..p4, full search and\n"
    "       tracking, with the axis RMSE those frames give.\n"
    "\n"
    "    The paper's times were measured on an Intel i5-8250U; ours are this\n"
    "    machine's, one thread.\n\n";

static const char bench_after[] =
    "FILES\n"
    "    DIR/bench_noise.csv   noise_px, rmse_p1..rmse_p4, rmse_mean, failures,\n"
    "                          paper_rmse (empty where the paper gives none)\n"
    "    DIR/bench_radius.csv  dr_mm, rmse_p1..rmse_p4, rmse_mean, exact, paper_rmse\n"
    "    DIR/bench_time.csv    path, median_us, mean_us, runs, paper_us\n"
    "    DIR/bench_noise.svg   RMSE against noise, with the paper's figures\n"
    "\n"
    "EXAMPLES\n"
    "    cdsp_tool bench --out bench\n"
    "    cdsp_tool bench --levels 0,0.5,1 --trials 3 --no-frames\n";

static const char bench_exit[] =
    "    0  every reconstruction succeeded\n"
    "    1  some reconstruction failed (counted in the tables)\n"
    "    2  usage error or a file could not be written\n";

int tool_bench_main(int argc, char **argv)
{
    static const double default_levels[] = {0, 0.1, 0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75,
                                            2.0, 2.25, 2.5, 2.75, 3.0};
    static const double dr_list[6] = {-0.10, -0.05, -0.02, 0.02, 0.05, 0.10};
    static const double paper_dr[6] = {4.721, 2.361, 0.944, 0.944, 2.361, 4.721};
    bench_opts B;
    cdsp_camera cam;
    cdsp_params params;
    pipe_case *pc = NULL;
    cdsp_points_ws pws;
    cdsp_edge *noisy = NULL;
    double *mean_rmse = NULL, t_points = 0, mean_dist = 0;
    long n_points_runs = 0;
    char **pos, path[4200];
    int npos = 0, rc, i, k, failures_total = 0;
    const double r = 8.0;
    FILE *csv;
    static const tool_doc doc = {"bench", "the paper's accuracy study on simulated data",
                                 "[--out DIR] [OPTIONS]", bench_description, bench_after,
                                 bench_exit};
    memset(&B, 0, sizeof B);
    B.out = "cdsp_bench";
    B.trials = 10;
    B.points = 1000;
    B.samples = 100;
    B.frame_runs = 5;
    B.seed = 1;
    B.rack_frames = 2;
    B.rack_refine = 3;
    B.rack_noise = 2;
    B.levels.n = (int)(sizeof default_levels / sizeof default_levels[0]);
    memcpy(B.levels.v, default_levels, sizeof default_levels);
    {
        const tool_opt opts[] = {
            {"out", 'o', OPT_STR, &B.out, 0, 0, "DIR", "Where the CSV files and the plot go "
             "(created if missing).", NULL, 0},
            {"trials", 0, OPT_INT, &B.trials, 1, 10000, "N", "Trials per noise level.", NULL, 0},
            {"levels", 0, OPT_LIST, &B.levels, 0, 50, "S1,S2,...",
             "Noise levels, px (standard deviation per coordinate).", NULL, 0},
            {"points", 0, OPT_INT, &B.points, 20, CDSP_MAX_POINTS / 2, "N",
             "Contour points per line at most (about one per pixel of contour).", NULL, 0},
            {"samples", 0, OPT_INT, &B.samples, 2, 100000, "N",
             "Points along the reconstructed segment for the RMSE.", NULL, 0},
            {"frame-runs", 0, OPT_INT, &B.frame_runs, 1, 1000, "N",
             "Timed runs per rendered frame in table 3.", NULL, 0},
            {"no-frames", 0, OPT_FLAG, &B.no_frames, 0, 0, NULL,
             "Skip the rendered frames of table 3 (rendering takes a few seconds).", NULL, 0},
            {"seed", 0, OPT_U64, &B.seed, 0, 0, "S", "Seed of the noise and of RANSAC.", NULL, 0},
            {"quiet", 'q', OPT_FLAG, &B.quiet, 0, 0, NULL, "Print only the tables.", NULL, 0},
            {"rack", 0, OPT_FLAG, &B.rack, 0, 0, NULL,
             "Instead: the paper's real experiment rendered (its camera and lens, two "
             "16 mm pipes 100 mm apart on their support columns, two arrangements of five "
             "groups): the spacing RMSE per group and on average beside the paper's, with "
             "the edge-profile model off and on, the rack detection rate, and "
             "DIR/bench_rack.csv.", NULL, 0},
            {"rack-frames", 0, OPT_INT, &B.rack_frames, 1, 100, "N",
             "With --rack: frames per group (noise and position change).", NULL, 0},
            {"rack-refine-step", 0, OPT_INT, &B.rack_refine, 0, 64, "K",
             "With --rack: the solves' final pass (cdsp_params.refine_step, cdsp_tool solve "
             "--refine-step): every pipe's contours read again on every Kth scanline "
             "around them and refitted (K >= 3; 3 reads every pixel near them once); "
             "0: off, the search's every 4th scanline only.", NULL, 0},
            {"rack-point-fit", 0, OPT_FLAG, &B.rack_point_fit, 0, 0, NULL,
             "With --rack: the final pass's points refitted to their windows' pixels "
             "(cdsp_params.point_fit; needs --rack-refine-step >= 3).", NULL, 0},
            {"rack-noise", 0, OPT_REAL, &B.rack_noise, 0, 50, "G",
             "With --rack: the frames' sensor noise, gray levels (standard deviation). "
             "0 shows the systematic part of the spacing error alone.",
             NULL, 0},
            {NULL, 0, OPT_FLAG, NULL, 0, 0, NULL, NULL, NULL, 0},
        };
        rc = tool_parse_alloc("bench", &doc, opts, argc, argv, &pos, &npos);
        if (rc)
            return rc - 1;
    }
    rc = TOOL_EXIT_USAGE;
    if (npos > 0) {
        tool_usage_error("bench", "unexpected argument '%s' (see --help)", pos[0]);
        goto out;
    }
    if (tool_mkdir(B.out) != 0) {
        tool_usage_error("bench", "%s: cannot create the directory: %s", B.out, strerror(errno));
        goto out;
    }
    if (B.rack && B.rack_refine > 0 && B.rack_refine < 3) {
        tool_usage_error("bench", "--rack-refine-step must be 0 or at least 3 (see --help)");
        goto out;
    }
    if (B.rack) {
        rc = tool_bench_rack(B.out, B.rack_frames, B.rack_refine, B.rack_point_fit, B.rack_noise, B.seed,
                             B.quiet);
        goto out;
    }
    tool_paper_camera(&cam);
    pc = malloc(N_PIPES * sizeof *pc);
    noisy = malloc(CDSP_MAX_POINTS * sizeof *noisy);
    mean_rmse = calloc((size_t)B.levels.n, sizeof *mean_rmse);
    if (!pc || !noisy || !mean_rmse) {
        tool_usage_error("bench", "out of memory");
        goto out;
    }
    for (k = 0; k < N_PIPES; k++) {
        if (make_case(&cam, k, r, B.points, &pc[k]) != 0) {
            tool_usage_error("bench", "pipe p%d is not visible (internal error)", k + 1);
            goto out;
        }
        mean_dist += pc[k].dist / N_PIPES;
    }
    cdsp_params_default(&params);

    printf("cdsp_tool bench: the accuracy study of Yao et al. 2024 (docs/method.md), simulated\n"
           "camera %dx%d, fx = fy = %.2f px; pipes p1..p4, r = %g mm, 500 mm long, at\n"
           "%.1f / %.1f / %.1f / %.1f mm; visible contours %.0f / %.0f / %.0f / %.0f px long,\n"
           "%zu / %zu / %zu / %zu points per line (at most --points; the points path takes\n"
           "%d points in all). RMSE falls as 1 / sqrt(points per line): the paper's one\n"
           "point per pixel would give sqrt(points / length) times the figures below.\n\n",
           cam.width, cam.height, (double)cam.fx, r, pc[0].dist, pc[1].dist, pc[2].dist,
           pc[3].dist, pc[0].length_px, pc[1].length_px, pc[2].length_px, pc[3].length_px,
           pc[0].n / 2, pc[1].n / 2, pc[2].n / 2, pc[3].n / 2, CDSP_MAX_POINTS);

    /* ---- table 1 ---- */
    csv = open_csv(&B, "bench_noise.csv", path, sizeof path);
    if (!csv)
        goto out;
    fprintf(csv, "noise_px,rmse_p1,rmse_p2,rmse_p3,rmse_p4,rmse_mean,failures,paper_rmse\n");
    printf("Table 1. Axis RMSE (mm) against Gaussian noise on the contour points,\n"
           "         %d trials per level\n"
           "  noise px      p1        p2        p3        p4      mean   fails   paper\n",
           B.trials);
    for (i = 0; i < B.levels.n; i++) {
        double sigma = B.levels.v[i], rm[N_PIPES], paper = paper_noise(sigma);
        int fails = 0;
        params.pair.inlier_px = (cdsp_real)(3 * sigma > 1 ? 3 * sigma : 1);
        for (k = 0; k < N_PIPES; k++) {
            double sum = 0;
            int t, ok = 0;
            for (t = 0; t < B.trials; t++) {
                cdsp_rng noise, ransac;
                cdsp_result res;
                cdsp_status st;
                size_t p;
                double t0;
                /* stream per (level, pipe, trial): independent of the others */
                cdsp_rng_seed(&noise, B.seed, ((uint64_t)i * N_PIPES + (uint64_t)k) * 100000u +
                                                  (uint64_t)t);
                cdsp_rng_seed(&ransac, B.seed ^ 0x9e3779b97f4a7c15ull, (uint64_t)t);
                for (p = 0; p < pc[k].n; p++) {
                    noisy[p] = pc[k].pts[p];
                    noisy[p].x += (cdsp_real)sigma * cdsp_rng_normal(&noise);
                    noisy[p].y += (cdsp_real)sigma * cdsp_rng_normal(&noise);
                }
                t0 = tool_now_us();
                st = cdsp_points_solve(&cam, (cdsp_real)r, noisy, pc[k].n, &params, NULL, &pws,
                                       &ransac, &res);
                t_points += tool_now_us() - t0;
                n_points_runs++;
                if (st != CDSP_OK) {
                    fails++;
                    continue;
                }
                {
                    double e = axis_rmse(&res, &pc[k], B.samples);
                    sum += e * e;
                    ok++;
                }
            }
            rm[k] = ok ? sqrt(sum / ok) : NAN;
        }
        mean_rmse[i] = (rm[0] + rm[1] + rm[2] + rm[3]) / 4;
        failures_total += fails;
        printf("  %7.2f  %8.4f  %8.4f  %8.4f  %8.4f  %8.4f  %5d  ", sigma, rm[0], rm[1], rm[2],
               rm[3], mean_rmse[i], fails);
        if (paper > 0)
            printf("%s%.3f\n", fabs(sigma - 0.1) < 1e-9 ? " " : "~", paper);
        else
            printf("\n");
        fprintf(csv, "%g,%.6g,%.6g,%.6g,%.6g,%.6g,%d,", sigma, rm[0], rm[1], rm[2], rm[3],
                mean_rmse[i], fails);
        if (paper > 0)
            fprintf(csv, "%g", paper);
        fprintf(csv, "\n");
    }
    printf("  paper at 0.1 px: Doignon's conic method 0.057, Cheng's coupled point pairs "
           "0.033\n\n");
    if (close_file(csv, path) != 0)
        goto out;

    /* ---- table 2 ---- */
    csv = open_csv(&B, "bench_radius.csv", path, sizeof path);
    if (!csv)
        goto out;
    fprintf(csv, "dr_mm,rmse_p1,rmse_p2,rmse_p3,rmse_p4,rmse_mean,exact,paper_rmse\n");
    printf("Table 2. Axis RMSE (mm) with a wrong radius, no noise (exact: |dr| / r x mean\n"
           "         distance %.2f mm)\n"
           "    dr mm      p1        p2        p3        p4      mean     exact   paper\n",
           mean_dist);
    params.pair.inlier_px = 1;
    for (i = 0; i < 6; i++) {
        double rm[N_PIPES], m = 0, exact = fabs(dr_list[i]) / r * mean_dist;
        for (k = 0; k < N_PIPES; k++) {
            cdsp_rng ransac;
            cdsp_result res;
            cdsp_rng_seed(&ransac, B.seed, (uint64_t)k);
            if (cdsp_points_solve(&cam, (cdsp_real)(r + dr_list[i]), pc[k].pts, pc[k].n, &params,
                                  NULL, &pws, &ransac, &res) != CDSP_OK) {
                rm[k] = NAN;
                failures_total++;
            } else {
                rm[k] = axis_rmse(&res, &pc[k], B.samples);
            }
            m += rm[k] / N_PIPES;
        }
        printf("  %+7.2f  %8.4f  %8.4f  %8.4f  %8.4f  %8.4f  %8.4f  %6.3f\n", dr_list[i], rm[0],
               rm[1], rm[2], rm[3], m, exact, paper_dr[i]);
        fprintf(csv, "%g,%.6g,%.6g,%.6g,%.6g,%.6g,%.6g,%g\n", dr_list[i], rm[0], rm[1], rm[2],
                rm[3], m, exact, paper_dr[i]);
    }
    printf("\n");
    if (close_file(csv, path) != 0)
        goto out;

    /* ---- table 3 ---- */
    csv = open_csv(&B, "bench_time.csv", path, sizeof path);
    if (!csv)
        goto out;
    fprintf(csv, "path,median_us,mean_us,runs,paper_us\n");
    printf("Table 3. Time per reconstruction (this machine, one thread)\n");
    {
        char label[64];
        snprintf(label, sizeof label, "points path, 2 x %d points:", B.points);
        printf("  %-34s mean   %8.1f us   paper  998.4 us (simulation)\n", label,
               t_points / (double)n_points_runs);
    }
    fprintf(csv, "points,,%.1f,%ld,998.4\n", t_points / (double)n_points_runs, n_points_runs);
    if (!B.no_frames) {
        cdsp_scene scene;
        cdsp_host_image img;
        cdsp_host_err err;
        cdsp_frame_ws *ws = malloc(sizeof *ws);
        size_t scratch_len = cdsp_render_scratch_size(cam.width, cam.height);
        float *scratch = malloc(scratch_len * sizeof *scratch);
        double *full = malloc((size_t)(N_PIPES * B.frame_runs) * sizeof *full);
        double *track = malloc((size_t)(N_PIPES * B.frame_runs) * sizeof *track);
        double frame_rmse[N_PIPES];
        int nfull = 0, ntrack = 0;
        if (!ws || !scratch || !full || !track ||
            cdsp_host_image_alloc(&img, cam.width, cam.height, 8, &err) != 0) {
            free(ws);
            free(scratch);
            free(full);
            free(track);
            fclose(csv);
            tool_usage_error("bench", "out of memory");
            goto out;
        }
        cdsp_scene_default(&scene);
        params.pair.inlier_px = 1;
        for (k = 0; k < N_PIPES; k++) {
            cdsp_rng rng;
            cdsp_image view = cdsp_host_image_view(&img);
            cdsp_result res, prior;
            int run, have = 0;
            double dir[3];
            tool_paper_pipe(k, pc[k].A, dir, &pc[k].half);
            for (i = 0; i < 3; i++) {
                scene.axis_point[i] = (cdsp_real)pc[k].A[i];
                scene.axis_dir[i] = (cdsp_real)dir[i];
            }
            scene.radius = (cdsp_real)r;
            scene.half_length = (cdsp_real)pc[k].half;
            if (!B.quiet) {
                fprintf(stderr, "bench: rendering p%d (2448 x 2048)...\r", k + 1);
                fflush(stderr);
            }
            cdsp_rng_seed(&rng, B.seed, 1000u + (uint64_t)k);
            if (cdsp_render(&scene, &cam, img.data, img.stride, 8, scratch, scratch_len, &rng) !=
                CDSP_OK) {
                frame_rmse[k] = NAN;
                failures_total++;
                continue;
            }
            frame_rmse[k] = NAN;
            for (run = 0; run < B.frame_runs; run++) {
                double t0;
                cdsp_status st;
                cdsp_rng_seed(&rng, B.seed, (uint64_t)run);
                t0 = tool_now_us();
                st = cdsp_frame_solve(&view, &cam, (cdsp_real)r, &params, NULL, ws, &rng, &res);
                full[nfull++] = tool_now_us() - t0;
                if (st != CDSP_OK) {
                    failures_total++;
                    continue;
                }
                frame_rmse[k] = axis_rmse(&res, &pc[k], B.samples);
                prior = res;
                have = 1;
            }
            for (run = 0; have && run < B.frame_runs; run++) {
                double t0;
                cdsp_status st;
                cdsp_rng_seed(&rng, B.seed, (uint64_t)run);
                t0 = tool_now_us();
                st = cdsp_frame_solve(&view, &cam, (cdsp_real)r, &params, &prior, ws, &rng, &res);
                track[ntrack++] = tool_now_us() - t0;
                if (st != CDSP_OK)
                    failures_total++;
            }
        }
        if (!B.quiet)
            fprintf(stderr, "%40s\r", "");
        qsort(full, (size_t)nfull, sizeof *full, cmp_double);
        qsort(track, (size_t)ntrack, sizeof *track, cmp_double);
        if (nfull) {
            double mean = 0;
            for (i = 0; i < nfull; i++)
                mean += full[i] / nfull;
            printf("  %-34s median %8.1f us   paper 1917 us (real data)\n",
                   "frame path, full search:", full[nfull / 2]);
            fprintf(csv, "frame_full,%.1f,%.1f,%d,1917\n", full[nfull / 2], mean, nfull);
        }
        if (ntrack) {
            double mean = 0;
            for (i = 0; i < ntrack; i++)
                mean += track[i] / ntrack;
            printf("  %-34s median %8.1f us\n", "frame path, tracking:", track[ntrack / 2]);
            fprintf(csv, "frame_tracking,%.1f,%.1f,%d,\n", track[ntrack / 2], mean, ntrack);
        }
        printf("  axis RMSE on the rendered frames (mm): p1 %.4f  p2 %.4f  p3 %.4f  p4 %.4f\n",
               frame_rmse[0], frame_rmse[1], frame_rmse[2], frame_rmse[3]);
        printf("  paper: Doignon 2.451 s, Cheng 2.367 s per reconstruction\n");
        cdsp_host_image_free(&img);
        free(ws);
        free(scratch);
        free(full);
        free(track);
    }
    if (close_file(csv, path) != 0)
        goto out;
    if (write_svg(&B, mean_rmse, B.levels.n) != 0)
        goto out;
    if (!B.quiet)
        printf("\nwrote %s/bench_noise.csv, bench_radius.csv, bench_time.csv, bench_noise.svg\n",
               B.out);
    rc = failures_total ? TOOL_EXIT_PARTIAL : TOOL_EXIT_OK;
out:
    free(pc);
    free(noisy);
    free(mean_rmse);
    free(pos);
    return rc;
}
