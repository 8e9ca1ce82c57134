/*
 * mount.c - see mount.h.
 */
#define _GNU_SOURCE /* M_PI */
#include "mount.h"

#include <math.h>
#include <string.h>

static const struct {
    const char *name;
    double rpy[3];
} presets[] = {
    {"forward", {0, 0, 0}},
    {"down", {0, -90, 0}},
    {"down-right", {0, -90, 90}},
    {"down-aft", {0, -90, 180}},
    {"down-left", {0, -90, -90}},
};
#define N_PRESETS (sizeof presets / sizeof presets[0])

int cdspd_mount_preset(const char *name, double rpy_deg[3])
{
    size_t i;
    for (i = 0; i < N_PRESETS; i++)
        if (!strcmp(name, presets[i].name)) {
            memcpy(rpy_deg, presets[i].rpy, sizeof presets[i].rpy);
            return 0;
        }
    return -1;
}

const char *cdspd_mount_preset_names(void)
{
    return "forward, down, down-right, down-aft, down-left";
}

/* cos and sin of a whole number of quarter turns exactly (a preset's R is
 * then exactly a signed permutation), else the library's. */
static void cos_sin_deg(double deg, double *c, double *s)
{
    double q = deg / 90;
    if (isfinite(q) && q == floor(q)) { /* Inf would reach (int) as NaN (tests/fuzz mavlink) */
        static const double cq[4] = {1, 0, -1, 0}, sq[4] = {0, 1, 0, -1};
        int k = (int)fmod(fmod(q, 4) + 4, 4);
        *c = cq[k];
        *s = sq[k];
        return;
    }
    *c = cos(deg * (M_PI / 180));
    *s = sin(deg * (M_PI / 180));
}

void cdspd_mount_from_euler(cdspd_mount *m, const double rpy_deg[3], const double t[3])
{
    double cr, sr, cp, sp, cy, sy, F[3][3];
    int i, j;
    cos_sin_deg(rpy_deg[0], &cr, &sr);
    cos_sin_deg(rpy_deg[1], &cp, &sp);
    cos_sin_deg(rpy_deg[2], &cy, &sy);
    /* R_frd = Rz(yaw) Ry(pitch) Rx(roll) */
    F[0][0] = cy * cp;
    F[0][1] = cy * sp * sr - sy * cr;
    F[0][2] = cy * sp * cr + sy * sr;
    F[1][0] = sy * cp;
    F[1][1] = sy * sp * sr + cy * cr;
    F[1][2] = sy * sp * cr - cy * sr;
    F[2][0] = -sp;
    F[2][1] = cp * sr;
    F[2][2] = cp * cr;
    /* R = R_frd P: optical X is camera right (column 1 of R_frd), optical Y
     * camera down (column 2), optical Z camera forward (column 0) */
    for (i = 0; i < 3; i++) {
        m->R[i][0] = F[i][1];
        m->R[i][1] = F[i][2];
        m->R[i][2] = F[i][0];
    }
    for (j = 0; j < 3; j++)
        m->t[j] = t[j];
}

void cdspd_mount_apply(const cdspd_mount *m, const double p[3], const double v[3],
                       cdspd_body_pose *out)
{
    double pb[3], d[3], n, s, h, rel[3];
    int i, j;
    for (i = 0; i < 3; i++) {
        pb[i] = m->t[i];
        d[i] = 0;
        for (j = 0; j < 3; j++) {
            pb[i] += m->R[i][j] * p[j];
            d[i] += m->R[i][j] * v[j];
        }
    }
    n = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    for (i = 0; i < 3; i++)
        d[i] /= n;
    /* the first component clearly away from zero decides the sign; 1e-12
     * is far below a unit vector's rounding noise of any real pose */
    for (i = 0; i < 3; i++)
        if (fabs(d[i]) > 1e-12) {
            if (d[i] < 0)
                for (j = 0; j < 3; j++)
                    d[j] = -d[j];
            break;
        }
    s = pb[0] * d[0] + pb[1] * d[1] + pb[2] * d[2];
    for (i = 0; i < 3; i++) {
        out->point[i] = pb[i] - s * d[i];
        out->direction[i] = d[i];
    }
    h = sqrt(d[0] * d[0] + d[1] * d[1]);
    out->yaw = h > 0 ? atan2(d[1], d[0]) : 0;
    out->pitch = atan2(-d[2], h);
    /* q of Rz(yaw) Ry(pitch) (roll 0): the ZYX Euler quaternion */
    out->q[0] = cos(out->yaw / 2) * cos(out->pitch / 2);
    out->q[1] = -sin(out->yaw / 2) * sin(out->pitch / 2);
    out->q[2] = cos(out->yaw / 2) * sin(out->pitch / 2);
    out->q[3] = sin(out->yaw / 2) * cos(out->pitch / 2);
    /* back to the optical frame: R^T (point - t) */
    for (i = 0; i < 3; i++)
        rel[i] = out->point[i] - m->t[i];
    for (j = 0; j < 3; j++) {
        out->point_cam[j] = 0;
        for (i = 0; i < 3; i++)
            out->point_cam[j] += m->R[i][j] * rel[i];
    }
}
