/*
 * bench_rack.c - instruction counts of cdsp_frame_solve_all on the paper's
 * rack (issue 13): two 16 mm pipes 100 mm apart on two 12.68 mm columns,
 * 2448 x 2048, fx = fy = 4637.68 px, light 40 % ambient, blur 0.8 px,
 * noise 2 gray levels (the scene of tools/tool_rack.c, arrangement A,
 * group 3; repeated here because the tool is not linked into tests). Two
 * frames, the rack moved by 1 mm (7.7 px, inside the 12 px tracking bands)
 * between them, rendered once and cached raw in DIR/rack.raw (valgrind
 * would take minutes to render). Frame 0 is solved with a new tracker (a
 * full search), then frame 1, the solve counted by valgrind
 * --tool=callgrind --toggle-collect=measured_solve, from the same
 * generator state in both modes:
 *   full   without the tracker (a full search);
 *   track  with it (the tracked solve, when it finds every track).
 * Prints each solve's pipes and flags. Figures, not pass/fail.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include "support.h"

#define W 2448
#define H 2048
#define FOC (16.0 / 0.00345)

static cdsp_frame_all_ws ws;

static void unit3(double a[3])
{
    double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    a[0] /= n;
    a[1] /= n;
    a[2] /= n;
}

/* tool_rack.c's rack_scene(0, 2, f) with the rack's middle at x = dx mm */
static void scene(double dx, cdsp_scene *s)
{
    double tilt = 25 * 3.14159265358979 / 180, v[3] = {1, 0, 0.15}, up[3] = {0, 1, 0}, side[3], mid[3], d,
           back[3];
    int i, k;
    cdsp_scene_default(s);
    unit3(v);
    for (i = 0; i < 3; i++)
        side[i] = cos(tilt) * up[i] + (i == 2 ? -sin(tilt) : 0);
    d = side[0] * v[0] + side[1] * v[1] + side[2] * v[2];
    for (i = 0; i < 3; i++)
        side[i] -= d * v[i];
    unit3(side);
    mid[0] = dx;
    mid[1] = 0;
    mid[2] = 680;
    for (i = 0; i < 3; i++) {
        s->axis_point[i] = (cdsp_real)(mid[i] - 50 * side[i]);
        s->extra_pipe[0].axis_point[i] = (cdsp_real)(mid[i] + 50 * side[i]);
        s->axis_dir[i] = s->extra_pipe[0].axis_dir[i] = (cdsp_real)v[i];
    }
    s->radius = s->extra_pipe[0].radius = 8;
    s->half_length = s->extra_pipe[0].half_length = 150;
    s->n_extra_pipes = 1;
    back[0] = v[1] * side[2] - v[2] * side[1];
    back[1] = v[2] * side[0] - v[0] * side[2];
    back[2] = v[0] * side[1] - v[1] * side[0];
    if (back[2] < 0)
        for (i = 0; i < 3; i++)
            back[i] = -back[i];
    s->n_clutter = 2;
    for (k = 0; k < 2; k++)
        for (i = 0; i < 3; i++) {
            double o = mid[i] + (k ? 100 : -100) * v[i] + (8 + 6.34) * back[i];
            s->clutter[k].p0[i] = (cdsp_real)(o - 110 * side[i]);
            s->clutter[k].p1[i] = (cdsp_real)(o + 110 * side[i]);
            s->clutter[k].half_width = (cdsp_real)6.34;
            s->clutter[k].level = (cdsp_real)0.45;
        }
    s->pipe_level = (cdsp_real)0.75;
    s->background_level = (cdsp_real)0.2;
    s->light[0] = (cdsp_real)0.4;
    s->light[1] = (cdsp_real)-0.7;
    s->light[2] = (cdsp_real)-0.6;
    s->ambient = (cdsp_real)0.4;
    s->texture = (cdsp_real)0.02;
    s->texture_scale_px = 60;
    s->texture_seed = 3;
    s->blur_sigma_px = (cdsp_real)0.8;
    s->noise_sigma = (cdsp_real)(2.0 / 255);
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
        fprintf(stderr, "usage: bench_rack DIR full|track|load\n");
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
