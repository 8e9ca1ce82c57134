/*
 * bench_rack.c - instruction counts of cdsp_frame_solve_all on the paper's
 * rack (issue 13): two 16 mm pipes 100 mm apart on two 12.68 mm columns,
 * 2448 x 2048, fx = fy = 4637.68 px, light 40 % ambient, blur 0.8 px,
 * noise 2 gray levels (the scene of tools/tool_rack_scene.c, which this
 * bench builds: arrangement A, group 2, texture seed 3). Two
 * frames, the rack moved by 1 mm (7.7 px, inside the 12 px tracking bands)
 * between them, rendered once and cached raw in DIR/rack.raw (valgrind
 * would take minutes to render). Frame 0 is solved with a new tracker (a
 * full search), then frame 1, the solve counted by valgrind
 * --tool=callgrind --toggle-collect=measured_solve, from the same
 * generator state in both modes:
 *   full   without the tracker (a full search);
 *   track  with it (the tracked solve, when it finds every track).
 * An optional third argument K sets cdsp_params.refine_step (the final
 * pass of lib/rescan.c; 0 = off, the default) for both frames, and a
 * fourth P cdsp_params.point_fit (0 or 1, with K >= 3).
 * Prints each solve's pipes and flags. Figures, not pass/fail.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "support.h"
#include "tool_rack_scene.h"

#define W RACK_W
#define H RACK_H
#define FOC RACK_F

static cdsp_frame_all_ws ws;

/* tool_rack.c's arrangement A, group 2 (tilt 25 degrees, no roll) with
 * the rack's middle at (dx, 0, 680) mm and texture seed 3 */
static void scene(double dx, cdsp_scene *s)
{
    double mid[3], c[2][3], v[3];
    mid[0] = dx;
    mid[1] = 0;
    mid[2] = 680;
    tool_rack_place(25 * 3.14159265358979 / 180, 0, mid, 3, s, c, v);
}

static void show(const char *what, cdsp_status st, const cdsp_result *out, size_t n)
{
    size_t k;
    printf("%s: %s, %zu pipes\n", what, cdsp_strerror(st), n);
    for (k = 0; k < n; k++)
        printf("  #%zu distance %.3f mm, flags 0x%x (%s), %u edge points, inliers %u %u, rms %.3f %.3f px, id %u\n", k,
               (double)out[k].distance, out[k].flags,
               out[k].flags & CDSP_FLAG_TRACKED ? "tracked" : "full search", out[k].n_edges, out[k].inliers[0],
               out[k].inliers[1], (double)out[k].rms[0], (double)out[k].rms[1], out[k].track_id);
}

/* The one solve counted (callgrind --toggle-collect=measured_solve),
 * called through a volatile pointer so that it is not inlined. */
static cdsp_status measured_solve(const cdsp_image *img, const cdsp_camera *cam, const cdsp_params *p,
                                  cdsp_tracker *trk, cdsp_rng *rng, cdsp_result *out, size_t *n)
{
    return cdsp_frame_solve_all(img, cam, 8, p, trk, &ws, rng, out, CDSP_MAX_PIPES, n);
}
static cdsp_status (*volatile measured)(const cdsp_image *, const cdsp_camera *, const cdsp_params *,
                                        cdsp_tracker *, cdsp_rng *, cdsp_result *, size_t *) = measured_solve;

int main(int argc, char **argv)
{
    static unsigned char px[2][(size_t)W * H];
    char path[4096];
    cdsp_camera cam;
    cdsp_params p;
    cdsp_tracker trk;
    cdsp_result out[CDSP_MAX_PIPES];
    cdsp_image img[2];
    cdsp_rng rng;
    size_t n;
    int f;
    cdsp_status st;
    FILE *fp;
    if (argc < 3 || (strcmp(argv[2], "full") && strcmp(argv[2], "track") && strcmp(argv[2], "load"))) {
        fprintf(stderr, "usage: bench_rack DIR full|track|load [REFINE_STEP]\n");
        return 2;
    }
    sup_camera(&cam, W, H, FOC, 0, 0);
    snprintf(path, sizeof path, "%s/rack.raw", argv[1]);
    fp = fopen(path, "rb");
    if (!fp || fread(px, 1, sizeof px, fp) != sizeof px) {
        if (fp)
            fclose(fp);
        for (f = 0; f < 2; f++) {
            cdsp_scene s;
            void *buf;
            cdsp_image im;
            scene(f * 1.0, &s);
            buf = sup_render(&s, &cam, 8, 11 + (uint64_t)f, &im);
            if (!buf)
                return 1;
            memcpy(px[f], buf, sizeof px[f]);
            free(buf);
        }
        fp = fopen(path, "wb");
        if (!fp || fwrite(px, 1, sizeof px, fp) != sizeof px)
            return 1;
    }
    fclose(fp);
    for (f = 0; f < 2; f++) {
        img[f].data = px[f];
        img[f].width = W;
        img[f].height = H;
        img[f].stride = W;
        img[f].bits = 8;
    }
    if (!strcmp(argv[2], "load"))
        return 0;
    cdsp_params_default(&p);
    if (argc > 3)
        p.refine_step = atoi(argv[3]);
    if (argc > 4)
        p.point_fit = atoi(argv[4]);
    cdsp_tracker_init(&trk);
    cdsp_rng_seed(&rng, 1, 1);
    st = cdsp_frame_solve_all(&img[0], &cam, 8, &p, &trk, &ws, &rng, out, CDSP_MAX_PIPES, &n);
    show("frame 0, tracker", st, out, n);
    /* frame 1 from the same generator state in both modes */
    cdsp_rng_seed(&rng, 1, 2);
    st = measured(&img[1], &cam, &p, strcmp(argv[2], "track") ? NULL : &trk, &rng, out, &n);
    show(strcmp(argv[2], "track") ? "frame 1, no tracker" : "frame 1, tracker", st, out, n);
    return 0;
}
