/*
 * test_stats.c - daemon/stats.c: which counter a frame's libcdsp status
 * goes to (issue 9 defect 3: bad-argument frames were counted as "no
 * pipe", hiding a configuration the library refuses), and that a frame
 * the library refuses for its arguments lands in arg_errors end to end.
 */
#define _POSIX_C_SOURCE 200809L
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>
#include <cmocka.h>

#include "cdsp.h"
#include "stats.h"

static void test_status_field(void **state)
{
    static const struct {
        int status;
        size_t field;
    } cases[] = {
        {CDSP_OK, CDSPD_STAT(ok)},
        {CDSP_E_ARG, CDSPD_STAT(arg_errors)},
        {CDSP_E_NONFINITE, CDSPD_STAT(arg_errors)},
        {CDSP_E_FORMAT, CDSPD_STAT(arg_errors)},
        {CDSP_E_NOCONVERGE, CDSPD_STAT(not_found)},
        {CDSP_E_CAPACITY, CDSPD_STAT(not_found)},
        {CDSP_E_FEW_POINTS, CDSPD_STAT(not_found)},
        {CDSP_E_NO_PIPE, CDSPD_STAT(not_found)},
        {CDSP_E_DEGENERATE, CDSPD_STAT(not_found)},
    };
    size_t i;
    (void)state;
    for (i = 0; i < sizeof cases / sizeof cases[0]; i++)
        if (cdspd_stats_status_field(cases[i].status) != cases[i].field)
            fail_msg("status %d (%s) counted in the wrong field", cases[i].status,
                     cdsp_status_token((cdsp_status)cases[i].status));
}

/* What the pipeline does with a refused frame: the library's own status
 * (min_contrast 1, which cdspd now refuses at load time) into the stats. */
static void test_bad_argument_counted(void **state)
{
    static cdspd_stats s;
    static cdsp_frame_ws ws;
    cdspd_counts c;
    cdsp_params p;
    cdsp_camera cam = {100, 100, 8, 8, 0, 0, 0, 0, 0, 16, 16};
    uint8_t px[16 * 16] = {0};
    cdsp_image img = {px, 16, 16, 16, 8};
    cdsp_rng rng;
    cdsp_result r;
    cdsp_status st;
    (void)state;
    cdspd_stats_init(&s);
    cdsp_params_default(&p);
    p.edge.min_contrast = 1;
    cdsp_rng_seed(&rng, 1, 1);
    st = cdsp_frame_solve(&img, &cam, 5, &p, NULL, &ws, &rng, &r);
    assert_int_equal(st, CDSP_E_ARG);
    cdspd_stats_add(&s, cdspd_stats_status_field(st), 1);
    cdspd_stats_get(&s, &c);
    assert_int_equal(c.arg_errors, 1);
    assert_int_equal(c.not_found, 0);
    cdspd_stats_destroy(&s);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_status_field),
        cmocka_unit_test(test_bad_argument_counted),
    };
    return cmocka_run_group_tests_name("stats", tests, NULL, NULL);
}
