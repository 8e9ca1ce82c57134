/* diag_paper.c - `make bench-paper-contours`: per pipe and per contour
 * figures of the paper's rendered scene (issue 12's bound), which
 * bench-accuracy gives only as means: the pose's error, sigma and bound
 * with the model off and on, and per contour the detector's line against
 * the exact silhouette (sup_contour_lines), the profile fitted along it
 * (cdsp__profile_refine, at the bound's 256 scanlines and the model's
 * 2048), the model's moved line and cdsp_profile_bound. argv[1]: how many
 * of the light rows (flat, default 0.85, 0.4, second 0.85, 0.4; default
 * 2); argv[2]: a path prefix to write each contour's 2048-row bins to
 * (u, mean, count; "-" for none); argv[3], argv[4]: an optical blur
 * (sigma, px) and a motion blur (px along the frame's x) in place of the
 * scene's, for the forward model under a blur wider than the detector's
 * window (issue 12). Figures, not pass/fail. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <math.h>
#include "support.h"
#include "internal.h"

static cdsp_frame_ws fws;

/* signed offset (px, + toward the pipe) of line l from truth t at the truth's
 * point nearest c */
static double line_off(const cdsp_real l[3], const double t[3], const double c[2])
{
    double d = t[0] * c[0] + t[1] * c[1] + t[2], f[2] = {c[0] - d * t[0], c[1] - d * t[1]};
    double s = (double)l[0] * f[0] + (double)l[1] * f[1] + (double)l[2];
    /* distance of the truth's point f from line l, sign: l's offset toward the pipe = -s * (l.n . t.n) */
    double dot = (double)l[0] * t[0] + (double)l[1] * t[1];
    return -s * (dot > 0 ? 1 : -1);
}

int main(int argc, char **argv)
{
    /* short names of sup_paper_lights' rows */
    static const char *names[SUP_PAPER_NLIGHTS] = {"flat", "dir 0.85", "dir 0.4", "2nd 0.85", "2nd 0.4"};
    int nrows = argc > 1 ? atoi(argv[1]) : 2, ri, i, k;
    const char *dump = argc > 2 && strcmp(argv[2], "-") != 0 ? argv[2] : NULL;
    double blur = argc > 3 ? atof(argv[3]) : -1, motion = argc > 4 ? atof(argv[4]) : 0;
    cdsp_camera cam;
    cdsp_rng rng;
    sup_paper_camera(&cam, 0, 0);
    cdsp_rng_seed(&rng, 3, 3);
    if (nrows > SUP_PAPER_NLIGHTS)
        nrows = SUP_PAPER_NLIGHTS;
    for (ri = 0; ri < nrows; ri++)
        for (i = 0; i < 4; i++) {
            cdsp_scene s;
            cdsp_image img;
            cdsp_result r[2];
            cdsp_params prm;
            double P[3], v[3], tl[2][3], pin[2];
            void *px;
            int en;
            sup_paper_light_scene(&s, i, ri, P, v);
            if (blur >= 0)
                s.blur_sigma_px = (cdsp_real)blur;
            s.motion_px[0] = (cdsp_real)motion;
            px = sup_render(&s, &cam, 8, (uint64_t)(50 + i), &img);
            sup_contour_lines(&cam, P, v, 8, tl, pin);
            for (en = 1; en >= 0; en--) {
                cdsp_status st;
                cdsp_params_default(&prm);
                prm.profile.enable = en;
                st = cdsp_frame_solve(&img, &cam, 8, &prm, NULL, &fws, &rng, &r[en]);
                if (st != CDSP_OK) {
                    printf("%s p%d en%d: status %d\n", names[ri], i + 1, en, st);
                    continue;
                }
                {
                    double dt = sup_true_distance(P, v), srmse, got[3], dir[3], seg[2][3];
                    sup_result_pose(&r[en], got, dir, seg);
                    srmse = sup_axis_rmse(seg[0], seg[1], P, v, 100);
                    printf("%s p%d model%d: rmse %.4f mm d_err %+.4f sig %.4f bound %.4f | edge_off %+.3f %+.3f bound %.4f %.4f\n",
                           names[ri], i + 1, en, srmse, (double)r[en].distance - dt, (double)r[en].sigma_distance,
                           (double)r[en].bound_distance, (double)r[en].edge_offset[0], (double)r[en].edge_offset[1],
                           (double)r[en].edge_bound[0], (double)r[en].edge_bound[1]);
                }
            }
            if (r[0].label[0]) {
                /* the detector's lines (model off: the set's lines stay the detector's) */
                for (k = 0; k < 2; k++) {
                    cdsp_line ln = fws.pairs.lines[r[0].label[k] - 1], cp;
                    double c[2] = {(double)ln.centroid[0], (double)ln.centroid[1]}, o[2], cpin[2];
                    int t, best = 0, rows_i;
                    cdsp_real prin[2];
                    for (t = 0; t < 2; t++)
                        o[t] = line_off(ln.l, tl[t], c);
                    best = fabs(o[1]) < fabs(o[0]);
                    cpin[0] = pin[0]; cpin[1] = pin[1];
                    prin[0] = (cdsp_real)cpin[0]; prin[1] = (cdsp_real)cpin[1];
                    for (rows_i = 0; rows_i < 2; rows_i++) {
                        cdsp_profile pr;
                        cdsp_profile_params pp;
                        cdsp_real moved = 0, sigma_moved = 0;
                        cdsp_status st;
                        cdsp_profile_params_default(&pp);
                        pp.enable = 1;
                        pp.max_rows = rows_i ? 2048 : 256;
                        cp = ln;
                        st = cdsp__profile_refine(&img, &cam, fws.edge, r[0].n_edges, fws.label, r[0].label[k], &cp, prin, &pp, 4, 0, &fws.profile, &pr, &moved, &sigma_moved);
                        printf("   c%d rows%-4d det_err %+.4f px | st %d off %+.4f so %.4f blur %.3f J %.1f chi2 %.4f flat %d shadow %.2f clamp %d hw %.2f applies %d -> moved err %+.4f bound %.4f\n",
                               k, pp.max_rows, o[best], st, (double)pr.offset, (double)pr.sigma_offset, (double)pr.blur, (double)pr.contrast,
                               (double)pr.fit_chi2, pr.flat, (double)pr.shadow, pr.blur_clamped, (double)pr.half_width,
                               cdsp_profile_applies(&pr, &pp, 4), o[best] + (double)moved,
                               (double)cdsp_profile_bound(st == CDSP_OK || st == CDSP_E_NOCONVERGE ? &pr : NULL, &pp, 4));
                        if (dump && rows_i == 1) {
                            char fn[256];
                            FILE *f;
                            int b;
                            snprintf(fn, sizeof fn, "%s_r%d_p%d_c%d.txt", dump, ri, i + 1, k);
                            f = fopen(fn, "w");
                            for (b = 0; b < CDSP_PROFILE_NBINS; b++)
                                if (fws.profile.count[b])
                                    fprintf(f, "%.4f %.4f %u\n", (double)fws.profile.mean_u[b], (double)fws.profile.mean_v[b], fws.profile.count[b]);
                            fclose(f);
                        }
                    }
                }
            }
            free(px);
        }
    return 0;
}
