/* board_render.h: synthetic checkerboard images with an exactly known
 * camera and pose, for the test of cdsp_calib. Test code only.
 *
 * Every pixel is the mean intensity of the board over the pixel's square
 * footprint (pixel (u, v) covers [u - 0.5, u + 0.5] x [v - 0.5, v + 0.5],
 * OpenCV's convention). A footprint point is mapped to the board through
 * the exact inverse of the camera model: distorted pixel -> undistorted
 * normalized point (1-D Newton on the radius, to machine precision) ->
 * ray -> intersection with the board plane. Pixels whose four footprint
 * corners fall in one region (one square, the border or the background)
 * are that region's intensity; the others are supersampled (89 samples on
 * a Fibonacci lattice). */
#ifndef BOARD_RENDER_H
#define BOARD_RENDER_H

#include <stdint.h>

typedef struct {
    double fx, fy, cx, cy;     /* px */
    double k1, k2;             /* plumb_bob with p1 = p2 = k3 = 0 */
    int width, height;         /* px */
} br_camera;

typedef struct {
    int cols, rows;            /* inner corners (the --board of cdsp_calib) */
    double square;             /* side of a square */
    double border;             /* white border around the squares, in squares */
} br_board;

/* Board -> camera: X_cam = R X_board + t, R from the rotation vector rvec
 * (Rodrigues). Board corner (i, j) is at (i square, j square, 0). */
typedef struct {
    double rvec[3];
    double t[3];
} br_pose;

/* Intensities, 0..1. */
#define BR_BLACK 0.1
#define BR_WHITE 0.9
#define BR_BACKGROUND 0.45

/* Rotation matrix (row-major) of a rotation vector. */
void br_rodrigues(const double rvec[3], double R[9]);

/* Camera point -> distorted pixel. 0 if behind the camera. */
int br_project(const br_camera *cam, const double X[3], double pix[2]);

/* Board point -> distorted pixel under pose. 0 if behind the camera. */
int br_project_board(const br_camera *cam, const br_pose *pose, double X, double Y,
                     double pix[2]);

/* 1 if the whole board with its border projects inside the image, at
 * least margin px from its edges (findChessboardCorners needs it whole). */
int br_visible(const br_camera *cam, const br_board *b, const br_pose *pose, double margin);

/* Renders into img (width x height, row-major). 0 on allocation failure. */
int br_render(const br_camera *cam, const br_board *b, const br_pose *pose, double *img);

/* Seeded normal noise (splitmix64 + Box-Muller): reproducible everywhere. */
typedef struct {
    uint64_t s;
    int have;
    double spare;
} br_rng;

void br_rng_seed(br_rng *r, uint64_t seed);
double br_rng_normal(br_rng *r);

/* Adds N(0, sigma) noise, clamps to 0..1 and writes a binary PGM (P5) with
 * the given maxval (255: 8 bit; up to 65535: 16 bit, big-endian). 0 on
 * failure. */
int br_write_pgm(const char *path, const double *img, int width, int height,
                 double sigma, br_rng *rng, int maxval);

#endif
