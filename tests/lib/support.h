/*
 * support.h - shared helpers of the libcdsp tests and benchmarks: cameras,
 * poses, exact simulated points, and tolerances that follow the precision
 * the library was built with.
 */
#ifndef CDSP_TEST_SUPPORT_H
#define CDSP_TEST_SUPPORT_H

#include <stddef.h>
#include "cdsp.h"

/* Relative precision of the library build: the closed form loses a few
 * digits to cancellation in n1 x n2 when the pipe is far (alpha small), so
 * tolerances scale with eps / alpha. */
#ifdef CDSP_SINGLE
#define T_EPS 1.1920929e-7
#else
#define T_EPS 2.220446049250313e-16
#endif

#define SUP_PI 3.14159265358979323846

/* Exact contour lines of the infinite cylinder (point, dir, radius), computed
 * in double by the test itself (not by the library): undistorted px,
 * a^2 + b^2 = 1, (a, b) toward the pipe; p_in the image of an axis point in
 * front of the camera. Returns 0 when the camera is inside the pipe. */
int sup_contour_lines(const cdsp_camera *cam, const double point[3], const double dir[3],
                      double radius, double l[2][3], double p_in[2]);

/* The paper's simulated camera (docs/method.md): 2448 x 2048, 3.45 um pixels,
 * f = 12 mm -> fx = fy = 3478.26 px, principal point at the centre. */
void sup_paper_camera(cdsp_camera *cam, double k1, double k2);
/* A camera of any size with the same field of view ratio. */
void sup_camera(cdsp_camera *cam, int w, int h, double f, double k1, double k2);

/* The paper's four pipes (p1..p4) in camera coordinates: world frame with
 * the optical centre at (150, 200, 300) mm looking at the world origin.
 * i in 0..3; point and unit direction. Also the world->camera transform. */
void sup_paper_pipe(int i, double point[3], double dir[3]);
void sup_world_to_camera(const double Xw[3], double Xc[3]);

/* A random pipe in view: axis through a point at depth z in [zmin, zmax]
 * near the optical axis, direction random but not too close to the line of
 * sight. */
void sup_random_pipe(cdsp_rng *rng, double zmin, double zmax, double point[3], double dir[3]);

/* Distance from point X to the line (P, v). */
double sup_line_dist(const double P[3], const double v[3], const double X[3]);

/* RMSE (paper Eq. 17-21) of the reconstructed axis segment [a, b] against the
 * true axis (P, v), sampled at n points. */
double sup_axis_rmse(const double a[3], const double b[3], const double P[3], const double v[3],
                     int n);

/* Angle between two axis directions, radians, sign-insensitive. */
double sup_axis_angle(const double u[3], const double v[3]);

/* Sample per_line undistorted edge points on each contour of the pipe
 * (point, dir, radius): evenly over the part of the axial range [s0, s1]
 * (measured from `point` along dir) whose image lies inside the frame, with
 * Gaussian noise of sigma px perpendicular to the lines and gradients of
 * length `contrast` in the pipe-brighter convention. visible_px (may be
 * NULL) receives each contour's visible length in px. Returns the number
 * written (<= cap). */
size_t sup_contour_points(const cdsp_camera *cam, const double point[3], const double dir[3],
                          double radius, double s0, double s1, size_t per_line, double sigma,
                          double contrast, cdsp_rng *rng, cdsp_edge *out, size_t cap,
                          double visible_px[2]);

/* Convert a result's point/direction/segment to double arrays. */
void sup_result_pose(const cdsp_result *r, double point[3], double dir[3], double seg[2][3]);

/* Render a scene into a newly allocated 8- or 16-bit frame (test-side
 * malloc); returns NULL on failure. The image struct is filled. */
void *sup_render(const cdsp_scene *s, const cdsp_camera *cam, int bits, uint64_t seed,
                 cdsp_image *img);

/* A scene with the pipe (point, dir, radius) and the default look. */
void sup_scene(cdsp_scene *s, const double point[3], const double dir[3], double radius);
/* One pipe, or a rack of two 48 mm apart, of radius 8 at about 420 mm, the
 * axes (c[k], v) at roll_deg from the image's x axis, tilted 0.2 toward
 * the camera (test_rescan.c, test_pointfit.c); sup_row_scene: their flat-lit
 * untextured scene (sup_scene's defaults otherwise, half-length 400). */
void sup_row_pipes(int pipes, double roll_deg, double c[2][3], double v[3]);
void sup_row_scene(int pipes, const double c[2][3], const double v[3], cdsp_scene *s);
/* The result among out[0..n) whose axis is (c, v): direction within 2
 * degrees, P_C within tol_mm; -1 if none. */
int sup_find_axis(const cdsp_result *out, size_t n, const double c[3], const double v[3], double tol_mm);

/* Issue 12's paper scene (test_frame's bound test, test_multi's scatter
 * refusal): pipe i of the paper (radius 8 mm, half length 250 mm) at the
 * given ambient, noise 0.5 gray level; its axis in point, dir. */
