/*
 * cdsp.h - the public contract of libcdsp.
 *
 * libcdsp recovers the 3D axis of a constant-diameter straight pipe from one
 * camera frame and the pipe's known radius (Yao et al. 2024, "Rapid 3D
 * reconstruction of constant-diameter straight pipelines via single-view
 * perspective projection"; equations restated in docs/method.md).
 *
 * Where a frame enters and a pose leaves:
 *
 *   frame (cdsp_image) --cdsp_edges_detect--> edge points (distorted px)
 *     --cdsp_camera_undistort_edges--> edge points (undistorted px)
 *     --cdsp_lines_find / cdsp_pair_select--> two contour lines
 *     --cdsp_axis_solve--> cdsp_result (axis, segment, uncertainty)
 *
 * cdsp_frame_solve() runs all of it; cdsp_points_solve() starts from edge
 * points you already have.
 *
 * Conventions (everywhere in this header):
 * - Camera frame: origin at the optical centre, X right, Y down, Z forward.
 *   Pixels: u right, v down; pixel (i, j) covers [i-0.5, i+0.5] x [j-0.5,
 *   j+0.5], i.e. integer coordinates are pixel centres.
 * - Lengths in 3D are in the unit of the radius you pass (mm in all docs).
 * - Image lines are homogeneous (a, b, c): a u + b v + c = 0 in undistorted
 *   pixels, scaled so that a^2 + b^2 = 1 and (a, b) points to the brighter
 *   side of the edge.
 * - Buffers: every buffer is owned by the caller; the library keeps no
 *   pointer past the call that received it. The library never allocates,
 *   prints, exits, or keeps mutable global state: all calls are reentrant.
 * - Every call that can fail returns cdsp_status; outputs are written only
 *   when it returns CDSP_OK unless the function says otherwise.
 */
#ifndef CDSP_H
#define CDSP_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define CDSP_VERSION_MAJOR 0
#define CDSP_VERSION_MINOR 1
#define CDSP_VERSION_PATCH 0

/* ------------------------------------------------------------------------
 * Precision. Double by default; define CDSP_SINGLE (e.g. -DCDSP_SINGLE for
 * Cortex-M4F) to build the whole library in float. The two builds are
 * separate libraries: a program must be compiled with the same setting as
 * the libcdsp.a it links.
 * ---------------------------------------------------------------------- */
#ifdef CDSP_SINGLE
typedef float cdsp_real;
#else
typedef double cdsp_real;
#endif

/* ------------------------------------------------------------------------
 * Capacities (override with -D at build time of the library AND the caller).
 * ---------------------------------------------------------------------- */

/* Edge points the frame path keeps per frame (cdsp_frame_ws). */
#ifndef CDSP_MAX_EDGES
#define CDSP_MAX_EDGES 16384
#endif

/* Points accepted by the points path (cdsp_points_ws). */
#ifndef CDSP_MAX_POINTS
#define CDSP_MAX_POINTS 2048
#endif

/* Candidate lines RANSAC extracts before the pair is chosen (the most
 * max_lines may ask for). Each costs one pass over the points. */
#ifndef CDSP_MAX_LINES
#define CDSP_MAX_LINES 24
#endif
#if CDSP_MAX_LINES < 2 || CDSP_MAX_LINES > 254
#error "CDSP_MAX_LINES: 2 to 254 (a line's label is a byte, 0 = none)"
#endif

/* Ranked pipe candidates kept in the workspaces (the chosen one first). */
#ifndef CDSP_MAX_CANDIDATES
#define CDSP_MAX_CANDIDATES 8
#endif

/* ------------------------------------------------------------------------
 * Status: the one error enum. 0 is success, everything else is negative.
 * ---------------------------------------------------------------------- */
typedef enum {
    CDSP_OK = 0,
    CDSP_E_ARG = -1,          /* NULL pointer, size or parameter out of range */
    CDSP_E_NONFINITE = -2,    /* NaN or Inf in an input */
    CDSP_E_NOCONVERGE = -3,   /* an iteration hit its bound before its tolerance */
    CDSP_E_CAPACITY = -4,     /* more data than the fixed buffers hold */
    CDSP_E_FEW_POINTS = -5,   /* too few edge points to fit two lines */
    CDSP_E_NO_PIPE = -6,      /* no pair of lines looks like a pipe's contour */
    CDSP_E_DEGENERATE = -7,   /* geometry admits no unique axis (see cdsp_axis_solve) */
    CDSP_E_FORMAT = -8        /* image format not supported (bits, stride) */
} cdsp_status;

/* A short, constant, English description of a status ("ok", "no pipe
 * found", ...). Never NULL; unknown codes give "unknown status". */
const char *cdsp_strerror(cdsp_status s);

/* A stable machine-readable token for a status ("ok", "no-pipe",
 * "degenerate", ...), used by the tools' JSON and the UDP protocol. */
const char *cdsp_status_token(cdsp_status s);

/* ------------------------------------------------------------------------
 * Random numbers: caller-owned state, so every run is reproducible.
 * (PCG32, O'Neill 2014: 64-bit state, 32-bit output.)
 * ---------------------------------------------------------------------- */
typedef struct {
    uint64_t state;
    uint64_t inc;
} cdsp_rng;

void cdsp_rng_seed(cdsp_rng *rng, uint64_t seed, uint64_t stream);
uint32_t cdsp_rng_u32(cdsp_rng *rng);
/* Uniform integer in [0, n), n > 0, without modulo bias. */
uint32_t cdsp_rng_below(cdsp_rng *rng, uint32_t n);
/* Uniform in [0, 1). */
cdsp_real cdsp_rng_uniform(cdsp_rng *rng);
/* Standard normal (Marsaglia polar method). */
cdsp_real cdsp_rng_normal(cdsp_rng *rng);

/* ------------------------------------------------------------------------
 * Camera model: pinhole K plus plumb_bob distortion (OpenCV / ROS):
 *   r2 = x^2 + y^2 (undistorted normalized coordinates)
 *   xd = x (1 + k1 r2 + k2 r2^2 + k3 r2^3) + 2 p1 x y + p2 (r2 + 2 x^2)
 *   yd = y (1 + k1 r2 + k2 r2^2 + k3 r2^3) + p1 (r2 + 2 y^2) + 2 p2 x y
 *   u = fx xd + cx,  v = fy yd + cy
 * The paper uses k1, k2 only (p1 = p2 = k3 = 0).
 * ---------------------------------------------------------------------- */
typedef struct {
    cdsp_real fx, fy;          /* focal lengths, pixels */
    cdsp_real cx, cy;          /* principal point, pixels */
    cdsp_real k1, k2, p1, p2, k3;
    int width, height;         /* image size the calibration belongs to, px */
} cdsp_camera;

/* Undistortion stops when the distorted-pixel residual falls below this
 * (pixels) and fails with CDSP_E_NOCONVERGE after CDSP_UNDISTORT_MAX_ITER
 * Newton steps. Float builds cannot reach the double tolerance, so it is
 * relaxed there (float eps ~ 1.2e-7 of a coordinate ~ 1e3 px). */
#ifdef CDSP_SINGLE
#define CDSP_UNDISTORT_TOL_PX 1e-3
#else
#define CDSP_UNDISTORT_TOL_PX 1e-9
#endif
#define CDSP_UNDISTORT_MAX_ITER 20

/* CDSP_OK, or CDSP_E_ARG (fx, fy <= 0, size <= 0) / CDSP_E_NONFINITE. */
cdsp_status cdsp_camera_check(const cdsp_camera *cam);

/* Undistorted pixel -> distorted pixel (closed form). */
cdsp_status cdsp_camera_distort(const cdsp_camera *cam, const cdsp_real und[2],
                                cdsp_real dist[2]);

/* Distorted pixel -> undistorted pixel (Newton iteration, see the
 * tolerance macros above). The output is written even on
 * CDSP_E_NOCONVERGE (last iterate) so callers may inspect it. */
cdsp_status cdsp_camera_undistort(const cdsp_camera *cam, const cdsp_real dist[2],
                                  cdsp_real und[2]);

