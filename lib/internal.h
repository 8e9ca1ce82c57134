/*
 * internal.h - private helpers shared by the lib modules: precision-generic math
 * (so the float build never promotes to double on a single-precision FPU)
 * and small 3-vector operations. Not installed; not part of the contract.
 */
#ifndef CDSP_INTERNAL_H
#define CDSP_INTERNAL_H

#include <float.h> /* a freestanding header: every compiler has it */
#include "cdsp.h"

/* Hosted builds take the math functions from <math.h>; freestanding ones
 * (-ffreestanding, e.g. riscv64-unknown-elf without a C library) use the
 * compiler's builtins, which become the same libm calls the firmware links. */
#if defined(__STDC_HOSTED__) && __STDC_HOSTED__ == 0 && defined(__GNUC__)
#define CDSP__MATH(f) __builtin_##f
#define R_FINITE(x) (__builtin_isfinite(x))
#else
#include <math.h>
#define CDSP__MATH(f) f
#define R_FINITE(x) (isfinite(x)) /* C99 generic: float and double */
#endif

/* R(x): a literal in the working precision. */
#define R(x) ((cdsp_real)(x))

#ifdef CDSP_SINGLE
#define R_SQRT CDSP__MATH(sqrtf)
#define R_FABS CDSP__MATH(fabsf)
#define R_ATAN2 CDSP__MATH(atan2f)
#define R_SIN CDSP__MATH(sinf)
#define R_COS CDSP__MATH(cosf)
#define R_LOG CDSP__MATH(logf)
#define R_EXP CDSP__MATH(expf)
#define R_FLOOR CDSP__MATH(floorf)
#define R_CEIL CDSP__MATH(ceilf)
#define R_EPS FLT_EPSILON
#define R_MAX FLT_MAX
#else
#define R_SQRT CDSP__MATH(sqrt)
#define R_FABS CDSP__MATH(fabs)
#define R_ATAN2 CDSP__MATH(atan2)
#define R_SIN CDSP__MATH(sin)
#define R_COS CDSP__MATH(cos)
#define R_LOG CDSP__MATH(log)
#define R_EXP CDSP__MATH(exp)
#define R_FLOOR CDSP__MATH(floor)
#define R_CEIL CDSP__MATH(ceil)
#define R_EPS DBL_EPSILON
#define R_MAX DBL_MAX
#endif

#define R_PI R(3.14159265358979323846)


static inline cdsp_real v3_dot(const cdsp_real a[3], const cdsp_real b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

static inline void v3_cross(const cdsp_real a[3], const cdsp_real b[3], cdsp_real out[3])
{
    cdsp_real x = a[1] * b[2] - a[2] * b[1];
    cdsp_real y = a[2] * b[0] - a[0] * b[2];
    cdsp_real z = a[0] * b[1] - a[1] * b[0];
    out[0] = x;
    out[1] = y;
    out[2] = z;
}

static inline cdsp_real v3_norm(const cdsp_real a[3])
{
    return R_SQRT(v3_dot(a, a));
}

/* Normalizes in place; returns the original length (0 leaves a untouched). */
static inline cdsp_real v3_normalize(cdsp_real a[3])
{
    cdsp_real n = v3_norm(a);
    if (n > R(0)) {
        a[0] /= n;
        a[1] /= n;
        a[2] /= n;
    }
    return n;
}

static inline void v3_scale(cdsp_real a[3], cdsp_real s)
{
    a[0] *= s;
    a[1] *= s;
    a[2] *= s;
}

static inline int v3_finite(const cdsp_real a[3])
{
    return R_FINITE(a[0]) && R_FINITE(a[1]) && R_FINITE(a[2]);
}

static inline int iabs(int v)
{
    return v < 0 ? -v : v;
}

/* Zero an object byte by byte, padding included (no <string.h> needed). */
static inline void zero_bytes(void *p, size_t n)
{
    unsigned char *b = (unsigned char *)p;
    while (n--)
        *b++ = 0;
}

/* A hint that the cache line holding p will be read soon: where the
 * frame path's data come from memory (a camera frame arrives by DMA, not
 * in the caches) the scans issue it some rows ahead of what they read, so
 * that the misses overlap instead of stalling one after the other. GCC /
 * clang on the targets with a cache hierarchy it pays on (x86, AArch64);
 * elsewhere (Cortex-M, other compilers) nothing. A prefetch never faults
 * and changes no result. */
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__) || defined(__aarch64__))
#define CDSP__PREFETCH(p) __builtin_prefetch((const void *)(p), 0, 3)
/* Every cache line of bytes [p, p + n), n >= 1 (a row the scan reads
 * next). A macro, not a function: GCC 12 finds a void function whose only
 * effect is __builtin_prefetch const and drops its calls. */