void sup_paper_bound_scene(cdsp_scene *s, int i, double ambient, double point[3], double dir[3]);

/* The light rows of bench-accuracy's paper scene (bench_accuracy.c and
 * diag_paper.c render the same frames): flat (ambient 1), the renderer's
 * default light at ambient 0.85 and 0.4, a second light from the upper
 * left at 0.85 and 0.4. light NULL: the renderer's default direction. */
typedef struct {
    const char *name;
    double ambient;
    const double *light;
} sup_paper_light;
#define SUP_PAPER_NLIGHTS 5
extern const sup_paper_light sup_paper_lights[SUP_PAPER_NLIGHTS];

/* sup_paper_bound_scene under light row `row` of sup_paper_lights. */
void sup_paper_light_scene(cdsp_scene *s, int i, int row, double point[3], double dir[3]);

/* The exact distance (mm) from the optical centre to the axis through
 * point along the unit dir: |P - (P . v) v|, the figure cdsp_result's
 * distance estimates. */
double sup_true_distance(const double point[3], const double dir[3]);

/* Add a clutter bar (a cylinder between camera-frame points a and b, mm)
 * of half_width (mm) and level (0..1) to s; ignored when s is full. */
void sup_add_bar(cdsp_scene *s, const double a[3], const double b[3], double half_width, double level);

/* A straight limb of a shaded pipe as an exact small frame, for studies of
 * an edge's profile without the full renderer: the scene depends only on
 * the signed distance u from the silhouette (u > 0 on the pipe), so the
 * frame is that 1D scene convolved with the optical Gaussian, the motion
 * blur's box (its length times |cos| of its angle to the contour normal;
 * motion along the contour changes nothing on a straight edge) and the
 * pixel's footprint projected on the normal (boxes |n_x| and |n_y| wide),
 * computed on a 1/32 px grid and sampled at the pixel centres. The pipe
 * side is a Lambertian cylinder of radius radius_px seen side on: at the
 * angle phi from the limb (cos phi = 1 - u / radius_px) its normal is
 * cos(phi) n_out + sin(phi) v, so the shading is
 *   ambient + (1 - ambient) max(0, light_n cos(phi) + light_v sin(phi)),
 * plus an optional specular stripe (Gaussian in u); vignetting multiplies
 * by 1 - vignette (r / r_corner)^2. Levels in gray levels of the output;
 * values clamp to [0, 2^bits - 1] (a saturation plateau when above). */
typedef struct {
    int width, height, bits;
    double angle_deg;           /* contour direction from the v axis */
    double offset_px;           /* silhouette's distance from the frame centre along n */
    double radius_px;           /* limb curvature radius (the pipe's image radius) */
    double pipe, background;    /* albedo level of the pipe, background level */
    double ambient, light_n, light_v;
    double blur_px;             /* optical Gaussian sigma */
    double motion_px, motion_deg; /* box length; its angle to the contour normal */
    double spec_amp, spec_u, spec_width; /* specular stripe: amplitude, centre, sigma */
    double vignette;
    double noise;               /* Gaussian noise sigma, gray levels */
    uint64_t seed;
} sup_edge_spec;

/* Defaults: 128 x 128, 8 bit, vertical, flat (ambient 1), pipe 160 on 60,
 * radius 80 px, blur 0.7 px, no motion, stripe, vignetting or noise. */
void sup_edge_spec_default(sup_edge_spec *e);
/* Render into a newly allocated frame (NULL on failure); n_pipe receives
 * the unit normal toward the pipe and l the true silhouette line oriented
 * as cdsp_line (toward the brighter side at the silhouette). */
void *sup_edge_render(const sup_edge_spec *e, cdsp_image *img, double n_pipe[2], double l[3]);
/* Signed distance of pixel (x, y) from the silhouette, toward the pipe. */
double sup_edge_u(const sup_edge_spec *e, double x, double y);
/* The detector's line on a rendered limb frame as the frame path gets it:
 * the points (cdsp_edges_detect, min_contrast 0.03, step 2) within 10 px
 * of the silhouette (a 15 px blur moves them by ~3), trimmed as RANSAC
 * would (2 px, then inlier_px 1 px) and refitted. pts holds cap points;
 * *m receives the line's points (pts[0..m)). 0 when fewer than 20. */
int sup_edge_line(const sup_edge_spec *e, const cdsp_image *img, cdsp_edge *pts, size_t cap, size_t *m,
                  cdsp_line *ln);
/* The edge-profile model fitted along that line's extent (its inliers'
 * t_min..t_max), the pipe's middle radius_px from the silhouette's point
 * at the frame's centre along n_pipe (sup_edge_render's): as the frame
 * path calls it. */
cdsp_status sup_edge_profile(const sup_edge_spec *e, const cdsp_image *img, const cdsp_line *ln,
                             const double n_pipe[2], const cdsp_profile_params *pp, cdsp_profile_ws *ws,
                             cdsp_profile *pr);

/* Monotonic time in seconds. */
double sup_now(void);

#endif