/* Camera-frame point (Z > 0) -> distorted pixel. CDSP_E_DEGENERATE if Z <= 0. */
cdsp_status cdsp_camera_project(const cdsp_camera *cam, const cdsp_real X[3],
                                cdsp_real pix[2]);

/* Undistorted pixel -> ray direction K^-1 (u, v, 1) (not normalized). */
void cdsp_camera_ray(const cdsp_camera *cam, const cdsp_real und[2], cdsp_real ray[3]);

/* ------------------------------------------------------------------------
 * Images. 8-bit (bits <= 8, one byte per pixel) or 9..16-bit (two bytes per
 * pixel, native endianness, values in [0, 2^bits - 1]: Mono10/12 unpacked
 * and Mono16 all fit). stride in bytes, >= width * bytes per pixel.
 * ---------------------------------------------------------------------- */
typedef struct {
    const void *data;
    int width, height;
    size_t stride;            /* bytes from one row to the next */
    int bits;                 /* significant bits: 8, 10, 12, 14 or 16 */
} cdsp_image;

/* Region of interest in pixels; w or h = 0 means the whole frame. */
typedef struct {
    int x, y, w, h;
} cdsp_roi;

/* CDSP_OK or CDSP_E_ARG / CDSP_E_FORMAT. */
cdsp_status cdsp_image_check(const cdsp_image *img);

/* ------------------------------------------------------------------------
 * Edge points.
 * ---------------------------------------------------------------------- */
typedef struct {
    cdsp_real x, y;   /* subpixel position, pixels (distorted as detected;
                         undistorted after cdsp_camera_undistort_edges) */
    cdsp_real gx, gy; /* gradient: direction of increasing intensity, length =
                         the intensity step across the edge (gray levels) */
} cdsp_edge;

typedef struct {
    int step;               /* scanline spacing, px (1..CDSP_EDGE_MAX_STEP).
                               Default 4: a quarter of the rows and columns
                               are read. */
    int half_window;        /* partial-area window half-length, px (2..8).
                               Default 4 (9-px window): covers an edge
                               blurred with sigma up to ~1.2 px. */
    cdsp_real min_contrast; /* minimum intensity step across an edge as a
                               fraction of full scale (2^bits - 1).
                               Default 0.06 (15 gray levels at 8 bit). */
    cdsp_roi roi;           /* where to look; default whole frame; any
                               values (clipped to the frame, no overflow) */
    int coarse;             /* coarse pass, 0..CDSP_EDGE_MAX_COARSE: with
                               F >= 2, every F-th row of the search is read
                               first, then the other rows and the column
                               blocks only within bands around the edges
                               and the near-horizontal crossings ("hints")
                               found there (docs/method.md §2: a subsequence
                               of the full search's edges, in its order;
                               every edge of a contour reaching a coarse
                               row within F*step px is still found). 0 or
                               1: off, the whole roi (the default here;
                               cdsp_params turns it on for cdsp_frame_solve;
                               cdsp_frame_solve_all's full search reads
                               the whole roi: every pipe needs every
                               contour) */
} cdsp_edge_params;

/* Largest scanline spacing (a wider step than any frame reads one line). */
#define CDSP_EDGE_MAX_STEP 65536
/* Largest coarse factor (cdsp_edge_params.coarse). */
#define CDSP_EDGE_MAX_COARSE 64

void cdsp_edge_params_default(cdsp_edge_params *p);

/*
 * Subpixel edges by the partial area effect (Trujillo-Pino et al. 2013,
 * first-order variant: a straight edge through a 3 x (2h+1) window), with a
 * second pass that takes each side's intensity as its mean over its part of
 * the window (sampled half way along it) rather than at the window's end,
 * which removes most of the bias of a shaded pipe's limb (lib/edges.c).
 * Rows y = roi.y + k*step are scanned for near-vertical edges and columns
 * for near-horizontal ones; each edge is reported once, by the family whose
 * scan direction is closer to its gradient.
 * Writes at most cap points to out and their number to *n. When more than
 * cap are found, the buffer filling up does not decide which contours are
 * seen: the family that does not fit (the one with more points, when rows
 * and columns fit alone but not together) is scanned again at twice its
 * step, until both fit; out then holds both families, each over the whole
 * roi at one uniform step (a power-of-two multiple of p->step), and the
 * call returns CDSP_E_CAPACITY with *n <= cap. (Only if one line at a step
 * past the frame's extent still overflows is out a truncated scan.)
 */
cdsp_status cdsp_edges_detect(const cdsp_image *img, const cdsp_edge_params *p,
                              cdsp_edge *out, size_t cap, size_t *n);

/*
 * The full search in strips, for callers that spread one frame over several
 * cores (the library itself starts no thread). Strip k (0 <= k < n <=
 * CDSP_EDGE_MAX_STRIPS) reads its share of the rows and of the column
 * blocks (with the coarse pass, the coarse rows around them too, and
 * every coarse row when it has column blocks: they take their bands from
 * the coarse rows' hints, over the whole height) and
 * writes its row edges to out[0, *n_rows) and its column edges after them
 * (*n_cols); strips are independent (any order, any thread; out is the
 * caller's, one per strip). cdsp_edges_merge_strips then lists every
 * strip's rows and then every strip's columns, in strip order: exactly
 * cdsp_edges_detect's result for the same image and parameters, bit for
 * bit, whenever the merge returns CDSP_OK. Either returns CDSP_E_CAPACITY
 * when the edges may not fit (a strip in its cap; the merge: cap edges or
 * more, or cap / 2 with p->coarse >= 2, whose coarse lines share the
 * whole-frame buffer): then call cdsp_edges_detect, whose rule for a full
 * buffer (coarsening a family) needs the whole frame. Other returns:
 * CDSP_OK, CDSP_E_ARG, CDSP_E_FORMAT.
 */
#define CDSP_EDGE_MAX_STRIPS 64
cdsp_status cdsp_edges_detect_strip(const cdsp_image *img, const cdsp_edge_params *p, int k, int n,
                                    cdsp_edge *out, size_t cap, size_t *n_rows, size_t *n_cols);
cdsp_status cdsp_edges_merge_strips(const cdsp_edge_params *p, const cdsp_edge *const *strip,
                                    const size_t *n_rows, const size_t *n_cols, int n,
                                    cdsp_edge *out, size_t cap, size_t *count);

/* In place: distorted -> undistorted positions; gradients are carried
 * through the local Jacobian (normals map by J^T) keeping their length.
 * Points that do not converge are removed (the array is compacted and *n
 * updated); CDSP_OK unless arguments are invalid. */
cdsp_status cdsp_camera_undistort_edges(const cdsp_camera *cam, cdsp_edge *e, size_t *n);

/* ------------------------------------------------------------------------
 * Small numerics (exposed because they are tested on their own and useful
 * to callers): 3x3 SVD by one-sided Jacobi.  A = U diag(S) V^T, row-major,
 * S descending and non-negative, U and V orthogonal (det V = +1).
 * CDSP_E_NOCONVERGE if the sweeps do not converge (never seen for finite
 * input), CDSP_E_NONFINITE for NaN/Inf.
 * ---------------------------------------------------------------------- */
cdsp_status cdsp_svd3(const cdsp_real A[9], cdsp_real U[9], cdsp_real S[3], cdsp_real V[9]);

/* ------------------------------------------------------------------------
 * Lines.
 * ---------------------------------------------------------------------- */
typedef struct {
    cdsp_real l[3];        /* a u + b v + c = 0, a^2+b^2 = 1, (a,b) toward bright */
    cdsp_real centroid[2]; /* mean of the inliers, px */
    cdsp_real dir[2];      /* unit direction along the line: (-b, a) */
    cdsp_real t_min, t_max;/* inlier extent along dir from the centroid, px */
    cdsp_real rms;         /* orthogonal RMS residual of the inliers, px */
    cdsp_real spread;      /* sum of squared positions along dir, px^2 */
    cdsp_real strength;    /* mean gradient length of the inliers */
    uint32_t count;        /* inliers */
} cdsp_line;

/* Total least squares line through points (Hartley-normalized, 3x3 SVD of
 * [u v 1]); (a, b) points along the points' mean gradient (when that is
 * zero: b > 0, or b == 0 and a > 0).
 * idx selects the points (NULL = all n). CDSP_E_FEW_POINTS below 2 points,
 * CDSP_E_DEGENERATE when all points coincide. */