#define CDSP__PREFETCH_RANGE(p, n)                                                                 \
    do {                                                                                           \
        const unsigned char *pr_p = (const unsigned char *)(p);                                    \
        size_t pr_i, pr_n = (size_t)(n);                                                           \
        for (pr_i = 0; pr_i < pr_n; pr_i += 64)                                                    \
            CDSP__PREFETCH(pr_p + pr_i);                                                           \
        CDSP__PREFETCH(pr_p + pr_n - 1);                                                           \
    } while (0)
#else
#define CDSP__PREFETCH(p) ((void)(p))
#define CDSP__PREFETCH_RANGE(p, n) ((void)(p), (void)(n))
#endif

/* The closed form's output before it becomes a cdsp_result (small: the
 * uncertainty propagation keeps several alive at once on MCU stacks). */
typedef struct {
    cdsp_real point[3], direction[3], distance, alpha, normals[2][3];
} cdsp__axis;

/* Pixel fetch for 8- or 16-bit frames (bounds are the caller's job). */
static inline int img_px(const cdsp_image *img, int x, int y)
{
    const unsigned char *row = (const unsigned char *)img->data + (size_t)y * img->stride;
    if (img->bits <= 8)
        return row[x];
    return ((const uint16_t *)(const void *)row)[x];
}

/* Internal entry points shared between modules (see their .c files). */
/* cdsp_rng_below in two steps, for many draws with one n (RANSAC): the
 * rejection threshold once, then draws that give the same stream as
 * cdsp_rng_below(rng, n) with one division each instead of two. n > 0. */
uint32_t cdsp__rng_threshold(uint32_t n);
uint32_t cdsp__rng_below_t(cdsp_rng *rng, uint32_t n, uint32_t threshold);
/* cos_tol = cos(p->normal_tol_deg): computed by the caller, which keeps the
 * trigonometry (and libm's deep range reduction) off this call's stack.
 * seed: NULL, or the two lines where contours are expected (the tracking
 * prior's, in the points' coordinates), tried before any draw
 * (lib/lines.c). */
cdsp_status cdsp__lines_find(const cdsp_edge *pts, size_t n, uint8_t *label,
                             const cdsp_pair_params *p, cdsp_real cos_tol, const cdsp_real (*seed)[3],
                             cdsp_rng *rng, cdsp_line *lines, int *nlines, int *capped);
/* The points path's pose (lib/pair.c): score_pairs, cdsp__pair_rank and
 * cdsp__pair_pose without the frame. min_step: the edge step threshold the
 * points were detected with (gray levels; 0 when unknown, e.g. the points
 * path): contrast is scored relative to it. cand: CDSP_MAX_CANDIDATES slots
 * for the ranked list; set: the workspace's pair set. The frame path
 * (lib/frame.c) makes the same calls with cdsp__pair_score_frame and the
 * edge-profile model between rank and pose, so that a points-only firmware
 * links neither the frame sampling nor the model (docs/mcu.md). */
cdsp_status cdsp__pair_solve(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts,
                             size_t n, uint8_t *label, cdsp_candidate *cand, cdsp_pair_set *set,
                             const cdsp_params *p, cdsp_real min_step, const cdsp_result *prior,
                             cdsp_rng *rng, cdsp_result *out);
/* What the edge-profile model did to a pair's two lines (lib/frame.c):
 * each line's move along its normal and the modelled blur, px (0 for a
 * line it could not model), and how many of the two it modelled. */
