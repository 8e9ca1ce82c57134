/*
 * gen.c - writes the firmware tests' inputs as a C header: fixed edge-point
 * sets sampled on exact pipe contours and a small rendered frame, each with
 * its ground truth. Runs on the host against the double build of libcdsp
 * (cdsp_cylinder_contours gives the exact contour lines, cdsp_render the
 * frame), so the inputs come from the same geometry the library inverts.
 *
 *   gen OUT.h      exit 0 on success, 1 when a case cannot be built or the
 *                  file cannot be written (message names the case / file)
 *
 * Every real written is first rounded to float and printed with 9
 * significant digits, so the float and the double firmware read exactly the
 * same inputs (the literal converts without rounding in both precisions).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cdsp.h"

#define GEN_MAX_PTS 8192

typedef struct {
    const char *name;
    int cam;                  /* index into cams[] */
    double point[3], dir[3];  /* a point on the axis and its direction */
    double radius;
    double s0, s1;            /* visible stretch: axial parameters around point */
    int per_line;             /* points per contour (0: none on that contour) */
    int lines;                /* contours sampled: 2 = both, 1 = only the first */
    double sigma;             /* Gaussian noise across the contour, px */
    int outliers;             /* uniform clutter points with random gradients */
    const char *expect;       /* status token the library must return */
} gen_points_case;

/* Cameras: 0 = the paper's (2448 x 2048, f = 12 mm at 3.45 um), 1 = a VGA
 * module with a short lens, 2 = the small frame's camera. */
static const cdsp_camera cams[] = {
    {3478.26, 3478.26, 1223.5, 1023.5, -0.05, 0.01, 0, 0, 0, 2448, 2048},
    {520.0, 520.0, 319.5, 239.5, -0.12, 0.03, 0, 0, 0, 640, 480},
    {150.0, 150.0, 79.5, 59.5, -0.08, 0.0, 0, 0, 0, 160, 120},
};

static const gen_points_case pcases[] = {
    /* the budget case: 2048 points on a pipe 400 mm away, 0.1 px noise */
    {"paper-2048", 0, {20, -10, 400}, {0.2, 1, 0.1}, 8, -90, 90, 1024, 2, 0.1, 0, "ok"},
    /* far pipe: alpha ~ 0.008 rad, the closed form's hardest regime */
    {"far", 0, {-60, 40, 2000}, {1, 0.15, 0.3}, 8, -300, 300, 300, 2, 0.1, 0, "ok"},
    /* strongly inclined to the line of sight: the contours converge */
    {"oblique", 1, {10, 5, 250}, {0.3, 0.6, 0.75}, 10, -120, 60, 400, 2, 0.2, 0, "ok"},
    /* 30 % clutter: RANSAC must pick the contours out */
    {"clutter", 1, {-15, 20, 300}, {1, -0.3, 0.2}, 12, -110, 110, 350, 2, 0.3, 300, "ok"},
    /* too few points, and only one contour: the error paths */
    {"few", 1, {0, 0, 300}, {0, 1, 0}, 10, -50, 50, 1, 2, 0.0, 1, "few-points"},
    {"one-contour", 1, {0, 0, 300}, {0, 1, 0}, 10, -100, 100, 300, 1, 0.1, 0, "no-pipe"},
};

/* The frame: camera 2, a textured background, shading, blur and noise
 * (cdsp_scene_default), a pipe 150 mm away seen 16 px wide. The firmware
 * searches only the region of interest, then tracks from its own result. */
static const double frame_point[3] = {5, 0, 150}, frame_dir[3] = {0.25, 1, 0.15};
static const double frame_radius = 8;
static const cdsp_roi frame_roi = {16, 8, 128, 104};
/* Bound on the partial-area detector's contour placement error on this
 * frame (blur 0.7 px, texture 3 %, noise 0.4 %): the truth tolerance of the
 * frame cases is the pose change this shift of either contour causes.
 * Measured (compare.py's "truth err/tol"): with 0.5 px, 0.227 on every
 * target and both precisions, the error of a ~0.11 px shift of one
 * contour (51 inliers per line on a 16 px wide pipe: the background
 * texture and the shaded limb's bias, not averaged away); bound 0.25 px,
 * 2.2x that. */
