/*
 * fw.c - the firmware test: fixed edge-point sets and a small frame through
 * libcdsp, results printed one line each. The same source runs on Cortex-M
 * under QEMU (semihosting printf) and on the host; tests/mcu/compare.py
 * checks that the two agree and that both match the ground truth.
 *
 * Output (one record per line, space-separated key=value, reals as decimal
 * with enough digits to round-trip the precision in use):
 *   fw target=<name> real=<float|double> max_edges=<n> max_points=<n>
 *   result name=<case> entry=<function> status=<token> expect=<token> flags=<n>
 *          n_edges=<n> inliers=<a>,<b> point=<x>,<y>,<z> direction=<x>,<y>,<z>
 *          distance=<d> alpha=<a> segment=<6 reals> sigma_point=<3>
 *          sigma_direction=<3> sigma_distance=<s> rms=<2>
 *          truth_point=<3> truth_direction=<3> truth_tol=<point>,<angle>
 *          stack=<bytes used by the call; 0 on the host>
 *   golden n=<n> start=<floor(0.618034 n) as the library computes it>
 *   end results=<n> goldens=<n> stack_size=<bytes>
 * Exit status 0 when every record was produced (agreement is judged by
 * compare.py, not here), 1 when the stack overflowed its block.
 */
#include <stdio.h>
#include <string.h>

#include "cdsp.h"
#include "mcu.h"

typedef struct {
    const char *name;
    int cam;
    double radius;
    unsigned long first, count;
    const char *expect;
    double truth_point[3], truth_dir[3];
} mcu_points_case;

#include "mcu_cases.h"

#ifdef MCU_BOARD
#define FW_TARGET MCU_BOARD
#else
#define FW_TARGET "host"
#endif

#ifdef CDSP_SINGLE
#define FW_REAL "float"
#define FW_FMT "%.9g"
#else
#define FW_REAL "double"
#define FW_FMT "%.17g"
#endif

/* Caller-owned workspaces in static memory, as firmware would place them. */
static cdsp_points_ws fw_points_ws;
static cdsp_frame_ws fw_frame_ws;
static int fw_overflow;

static void put_reals(const char *key, const cdsp_real *v, int n)
{
    int i;
    printf(" %s=", key);
    for (i = 0; i < n; i++)
        printf(i ? "," FW_FMT : FW_FMT, (double)v[i]);
}

static void put_doubles(const char *key, const double *v, int n)
{
    int i;
    printf(" %s=", key);
    for (i = 0; i < n; i++)
        printf(i ? ",%.17g" : "%.17g", v[i]);
}

static void put_result(const char *name, const char *entry, cdsp_status st, const char *expect,
                       const cdsp_result *r, const double tp[3], const double tv[3],
                       double tol_point, double tol_angle, size_t stack)
{
    static const cdsp_result zero;
    double tol[2];
    tol[0] = tol_point;
    tol[1] = tol_angle;
    if (st != CDSP_OK)
        r = &zero; /* outputs are not written on failure: print zeros */
    printf("result name=%s entry=%s status=%s expect=%s flags=%lu n_edges=%lu inliers=%lu,%lu",
           name, entry, cdsp_status_token(st), expect, (unsigned long)r->flags,
           (unsigned long)r->n_edges, (unsigned long)r->inliers[0], (unsigned long)r->inliers[1]);
    put_reals("point", r->point, 3);
    put_reals("direction", r->direction, 3);
    put_reals("distance", &r->distance, 1);
    put_reals("alpha", &r->alpha, 1);
    put_reals("segment", &r->segment[0][0], 6);
    put_reals("sigma_point", r->sigma_point, 3);
    put_reals("sigma_direction", r->sigma_direction, 3);
    put_reals("sigma_distance", &r->sigma_distance, 1);
    put_reals("rms", r->rms, 2);
    put_doubles("truth_point", tp, 3);
    put_doubles("truth_direction", tv, 3);
    put_doubles("truth_tol", tol, 2);
    printf(" stack=%lu\n", (unsigned long)stack);
}

#if defined(__arm__)
#define FW_MARK() void *fw_mark = mcu_stack_mark()
#define FW_PEAK() fw_peak(fw_mark)
static size_t fw_peak(const void *mark)
{
    size_t used = mcu_stack_peak(mark);
    /* the paint reached the block's limit: the stack may have overflowed */
    if (used + 256 >= mcu_stack_size())
        fw_overflow = 1;
    return used;
}
#else
#define FW_MARK() (void)0
#define FW_PEAK() ((size_t)0)
#endif

