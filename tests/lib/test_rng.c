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
#include "../../lib/internal.h"

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

/* RANSAC computes the rejection threshold once per search: the draws must
 * be cdsp_rng_below's, draw for draw, whatever n. The n include 1, small
 * ones, the edge counts RANSAC sees and 2^31 + 1 and 2^32 - 1, whose
 * thresholds (2^31 - 1, 1) make the rejection loop run (about every second
 * draw for 2^31 + 1), so the two streams stay in step only if the rejection
 * is the same. */
static void test_below_threshold(void **state)
{
    static const uint32_t ns[] = {1, 2, 3, 7, 19, 160, 617, 16384, 4000037u, 2147483649u, 4294967295u};
    size_t i;
    int k;
    (void)state;
    for (i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        cdsp_rng a, b;
        uint32_t t = cdsp__rng_threshold(ns[i]);
        assert_int_equal(t, (uint32_t)((((uint64_t)1 << 32) - ns[i]) % ns[i]));
        cdsp_rng_seed(&a, 99, (uint64_t)i);
        cdsp_rng_seed(&b, 99, (uint64_t)i);
        for (k = 0; k < 2000; k++)
            assert_int_equal(cdsp__rng_below_t(&a, ns[i], t), cdsp_rng_below(&b, ns[i]));
        assert_int_equal(a.state, b.state);
    }
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
        cmocka_unit_test(test_below_threshold),
        cmocka_unit_test(test_moments),
    };
    return cmocka_run_group_tests_name("rng", tests, NULL, NULL);
}
