/*
 * tool_rack.c - `cdsp_tool bench --rack`: the paper's real experiment
 * (Yao et al. 2024, section 5; docs/method.md §9) rendered: a Daheng
 * MER-503-23GM-P (2448 x 2048, 3.45 um pixels) with a 16 mm lens
 * (fx = fy = 16 / 0.00345 = 4637.68 px), two pipes 16 mm in diameter and
 * 300 mm long with their axes 100 mm apart, lying on two support columns
 * 12.68 mm in diameter across them (behind them as the camera sees it),
 * directional light with 40 % ambient, the optical blur (0.8 px) and
 * sensor noise (2 gray levels) of a real camera, a faintly textured
 * background. Two arrangements, five groups (camera poses) each, both
 * pipes in every frame:
 *   A  side by side: the pipes' plane faces the camera, tilted 15..35
 *      degrees, 600..760 mm away;
 *   B  one behind the other: the plane holding both axes turned 50..70
 *      degrees toward the line of sight, so one pipe is 75..95 mm nearer.
 * Every frame is solved with cdsp_frame_solve_all; the spacing is the
 * paper's measure (Eq. 17-21): the distances d_n from points along one
 * reconstructed axis segment to the other axis, RMSE = sqrt(mean (100 -
 * d_n)^2) over every frame of a group (both directions, 100 points per
 * segment). Printed per group and on average beside the paper's 0.165
 * (its method on real frames), 0.180 (Cheng) and 0.314 (Doignon) mm, with
 * the edge-profile model (cdsp_params.profile.enable) off and on, the
 * noise floor (the RMSE the poses' own first-order sigmas predict, from
 * their cov_factor: what the edge points' noise alone would give), with
 * what the spacing is made of: each pipe's distance bias (a scale common
 * to both pipes moves the spacing by that fraction) and its direction
 * error (which tilts one axis against the other), and each pipe's two
 * contours' inlier counts and residual RMS (the noisier one, the shadowed
 * limb, apart: its line's tilt and offset noise set the direction and
 * distance noise); and the rack detection
 * rate: frames where both pipes were found (each within 2 degrees and 2 %
 * of its distance) and nothing else was reported.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"
#include "tool_rack_scene.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define RACK_SAMPLES 100

/* Which found pipe is true axis (c, v): direction within 2 degrees, P_C
 * within 2 % of its distance; -1 if none. */
static int rack_match(const cdsp_result *out, size_t n, const double c[3], const double v[3])
{
    double foot[3], t = c[0] * v[0] + c[1] * v[1] + c[2] * v[2], d;
    size_t k;
    int i;
    for (i = 0; i < 3; i++)
        foot[i] = c[i] - t * v[i];
    d = sqrt(foot[0] * foot[0] + foot[1] * foot[1] + foot[2] * foot[2]);
    for (k = 0; k < n; k++) {
        double dot = 0, e = 0;
        for (i = 0; i < 3; i++) {
            dot += (double)out[k].direction[i] * v[i];
            e += ((double)out[k].point[i] - foot[i]) * ((double)out[k].point[i] - foot[i]);
        }
        if (fabs(dot) > cos(2 * 3.14159265358979 / 180) && sqrt(e) < 0.02 * d)
            return (int)k;
    }
    return -1;
}

/* Distance from X to the axis (P, v) of r, v unit. */
static double axis_dist(const double P[3], const double v[3], const double X[3])
{
    double d[3], t = 0, e = 0;
    int i;
    for (i = 0; i < 3; i++)
        t += (X[i] - P[i]) * v[i];
    for (i = 0; i < 3; i++) {
        d[i] = X[i] - P[i] - t * v[i];
        e += d[i] * d[i];
    }
    return sqrt(e);
}

/* A pose's axis (P, v) moved by column k of its cov_factor (one standard
 * deviation of its k-th line parameter; k < 0: not moved), v unit. */
static void axis_moved(const cdsp_result *r, int k, double P[3], double v[3])
{
    double n = 0;
    int i;
    for (i = 0; i < 3; i++) {
        P[i] = (double)r->point[i] + (k >= 0 ? (double)r->cov_factor[i][k] : 0);
        v[i] = (double)r->direction[i] + (k >= 0 ? (double)r->cov_factor[3 + i][k] : 0);
        n += v[i] * v[i];
    }
    n = sqrt(n);
    for (i = 0; i < 3; i++)
        v[i] /= n;
}

