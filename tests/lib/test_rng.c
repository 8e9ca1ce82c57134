/*
 * test_rng.c - the caller-owned PCG32: reproducible, streams independent,
 * bounded draws in range and unbiased, normal draws with the right moments.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <math.h>
#include <stdlib.h>
#include <cmocka.h>
#include "support.h"

static void test_reproducible(void **state)
{
    cdsp_rng a, b, c;
    int i, differ = 0;
    (void)state;
    cdsp_rng_seed(&a, 42, 54);
    cdsp_rng_seed(&b, 42, 54);
    cdsp_rng_seed(&c, 42, 55);
    for (i = 0; i < 1000; i++) {
        uint32_t x = cdsp_rng_u32(&a), y = cdsp_rng_u32(&b), z = cdsp_rng_u32(&c);
        assert_int_equal(x, y);
        differ += x != z;
    }
    assert_true(differ > 990);
}

/* Counts of cdsp_rng_below(7) over 70000 draws: each bucket ~ 10000 with
 * sd ~ 93; 6 sd bounds. */
static void test_below(void **state)
{
    cdsp_rng r;
    int counts[7] = {0}, i;
    (void)state;
    cdsp_rng_seed(&r, 7, 1);
    for (i = 0; i < 70000; i++) {
        uint32_t v = cdsp_rng_below(&r, 7);
        assert_true(v < 7);
        counts[v]++;
    }
    for (i = 0; i < 7; i++)
        assert_true(abs(counts[i] - 10000) < 6 * 93);
    assert_int_equal(cdsp_rng_below(&r, 1), 0);
}

/* Mean and variance of 1e5 draws: standard errors 0.0029 (uniform mean),
 * 0.0032 (normal mean), 0.0045 (normal variance); 6 standard errors. */
static void test_moments(void **state)
{
    cdsp_rng r;
    double su = 0, sn = 0, sn2 = 0;
    int i, n = 100000;
    (void)state;
    cdsp_rng_seed(&r, 2024, 9);
    for (i = 0; i < n; i++) {
        double u = (double)cdsp_rng_uniform(&r), z = (double)cdsp_rng_normal(&r);
        assert_true(u >= 0 && u < 1);
        su += u;
        sn += z;
        sn2 += z * z;
    }
    assert_true(fabs(su / n - 0.5) < 6 * 0.0029);
    assert_true(fabs(sn / n) < 6 * 0.0032);
    assert_true(fabs(sn2 / n - 1) < 6 * 0.0045);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_reproducible),
        cmocka_unit_test(test_below),
        cmocka_unit_test(test_moments),
    };
    return cmocka_run_group_tests_name("rng", tests, NULL, NULL);
}