cdsp_status cdsp_line_fit(const cdsp_edge *pts, const uint32_t *idx, size_t n,
                          cdsp_line *out);

typedef struct {
    cdsp_real inlier_px;      /* max orthogonal distance of an inlier, px. Default 1.0 */
    cdsp_real normal_tol_deg; /* max angle between an inlier's gradient and the
                                 line normal, degrees. Default 20 */
    cdsp_real confidence;     /* RANSAC success probability for the adaptive
                                 iteration count. Default 0.999 */
    int max_iterations;       /* hard cap of hypotheses per line. Default 300.
                                 Half of them are guided (a second point on
                                 the first one's edge direction, see
                                 lib/lines.c), so a short contour among long
                                 clutter edges is still sampled. */
    int max_lines;            /* candidate lines (<= CDSP_MAX_LINES). Default
                                 24; when reached while significant points
                                 remain, CDSP_FLAG_CAPPED is set */
    int min_inliers;          /* a line needs at least this many; a pair, half
                                 as many supported on its common stretch per
                                 contour (the pair score's n q). Default 12 */
    cdsp_real min_overlap;    /* a pair's contours must overlap along the pipe
                                 by this fraction of the shorter one. Default 0.5 */
    cdsp_real max_contour_angle_deg; /* largest image angle between the two
                                 contours (perspective convergence). Default 60 */
    int polarity;             /* 0 either; +1 pipe brighter than background;
                                 -1 darker. Default 0 */
    cdsp_real min_distance, max_distance; /* plausible |P_C|, radius units;
                                 0 = no bound. Default 0, 0. With a bound,
                                 no pose outside it is ever reported (the
                                 pair test and, after the edge-profile
                                 model moved the contours, the pose). */
    cdsp_real min_support;    /* fraction of the overlap each contour's inliers
                                 must cover (in 32 bins along it): support all
                                 on one short piece is not a contour. Default
                                 0.35 */
} cdsp_pair_params;

void cdsp_pair_params_default(cdsp_pair_params *p);

/* ------------------------------------------------------------------------
 * The axis.
 * ---------------------------------------------------------------------- */

/* Largest radius the solvers accept (radius units: 1e9 mm is 1000 km).
 * Beyond it the covariance's squares leave the float range and the
 * uncertainty would come out infinite; CDSP_E_ARG instead. */
#define CDSP_MAX_RADIUS 1e9
typedef struct {
    cdsp_real point[3];      /* P_C: foot of the perpendicular from the optical
                                centre onto the axis (camera frame) */
    cdsp_real direction[3];  /* v_L, unit; sign: its largest-magnitude
                                component is positive (or, with a prior, it
                                agrees with the prior's direction) */
    cdsp_real distance;      /* |P_C| = r / sin(alpha / 2) */
    cdsp_real alpha;         /* angle between the tangent planes, rad */
    cdsp_real normals[2][3]; /* n1, n2 oriented: n1.P = +r, n2.P = -r */
    cdsp_real lines[2][3];   /* the two contours, undistorted px (see top) */
    cdsp_real segment[2][3]; /* visible axis segment, ordered along direction;
                                equal to point twice when extents are unknown */
    /* First-order uncertainty propagated from the line fits' residuals
     * (on the frame path scaled for points that share scanlines at an
     * edge.step below 3, docs/method.md §6; the points path takes its
     * points as independent): cov is the covariance of (point[0..2],
     * direction[0..2]). It covers the random error of the edge points only; systematic errors (calibration,
     * a wrong radius, the edge bias of a shaded pipe's limb, see README
     * "Accuracy") are not in it. cov = F F^T, F = cov_factor: positive
     * semi-definite of rank 4 (the axis' 4 degrees of freedom: 2 of
     * direction, 2 of position across it), singular along the constraints
     * dv.v = 0 and dP.v = -P.dv (point is the foot of the perpendicular
     * from the optical centre). Column k of F is the change of
     * (point, direction) for a one-standard-deviation change of the k-th
     * independent line parameter (contour 0 offset, contour 0 angle,
     * contour 1 offset, contour 1 angle): draw g ~ N(0, I4), F g is a
     * draw of the error. Prefer F to cov when the pipe is far: the
     * variance along the constraints, (|P| sigma_v)^2, can exceed the
     * smallest observable one by about 1 / eps, and then rounding cov's
     * entries alone spoils the observable dof (single precision, 16 mm
     * pipe, f = 3478 px: a quarter of the poses at 3-5 m, some at 1.5 m;
     * docs/method.md §6), while F keeps each column to its relative
     * precision. */
    cdsp_real cov[6][6];
    cdsp_real cov_factor[6][4];
    cdsp_real sigma_point[3];
    cdsp_real sigma_direction[3];
    cdsp_real sigma_distance;
    cdsp_real rms[2];        /* per-contour RMS residual, px */
    uint32_t inliers[2];     /* per-contour inlier counts */
    uint32_t n_edges;        /* edge points considered */
    uint8_t label[2];        /* points path / frame path: ws->label[i] == label[k]
                                marks the inliers of contour k (valid until the
                                workspace is used again); 0 from cdsp_axis_solve */
    uint32_t flags;          /* CDSP_FLAG_* */
    /* The edge-profile model (frame path, CDSP_FLAG_PROFILE): how far each
     * contour was moved from the detector's line to the modelled silhouette
     * (undistorted px, + toward the pipe; 0 when not applied) and the edge
     * spread measured on it (sigma, px; 0 when not applied). */
    cdsp_real edge_offset[2];
    cdsp_real edge_blur[2];
    /* Since issue 10: how sure, and on what evidence. */
    cdsp_real confidence;    /* in [0, 1]: how likely this is the pipe, a
                                logistic model of the pair's evidence and its
                                margin over the best rival (see "The pair
                                score" below), fitted on `make bench-detect`;
                                at most 0.78 when a contour's points are
                                scattered beyond the frame's noise (frame
                                path, CDSP_FLAG_BOUND then clear, see
                                cdsp_frame_solve). 0 from cdsp_axis_solve */
    cdsp_real score;         /* the pair score the pose won with (below) */
    cdsp_real noise;         /* frame path: the frame's measured noise sigma,
                                gray levels (0 on the points path) */
    cdsp_real min_step;      /* frame path: the edge step required, gray levels */
    uint32_t n_lines;        /* candidate contour lines considered */
    uint32_t n_candidates;   /* plausible pipe candidates found (>= 1 on CDSP_OK);
                                the ranked list is in the workspace */
    /* Since issue 13 (every pipe in view, lib/multi.c). */
    uint32_t track_id;       /* cdsp_frame_solve_all / cdsp_points_solve_all with
                                a tracker: the pipe's id, kept from frame to
                                frame while it stays in view (1, 2, ...);
                                0 without a tracker and from the single-pipe
                                calls */
    /* Since issue 12: the systematic part, a BOUND, NOT A SIGMA (frame path,
     * CDSP_FLAG_BOUND; all 0 without it). edge_bound[k]: contour k's line
     * may be off its silhouette by up to this, undistorted px
     * (cdsp_profile_bound). The pose's bounds: the worst case of both
     * contours shifted by up to their edge_bound through the pose's
     * first-order Jacobian (the one cov uses): |d point[i]| <=
     * bound_point[i] and |d distance| <= bound_distance (radius units),
     * |d direction[i]| <= bound_direction[i] (unit vector components).
     * The error of a pose is within sigma (random, ~68 % per component) plus
     * the bound (systematic); the bound holds neither calibration nor the
     * radius (README "Accuracy"). Tracked frames with the profile model
     * off (its default) carry the prior's edge bounds, the larger of the
     * two for both contours, instead of fitting again (the fit is ~3.4 M
     * instructions on a 5 MP frame; the edge's shape changes with light
     * and blur over many frames): a tracked pose's bound is that of the
     * last full search's fit. */
    cdsp_real edge_bound[2];
    cdsp_real bound_point[3];
    cdsp_real bound_direction[3];
    cdsp_real bound_distance;
} cdsp_result;