typedef struct {
    cdsp_real offset[2], blur[2];
    cdsp_real bound[2]; /* cdsp_result.edge_bound, valid when bounded */
    int profiled, bounded;
    cdsp_real var_scale; /* the line fits' variance factor for points that
                            share scanlines (cdsp__edges_scan_var); 1:
                            independent points */
    cdsp_real sigma_offset[2]; /* > 0: the line sits on the model's
                                  silhouette, whose noise (px, undistorted)
                                  is its offset's, in place of the points'
                                  (0: the points', lib/pair.c propagate) */
} cdsp__pair_refined;
/* The ranking of set's scored pairs into cand (confidences included; the
 * best pair in *best, the candidates' number in *n_cand; CDSP_E_NO_PIPE when
 * none), and the pose of that pair: confidence, n_candidates, the
 * min_confidence test and the direction's sign (prior's, or the
 * convention) included; ref: NULL, or the edge-profile model's moves, the
 * lines in set already moved. */
cdsp_status cdsp__pair_rank(const cdsp_camera *cam, cdsp_real radius, const cdsp_pair_set *set,
                            cdsp_candidate *cand, const cdsp_params *p, cdsp_real min_step,
                            cdsp_pair_eval *best, uint32_t *n_cand);
cdsp_status cdsp__pair_pose(const cdsp_camera *cam, cdsp_real radius, size_t n,
                            const cdsp_pair_set *set, const cdsp_pair_eval *best, uint32_t n_cand,
                            const cdsp_candidate *cand, const cdsp_params *p,
                            const cdsp_result *prior, const cdsp__pair_refined *ref, cdsp_result *out);
/* conf capped at the flip rule's FLIP_CONF (lib/pair.c: a narrow band with
 * a contour whose contrast flips along it, its direction in depth unsure);
 * the single path's ranking and the multi-pipe path's results both. */
cdsp_real cdsp__pair_flip_cap(const cdsp_camera *cam, cdsp_real radius, const cdsp_pair_set *pset,
                              const cdsp_pair_eval *c, cdsp_real conf);
/* pair.c, split for the multi-pipe path (lib/multi.c): every candidate
 * line and scored pair (CDSP_E_NO_PIPE when none), one pair's full result
 * (confidence, n_candidates, track_id and the direction's sign are the
 * caller's), and a pair's evidence E (include/cdsp.h, "The pair score"). */
cdsp_status cdsp__pair_score_all(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts,
                                 size_t n, uint8_t *label, const cdsp_params *p, cdsp_real min_step,
                                 const cdsp_result *prior, cdsp_rng *rng, cdsp_pair_set *set);
/* The single path's scores (lib/pair.c): cdsp__pair_score_all's, with the
 * band's shading read from the frame (img, or NULL) and test (ix), gaps. */
cdsp_status cdsp__pair_score_frame(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts,
                                   size_t n, uint8_t *label, const cdsp_params *p, cdsp_real min_step,
                                   const cdsp_result *prior, cdsp_rng *rng, const cdsp_image *img,
                                   cdsp_pair_set *set);
/* One pair's result (ref as in cdsp__pair_pose; out written only on
 * CDSP_OK). */
cdsp_status cdsp__pair_result(const cdsp_camera *cam, cdsp_real radius, size_t n,
                              const cdsp_pair_set *set, const cdsp_pair_eval *c,
                              const cdsp__pair_refined *ref, cdsp_result *out);
cdsp_real cdsp__pair_evidence(const cdsp_pair_eval *c, int contrast_known);
/* Distance d within the pair parameters' range (a bound of 0: none). */
int cdsp__pair_in_range(const cdsp_pair_params *p, cdsp_real d);
/* Which of the pair tests (lib/pair.c, docs/method.md §4) lines i and j of
 * set fail (no prior): CDSP__PAIR_PASSED, a CDSP__PAIR_* code, -1 for bad
 * indices. For diagnosis (tests/bench/bench_detect.c). */
