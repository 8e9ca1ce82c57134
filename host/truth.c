/*
 * truth.c - the ground truth of a pipe axis in the form the solver reports
 * it (cdsp_result): cdsp_tool sim's truth.json, cdspd's sim.truth field and
 * the tests all take it from here, so they cannot disagree on the sign rule.
 */
#include <math.h>

#include "cdsp_host.h"

void cdsp_host_axis_truth(const double point[3], const double dir[3], double foot[3],
                          double unit[3], double *distance)
{
    double n = sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]), t;
    int i, big = 0;
    for (i = 0; i < 3; i++)
        unit[i] = n > 0 ? dir[i] / n : 0;
    /* cdsp_result.direction's sign rule: largest-magnitude component > 0 */
    for (i = 1; i < 3; i++)
        if (fabs(unit[i]) > fabs(unit[big]))
            big = i;
    if (unit[big] < 0)
        for (i = 0; i < 3; i++)
            unit[i] = -unit[i];
    /* foot of the perpendicular from the origin: P - (P . v) v */
    t = point[0] * unit[0] + point[1] * unit[1] + point[2] * unit[2];
    for (i = 0; i < 3; i++)
        foot[i] = point[i] - t * unit[i];
    *distance = sqrt(foot[0] * foot[0] + foot[1] * foot[1] + foot[2] * foot[2]);
}