#define CDSP_FLAG_TRACKED 1u     /* found in the bands around the prior */
#define CDSP_FLAG_FULL_SEARCH 2u /* searched the whole frame / ROI */
#define CDSP_FLAG_TRUNCATED 4u   /* more edges than CDSP_MAX_EDGES were found: the
                                    frame was scanned at a coarser step (see
                                    cdsp_edges_detect; tracking bands likewise) */
#define CDSP_FLAG_PROFILE 8u     /* the edge-profile model fitted both contours
                                    (edge_offset: how far each was moved) */
#define CDSP_FLAG_CAPPED 16u     /* max_lines lines were extracted while enough
                                    free points for another remained: a contour
                                    may not have been considered */
#define CDSP_FLAG_BOUND 32u      /* edge_bound and bound_* were measured (frame
                                    path: the edge-profile model fitted, or
                                    tried, on both contours). Clear (bounds 0,
                                    not measured) on a pose with a scattered
                                    contour: its error may exceed sigma by
                                    far (cdsp_frame_solve) */

/*
 * The pair score (issue 10; lib/pair.c; docs/method.md §4). Every pair of
 * candidate lines that passes the plausibility tests (opposite polarity
 * forming a band, or on the frame path the same polarity across a band
 * whose shading crosses the one background's level, a pipe lit from one
 * side with its shaded limb darker than the background; within
 * max_contour_angle, overlapping by min_overlap, not
 * crossing inside their stretch, a band at least as wide as the edge window
 * 2 half_window + 1, each contour's support covering min_support of the
 * overlap and n_k q_k (below) at least min_inliers / 2, the closed
 * form's distance inside [min_distance, max_distance],
 * one object inside: no strong interior contours of both polarities an
 * edge window or more apart (on the frame path, a darker pipe's specular
 * stripe excepted: the strip between them peaked at its middle, a
 * highlight's lobe, not a gap's flat level), no
 * strong one opposing its nearer contour without a stripe's other side of
 * half its strength, no strong one continuing its nearer contour's step
 * with nothing of the other polarity beyond it (a staircase onto an object
 * beside), on the single-pipe path not the gap between two objects, and on
 * the frame path no corner of a flat frame: where a contour ends inside
 * the frame, the level just past its end outside the band is not the
 * band's own, as at a door post meeting its lintel)
 * is scored by its weaker contour times its width squared and an angle prior
 *   S = min(n1 c1 q1, n2 c2 q2) * (w / w0)^2 * exp(-sin(a) / 0.4) * T
 * with, per contour k: n_k its inliers on the common stretch, c_k its mean
 * edge step divided by the frame's step threshold (contrast, counted up to
 * 2), q_k the fraction of the overlap its inliers cover (spread, not one
 * short piece); w the band's width at its middle, w0 the edge window: the
 * largest, clearest band wins (a long thin bar has the length, not the
 * width), and a gap borrowing one strong edge of a neighbour does not win
 * on that edge; a the angle between the contours (a pipe's are nearly
 * parallel unless it is close and steeply tilted); T, in tracking, 1 + 2 exp(-e^2 / 2) with e the pair's offset
 * from the prior's contours in units of track_band_px (the pipe being
 * followed wins over a newcomer). The multi-pipe calls below keep S =
 * min(n1 c1 q1, n2 c2 q2) * T (their matching tells pipes from gaps). A
 * contour belongs to one pipe: pairs are taken best first and a pair
 * sharing a line with a better one is dropped; a pair is also passed over
 * when each of its two lines forms a pair at least as good with another
 * line (the gap between two pipes of a rack, each pipe as good as the gap).
 * The survivors, ranked, are the candidates (the workspace's cand[], first
 * = the pose returned, each with its evidence; "every pipe in view" can
 * take them all).
 * confidence: P(right) of a logistic model, 1 / (1 + exp(-w . x)), on the
 * candidate's features x: 1, log(1 + support), log(contrast), log(width),
 * the margin 1 - S2 / S1 over its best rival (1 alone), log(candidates),
 * whether a distance range was given, the sine of the contours' angle and
 * log(0.1 + shading) (the band's smooth intensity range across, frame path);
 * w fitted on `make bench-detect`'s seed-1 frames and validated on seed 2
 * (docs/method.md §4). A flat band (frame path, shading below 0.15 step
 * thresholds) is capped at 0.89, out of the >= 0.9 bin: flat bars that are
 * plausible pipes of the radius look like evenly lit pipes, and the model
 * put such bands at >= 0.9 when only 92 % of them were right. With the cap
 * no false positive of bench-detect reaches 0.9 (seeds 1-3), and among
 * poses at >= 0.9 96-99 % are right, still NOT the issue's >= 99 % (the
 * rest: the true contours with the pose more than 5 % off, issue 12). A
 * band with a contour whose contrast flips along it (a collinear line of
 * the opposite polarity beyond its stretch: the background crosses the
 * pipe's level there, and the edge's points drift near the crossing) is
 * capped at 0.89 too when its direction would turn by more than 2 degrees
 * for a 0.3 px drift of its contours' ends (a narrow band: docs/method.md
 * §4). Each candidate's confidence is the model's as if it were the one
 * returned.
 */

/*
 * The closed form (docs/method.md): from two contour lines (undistorted px), a
 * pixel p_in between them on the pipe, the radius r (0 < r <= CDSP_MAX_RADIUS).
 * Fills point, direction, distance, alpha, normals, lines; segment is set to
 * point; cov, cov_factor, sigma zero; counts zero.
 * CDSP_E_DEGENERATE when: the back-projection planes are parallel
 * (|n1 x n2| tiny), p_in lies on a line, or alpha is so close to pi that the
 * optical centre would be inside the pipe (d < r (1 + 1e-6)).
 * CDSP_E_NONFINITE / CDSP_E_ARG for bad inputs.
 */
cdsp_status cdsp_axis_solve(const cdsp_camera *cam, const cdsp_real l1[3],
                            const cdsp_real l2[3], const cdsp_real p_in[2],
                            cdsp_real radius, cdsp_result *out);

/* ------------------------------------------------------------------------
 * Points -> pose and frame -> pose.
 * ---------------------------------------------------------------------- */
/* ------------------------------------------------------------------------
 * Edge-profile model (lib/profile.c): where a contour's silhouette is, from
 * the intensity profile across it accumulated along the whole contour.
 * The detector's points sit where its partial-area window puts the edge;
 * on a shaded limb, a blur wider than its window or a contour that is not
 * axis-aligned that is off the silhouette by up to a few tenths of a pixel
 * (motion blur: pixels). The model takes the profile (pixel centres at
 * their signed distance u from the fitted line, in 1/4 px bins over
 * hundreds of scanlines) as a step blurred by a symmetric kernel of unknown
 * width (optics, motion, the pixel's footprint) between a background side
 * D + E u and a pipe side A + B s + C sqrt(s (2 Rc - s)) (s = distance
 * from the silhouette, Rc the pipe's image radius: a Lambertian cylinder's
 * shading, ~ sqrt(s) at the limb), and solves the area balance
 * (blur moves intensity across the silhouette, never out of a window wider
 * than the blur) for the silhouette. Details and limits: lib/profile.c,
 * docs/method.md.
 * ---------------------------------------------------------------------- */
#ifndef CDSP_PROFILE_RANGE_PX
#define CDSP_PROFILE_RANGE_PX 24   /* largest half-width of a profile, px */
#endif
#define CDSP_PROFILE_BINS_PER_PX 4
#define CDSP_PROFILE_NBINS (2 * CDSP_PROFILE_RANGE_PX * CDSP_PROFILE_BINS_PER_PX)
/* The forward model of a blur wider than the detector's window
 * (lib/profile.c, fwd_*): the blurred basis on a grid of 1/8 px over the
 * window, the kernel's cells, the pipe side's cell means and the fit's
 * residual vectors (its scratch, in the workspace: not on an MCU's stack) */
#define CDSP_PROFILE_FWD_SUB 8
#define CDSP_PROFILE_FWD_NX (2 * (CDSP_PROFILE_RANGE_PX + 1) * CDSP_PROFILE_FWD_SUB + 1)
#define CDSP_PROFILE_FWD_NK (2 * CDSP_PROFILE_RANGE_PX * CDSP_PROFILE_FWD_SUB)
#define CDSP_PROFILE_FWD_NQ ((CDSP_PROFILE_RANGE_PX + 1) * CDSP_PROFILE_FWD_SUB + CDSP_PROFILE_FWD_NK / 2 + 1)

