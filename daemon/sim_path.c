/*
 * sim_path.c - see sim_path.h.
 */
#include "sim_path.h"

#include <math.h>

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
