/*
 * bench_pixfmt - what cdspd's pixel-format conversion (daemon/pixfmt.c)
 * costs beside the solve, at the paper's 2448 x 2048: one frame of the
 * paper's pipe is rendered at 8 and 16 bit, turned into each camera format
 * as the fake camera does (tests/fakecam/fakecam_pixels.h), and each
 * conversion is timed (median of 15) against the median full-search and
 * tracked cdsp_frame_solve of the converted frame. Times are the thread's
 * CPU time (CLOCK_THREAD_CPUTIME_ID): on a shared machine wall time counts
 * the other programs' turns, which inflate long calls (a full solve, a
 * Bayer frame) more than short ones (a tracked solve) and so the ratios.
 * `make bench` (bench-pixfmt). Figures, not a test: exit 0 unless
 * something fails.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cdsp.h"
#include "fakecam_pixels.h"
#include "pixfmt.h"
#include "support.h"

static cdsp_frame_ws ws;

static double cpu_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int cmp(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

static double median(double *t, int n)
{
    qsort(t, (size_t)n, sizeof *t, cmp);
    return t[n / 2];
}

int main(void)
{
    static const char *names[] = {"Mono8", "Mono12", "Mono12Packed", "Mono10p", "BayerRG8",
                                  "BayerRG12", "BayerGB16", "RGB8"};
    static const double gain[3] = {FAKECAM_GAIN_R, FAKECAM_GAIN_G, FAKECAM_GAIN_B};
    cdsp_camera cam;
    cdsp_params prm;
    cdsp_scene s;
    cdsp_image img8, img16;
    cdsp_rng rng;
    double P[3], v[3], t[15], solve_full, solve_track;
    int w, h, i, k;
    size_t n;
    uint8_t *raw, *out;
    uint16_t *tmp;
    void *scratch;
    const uint8_t *g8;
    const uint16_t *g16;

    sup_paper_camera(&cam, 0, 0);
    cdsp_params_default(&prm);
    w = cam.width;
    h = cam.height;
    n = (size_t)w * (size_t)h;
    sup_paper_pipe(0, P, v);
    sup_scene(&s, P, v, 8);
    fprintf(stderr, "bench-pixfmt: rendering a %dx%d frame at 8 and 16 bit...\n", w, h);
    g8 = sup_render(&s, &cam, 8, 1, &img8);
    g16 = sup_render(&s, &cam, 16, 1, &img16);
    raw = malloc(3 * n + 16);
    out = malloc(2 * n);
    tmp = malloc(2 * n);
    scratch = malloc(3 * (size_t)w * sizeof(uint32_t));
    if (!g8 || !g16 || !raw || !out || !tmp || !scratch) {
        fprintf(stderr, "bench-pixfmt: out of memory\n");
        return 1;
    }
    cdsp_rng_seed(&rng, 1, 1);
    {
        cdsp_result r, r2;
        double tt[15];
        for (k = 0; k < 15; k++) {
            double t0 = cpu_now();
            if (cdsp_frame_solve(&img8, &cam, 8, &prm, NULL, &ws, &rng, &r) != CDSP_OK) {
                fprintf(stderr, "bench-pixfmt: the frame does not solve\n");
                return 1;
            }
            t[k] = (cpu_now() - t0) * 1e3;
            t0 = cpu_now();
            cdsp_frame_solve(&img8, &cam, 8, &prm, &r, &ws, &rng, &r2);
            tt[k] = (cpu_now() - t0) * 1e3;
        }
        solve_full = median(t, 15);
        solve_track = median(tt, 15);
    }
    printf("\n== pixel formats at %d x %d (daemon/pixfmt.c), CPU time, median of 15\n", w, h);
    printf("solve of the same frame: full search %.2f ms, tracked %.2f ms\n", solve_full, solve_track);
    printf("| %-13s | %-10s | %-17s | %-14s |\n", "format", "convert", "/ full solve", "/ tracked solve");
    for (i = 0; i < (int)(sizeof names / sizeof names[0]); i++) {
        const cdspd_pixfmt *f = cdspd_pixfmt_find(names[i]);
        int bits = f->bits, x, y;
        /* the camera's delivery of the grey frame (fakecam_pixels.h) */
        for (y = 0; y < h; y++)
            for (x = 0; x < w; x++) {
                size_t q = (size_t)y * (size_t)w + (size_t)x;
                double g = f->family == CDSPD_PIX_BAYER
                               ? gain[fakecam_bayer_colour(f->order == 0 ? "RGGB" : f->order == 1 ? "GRBG"
                                                          : f->order == 2 ? "GBRG" : "BGGR", x, y)]
                               : 1.0;
                unsigned v16 = (unsigned)(g16[q] * g + 0.5) >> (16 - (bits > 8 ? bits : 16));
                if (f->family == CDSPD_PIX_RGB) {
                    raw[3 * q] = (uint8_t)(g8[q] * gain[0] + 0.5);
                    raw[3 * q + 1] = (uint8_t)(g8[q] * gain[1] + 0.5);
                    raw[3 * q + 2] = (uint8_t)(g8[q] * gain[2] + 0.5);
                } else if (bits == 8) {
                    raw[q] = (uint8_t)(g8[q] * g + 0.5);
                } else {
                    tmp[q] = (uint16_t)v16;
                    raw[2 * q] = (uint8_t)v16;
                    raw[2 * q + 1] = (uint8_t)(v16 >> 8);
                }
            }
        if (f->packing == CDSPD_PACK_GV || f->packing == CDSPD_PACK_P)
            fakecam_pack(tmp, n, bits, f->packing == CDSPD_PACK_P ? 'p' : 'g', raw);
        for (k = 0; k < 15; k++) {
            double t0 = cpu_now();
            if (cdspd_pixfmt_convert(f, raw, 3 * n + 16, w, h, 0, 0, NULL, out,
                                     (size_t)w * (size_t)cdspd_pixfmt_out_bytes(f), scratch,
                                     3 * (size_t)w * sizeof(uint32_t))) {
                fprintf(stderr, "bench-pixfmt: %s: conversion refused\n", f->name);
                return 1;
            }
            t[k] = (cpu_now() - t0) * 1e3;
        }
        {
            double m = median(t, 15);
            printf("| %-13s | %7.2f ms | %16.0f %% | %13.0f %% |\n", f->name, m, 100 * m / solve_full,
                   100 * m / solve_track);
        }
    }
    free(raw);
    free(out);
    free(tmp);
    free(scratch);
    free((void *)g8);
    free((void *)g16);
    return 0;
}