static const double frame_contour_err_px = 0.25;

static double round_f(double x)
{
    return (double)(float)x;
}

/* P_C (foot of the perpendicular from the optical centre) and the unit
 * direction with its largest-magnitude component positive (cdsp.h). */
static void truth_pose(const double p[3], const double d[3], double pc[3], double v[3])
{
    double n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), t;
    int i, big = 0;
    for (i = 0; i < 3; i++)
        v[i] = d[i] / n;
    for (i = 1; i < 3; i++)
        if (fabs(v[i]) > fabs(v[big]))
            big = i;
    if (v[big] < 0)
        for (i = 0; i < 3; i++)
            v[i] = -v[i];
    t = p[0] * v[0] + p[1] * v[1] + p[2] * v[2];
    for (i = 0; i < 3; i++)
        pc[i] = p[i] - t * v[i];
}

/* Undistorted pixel of a camera-frame point (pinhole only: points-path
 * inputs are undistorted). */
static void project(const cdsp_camera *c, const double X[3], double px[2])
{
    px[0] = c->fx * X[0] / X[2] + c->cx;
    px[1] = c->fy * X[1] / X[2] + c->cy;
}

static int sample_case(const gen_points_case *g, cdsp_rng *rng, cdsp_edge *out, size_t cap,
                       size_t *n)
{
    const cdsp_camera *cam = &cams[g->cam];
    cdsp_real P[3], V[3], l[2][3], pin[2];
    double a0[3], a1[3], q0[2], q1[2];
    int i, k;
    size_t m = 0;
    for (i = 0; i < 3; i++) {
        P[i] = g->point[i];
        V[i] = g->dir[i];
        a0[i] = g->point[i] + g->s0 * g->dir[i];
        a1[i] = g->point[i] + g->s1 * g->dir[i];
    }
    if (cdsp_cylinder_contours(cam, P, V, g->radius, 1, l[0], l[1], pin) != CDSP_OK ||
        a0[2] <= 0 || a1[2] <= 0)
        return 0;
    project(cam, a0, q0);
    project(cam, a1, q1);
    for (k = 0; k < g->lines; k++) {
        /* the stretch of contour k between the feet of the two projected
         * axis end points, sampled evenly with noise across the line */
        double a = l[k][0], b = l[k][1], c = l[k][2], dx = -b, dy = a;
        double f0 = a * q0[0] + b * q0[1] + c, f1 = a * q1[0] + b * q1[1] + c;
        double u0 = q0[0] - f0 * a, v0 = q0[1] - f0 * b;
        double t1 = (q1[0] - f1 * a - u0) * dx + (q1[1] - f1 * b - v0) * dy;
        for (i = 0; i < g->per_line; i++) {
            double t = g->per_line > 1 ? t1 * i / (g->per_line - 1) : 0.5 * t1;
            double nz = g->sigma * cdsp_rng_normal(rng);
            double x = u0 + t * dx + nz * a, y = v0 + t * dy + nz * b;
            if (m == cap || x < 0 || y < 0 || x > cam->width - 1 || y > cam->height - 1)
                return 0;
            out[m].x = round_f(x);
            out[m].y = round_f(y);
            out[m].gx = round_f(120 * a); /* gradient toward the bright pipe */
            out[m].gy = round_f(120 * b);
            m++;
        }
    }
    for (i = 0; i < g->outliers && m < cap; i++) {
        double ang = 2 * 3.14159265358979323846 * cdsp_rng_uniform(rng);
        out[m].x = round_f((cam->width - 1) * cdsp_rng_uniform(rng));
        out[m].y = round_f((cam->height - 1) * cdsp_rng_uniform(rng));
        out[m].gx = round_f(120 * cos(ang));
        out[m].gy = round_f(120 * sin(ang));
        m++;
    }
    /* shuffle (Fisher-Yates): contours and clutter arrive interleaved */
    for (i = (int)m - 1; i > 0; i--) {
        uint32_t j = cdsp_rng_below(rng, (uint32_t)i + 1);
        cdsp_edge tmp = out[i];
        out[i] = out[j];
        out[j] = tmp;
    }
    *n = m;
    return 1;
}

