/*
 * tool_rack_scene.c - the paper's rack scene (tools/tool_rack_scene.h):
 * defined once for `cdsp_tool bench --rack` and tests/bench/bench_rack.c.
 */
#include "tool_rack_scene.h"

#include <math.h>
#include <string.h>

static void unit3(double a[3])
{
    double n = sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
    a[0] /= n;
    a[1] /= n;
    a[2] /= n;
}

void tool_rack_place(double tilt, double roll, const double mid[3], uint32_t texture_seed, cdsp_scene *s,
                     double c[2][3], double v[3])
{
    double side[3], n[3], up[3];
    int k, i;
    cdsp_scene_default(s);
    /* the axes along v (roughly the image's x, rolled), spaced along side:
     * side is the plane's in-plane normal to v, tilted by `tilt` from the
     * image plane toward the line of sight */
    v[0] = cos(roll);
    v[1] = sin(roll);
    v[2] = 0.15;
    unit3(v);
    up[0] = -sin(roll);
    up[1] = cos(roll);
    up[2] = 0;
    for (i = 0; i < 3; i++)
        n[i] = 0;
    n[2] = -1;
    for (i = 0; i < 3; i++)
        side[i] = cos(tilt) * up[i] + sin(tilt) * n[i];
    /* side _|_ v exactly */
    {
        double d = side[0] * v[0] + side[1] * v[1] + side[2] * v[2];
        for (i = 0; i < 3; i++)
            side[i] -= d * v[i];
        unit3(side);
    }
    for (k = 0; k < 2; k++)
        for (i = 0; i < 3; i++)
            c[k][i] = mid[i] + (k ? 0.5 : -0.5) * RACK_SPACING * side[i];
    for (i = 0; i < 3; i++) {
        s->axis_point[i] = (cdsp_real)c[0][i];
        s->axis_dir[i] = (cdsp_real)v[i];
        s->extra_pipe[0].axis_point[i] = (cdsp_real)c[1][i];
        s->extra_pipe[0].axis_dir[i] = (cdsp_real)v[i];
    }
    s->radius = s->extra_pipe[0].radius = (cdsp_real)RACK_R;
    s->half_length = s->extra_pipe[0].half_length = (cdsp_real)RACK_HALF;
    s->n_extra_pipes = 1;
    /* the columns: across both pipes at +-100 mm along them, just behind
     * (touching the pipes from the far side), a little longer than the rack */
    {
        double back[3];
        /* the plane's normal, v x side */
        back[0] = v[1] * side[2] - v[2] * side[1];
        back[1] = v[2] * side[0] - v[0] * side[2];
        back[2] = v[0] * side[1] - v[1] * side[0];
        if (back[2] < 0)
            for (i = 0; i < 3; i++)
                back[i] = -back[i];
        s->n_clutter = 2;
        for (k = 0; k < 2; k++) {
            cdsp_clutter *cl = &s->clutter[k];
            for (i = 0; i < 3; i++) {
                double o = mid[i] + (k ? 100 : -100) * v[i] + (RACK_R + RACK_COLUMN_R) * back[i];
                cl->p0[i] = (cdsp_real)(o - 0.5 * (RACK_SPACING + 120) * side[i]);
                cl->p1[i] = (cdsp_real)(o + 0.5 * (RACK_SPACING + 120) * side[i]);
            }
            cl->half_width = (cdsp_real)RACK_COLUMN_R;
            cl->level = (cdsp_real)0.45;
        }
    }
    s->pipe_level = (cdsp_real)0.75;
    s->background_level = (cdsp_real)0.2;
    s->light[0] = (cdsp_real)0.4;
    s->light[1] = (cdsp_real)-0.7;
    s->light[2] = (cdsp_real)-0.6;
    s->ambient = (cdsp_real)0.4;
    s->texture = (cdsp_real)0.02;
    s->texture_scale_px = (cdsp_real)60;
    s->texture_seed = texture_seed;
    s->blur_sigma_px = (cdsp_real)0.8;
    s->noise_sigma = (cdsp_real)(2.0 / 255);
}

void tool_rack_frame(int arr, int g, int f, cdsp_scene *s, double c[2][3], double v[3])
{
    double t = (double)g / (RACK_GROUPS - 1), mid[3];
    double tilt = (arr == 0 ? 15 + 20 * t : 50 + 20 * t) * 3.14159265358979 / 180;
    double roll = (-12 + 24 * t) * 3.14159265358979 / 180;
    mid[0] = 8 * (f - 1);
    mid[1] = -10 + 5 * g;
    mid[2] = 600 + 160 * t + 5 * f;
    tool_rack_place(tilt, roll, mid, (uint32_t)(1000 * arr + 10 * g + f + 1), s, c, v);
}

void tool_rack_camera(cdsp_camera *cam)
{
    memset(cam, 0, sizeof *cam);
    cam->fx = cam->fy = (cdsp_real)RACK_F;
    cam->cx = (cdsp_real)((RACK_W - 1) / 2.0);
    cam->cy = (cdsp_real)((RACK_H - 1) / 2.0);
    cam->width = RACK_W;
    cam->height = RACK_H;
}