enum {
    CDSP__PAIR_PASSED, CDSP__PAIR_ANGLE, CDSP__PAIR_STAIRCASE, CDSP__PAIR_POLARITY, CDSP__PAIR_CLOSE,
    CDSP__PAIR_OVERLAP, CDSP__PAIR_MEET, CDSP__PAIR_AXIS, CDSP__PAIR_RANGE, CDSP__PAIR_WIDTH,
    CDSP__PAIR_SUPPORT, CDSP__PAIR_SPLIT, CDSP__PAIR_GAP, CDSP__PAIR_BUSY, CDSP__PAIR_JUNCTION,
    CDSP__PAIR_NTESTS
};
/* The confidence model (lib/pair.c): features of candidate k among the nc
 * ranked ones, and the confidence they give. */
#define CDSP__CONF_NX 9
void cdsp__pair_features(const cdsp_candidate *cand, uint32_t nc, uint32_t k, int ranged,
                         int contrast_known, cdsp_real x[CDSP__CONF_NX]);
cdsp_real cdsp__pair_confidence(const cdsp_candidate *cand, uint32_t nc, uint32_t k, int ranged,
                                int contrast_known);
int cdsp__pair_why(const cdsp_camera *cam, cdsp_real radius, const cdsp_edge *pts, size_t n,
                   const uint8_t *label, const cdsp_params *p, cdsp_real min_step,
                   const cdsp_image *img, const cdsp_pair_set *set, int i, int j);
/* Every coordinate and gradient of the n points is finite. */
int cdsp__points_finite(const cdsp_edge *e, size_t n);
/* frame.c: a full search's edge points (undistorted; the whole frame,
 * whatever p->edge.coarse says) in ws->edge, *n of them, with the frame's noise and step threshold; *flags gets
 * CDSP_FLAG_FULL_SEARCH and CDSP_FLAG_TRUNCATED when it applies. */
cdsp_status cdsp__frame_edges(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                              cdsp_frame_ws *ws, size_t *n, cdsp_real *sigma, cdsp_real *min_step,
                              uint32_t *flags);
/* frame.c: the segment [*from, *to] of scanline `line` (a row when
 * horizontal, else a column) that a tracked solve reads around undistorted
 * line l: +-band px of where l crosses it in the distorted frame, clipped
 * to [smin, smax] and to the edge window's reach (h + 1 .. ext - h - 1,
 * ext the scanline's length); 0 when l does not cross it within band of
 * [smin, smax] or the crossing cannot be computed. nodist:
 * cdsp__camera_no_distortion(cam), the fast form. lib/frame.c's and
 * lib/multi.c's tracked solves. */
int cdsp__frame_band(const cdsp_camera *cam, int nodist, const cdsp_real l[3], int horizontal, int line,
                     cdsp_real band, int smin, int smax, int h, int ext, int *from, int *to);
/* frame.c: whether a contour of pose out (its lines named by out->label in
 * ws->pairs) has points too scattered to be one edge for the frame's noise
 * sigma (issue 12; the rule and its figures at its definition). The single
 * path and cdsp_frame_solve_all report such a pose without a bound
 * (cdsp__frame_scatter_mark). */
int cdsp__frame_scattered(const cdsp_frame_ws *ws, const cdsp_result *out, cdsp_real sigma);
/* frame.c: when pose out is scattered (above), its systematic bound marked
 * not measured (CDSP_FLAG_BOUND clear, edge_bound and bound_* 0) and *conf
 * capped below 0.9; 1 then, 0 (nothing changed) otherwise. */
int cdsp__frame_scatter_mark(const cdsp_frame_ws *ws, cdsp_result *out, cdsp_real sigma, cdsp_real *conf);
/* frame.c: the edge-profile model on pair c's two lines of set (moved in
 * place when modelled; the moves and their noise in *ref, noise the frame's
 * measured noise), with scratch pws; nothing when p->profile.enable is 0.
 * Only the frame paths call it, so the points path does not link
 * lib/profile.c. */
void cdsp__frame_refine(const cdsp_image *img, const cdsp_camera *cam, const cdsp_edge *pts, size_t n,
                        const uint8_t *label, cdsp_pair_set *set, const cdsp_pair_eval *c,
                        const cdsp_params *p, cdsp_real noise, cdsp_profile_ws *pws, cdsp__pair_refined *ref);
