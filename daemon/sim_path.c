/*
 * sim_path.c - see sim_path.h.
 */
#include "sim_path.h"

#include <math.h>

#include "cdsp_host.h"

int cdspd_sim_slot(const cdspd_config *c, uint64_t frame)
{
    return (int)(frame % (uint64_t)c->sim.frames);
}

int cdspd_sim_pose(const cdspd_config *c, int slot, double point[3], double dir[3])
{
    const double pi = 3.14159265358979323846;
    double a = 2 * pi * slot / c->sim.frames;
    double tilt = c->sim.tilt_deg * pi / 180 * sin(a), nod = c->sim.nod_deg * pi / 180 * cos(a);
    double d[3], e[3], n;
    int away_from = (int)ceil(c->sim.frames * (1 - c->sim.away) - 1e-9);

    point[0] = c->sim.center[0] + c->sim.sway[0] * sin(a);
    point[1] = c->sim.center[1] + c->sim.sway[1] * sin(2 * a);
    point[2] = c->sim.center[2] + c->sim.sway[2] * cos(a);
    d[0] = c->sim.direction[0];
    d[1] = c->sim.direction[1];
    d[2] = c->sim.direction[2];
    /* Rx(nod): y, z rotate */
    e[0] = d[0];
    e[1] = cos(nod) * d[1] - sin(nod) * d[2];
    e[2] = sin(nod) * d[1] + cos(nod) * d[2];
    /* Rz(tilt): x, y rotate (in the image plane) */
    d[0] = cos(tilt) * e[0] - sin(tilt) * e[1];
    d[1] = sin(tilt) * e[0] + cos(tilt) * e[1];
    d[2] = e[2];
    n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    dir[0] = d[0] / n;
    dir[1] = d[1] / n;
    dir[2] = d[2] / n;
    return slot < away_from;
}

int cdspd_sim_truth(const cdspd_config *c, uint64_t frame, double foot[3], double dir[3],
                    double *distance)
{
    double p[3], v[3];
    if (!cdspd_sim_pose(c, cdspd_sim_slot(c, frame), p, v))
        return 0;
    cdsp_host_axis_truth(p, v, foot, dir, distance);
    return 1;
}

void cdspd_sim_scene(const cdspd_config *c, int slot, cdsp_scene *s)
{
    double p[3], v[3];
    int i;
    cdsp_scene_default(s);
    if (!cdspd_sim_pose(c, slot, p, v)) {
        p[0] = 0;
        p[1] = 0;
        p[2] = -1000 - 100 * c->radius;
        v[0] = 1;
        v[1] = 0;
        v[2] = 0;
    }
    for (i = 0; i < 3; i++) {
        s->axis_point[i] = (cdsp_real)p[i];
        s->axis_dir[i] = (cdsp_real)v[i];
    }
    s->radius = (cdsp_real)c->radius;
    s->half_length = 0;
    s->ambient = (cdsp_real)c->sim.ambient;
    s->noise_sigma = (cdsp_real)c->sim.noise;
    s->blur_sigma_px = (cdsp_real)c->sim.blur;
    s->texture = (cdsp_real)c->sim.texture;
    s->texture_seed = (uint32_t)c->sim.seed;
}
