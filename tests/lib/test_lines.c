/*
 * test_lines.c - lib/lines.c's internals that have no public entry point of
 * their own (the line fits and RANSAC are exercised through the points and
 * frame suites).
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <cmocka.h>
#include "support.h"
#include "../../lib/internal.h"

/* The start of RANSAC's golden-ratio subsample stride, floor(0.618034 n),
 * must be exact at every n: with 32-bit size_t the plain n * 618034 wraps
 * past n = 6949, below the 16384 edges the Cortex-M builds hold (issue 9),
 * and the stride degenerates (16384 gave 1535, 0.094 n). The MCU firmware
 * test prints the same table on the targets (tests/mcu/fw.c). The exact
 * value is computed here in 64-bit arithmetic. */
static void test_golden_start(void **state)
{
    static const uint64_t ns[] = {0, 1, 2, 999, 1000, 1001, 6949, 6950, 16383, 16384, 65535,
                                  999999, 1000000, 1234567, 4294967295u};
    size_t i;
    (void)state;
    for (i = 0; i < sizeof ns / sizeof ns[0]; i++) {
        uint64_t want = ns[i] * 618034u / 1000000u;
        if (ns[i] > (uint64_t)(size_t)-1)
            continue;
        assert_int_equal((uint64_t)cdsp__golden_start((size_t)ns[i]), want);
    }
    /* every n up to twice the default edge capacity */
    for (i = 0; i <= 2u * 16384u; i++)
        assert_int_equal((uint64_t)cdsp__golden_start(i), (uint64_t)i * 618034u / 1000000u);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_golden_start),
    };
    return cmocka_run_group_tests_name("lines", tests, NULL, NULL);
}