/* rescan.c (cdsp_params.refine_step): line ln refitted to its inliers
 * among the edges of the scanlines its extent crosses, read again at step
 * p->refine_step around it with the frame's threshold min_step (gray
 * levels); ln unchanged unless CDSP_OK (nothing done: refine_step 0).
 * cdsp__rescan_pair: both lines of pair c of set, each with the move
 * ref->offset of the edge-profile model (ref NULL: none) undone for the
 * refit; then the model fitted again about the refitted line from src's
 * points (src NULL, or where it no longer applies: the move done again);
 * neither changed unless both refit. */
typedef struct {
    const cdsp_edge *pts; /* the search's points and their line labels */
    size_t n;
    const uint8_t *label;
    cdsp_profile_ws *pws;
    cdsp_real noise; /* the frame's measured noise, gray levels */
} cdsp__profile_src;
cdsp_status cdsp__rescan_line(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                              cdsp_real min_step, cdsp_line *ln);
cdsp_status cdsp__rescan_pair(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                              cdsp_real min_step, cdsp_pair_set *set, const cdsp_pair_eval *c,
                              const cdsp__profile_src *src, cdsp__pair_refined *ref);
cdsp_status cdsp__profile_refine(const cdsp_image *img, const cdsp_camera *cam, const cdsp_edge *pts,
                                 size_t n, const uint8_t *label, uint8_t lab, cdsp_line *ln,
                                 const cdsp_real p_in[2], const cdsp_profile_params *pp,
                                 int detector_h, cdsp_real noise, cdsp_profile_ws *ws, cdsp_profile *prof,
                                 cdsp_real *moved, cdsp_real *sigma_moved);
cdsp_status cdsp__profile_params_check(const cdsp_profile_params *p);
cdsp_status cdsp__axis_core(const cdsp_camera *cam, const cdsp_real l1[3], const cdsp_real l2[3],
                            const cdsp_real p_in[2], cdsp_real radius, cdsp__axis *out);
void cdsp__axis_to_result(const cdsp__axis *a, const cdsp_real l1[3], const cdsp_real l2[3],
                          cdsp_result *r);
void cdsp__axis_swap(cdsp_result *r);
int cdsp__axis_wants_swap(const cdsp_real v[3]);
cdsp_status cdsp__params_check(const cdsp_params *p);
/* The checks every solve entry point makes: camera, radius, parameters. */
cdsp_status cdsp__solve_args_check(const cdsp_camera *cam, cdsp_real radius, const cdsp_params *p);
cdsp_status cdsp__edge_params_check(const cdsp_edge_params *p);
/* lines.c: floor(0.618034 n) without overflow for any size_t width (the
 * start of RANSAC's golden-ratio subsample stride); tested on its own. */
size_t cdsp__golden_start(size_t n);
/* The roi clipped to the frame as [x0, x1) x [y0, y1) (w or h <= 0: the
 * whole frame); any roi values, no overflow. */
void cdsp__edges_clip_roi(const cdsp_image *img, const cdsp_roi *roi, int *x0, int *y0, int *x1,
                          int *y1);
size_t cdsp__edges_scan_segment(const cdsp_image *img, const cdsp_edge_params *p,
                                int horizontal, int line, int from, int to,
                                cdsp_edge *out, size_t cap);
/* edges.c: the partial-area estimate at candidate (s along the scan, t
 * across it; horizontal: s is x on row t): 1 and *e filled when it is a
 * valid edge owned by this scan direction. The scans call it; so does the
 * reference scan of tests/lib/test_edges_scan.c. */
/* The variance factor of a line fitted to one family's points read at
 * scanline spacing step (see lib/edges.c): 3 at step 1, 5/3 at 2, 1 from 3. */
cdsp_real cdsp__edges_scan_var(int step);
int cdsp__edges_refine(const cdsp_image *img, int horizontal, int s, int t, int h, int min_step,
                       cdsp_edge *e);