/* Bins of one contour's profile (caller-owned scratch; contents undefined
 * between calls). Sums are exact integers for 8..16-bit pixels up to
 * max_rows = 4096. */
typedef struct {
    uint32_t count[CDSP_PROFILE_NBINS];
    uint32_t sum[CDSP_PROFILE_NBINS];
    uint64_t sumsq[CDSP_PROFILE_NBINS];
    cdsp_real sum_u[CDSP_PROFILE_NBINS];
    cdsp_real mean_u[CDSP_PROFILE_NBINS], mean_v[CDSP_PROFILE_NBINS]; /* the fit's
                               bins (here, not on an MCU's small stack) */
    cdsp_real fwd_p[3][CDSP_PROFILE_FWD_NX];       /* forward model: the blurred
                                                     basis on the grid */
    cdsp_real fwd_k[CDSP_PROFILE_FWD_NK];          /* the kernel's cell masses */
    cdsp_real fwd_q[CDSP_PROFILE_FWD_NQ];          /* the limb term's
                                                     cell means */
    cdsp_real fwd_r[4][CDSP_PROFILE_NBINS];        /* residuals: at the estimate
                                                     and its 3 steps */
} cdsp_profile_ws;

typedef struct {
    int enable;                  /* frame path: move each contour to its
                                    modelled silhouette. Default 0 (opt-in:
                                    see make bench's accuracy study for
                                    where it helps and where not yet) */
    int max_rows;                /* scanlines sampled per contour (16..4096):
                                    the frame path takes each sampled
                                    inlier's scanline and its two
                                    neighbours, inliers spread evenly.
                                    Default 2048 */
    cdsp_real max_half_width_px; /* profile half-width, px (6..CDSP_PROFILE_RANGE_PX;
                                    also kept inside 0.9 of the pipe's
                                    half-width). Default 20: a 15 px motion
                                    blur or a 3 px optical one plus the
                                    fit zones */
    cdsp_real max_fit_chi2;      /* frame path: a contour whose pipe side fits
                                    worse than this (fit_chi2) keeps the
                                    detector's line (a limb in shadow, a
                                    highlight, a plateau). Default 0.25:
                                    on the paper's rendered scene good
                                    contours give 0.01-0.03; the rack's
                                    low-contrast limbs in shadow (25 gray
                                    levels, make bench-rack) 0.4-0.9 even
                                    modelled, and keep the detector's line,
                                    exact on a flat shadow */
} cdsp_profile_params;

void cdsp_profile_params_default(cdsp_profile_params *p);

typedef struct {
    cdsp_real offset;       /* modelled silhouette minus the given line, px
                               along the normal, positive toward the pipe */
    cdsp_real sigma_offset; /* its standard deviation from the pixels' noise,
                               px, through the sides' fits, their
                               extrapolation to the silhouette and the
                               measured blur (first order, docs/method.md
                               2a: 0.88-1.08 of the scatter measured on
                               flat and shaded limbs, offset / sigma RMS
                               0.86-1.15); under a blur wider
                               than the detector's window (the forward
                               model) the fit's own covariance, the blur
                               and a terminator free (offset / sigma RMS
                               0.88-1.14 on lit limbs at 2-3 px of blur) */
    cdsp_real blur;         /* measured sigma of the edge spread (optics,
                               motion, the pixel's footprint), px */
    cdsp_real contrast;     /* pipe minus background at the silhouette, gray levels */
    cdsp_real half_width;   /* window half-width used, px */
    cdsp_real fit_chi2;     /* pipe side's chi-square per degree of freedom
                               of its residuals averaged over 1 px groups
                               of distance from the edge (a ripple at the
                               pixel lattice's spacing is not a misfit),
                               against the pixels' noise, floored at 0.2 %
                               of the step (<~1: the model fits; 1e6: fewer
                               than 4 bins beyond the blur zone, not
                               checked); under a blur wider than the
                               detector's window on a shaded limb (the
                               forward model, docs/method.md 2a) the
                               whole window's, blur zone included */
    int flat;               /* 1: the limb term is not significant
                               (F-test): the pipe side is a straight ramp,
                               which the detector handles exactly */
    int saturated;          /* 1: part of the profile sits at full scale */
    uint32_t rows;          /* scanlines accumulated */
    cdsp_real shadow;       /* the limb in shadow: the pipe side is flat
                               (ambient light only) from the silhouette to
                               this distance, px (the terminator); 0: lit
                               up to the limb */
    /* Since issue 12 (the systematic bound, cdsp_profile_bound): */
    cdsp_real noise;        /* the pixels' noise measured on the sides' bins,
                               gray levels (sd of one pixel) */
    int blur_clamped;       /* 1: the measured spread hit its largest value
                               (a quarter of the profile's half-width): the
                               edge is no blurred step this window holds */
} cdsp_profile;

/*
 * Fit the profile model to the frame along the straight line `line` (frame
 * px, a u + b v + c = 0, any scale) between the projections of ends[0] and
 * ends[1] onto it; p_in is the pipe's middle (its distance from the line
 * is taken as the limb's radius Rc, px). One scanline per frame row (or
 * column, for a contour nearer horizontal) between the ends, evenly
 * thinned to pp->max_rows; scanlines whose window leaves the frame are
 * skipped. CDSP_E_FEW_POINTS when fewer than
 * 16 scanlines fit, CDSP_E_NOCONVERGE when the model does not fit (no edge,
 * or the silhouette more than half the window away), CDSP_E_ARG for bad
 * arguments. Under a blur wider than the detector's window on a shaded
 * limb (measured sigma > 1 px) it fits the blurred scene to the whole
 * window (the forward model, docs/method.md 2a) whatever pp->enable; the
 * frame path does so only with the model enabled (6-10 M instructions a
 * contour).
 */
cdsp_status cdsp_profile_fit(const cdsp_image *img, const cdsp_real line[3],
                             const cdsp_real p_in[2], const cdsp_real ends[2][2],
                             const cdsp_profile_params *pp, cdsp_profile_ws *ws,
                             cdsp_profile *out);

/* Whether the frame path moves a contour by pr->offset: 1 when the model
 * fits (fit_chi2 <= pp->max_fit_chi2, not saturated) and is needed (a limb
 * term not in shadow over the detector's window, or a blur the window of
 * half-width h = detector_half_window does not span: sigma > (h + 1/2) /
 * 4.66, docs/method.md §2a); 0 keeps the detector's line. */
int cdsp_profile_applies(const cdsp_profile *pr, const cdsp_profile_params *pp,
                         int detector_half_window);

/* The systematic bound of a contour line (issue 12), px: how far the line
 * the frame path reports (the detector's, or the model's when it moved it)
 * may be from the silhouette for reasons the random part (cov, sigma_*)
 * does not hold: the edge's shape. A bound, not a sigma: calibrated on
 * make bench-accuracy's grid to cover the measured bias in >= 95 % of its
 * cells (lib/profile.c gives the rule and the figures). pr: the profile
 * fitted along the line (pr->rows == 0 or NULL: not fitted, the bound is
 * then half of pp->max_half_width_px). detector_half_window: the
 * detector's window h (cdsp_edge_params.half_window), as for
 * cdsp_profile_applies: where the edge is in the detector's regime its
 * floor is the detector's own error there (since the bound's tightening,
 * issue 12). 0 when pp is NULL. */
cdsp_real cdsp_profile_bound(const cdsp_profile *pr, const cdsp_profile_params *pp,
                             int detector_half_window);

