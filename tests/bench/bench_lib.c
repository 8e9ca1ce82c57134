/*
 * bench_lib.c - `make bench`: the library's speed and accuracy figures on
 * this machine, single core, as a table beside the targets of issue 2 and
 * the paper's figures (docs/method.md). Times are medians (and p99) of repeated
 * runs; accuracy is the paper's RMSE metric (Eq. 17-21) in mm.
 * Compare figures within one run; the machine is shared.
 */
#define _POSIX_C_SOURCE 199309L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include "support.h"

static cdsp_frame_ws ws;
static cdsp_points_ws pws;
static cdsp_edge pts[CDSP_MAX_POINTS];

static int cmp_d(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double pct(double *v, int n, double p)
{
    int i = (int)(p * (n - 1) + 0.5);
    qsort(v, (size_t)n, sizeof *v, cmp_d);
    return v[i];
}

static void row(const char *what, const char *value, const char *target, int met)
{
    printf("| %-46s | %-22s | %-16s | %-6s |\n", what, value, target, met < 0 ? "" : met ? "met" : "MISSED");
}

int main(int argc, char **argv)
{
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_rng rng;
    char buf[64];
    int frames = argc > 1 ? atoi(argv[1]) : 8;
    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    cdsp_rng_seed(&rng, 1, 1);

    printf("libcdsp %d.%d.%d, %s precision, paper camera 2448 x 2048, f = 3478.26 px\n\n",
           CDSP_VERSION_MAJOR, CDSP_VERSION_MINOR, CDSP_VERSION_PATCH,
#ifdef CDSP_SINGLE
           "single"
#else
           "double"
#endif
    );
    printf("| %-46s | %-22s | %-16s | %-6s |\n", "figure", "this machine", "target", "");
    printf("|%s|%s|%s|%s|\n", "------------------------------------------------", "------------------------",
           "------------------", "--------");

    /* 1. closed form from two lines */
    {
        double l[4][2][3], pin[4][2], t[21];
        cdsp_real L[4][2][3], PI[4][2];
        cdsp_result r;
        int i, k, j, rep, reps = 200000;
        volatile cdsp_real sink = 0;
        for (i = 0; i < 4; i++) {
            double P[3], v[3];
            sup_paper_pipe(i, P, v);
            sup_contour_lines(&cam, P, v, 8, l[i], pin[i]);
            for (k = 0; k < 2; k++) {
                for (j = 0; j < 3; j++)
                    L[i][k][j] = (cdsp_real)l[i][k][j];
                PI[i][k] = (cdsp_real)pin[i][k];
            }
        }
        for (rep = 0; rep < 21; rep++) {
            double t0 = sup_now();
            for (i = 0; i < reps; i++) {
                cdsp_axis_solve(&cam, L[i & 3][0], L[i & 3][1], PI[i & 3], 8, &r);
                sink += r.distance;
            }
            t[rep] = (sup_now() - t0) / reps * 1e9;
        }
        (void)sink;
        snprintf(buf, sizeof buf, "%.0f ns", pct(t, 21, 0.5));
        row("solve from two lines", buf, "< 1000 ns", pct(t, 21, 0.5) < 1000);
    }
    /* 2. points -> pose, 2000 points (0.1 px noise, the paper's pipes) */
    {
        double t[400];
        int i, n = 400;
        for (i = 0; i < n; i++) {
            double P[3], v[3], t0;
            cdsp_result r;
            size_t m;
            sup_paper_pipe(i & 3, P, v);
            m = sup_contour_points(&cam, P, v, 8, -250, 250, 1000, 0.1, 100, &rng, pts, CDSP_MAX_POINTS, NULL);
            t0 = sup_now();
            cdsp_points_solve(&cam, 8, pts, m, &prm, NULL, &pws, &rng, &r);
            t[i] = (sup_now() - t0) * 1e6;
        }
        {
            double med = pct(t, n, 0.5), p99 = pct(t, n, 0.99);
            snprintf(buf, sizeof buf, "%.1f us (p99 %.1f)", med, p99);
            row("points -> pose, 2000 points", buf, "< 50 us", med < 50);
        }
    }
    /* 3. frames -> pose at 2448 x 2048: a moving sequence, full and tracked */
    {
        double *tf = malloc(sizeof(double) * (size_t)frames * 5), *tt = malloc(sizeof(double) * (size_t)frames * 5);
        /* the same frames with the edge-profile model on (issue 12), interleaved */
        double *pf = malloc(sizeof(double) * (size_t)frames * 5), *pt = malloc(sizeof(double) * (size_t)frames * 5);
        int i, k, nf = 0, nt = 0, npf = 0, npt = 0;
        cdsp_result prev, pprev;
        int have = 0, phave = 0;
        cdsp_params pprm = prm;
        pprm.profile.enable = 1;
        fprintf(stderr, "rendering %d frames at 2448 x 2048...\n", frames);
        for (i = 0; i < frames; i++) {
            cdsp_scene s;
            cdsp_image img;
            double P[3], v[3];
            void *px;
            /* pipe p1 drifting and turning slowly, as seen from a moving drone */
            sup_paper_pipe(0, P, v);
            P[0] += 0.8 * i;
            P[1] -= 0.5 * i;
            v[1] += 0.004 * i;
            sup_scene(&s, P, v, 8);
            s.half_length = 250;
            s.noise_sigma = (cdsp_real)0.002;
            px = sup_render(&s, &cam, 8, (uint64_t)i, &img);
            for (k = 0; k < 5; k++) {
                cdsp_result r;
                double t0 = sup_now();
                cdsp_status st = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r);
                tf[nf++] = (sup_now() - t0) * 1e3;
                if (st == CDSP_OK && have) {
                    cdsp_result r2;
                    t0 = sup_now();
                    cdsp_frame_solve(&img, &cam, 8, &prm, &prev, &ws, &rng, &r2);
                    tt[nt++] = (sup_now() - t0) * 1e3;
                }
                if (st == CDSP_OK && k == 4) {
                    prev = r;
                    have = 1;
                }
                t0 = sup_now();
                st = cdsp_frame_solve(&img, &cam, 8, &pprm, NULL, &ws, &rng, &r);
                pf[npf++] = (sup_now() - t0) * 1e3;
                if (st == CDSP_OK && phave) {
                    cdsp_result r2;
                    t0 = sup_now();
                    cdsp_frame_solve(&img, &cam, 8, &pprm, &pprev, &ws, &rng, &r2);
                    pt[npt++] = (sup_now() - t0) * 1e3;
                }
                if (st == CDSP_OK && k == 4) {
                    pprev = r;
                    phave = 1;
                }
            }
            free(px);
        }
        {
            double m = pct(tf, nf, 0.5), p = pct(tf, nf, 0.99);
            snprintf(buf, sizeof buf, "%.2f ms (p99 %.2f)", m, p);
            row("frame -> pose 2448x2048, full search", buf, "< 3 ms", m < 3);
        }
        if (nt) {
            double m = pct(tt, nt, 0.5), p = pct(tt, nt, 0.99);
            snprintf(buf, sizeof buf, "%.3f ms (p99 %.3f)", m, p);
            row("frame -> pose 2448x2048, tracked", buf, "< 0.5 ms", m < 0.5);
        }
        if (npf) {
            double m = pct(pf, npf, 0.5), p = pct(pf, npf, 0.99), base = pct(tf, nf, 0.5);
            snprintf(buf, sizeof buf, "%.2f ms (p99 %.2f)", m, p);
            row("  same, edge-profile model on", buf, "<= 1.2 x off", m <= 1.2 * base);
        }
        if (npt && nt) {
            double m = pct(pt, npt, 0.5), p = pct(pt, npt, 0.99), base = pct(tt, nt, 0.5);
            snprintf(buf, sizeof buf, "%.3f ms (p99 %.3f)", m, p);
            row("  tracked, edge-profile model on", buf, "<= 1.2 x off", m <= 1.2 * base);
        }
        free(tf);
        free(tt);
        free(pf);
        free(pt);
    }
    /* 4. accuracy, point level: the paper's simulation (0.1 px, its four
     * pipes, 25 trials each) with 1000 points per contour over the visible
     * part, and scaled to the paper's one point per pixel of contour (RMSE
     * ~ 1/sqrt(points); CDSP_MAX_POINTS = 2048 holds 1024 per contour) */
    {
        double sum = 0, scaled = 0;
        int i, n = 100;
        for (i = 0; i < n; i++) {
            double P[3], v[3], got[3], dir[3], seg[2][3], vis[2], e;
            cdsp_result r;
            size_t m;
            sup_paper_pipe(i & 3, P, v);
            m = sup_contour_points(&cam, P, v, 8, -250, 250, 1000, 0.1, 100, &rng, pts,
                                   CDSP_MAX_POINTS, vis);
            if (cdsp_points_solve(&cam, 8, pts, m, &prm, NULL, &pws, &rng, &r) != CDSP_OK) {
                sum += 1e9;
                continue;
            }
            sup_result_pose(&r, got, dir, seg);
            e = sup_axis_rmse(seg[0], seg[1], P, v, 100);
            sum += e;
            scaled += e * sqrt(1000.0 / ((vis[0] + vis[1]) / 2));
        }
        snprintf(buf, sizeof buf, "%.4f mm", sum / n);
        row("RMSE, 0.1 px noise, 1000 points per contour", buf, "", -1);
        snprintf(buf, sizeof buf, "%.4f mm", scaled / n);
        row("  same, scaled to 1 point per px of contour", buf, "<= 0.013 mm", scaled / n <= 0.013);
    }
    /* 5. accuracy on rendered frames of the paper's scene (0.5 gray level of
     * noise, 8 bit, blur 0.7 px), diffuse and directional light */
    {
        int light;
        for (light = 0; light < 2; light++) {
            double sum = 0;
            int i, n = 4, ok = 0;
            for (i = 0; i < n; i++) {
                cdsp_scene s;
                cdsp_image img;
                cdsp_result r;
                double P[3], v[3], got[3], dir[3], seg[2][3];
                void *px;
                sup_paper_pipe(i, P, v);
                sup_scene(&s, P, v, 8);
                s.half_length = 250;
                s.noise_sigma = (cdsp_real)0.002;
                s.ambient = light ? (cdsp_real)0.85 : 1;
                px = sup_render(&s, &cam, 8, (uint64_t)(50 + i), &img);
                if (cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &ws, &rng, &r) == CDSP_OK) {
                    sup_result_pose(&r, got, dir, seg);
                    sum += sup_axis_rmse(seg[0], seg[1], P, v, 100);
                    ok++;
                }
                free(px);
            }
            snprintf(buf, sizeof buf, "%.4f mm (%d/%d found)", ok ? sum / ok : NAN, ok, n);
            row(light ? "RMSE, rendered frames, directional light" : "RMSE, rendered frames, diffuse light", buf,
                "< 0.03 mm", ok == n && sum / ok < 0.03);
        }
    }
    printf("\nworkspace: cdsp_frame_ws %zu bytes (CDSP_MAX_EDGES %d), cdsp_points_ws %zu bytes "
           "(CDSP_MAX_POINTS %d), cdsp_result %zu bytes\n",
           sizeof(cdsp_frame_ws), CDSP_MAX_EDGES, sizeof(cdsp_points_ws), CDSP_MAX_POINTS,
           sizeof(cdsp_result));
    return 0;
}