static void put_real3(FILE *f, const double v[3])
{
    fprintf(f, "{%.17g, %.17g, %.17g}", v[0], v[1], v[2]);
}

static void put_camera(FILE *f, const cdsp_camera *c)
{
    fprintf(f, "{%.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %.9g, %d, %d}",
            round_f(c->fx), round_f(c->fy), round_f(c->cx), round_f(c->cy), round_f(c->k1),
            round_f(c->k2), round_f(c->p1), round_f(c->p2), round_f(c->k3), c->width, c->height);
}

/* Largest pose change (point, distance; direction angle) when either exact
 * contour moves by +-err px: how far a detector error of err px can carry
 * the frame result from the truth. */
static int frame_sensitivity(const cdsp_camera *cam, double err, double *dpoint, double *dangle)
{
    cdsp_real P[3], V[3], l[2][3], pin[2];
    cdsp_result r0, r;
    int i, k, s;
    for (i = 0; i < 3; i++) {
        P[i] = frame_point[i];
        V[i] = frame_dir[i];
    }
    if (cdsp_cylinder_contours(cam, P, V, frame_radius, 1, l[0], l[1], pin) != CDSP_OK ||
        cdsp_axis_solve(cam, l[0], l[1], pin, frame_radius, &r0) != CDSP_OK)
        return 0;
    *dpoint = *dangle = 0;
    for (k = 0; k < 2; k++)
        for (s = -1; s <= 1; s += 2) {
            cdsp_real lm[2][3];
            double dp = 0, c;
            memcpy(lm, l, sizeof lm);
            lm[k][2] += s * err;
            if (cdsp_axis_solve(cam, lm[0], lm[1], pin, frame_radius, &r) != CDSP_OK)
                return 0;
            for (i = 0; i < 3; i++)
                dp += (r.point[i] - r0.point[i]) * (r.point[i] - r0.point[i]);
            c = fabs(r.direction[0] * r0.direction[0] + r.direction[1] * r0.direction[1] +
                     r.direction[2] * r0.direction[2]);
            if (sqrt(dp) > *dpoint)
                *dpoint = sqrt(dp);
            if (acos(c > 1 ? 1 : c) > *dangle)
                *dangle = acos(c > 1 ? 1 : c);
        }
    return 1;
}

static int write_frame(FILE *f)
{
    const cdsp_camera *cam = &cams[2];
    cdsp_camera camf;
    cdsp_scene s;
    cdsp_rng rng;
    size_t nscr = cdsp_render_scratch_size(cam->width, cam->height), i;
    size_t npx = (size_t)cam->width * (size_t)cam->height;
    unsigned char *img = malloc(npx);
    float *scr = malloc(nscr * sizeof *scr);
    double pc[3], v[3], dpoint, dangle;
    int ok;
    /* render with the camera exactly as the firmware will read it */
    camf = *cam;
    camf.fx = round_f(cam->fx);
    camf.fy = round_f(cam->fy);
    camf.cx = round_f(cam->cx);
    camf.cy = round_f(cam->cy);
    camf.k1 = round_f(cam->k1);
    camf.k2 = round_f(cam->k2);
    cdsp_scene_default(&s);
    for (i = 0; i < 3; i++) {
        s.axis_point[i] = frame_point[i];
        s.axis_dir[i] = frame_dir[i];
    }
    s.radius = frame_radius;
    cdsp_rng_seed(&rng, 2024, 6);
    ok = img && scr &&
         cdsp_render(&s, &camf, img, 0, 8, scr, nscr, &rng) == CDSP_OK &&
         frame_sensitivity(&camf, frame_contour_err_px, &dpoint, &dangle);
    if (ok) {
        truth_pose(frame_point, frame_dir, pc, v);
        fprintf(f, "\n/* frame: %dx%d 8-bit, rendered by cdsp_render (seed 2024) */\n",
                cam->width, cam->height);
        fprintf(f, "static const cdsp_camera mcu_frame_cam = ");
        put_camera(f, &camf);
        fprintf(f, ";\nstatic const double mcu_frame_radius = %.17g;\n", frame_radius);
        fprintf(f, "static const cdsp_roi mcu_frame_roi = {%d, %d, %d, %d};\n", frame_roi.x,
                frame_roi.y, frame_roi.w, frame_roi.h);
        fprintf(f, "static const double mcu_frame_truth_point[3] = ");
        put_real3(f, pc);
        fprintf(f, ";\nstatic const double mcu_frame_truth_dir[3] = ");
        put_real3(f, v);
        fprintf(f, ";\n/* pose change for a %.2g px contour error: point (mm), direction (rad) */\n",
                frame_contour_err_px);
        fprintf(f, "static const double mcu_frame_tol_point = %.17g;\n", dpoint);
        fprintf(f, "static const double mcu_frame_tol_angle = %.17g;\n", dangle);
        fprintf(f, "static const unsigned char mcu_frame[%lu] = {", (unsigned long)npx);
        for (i = 0; i < npx; i++)
            fprintf(f, "%s%u,", i % 24 ? "" : "\n    ", img[i]);
        fprintf(f, "\n};\n");
    }
    free(img);
    free(scr);
    return ok;
}