typedef struct {
    cdsp_edge_params edge;
    cdsp_pair_params pair;
    cdsp_real track_band_px;  /* half-width of the search band around each
                                 predicted contour in tracking mode. Default 12 */
    int track_min_inliers;    /* below this per contour, tracking falls back to a
                                 full search. Default 30 */
    cdsp_profile_params profile; /* the edge-profile model (frame path) */
    cdsp_real noise_factor;   /* frame path: an edge needs a step of at least
                                 min(edge.min_contrast * range, max(noise_factor
                                 * sigma, 2)) gray levels, sigma the frame's
                                 measured noise, range the data's real range
                                 (2^b - 1 for the largest value seen, so Mono10/12
                                 in 16-bit containers count as 10/12 bit).
                                 0 = the fixed fraction alone. Default 10 */
    cdsp_real min_confidence; /* a pose with a lower confidence is reported as
                                 CDSP_E_NO_PIPE. Default 0 (every pose) */
    int refine_step;          /* frame path: 0 (default) off; k >= 3 (up to
                                 CDSP_EDGE_MAX_STEP): once a pose's two
                                 contours are chosen, only the scanlines'
                                 segments of +-(pair.inlier_px + 2) px around
                                 them are read again, every k-th scanline
                                 along each, and each line is refitted to its
                                 inliers there (the edge-profile model's move
                                 kept); the search, its edge budget
                                 (CDSP_MAX_EDGES) and the confidences are
                                 untouched. 1 and 2 are refused: a point's
                                 position is the mean over its window's 3
                                 scanlines, so points nearer than 3 scanlines
                                 share noise, and 3 already reads every
                                 pixel near the contour once (docs/method.md
                                 §3a): against the default edge.step 4 the
                                 line's random error falls by sqrt(4 / 3) at
                                 most, against a coarser search by
                                 sqrt(edge.step / 3). */
    int point_fit;            /* frame path, with refine_step on: 0 (default)
                                 the refitted lines take the detector's
                                 points; 1: each point's position is first
                                 fitted again to its window's pixels, the
                                 least-squares offset of a blurred step with
                                 the contour's own spread and shading (its
                                 A, C and offset free), which weighs the
                                 step's pixels: ~1.8 times less noise per
                                 point on the rendered rack, but a shaded
                                 limb's bias 0.03 px larger; ~13 M
                                 instructions per pipe (docs/method.md §3a).
                                 1 with refine_step 0 is refused
                                 (CDSP_E_ARG): it would refit nothing */
} cdsp_params;

void cdsp_params_default(cdsp_params *p);

/* The parameter checks every solve entry point makes, for callers that
 * validate a configuration before any frame (cdspd at load time):
 * CDSP_OK, or CDSP_E_ARG when p is NULL or a field is outside its range
 * (documented at each field above: e.g. 0 < min_contrast < 1). */
cdsp_status cdsp_params_check(const cdsp_params *p);

/* Scored pairs of candidate lines a frame keeps (PAIR_KEEP in lib/pair.c):
 * what falls off the end is weaker than CDSP_MAX_PAIRS others. */
#ifndef CDSP_MAX_PAIRS
#define CDSP_MAX_PAIRS 48
#endif

/* One pair of candidate lines that passed the pair tests (internal to the
 * library; public only so the workspaces below have a size). */
typedef struct {
    uint8_t i, j;           /* the two lines (indices into cdsp_pair_set.lines; bytes:
                               48 pairs x 6 B of the M4F RAM budget, docs/mcu.md) */
    cdsp_real score;        /* the pair score */
    cdsp_real p_in[2];      /* a pixel between the lines */
    cdsp_real support;      /* min over both contours of inliers on the overlap x spread */
    cdsp_real contrast;     /* min over both contours of step / threshold */
    cdsp_real width;        /* band width at p_in, px */
    cdsp_real sin_angle;    /* sine of the angle between the contours */
    cdsp_real shade;        /* the band's shading (cdsp_candidate) */
} cdsp_pair_eval;

/* Candidate lines and their scored pairs (scratch; contents undefined
 * between calls). Part of every workspace below, not of the library's
 * stack: CDSP_MAX_LINES * sizeof(cdsp_line) + CDSP_MAX_PAIRS *
 * sizeof(cdsp_pair_eval) bytes, 2 988 (float) / 5 968 (double) at the
 * default 24 lines and 48 pairs. */
typedef struct {
    cdsp_line lines[CDSP_MAX_LINES];
    cdsp_pair_eval pair[CDSP_MAX_PAIRS]; /* best score first */
    int nlines, npairs, capped;
} cdsp_pair_set;

/* A ranked pipe candidate: its two contour lines (undistorted px, as in
 * cdsp_result.lines), a pixel between them, its score and confidence, and
 * the labels of its inliers in the workspace's label array. */
typedef struct {
    cdsp_real lines[2][3];
    cdsp_real p_in[2];
    cdsp_real score, confidence;
    /* the evidence behind them ("The pair score"): min over both contours
     * of inliers on the common stretch x spread, and of edge step over the
     * frame's threshold (1 on the points path); band width at p_in, px;
     * sine of the angle between the contours; the band's shading across
     * (frame path: median range of the interior over the step threshold;
     * -1 when not measured) */
    cdsp_real support, contrast, width, sin_angle, shade;
    uint8_t label[2];
} cdsp_candidate;

/* Workspace of the points path: one label byte per point, the ranked
 * candidates and the pair set (the library keeps no buffer of this size on
 * its stack; docs/mcu.md has the bytes per target). */
typedef struct {
    uint8_t label[CDSP_MAX_POINTS];
    cdsp_candidate cand[CDSP_MAX_CANDIDATES]; /* ranked, best first; result.n_candidates
                                                 of them (at most CDSP_MAX_CANDIDATES) */
    cdsp_pair_set pairs;                      /* scratch */
} cdsp_points_ws;

/* Workspace of the frame path. Large (CDSP_MAX_EDGES * (4 reals + 1));
 * place it in static memory or allocate it yourself. */
typedef struct {
    cdsp_edge edge[CDSP_MAX_EDGES];
    uint8_t label[CDSP_MAX_EDGES];
    cdsp_profile_ws profile;
    cdsp_candidate cand[CDSP_MAX_CANDIDATES]; /* as in cdsp_points_ws */
    cdsp_pair_set pairs;                      /* scratch */
} cdsp_frame_ws;

/* Bytes of each single-path workspace as the library was built: equal to
 * the caller's sizeof only when both were compiled with the same
 * capacities (CDSP_MAX_POINTS, _EDGES, _LINES, _PAIRS, _CANDIDATES), which
 * firmware with smaller capacities can check once at start. */
size_t cdsp_points_ws_size(void);
size_t cdsp_frame_ws_size(void);

/*
 * Undistorted edge points -> pipe axis: RANSAC candidate lines, pair
 * selection (polarity, pipe side, overlap, radius/distance plausibility),
 * refit, closed-form solve, uncertainty and visible segment.
 * pts must be undistorted (cdsp_camera_undistort_edges); n <= CDSP_MAX_POINTS.
 * prior may be NULL; when given, the line search tries its two contours
 * first (seeds: no random samples when they hold the points, docs/method.md
 * §3) and the direction sign follows it.
 * Returns CDSP_OK, CDSP_E_FEW_POINTS, CDSP_E_NO_PIPE, CDSP_E_DEGENERATE,
 * CDSP_E_CAPACITY, CDSP_E_ARG, CDSP_E_NONFINITE.
 */
cdsp_status cdsp_points_solve(const cdsp_camera *cam, cdsp_real radius,
                              const cdsp_edge *pts, size_t n, const cdsp_params *p,
                              const cdsp_result *prior, cdsp_points_ws *ws,
                              cdsp_rng *rng, cdsp_result *out);

/*
 * Frame -> pipe axis. With prior == NULL: full search over p->edge.roi.
 * With a prior (the previous frame's result): edges are searched only in
 * bands of +-track_band_px around the prior's contours (distorted back into
 * the frame), and the line search tries the prior's contours first (as in
 * cdsp_points_solve); if that yields too few inliers or no pipe, a full
 * search follows. out->flags tells which path produced the result.
 * The frame's size must equal the calibration's (CDSP_E_ARG otherwise).
 * When a contour of the pose has points scattered beyond the frame's
 * noise (rms above 1.5 x 3 sigma / step and more than 0.2 px beyond it,
 * lib/frame.c) its line, and any sigma or bound from it, would not hold
 * (issue 12: the shadowed limb at ambient 0.4): the pose is reported with
 * CDSP_FLAG_BOUND clear (bounds 0) and its confidence capped at 0.78, the
 * fraction of such poses right on make bench-detect (docs/method.md §6),
 * so min_confidence above 0.78 gives CDSP_E_NO_PIPE for it.
 * out->edge_bound and bound_* (CDSP_FLAG_BOUND): the systematic bound.
 */