static int run_points(void)
{
    size_t i;
    for (i = 0; i < sizeof mcu_points_cases / sizeof mcu_points_cases[0]; i++) {
        const mcu_points_case *c = &mcu_points_cases[i];
        cdsp_params p;
        cdsp_rng rng;
        cdsp_result r;
        cdsp_status st;
        size_t stack;
        cdsp_params_default(&p);
        cdsp_rng_seed(&rng, 0x6d6375u, (uint64_t)i);
        {
            FW_MARK();
            st = cdsp_points_solve(&mcu_cams[c->cam], (cdsp_real)c->radius,
                                   &mcu_points[c->first], (size_t)c->count, &p, NULL,
                                   &fw_points_ws, &rng, &r);
            stack = FW_PEAK();
        }
        put_result(c->name, "cdsp_points_solve", st, c->expect, &r, c->truth_point,
                   c->truth_dir, 0, 0, stack);
    }
    return (int)i;
}

static int run_frame(void)
{
    cdsp_image img;
    cdsp_params p;
    cdsp_rng rng;
    cdsp_result full, tracked;
    cdsp_status st;
    size_t stack;
    img.data = mcu_frame;
    img.width = mcu_frame_cam.width;
    img.height = mcu_frame_cam.height;
    img.stride = (size_t)img.width;
    img.bits = 8;
    cdsp_params_default(&p);
    /* a small region, every other row/column: ~50 points per contour */
    p.edge.roi = mcu_frame_roi;
    p.edge.step = 2;
    cdsp_rng_seed(&rng, 0x6d6375u, 100);
    {
        FW_MARK();
        st = cdsp_frame_solve(&img, &mcu_frame_cam, (cdsp_real)mcu_frame_radius, &p, NULL,
                              &fw_frame_ws, &rng, &full);
        stack = FW_PEAK();
    }
    put_result("frame-roi", "cdsp_frame_solve", st, "ok", &full, mcu_frame_truth_point,
               mcu_frame_truth_dir, mcu_frame_tol_point, mcu_frame_tol_angle, stack);
    if (st != CDSP_OK)
        return 1;
    /* the next frame (the same picture) tracked from the first result */
    {
        FW_MARK();
        st = cdsp_frame_solve(&img, &mcu_frame_cam, (cdsp_real)mcu_frame_radius, &p, &full,
                              &fw_frame_ws, &rng, &tracked);
        stack = FW_PEAK();
    }
    put_result("frame-track", "cdsp_frame_solve", st, "ok", &tracked, mcu_frame_truth_point,
               mcu_frame_truth_dir, mcu_frame_tol_point, mcu_frame_tol_angle, stack);
    return 2;
}

/* lines.c's golden-ratio stride start, floor(0.618034 n), at the sizes
 * that matter on a 32-bit target: past 6949 the naive n * 618034 wraps,
 * the default CDSP_MAX_EDGES (16384) and SIZE_MAX. compare.py checks each
 * against exact integer arithmetic. Internal to the library, declared here. */
size_t cdsp__golden_start(size_t n);

static int run_golden(void)
{
    static const unsigned long ns[] = {0, 1, 2, 999, 1000, 6949, 6950, 16384, 65535, 1000000,
                                       1234567, 4294967295ul};
    size_t i;
    for (i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        size_t n = (size_t)ns[i];
        printf("golden n=%lu start=%lu\n", (unsigned long)n, (unsigned long)cdsp__golden_start(n));
    }
    return (int)i;
}

int main(void)
{
    int n;
    unsigned long stack_size = 0;
#if defined(__arm__)
    stack_size = (unsigned long)mcu_stack_size();
#endif
    printf("fw target=%s real=%s max_edges=%lu max_points=%lu\n", FW_TARGET, FW_REAL,
           (unsigned long)CDSP_MAX_EDGES, (unsigned long)CDSP_MAX_POINTS);
    n = run_points();
    n += run_frame();
    printf("end results=%d goldens=%d stack_size=%lu\n", n, run_golden(), stack_size);
    if (fw_overflow) {
        printf("fw: the stack reached the end of its %lu-byte block\n", stack_size);
        return 1;
    }
    return 0;
}