/* The spacing's noise floor (the RMSE's square expected from the two
 * poses' own first-order sigmas, the random error of their edge points):
 * the distances d_n from RACK_SAMPLES points along from's segment to to's
 * axis, each pose moved in turn by each of its 4 independent one-sigma
 * line changes (cov_factor; the segment's points move with from's axis,
 * at their positions along it), mean over n of the sum over the 8 changes
 * of the change of d_n squared. */
static double spacing_floor2(const cdsp_result *from, const cdsp_result *to)
{
    double P[3], v[3], Q[3], w[3], sum = 0;
    int n, k, i;
    axis_moved(from, -1, P, v);
    axis_moved(to, -1, Q, w);
    for (n = 0; n < RACK_SAMPLES; n++) {
        double t = (n + 0.5) / RACK_SAMPLES, X[3], s = 0, d0;
        for (i = 0; i < 3; i++) {
            X[i] = (double)from->segment[0][i] + t * ((double)from->segment[1][i] - (double)from->segment[0][i]);
            s += (X[i] - P[i]) * v[i];
        }
        d0 = axis_dist(Q, w, X);
        for (k = 0; k < 8; k++) {
            double P2[3], v2[3], X2[3], d;
            if (k < 4) {
                axis_moved(from, k, P2, v2);
                for (i = 0; i < 3; i++)
                    X2[i] = P2[i] + s * v2[i];
                d = axis_dist(Q, w, X2);
            } else {
                axis_moved(to, k - 4, P2, v2);
                d = axis_dist(P2, v2, X);
            }
            sum += (d - d0) * (d - d0);
        }
    }
    return sum / RACK_SAMPLES;
}