/* The scans' candidate test on n parallel positions (8-bit samples,
 * 1 <= thr <= 255), lib/edges.c: f[0..4] are the runs of pixels at -2 .. +2
 * along the scan; position i's flag, bit i % 32 of bits[i / 32], is 1 when
 * |f[3][i] - f[1][i]| >= thr, > |f[2][i] - f[0][i]| and >= |f[4][i] -
 * f[2][i]| (a local maximum of the central difference) and sel[i] = 1
 * (sel: 0/1 bytes, or NULL for all), else 0; the (n + 31) / 32 words are
 * written, bits from n on 0, nothing past them; returns the OR of the
 * words (non-zero when any flag is set). bits must not overlap the
 * inputs. The portable form is always built (the reference);
 * cdsp__edges_peaks is the form the scans use: the SIMD one of
 * lib/edges_simd.c (SSE2 on x86-64, AVX2 when compiled with -mavx2, NEON
 * on AArch64) unless CDSP_NO_SIMD. */
uint32_t cdsp__edges_peaks_c(const uint8_t *const f[5], const uint8_t *sel, size_t n, int thr,
                             uint32_t *bits);
/* The column scans' gather (lib/edges.c): dst[k] = src[k * d], k < n (8-bit
 * samples, d >= 1), reading no byte outside [src, src + (n - 1) d];
 * portable form always built, cdsp__edges_gather the scans' form (the SIMD
 * one for d = 4, the default step, where the target has it). */
void cdsp__edges_gather_c(const uint8_t *src, ptrdiff_t d, int n, uint8_t *dst);
/* The same for rows r < rows: src + r stride into dst + r dstride. */
void cdsp__edges_gather_rows_c(const uint8_t *src, ptrdiff_t stride, ptrdiff_t d, int n, int rows,
                               uint8_t *dst, ptrdiff_t dstride);
/* The frame's noise estimate's small differences (lib/frame.c
 * frame_noise): of the n pairs' |q[2i + 1] - q[2i]| (8-bit samples),
 * cnt[v] += how many equal v, v = 0 .. 3; portable form always built,
 * the SIMD one (lib/edges_simd.c) what frame_noise uses where there is
 * one. */
void cdsp__noise_small_c(const uint8_t *q, size_t n, uint32_t cnt[4]);
#if !defined(CDSP_NO_SIMD) && (defined(__SSE2__) || (defined(__aarch64__) && defined(__ARM_NEON)))
#define CDSP__SIMD 1
void cdsp__noise_small_simd(const uint8_t *q, size_t n, uint32_t cnt[4]);
uint32_t cdsp__edges_peaks_simd(const uint8_t *const f[5], const uint8_t *sel, size_t n, int thr,
                                uint32_t *bits);
void cdsp__edges_gather_simd(const uint8_t *src, ptrdiff_t d, int n, uint8_t *dst);
void cdsp__edges_gather_rows_simd(const uint8_t *src, ptrdiff_t stride, ptrdiff_t d, int n, int rows,
                                  uint8_t *dst, ptrdiff_t dstride);
#define cdsp__edges_peaks cdsp__edges_peaks_simd
#define cdsp__edges_gather cdsp__edges_gather_simd
#define cdsp__edges_gather_rows cdsp__edges_gather_rows_simd
#else
#define CDSP__SIMD 0
#define cdsp__edges_peaks cdsp__edges_peaks_c
#define cdsp__edges_gather cdsp__edges_gather_c
#define cdsp__edges_gather_rows cdsp__edges_gather_rows_c
#endif

/* Frame-path speed (issue 17, session 6). */
/* camera.c: every distortion coefficient zero (distortion the identity in
 * floating point too; the fast forms of camera.c and lib/frame.c). */
int cdsp__camera_no_distortion(const cdsp_camera *c);
/* edges.c: tracking's column segments, up to CDSP__BAND_COLS columns
 * xs + k*step at a time over [from[k], to[k]) each: exactly the edges of
 * cdsp__edges_scan_segment on each column in turn (the same windows-fit
 * guarantee per column), read row by row. */
#define CDSP__BAND_COLS 32
size_t cdsp__edges_scan_col_bands(const cdsp_image *img, const cdsp_edge_params *p, int step, int xs,
                                  int ncols, const int *from, const int *to, cdsp_edge *out, size_t cap);

#endif /* CDSP_INTERNAL_H */