cdsp_status cdsp_frame_solve(const cdsp_image *img, const cdsp_camera *cam,
                             cdsp_real radius, const cdsp_params *p,
                             const cdsp_result *prior, cdsp_frame_ws *ws,
                             cdsp_rng *rng, cdsp_result *out);

/*
 * The full search in the caller's hands, e.g. in strips on its threads
 * (cdsp_edges_detect_strip; the library itself starts none):
 *   cdsp_frame_prepare(img, p, &fe): the frame's noise and the edge
 *     parameters the full search uses on it (fe.edge: p->edge with this
 *     frame's threshold); then the caller detects with fe.edge into
 *     ws->edge (at most CDSP_MAX_EDGES), setting fe.status (CDSP_OK, or
 *     CDSP_E_CAPACITY as cdsp_edges_detect returns it) and fe.n;
 *   cdsp_frame_solve_detected(img, cam, radius, p, &fe, ws, rng, out):
 *     the rest. With cdsp_edges_detect's edges (or strips merged into the
 *     same list) the result is cdsp_frame_solve's with no prior, bit for
 *     bit; the coarse pass's whole-frame fallback runs inside, on one core.
 * Returns as cdsp_frame_solve (prepare: CDSP_OK, CDSP_E_ARG, CDSP_E_FORMAT).
 */
typedef struct {
    cdsp_edge_params edge; /* the full search's parameters on this frame */
    cdsp_real min_step;    /* its edge step threshold, gray levels */
    cdsp_real sigma;       /* the frame's noise, gray levels */
    cdsp_status status;    /* set by the caller: the detection's status */
    size_t n;              /* set by the caller: edges in ws->edge */
} cdsp_frame_edges;

cdsp_status cdsp_frame_prepare(const cdsp_image *img, const cdsp_params *p, cdsp_frame_edges *fe);
cdsp_status cdsp_frame_solve_detected(const cdsp_image *img, const cdsp_camera *cam,
                                      cdsp_real radius, const cdsp_params *p,
                                      const cdsp_frame_edges *fe, cdsp_frame_ws *ws,
                                      cdsp_rng *rng, cdsp_result *out);

/* Distance from a 3D point to the axis of a result (radius units). */
cdsp_real cdsp_result_point_distance(const cdsp_result *r, const cdsp_real X[3]);

/* ------------------------------------------------------------------------
 * Every pipe in view (issue 13; lib/multi.c): the pipes of a rack.
 *
 * The single-pipe calls rank candidate bands and return the first. Here
 * every pair of candidate lines that passes the pair tests ("The pair
 * score" above) is an edge of a graph whose nodes are the contour lines,
 * and the pipes are a matching of it: no contour belongs to two pipes.
 * The matching has the most pairs the lines allow (then, among those, the
 * greedy best-score one, improved by augmenting paths taken in score
 * order): in a rack of k bright pipes the k pipes explain all 2k contours,
 * while the k - 1 dark gaps between them would leave the two outer
 * contours unexplained, so a gap (whose two "contours" are one contour of
 * each neighbour) is never chosen over the pipes beside it, whatever the
 * scores. Pipes are returned best score first. Confidence of each: its
 * evidence E alone (how sure this band is a pipe; the single path's margin
 * over rivals measures which pipe is meant, which a rack does not ask),
 * with the single path's cap for a narrow band whose contour's contrast
 * flips along it (0.89, cdsp_result.confidence); min_confidence drops
 * weaker pipes.
 * ---------------------------------------------------------------------- */

/* Pipes one call returns at most (capacity of the caller's output). */
#ifndef CDSP_MAX_PIPES
#define CDSP_MAX_PIPES 8
#endif

/* Workspaces of the two multi-pipe paths: the single path's, whose pair
 * set (every scored pair, not only the best) they use. */
typedef struct {
    cdsp_frame_ws frame;
} cdsp_frame_all_ws;

typedef struct {
    cdsp_points_ws points;
} cdsp_points_all_ws;

/* Bytes of each workspace (the query for callers that place them in
 * memory of their own, e.g. one per worker thread; as the single path's
 * queries above). */
size_t cdsp_frame_all_ws_size(void);
size_t cdsp_points_all_ws_size(void);

/* Tracks the tracker keeps: a pipe out of view for a few frames keeps its
 * slot (and id) for max_missed frames. */
#ifndef CDSP_MAX_TRACKS
#define CDSP_MAX_TRACKS (2 * CDSP_MAX_PIPES)
#endif

/* Caller-owned multi-pipe tracker state (place it anywhere; initialize
 * with cdsp_tracker_init, then pass it to every frame of the sequence). */
typedef struct {
    uint32_t id;             /* 0: free slot */
    uint32_t missed;         /* consecutive frames without a match */
    cdsp_real lines[2][3];   /* the pipe's contours last seen (undistorted px) */
    cdsp_real mid[2];        /* its visible segment's middle, undistorted px */
    cdsp_real direction[3];  /* its axis direction last seen (sign kept) */
    cdsp_real velocity[2];   /* each contour's shift along its normal from the
                                frame before to the last, px per frame: the
                                track is looked for where it will be, so a
                                rack panning by about a gap per frame does
                                not hand a pipe's track to the gap beside it */
} cdsp_track;

typedef struct {
    cdsp_track track[CDSP_MAX_TRACKS];
    uint32_t next_id;        /* the id the next new pipe gets (starts at 1) */
    cdsp_real gate_px;       /* a pipe continues a track when both its
                                contours lie within gate_px of the track's
                                predicted ones (at the pipe's middle,
                                undistorted px; constant velocity) and its
                                apparent width is within 25 % of theirs.
                                Default 24: the image may move that much
                                between two frames */
    int max_missed;          /* frames a track survives unseen. Default 2 */
    int full_every;          /* frame path: at most full_every - 1 frames in a
                                row are read in the bands alone, then one
                                full search, so that a pipe coming into view
                                while every track is held is found within
                                full_every frames (the bands see only the
                                tracks' contours). Default 10 (0.4 s at 25
                                frames/s; on the paper's rack a full search
                                costs 2.8 tracked frames, so +18 % on
                                average); 0: never while every track holds */
    uint32_t since_full;     /* state: frames read in the bands alone since
                                the last full search */
} cdsp_tracker;

void cdsp_tracker_init(cdsp_tracker *t);

/*
 * Frame -> every pipe in view, best score first: writes up to cap (at most
 * CDSP_MAX_PIPES are ever found) full results to out and their number to
 * *n_out; each has its own confidence, uncertainty, segment and (with a
 * tracker) track_id. Without a tracker, when a live track was not
 * seen the frame before, or every trk->full_every frames, a full search of
 * p->edge.roi; otherwise, with a tracker whose every live track was seen
 * the frame before, only bands of
 * +-track_band_px around each track's predicted contours are read (as
 * cdsp_frame_solve's tracking; results flagged CDSP_FLAG_TRACKED), and
 * when a track is not found there (within gate_px, track_min_inliers on
 * each contour) the full search runs instead. A pipe entering the view
 * while every track is held is found at the next full search, at most
 * full_every frames later. With a
 * tracker, each pipe is matched to the track whose contours are nearest
 * (within gate_px), keeps its id and its direction's sign, and new pipes
 * get new ids. Returns CDSP_OK with *n_out >= 1, or the single path's statuses
 * (CDSP_E_NO_PIPE when there is none; *n_out = 0 then). cdsp_frame_solve's
 * results are not changed by this call's existence.
 */
cdsp_status cdsp_frame_solve_all(const cdsp_image *img, const cdsp_camera *cam,
                                 cdsp_real radius, const cdsp_params *p, cdsp_tracker *trk,
                                 cdsp_frame_all_ws *ws, cdsp_rng *rng, cdsp_result *out,
                                 size_t cap, size_t *n_out);