int tool_bench_rack(const char *out_dir, int frames, int refine_step, int point_fit, double noise, uint64_t seed,
                    int quiet)
{
    static cdsp_frame_all_ws ws;
    cdsp_camera cam;
    size_t scratch_len = cdsp_render_scratch_size(RACK_W, RACK_H);
    float *scratch = malloc(scratch_len * sizeof *scratch);
    uint8_t *px = malloc((size_t)RACK_W * RACK_H);
    double sum2[2][2][RACK_GROUPS], total2[2] = {0, 0};
    /* the same from the poses' own sigmas: the noise floor */
    double floor2[2][2][RACK_GROUPS], ftotal2[2] = {0, 0};
    long count[2][2][RACK_GROUPS], found = 0, extra = 0, tries = 0, found_r = 0, extra_r = 0, gaps = 0;
    /* per pipe, model off / on: the distance bias (%) and the direction
     * error (mrad), what the spacing is made of */
    double bias2[2] = {0, 0}, bias_worst[2] = {0, 0}, dir2[2] = {0, 0};
    /* the same errors in units of the pose's own first-order sigma (the
     * random error of its edge points): near 1, the error is that noise */
    double zdist2[2] = {0, 0}, zdir2[2] = {0, 0};
    /* per pipe, model off / on: each contour's inliers and residual RMS,
     * the one with the larger RMS (the shadowed limb) [0] and the other [1] */
    double c_in[2][2] = {{0, 0}, {0, 0}}, c_rms2[2][2] = {{0, 0}, {0, 0}};
    long npipe[2] = {0, 0};
    int arr, g, f, prof, i;
    char path[4200];
    FILE *csv, *pcsv;
    if (!scratch || !px) {
        free(scratch);
        free(px);
        return tool_usage_error("bench", "out of memory for the rack frames");
    }
    memset(sum2, 0, sizeof sum2);
    memset(floor2, 0, sizeof floor2);
    memset(count, 0, sizeof count);
    tool_rack_camera(&cam);
    snprintf(path, sizeof path, "%s/bench_rack.csv", out_dir);
    csv = fopen(path, "w");
    if (!csv) {
        free(scratch);
        free(px);
        return tool_usage_error("bench", "%s: cannot create", path);
    }
    fprintf(csv, "arrangement,group,frame,profile,found,pipes,spacing_mean,spacing_rms_along,"
                 "spacing_rmse\n");
    snprintf(path, sizeof path, "%s/bench_rack_pipes.csv", out_dir);
    pcsv = fopen(path, "w");
    if (!pcsv) {
        fclose(csv);
        free(scratch);
        free(px);
        return tool_usage_error("bench", "%s: cannot create", path);
    }
    /* per pipe found: its errors in the frame of the line of sight u (to
     * the true foot point), the axis v and w = u x v (across the axis in
     * the image): the distance error (mm, along u), the lateral one (mm,
     * along w), the direction's turn toward u and toward w (mrad), and
     * its contours' inliers and residual RMS */
    fprintf(pcsv, "arrangement,group,frame,profile,pipe,distance_mm,err_u_mm,err_w_mm,dir_u_mrad,"
                  "dir_w_mrad,sigma_distance_mm,sigma_dir_mrad,inliers0,inliers1,rms0,rms1\n");
    if (!quiet)
        printf("\nThe paper's real experiment, rendered (--rack): %dx%d, fx = fy = %.2f px "
               "(3.45 um, 16 mm lens),\ntwo 16 mm pipes 300 mm long, axes %.0f mm apart, on "
               "two 12.68 mm columns; light 40 %% ambient,\nblur 0.8 px, noise %g gray levels; "
               "%d frames per group;\nrefine step %d (%s)%s; spacing RMSE (Eq. 17-21), mm.\n",
               RACK_W, RACK_H, RACK_F, RACK_SPACING, noise, frames, refine_step,
               refine_step == 3   ? "every pipe's contours refitted to every pixel near them"
               : refine_step > 0 ? "every pipe's contours refitted on every Kth scanline"
                                 : "off: the contours from the search's scanlines",
               point_fit && refine_step > 0 ? ", points refitted to their pixels" : "");
    for (arr = 0; arr < 2; arr++)
        for (g = 0; g < RACK_GROUPS; g++)
            for (f = 0; f < frames; f++) {
                cdsp_scene s;
                cdsp_rng rng;
                cdsp_image img;
                double c[2][3], v[3];
                tool_rack_frame(arr, g, f, &s, c, v);
                s.noise_sigma = (cdsp_real)(noise / 255); /* --rack-noise, 2 by default as the scene's */
                cdsp_rng_seed(&rng, seed, (uint64_t)(1000 * arr + 100 * g + f));
                if (cdsp_render(&s, &cam, px, 0, 8, scratch, scratch_len, &rng) != CDSP_OK) {
                    fclose(csv);
                    fclose(pcsv);
                    free(scratch);
                    free(px);
                    return tool_usage_error("bench", "rack frame cannot be rendered (internal error)");
                }
                img.data = px;
                img.width = RACK_W;
                img.height = RACK_H;
                img.stride = RACK_W;
                img.bits = 8;
                /* 0, 1: profile model off, on; 2: off, with the distance
                 * range of the pipes (x [0.8, 1.25]) for the detection rate */
                for (prof = 0; prof < 3; prof++) {
                    cdsp_params p;
                    cdsp_result out[CDSP_MAX_PIPES];
                    size_t n = 0;
                    int a, b, ok;
                    cdsp_params_default(&p);
                    p.profile.enable = prof == 1;
                    p.refine_step = refine_step;
                    p.point_fit = point_fit;
                    if (prof == 2) {
                        double d0 = sqrt(c[0][0] * c[0][0] + c[0][1] * c[0][1] + c[0][2] * c[0][2]);
                        double d1 = sqrt(c[1][0] * c[1][0] + c[1][1] * c[1][1] + c[1][2] * c[1][2]);
                        p.pair.min_distance = (cdsp_real)(0.8 * (d0 < d1 ? d0 : d1));
                        p.pair.max_distance = (cdsp_real)(1.25 * (d0 > d1 ? d0 : d1));
                    }
                    cdsp_rng_seed(&rng, seed, (uint64_t)(7 + 1000 * arr + 100 * g + f));
                    if (cdsp_frame_solve_all(&img, &cam, (cdsp_real)RACK_R, &p, NULL, &ws, &rng, out,
                                             CDSP_MAX_PIPES, &n) != CDSP_OK)
                        n = 0;
                    a = rack_match(out, n, c[0], v);
                    b = rack_match(out, n, c[1], v);
                    ok = a >= 0 && b >= 0 && a != b;
                    /* anything else parallel to the pipes is a gap taken
                     * for a pipe (the columns run across them) */
                    for (i = 0; i < (int)n; i++) {
                        double dot = 0;
                        int q;
                        for (q = 0; q < 3; q++)
                            dot += (double)out[i].direction[q] * v[q];
                        gaps += i != a && i != b && fabs(dot) > cos(2 * 3.14159265358979 / 180);
                    }
                    if (prof == 0) {
                        tries++;
                        found += ok;
                        extra += ok && n > 2;
                    }
                    if (prof == 2) {
                        found_r += ok;
                        extra_r += ok && n > 2;
                        continue;
                    }
                    if (!ok) {
                        fprintf(csv, "%c,%d,%d,%d,0,%zu,,,\n", 'A' + arr, g + 1, f, prof, n);
                        continue;
                    }
                    for (i = 0; i < 2; i++) {
                        const cdsp_result *o = &out[i ? b : a];
                        double t = c[i][0] * v[0] + c[i][1] * v[1] + c[i][2] * v[2], fo[3], dd, dot = 0, bias;
                        int q;
                        for (q = 0; q < 3; q++) {
                            fo[q] = c[i][q] - t * v[q];
                            dot += (double)o->direction[q] * v[q];
                        }
                        dd = sqrt(fo[0] * fo[0] + fo[1] * fo[1] + fo[2] * fo[2]);
                        bias = 100 * ((double)o->distance / dd - 1);
                        {
                            double u[3], w[3], eu = 0, ew = 0, du = 0, dw = 0, sg = (dot < 0 ? -1 : 1);
                            for (q = 0; q < 3; q++)
                                u[q] = fo[q] / dd;
                            w[0] = u[1] * v[2] - u[2] * v[1];
                            w[1] = u[2] * v[0] - u[0] * v[2];
                            w[2] = u[0] * v[1] - u[1] * v[0];
                            for (q = 0; q < 3; q++) {
                                double e = (double)o->point[q] - fo[q], dv = sg * (double)o->direction[q] - v[q];
                                eu += e * u[q];
                                ew += e * w[q];
                                du += dv * u[q];
                                dw += dv * w[q];
                            }
                            fprintf(pcsv, "%c,%d,%d,%d,%d,%.4f,%.5f,%.5f,%.4f,%.4f,%.5f,%.4f,%u,%u,%.4f,%.4f\n",
                                    'A' + arr, g + 1, f, prof, i, dd, eu, ew, 1e3 * du, 1e3 * dw,
                                    (double)o->sigma_distance,
                                    1e3 * sqrt((double)o->sigma_direction[0] * o->sigma_direction[0] +
                                               (double)o->sigma_direction[1] * o->sigma_direction[1] +
                                               (double)o->sigma_direction[2] * o->sigma_direction[2]),
                                    (unsigned)o->inliers[0], (unsigned)o->inliers[1], (double)o->rms[0],
                                    (double)o->rms[1]);
                        }
                        bias2[prof] += bias * bias;
                        if (fabs(bias) > fabs(bias_worst[prof]))
                            bias_worst[prof] = bias;
                        dot = fabs(dot) < 1 ? acos(fabs(dot)) * 1e3 : 0;
                        dir2[prof] += dot * dot;
                        {
                            double sd = 1e3 * sqrt((double)o->sigma_direction[0] * o->sigma_direction[0] +
                                                   (double)o->sigma_direction[1] * o->sigma_direction[1] +
                                                   (double)o->sigma_direction[2] * o->sigma_direction[2]);
                            double zd = ((double)o->distance - dd) / (double)o->sigma_distance;
                            zdir2[prof] += sd > 0 ? dot * dot / (sd * sd) : 0;
                            zdist2[prof] += isfinite(zd) ? zd * zd : 0;
                        }
                        {
                            int w = o->rms[1] > o->rms[0];
                            c_in[prof][0] += (double)o->inliers[w];
                            c_in[prof][1] += (double)o->inliers[!w];
                            c_rms2[prof][0] += (double)o->rms[w] * (double)o->rms[w];
                            c_rms2[prof][1] += (double)o->rms[!w] * (double)o->rms[!w];
                        }
                        npipe[prof]++;
                    }
                    for (i = 0; i < 2; i++) {
                        cdsp_real mean, spread;
                        double e2;
                        const cdsp_result *from = &out[i ? b : a], *to = &out[i ? a : b];
                        if (cdsp_result_axis_spacing(from, to, RACK_SAMPLES, &mean, &spread) != CDSP_OK)
                            continue;
                        /* mean over the segment of (100 - d_n)^2 = bias^2 + spread^2 */
                        e2 = ((double)mean - RACK_SPACING) * ((double)mean - RACK_SPACING) +
                             (double)spread * (double)spread;
                        sum2[prof][arr][g] += e2;
                        floor2[prof][arr][g] += spacing_floor2(from, to);
                        count[prof][arr][g]++;
                        if (i == 0)
                            fprintf(csv, "%c,%d,%d,%d,1,%zu,%.5f,%.5f,%.5f\n", 'A' + arr, g + 1, f,
                                    prof, n, (double)mean, (double)spread, sqrt(e2));
                    }
                }
            }
    fclose(csv);
    fclose(pcsv);
    /* floor: the RMSE the poses' own sigmas predict (spacing_floor2), with
     * the model off (the model's moves are not in the sigma) */
    printf("\n| group | model off | model on | floor  | paper (ours / Cheng / Doignon) |\n");
    printf("|-------|-----------|----------|--------|--------------------------------|\n");
    for (arr = 0; arr < 2; arr++)
        for (g = 0; g < RACK_GROUPS; g++) {
            double e[2], fl[2];
            for (prof = 0; prof < 2; prof++) {
                double c = (double)count[prof][arr][g];
                e[prof] = c > 0 ? sqrt(sum2[prof][arr][g] / c) : NAN;
                fl[prof] = c > 0 ? sqrt(floor2[prof][arr][g] / c) : NAN;
                total2[prof] += c > 0 ? sum2[prof][arr][g] / c : 0;
                ftotal2[prof] += c > 0 ? floor2[prof][arr][g] / c : 0;
            }
            printf("| %c%d    | %9.4f | %8.4f | %6.4f |                                |\n", 'A' + arr,
                   g + 1, e[0], e[1], fl[0]);
        }
    printf("| mean  | %9.4f | %8.4f | %6.4f | 0.165 / 0.180 / 0.314          |\n",
           sqrt(total2[0] / (2 * RACK_GROUPS)), sqrt(total2[1] / (2 * RACK_GROUPS)),
           sqrt(ftotal2[0] / (2 * RACK_GROUPS)));
    printf("floor: the RMSE the poses' own first-order sigmas predict, their edge points' noise alone "
           "(model off; on: %.4f)\n",
           sqrt(ftotal2[1] / (2 * RACK_GROUPS)));
    for (prof = 0; prof < 2; prof++)
        printf("model %s: each pipe's distance bias RMS %.4f %% (worst %+.4f %%, target <= 0.03 %%), "
               "direction error RMS %.3f mrad (%ld pipes)\n",
               prof ? "on " : "off", npipe[prof] ? sqrt(bias2[prof] / (double)npipe[prof]) : NAN, bias_worst[prof],
               npipe[prof] ? sqrt(dir2[prof] / (double)npipe[prof]) : NAN, npipe[prof]);
    for (prof = 0; prof < 2; prof++)
        printf("model %s: errors / their own sigma (RMS): distance %.2f, direction %.2f (near 1: the edge "
               "points' noise)\n",
               prof ? "on " : "off", npipe[prof] ? sqrt(zdist2[prof] / (double)npipe[prof]) : NAN,
               npipe[prof] ? sqrt(zdir2[prof] / (double)npipe[prof]) : NAN);
    for (prof = 0; prof < 2; prof++)
        if (npipe[prof])
            printf("model %s: contours: the noisier (the shadowed limb) %.0f inliers, residual RMS %.3f px; "
                   "the other %.0f, %.3f px (means over the pipes)\n",
                   prof ? "on " : "off", c_in[prof][0] / (double)npipe[prof],
                   sqrt(c_rms2[prof][0] / (double)npipe[prof]), c_in[prof][1] / (double)npipe[prof],
                   sqrt(c_rms2[prof][1] / (double)npipe[prof]));
    printf("target: <= 0.05 mm: model off %s, model on %s\n",
           sqrt(total2[0] / (2 * RACK_GROUPS)) <= 0.05 ? "met" : "NOT met",
           sqrt(total2[1] / (2 * RACK_GROUPS)) <= 0.05 ? "met" : "NOT met");
    printf("rack detection: both pipes found in %ld of %ld frames (%.1f %%), %ld of them with "
           "more pipes reported (the columns, solved as pipes of the wrong radius);\n"
           "  with the pipes' distance range (x [0.8, 1.25]): found in %ld, more reported in %ld;\n"
           "  a band parallel to the pipes reported besides them (a gap taken for a pipe), all "
           "solves: %ld\n",
           found, tries, 100.0 * (double)found / (double)(tries ? tries : 1), extra, found_r, extra_r,
           gaps);
    free(scratch);
    free(px);
    return TOOL_EXIT_OK;
}