int main(int argc, char **argv)
{
    static cdsp_edge pts[GEN_MAX_PTS];
    size_t first[sizeof pcases / sizeof pcases[0]], count[sizeof pcases / sizeof pcases[0]];
    size_t total = 0, i, j;
    const size_t ncases = sizeof pcases / sizeof pcases[0];
    cdsp_rng rng;
    FILE *f;
    if (argc != 2) {
        fprintf(stderr, "usage: gen OUT.h\n");
        return 1;
    }
    cdsp_rng_seed(&rng, 6, 1);
    for (i = 0; i < ncases; i++) {
        first[i] = total;
        if (!sample_case(&pcases[i], &rng, pts + total, GEN_MAX_PTS - total, &count[i])) {
            fprintf(stderr, "gen: case %s: contour outside the image or too many points\n",
                    pcases[i].name);
            return 1;
        }
        total += count[i];
    }
    f = fopen(argv[1], "w");
    if (!f) {
        fprintf(stderr, "gen: cannot write %s\n", argv[1]);
        return 1;
    }
    fprintf(f, "/* %s: generated by tests/mcu/gen.c; do not edit, do not commit. */\n",
            argv[1]);
    fprintf(f, "static const cdsp_camera mcu_cams[%lu] = {\n", (unsigned long)(sizeof cams /
                                                                           sizeof cams[0]));
    for (i = 0; i < sizeof cams / sizeof cams[0]; i++) {
        fprintf(f, "    ");
        put_camera(f, &cams[i]);
        fprintf(f, ",\n");
    }
    fprintf(f, "};\n\nstatic const mcu_points_case mcu_points_cases[%lu] = {\n",
            (unsigned long)ncases);
    for (i = 0; i < ncases; i++) {
        double pc[3], v[3];
        truth_pose(pcases[i].point, pcases[i].dir, pc, v);
        fprintf(f, "    {\"%s\", %d, %.17g, %lu, %lu, \"%s\", ", pcases[i].name, pcases[i].cam,
                pcases[i].radius, (unsigned long)first[i], (unsigned long)count[i],
                pcases[i].expect);
        put_real3(f, pc);
        fprintf(f, ", ");
        put_real3(f, v);
        fprintf(f, "},\n");
    }
    fprintf(f, "};\n\nstatic const cdsp_edge mcu_points[%lu] = {\n", (unsigned long)total);
    for (j = 0; j < total; j++)
        fprintf(f, "    {%.9g, %.9g, %.9g, %.9g},\n", (double)pts[j].x, (double)pts[j].y,
                (double)pts[j].gx, (double)pts[j].gy);
    fprintf(f, "};\n");
    if (!write_frame(f)) {
        fprintf(stderr, "gen: cannot render the frame case\n");
        fclose(f);
        remove(argv[1]);
        return 1;
    }
    if (fclose(f) != 0) {
        fprintf(stderr, "gen: error writing %s\n", argv[1]);
        remove(argv[1]);
        return 1;
    }
    return 0;
}