/* The paper's spacing measure (Eq. 17-21, docs/method.md §8): the mean
 * distance from n points evenly spaced along a's visible segment (segment
 * midpoints of n equal parts) to b's axis, and its spread (RMS about the
 * mean) along the segment; radius units. For two parallel pipes the mean
 * is their spacing. CDSP_E_ARG for NULL or n < 1, CDSP_E_NONFINITE for a
 * result holding NaN/Inf. */
cdsp_status cdsp_result_axis_spacing(const cdsp_result *a, const cdsp_result *b, int n,
                                     cdsp_real *mean, cdsp_real *spread);

/* Undistorted edge points -> every pipe (as cdsp_points_solve and
 * cdsp_frame_solve_all); n <= CDSP_MAX_POINTS. */
cdsp_status cdsp_points_solve_all(const cdsp_camera *cam, cdsp_real radius,
                                  const cdsp_edge *pts, size_t n, const cdsp_params *p,
                                  cdsp_tracker *trk, cdsp_points_all_ws *ws, cdsp_rng *rng,
                                  cdsp_result *out, size_t cap, size_t *n_out);

/* ------------------------------------------------------------------------
 * Simulated frames (tests, tools, the daemon's simulated camera).
 * ---------------------------------------------------------------------- */
#ifndef CDSP_RENDER_MAX_CLUTTER
#define CDSP_RENDER_MAX_CLUTTER 8
#endif

/* Largest blur_sigma_px: the kernel's radius (3 sigma) fits its buffer. */
#define CDSP_RENDER_MAX_BLUR_PX 8

typedef struct {
    cdsp_real p0[3], p1[3];  /* camera-frame endpoints of the clutter bar's
                                centre line (a box-like bar seen side on) */
    cdsp_real half_width;    /* radius units */
    cdsp_real level;         /* intensity, fraction of full scale */
} cdsp_clutter;

/* Pipes one scene can hold (the first plus extra_pipe[]). */
#ifndef CDSP_RENDER_MAX_PIPES
#define CDSP_RENDER_MAX_PIPES 8
#endif

/* A further pipe of a rack: a finite cylinder, camera frame, radius units,
 * as the scene's own axis_point, axis_dir, radius and half_length. */
typedef struct {
    cdsp_real axis_point[3];
    cdsp_real axis_dir[3];
    cdsp_real radius;
    cdsp_real half_length;     /* 0 = infinite */
} cdsp_scene_pipe;

typedef struct {
    /* the pipe: a finite cylinder, camera frame, radius units */
    cdsp_real axis_point[3];   /* one point on the axis */
    cdsp_real axis_dir[3];     /* direction (need not be unit) */
    cdsp_real radius;
    cdsp_real half_length;     /* the pipe spans axis_point +- half_length*dir;
                                  0 = infinite */
    /* intensities, fraction of full scale */
    cdsp_real pipe_level;      /* albedo of the pipe body */
    cdsp_real cap_level;       /* albedo of the end caps */
    cdsp_real background_level;
    cdsp_real light[3];        /* direction TO the light; shading =
                                  ambient + (1 - ambient) * max(0, n.light) */
    cdsp_real ambient;         /* 1 = flat, no shading */
    cdsp_real texture;         /* background texture amplitude (fraction) */
    cdsp_real texture_scale_px;/* its feature size, px */
    cdsp_real blur_sigma_px;   /* Gaussian optical blur, 0..CDSP_RENDER_MAX_BLUR_PX
                                  (needs scratch) */
    cdsp_real noise_sigma;     /* Gaussian sensor noise, fraction of full scale */
    int n_clutter;             /* <= CDSP_RENDER_MAX_CLUTTER, behind or in front */
    cdsp_clutter clutter[CDSP_RENDER_MAX_CLUTTER];
    uint32_t texture_seed;
    /* Added for the detection tests and benchmark (issue 10); all 0 in
     * cdsp_scene_default, and 0 leaves a frame bit-identical to before. */
    cdsp_real background_ramp[2]; /* background brightness slope, fraction of
                                  full scale per undistorted px along u and v,
                                  about the principal point: a ramp that
                                  crosses the pipe's level flips the contrast
                                  along a contour */
    cdsp_real specular;        /* Blinn-Phong highlight on the pipe body:
                                  specular * max(0, n.h)^specular_exp added
                                  (fraction of full scale; values above full
                                  scale saturate) */
    cdsp_real specular_exp;    /* its exponent (>= 1 when specular > 0) */
    cdsp_real motion_px[2];    /* linear motion blur: the image moves by this
                                  vector (distorted px) during the exposure;
                                  |motion| <= CDSP_RENDER_MAX_MOTION_PX */
    /* Added for racks (issue 13); 0 in cdsp_scene_default, and 0 leaves a
     * frame bit-identical to before. More pipes with the first one's look
     * (pipe_level, cap_level, light, ambient, specular), each rendered like
     * it: exact area coverage along its contours, the nearest surface wins
     * where they overlap in the image. */
    int n_extra_pipes;         /* 0..CDSP_RENDER_MAX_PIPES - 1 */
    cdsp_scene_pipe extra_pipe[CDSP_RENDER_MAX_PIPES - 1];
} cdsp_scene;

#define CDSP_RENDER_MAX_MOTION_PX 64

void cdsp_scene_default(cdsp_scene *s);

/* Floats of scratch cdsp_render needs for a w x h frame (two frame buffers,
 * the second for motion blur, and a line buffer); 0 is fine when
 * blur_sigma_px == 0 and motion_px is zero. */
size_t cdsp_render_scratch_size(int width, int height);

/*
 * Render the scene as seen by cam into out (width x height of the camera,
 * bits 8 or 16 as given by out_bits, tightly packed rows unless stride says
 * otherwise). Anti-aliased by exact area coverage along the pipe's contours
 * (supersampled near end caps and clutter), with the camera's distortion.
 * rng supplies sensor noise (may be NULL when noise_sigma == 0).
 * scratch: cdsp_render_scratch_size() floats, or NULL without blur (optical
 * or motion).
 * CDSP_E_NONFINITE when any real of the scene (levels, light, geometry,
 * clutter) is NaN or infinite; CDSP_E_ARG for values out of range.
 */
cdsp_status cdsp_render(const cdsp_scene *s, const cdsp_camera *cam, void *out,
                        size_t stride, int out_bits, float *scratch, size_t scratch_len,
                        cdsp_rng *rng);

/* The exact contour lines of an infinite cylinder (undistorted px, oriented
 * as in cdsp_line: toward the brighter side assuming pipe brighter when
 * pipe_brighter != 0) and a pixel inside; the ground truth for tests.
 * CDSP_E_DEGENERATE when the camera is inside or the pipe is behind (or so
 * close to the camera's plane that its image is not finite); the camera is
 * checked (cdsp_camera_check). */
cdsp_status cdsp_cylinder_contours(const cdsp_camera *cam, const cdsp_real axis_point[3],
                                   const cdsp_real axis_dir[3], cdsp_real radius,
                                   int pipe_brighter, cdsp_real l1[3], cdsp_real l2[3],
                                   cdsp_real p_in[2]);

/* The paper's simulated set-up (docs/method.md §9), the scene the tests,
 * `cdsp_tool sim` and `cdsp_tool bench` measure against:
 * - the camera: 2448 x 2048 pixels of 3.45 um behind a 12 mm lens
 *   (fx = fy = 3478.26 px), principal point at the centre of the pixel grid
 *   ((w - 1) / 2, (h - 1) / 2), no distortion;
 * - its pose: optical centre C = (150, 200, 300) mm in the world, looking
 *   at the world origin with Z_W up; x_cam = R (X_world - C), R row-major
 *   with rows (image right, image down, optical axis);
 * - pipe k = 0..3 (the paper's p1..p4, 500 mm long, in the plane Z_W = 0):
 *   the middle of its axis and its unit direction in camera coordinates
 *   (mm), and half its length (half_length may be NULL); CDSP_E_ARG for any
 *   other k. */
void cdsp_render_paper_camera(cdsp_camera *cam);
void cdsp_render_paper_pose(cdsp_real R[9], cdsp_real C[3]);
cdsp_status cdsp_render_paper_pipe(int k, cdsp_real point[3], cdsp_real dir[3],
                                   cdsp_real *half_length);

#ifdef __cplusplus
}
#endif

#endif /* CDSP_H */
