/*
 * test_status.c - every status has its own words and its own stable token.
 */
#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdint.h>
#include <string.h>
#include <cmocka.h>
#include "support.h"

static void test_distinct(void **state)
{
    const cdsp_status all[] = {CDSP_OK, CDSP_E_ARG, CDSP_E_NONFINITE, CDSP_E_NOCONVERGE,
                               CDSP_E_CAPACITY, CDSP_E_FEW_POINTS, CDSP_E_NO_PIPE,
                               CDSP_E_DEGENERATE, CDSP_E_FORMAT};
    size_t i, j, n = sizeof all / sizeof all[0];
    (void)state;
    for (i = 0; i < n; i++) {
        assert_string_not_equal(cdsp_strerror(all[i]), "unknown status");
        assert_string_not_equal(cdsp_status_token(all[i]), "unknown");
        for (j = 0; j < i; j++) {
            assert_string_not_equal(cdsp_strerror(all[i]), cdsp_strerror(all[j]));
            assert_string_not_equal(cdsp_status_token(all[i]), cdsp_status_token(all[j]));
        }
    }
    assert_string_equal(cdsp_status_token(CDSP_E_NO_PIPE), "no-pipe");
    assert_string_equal(cdsp_strerror((cdsp_status)-99), "unknown status");
    assert_string_equal(cdsp_status_token((cdsp_status)17), "unknown");
}

int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(test_distinct)};
    return cmocka_run_group_tests_name("status", tests, NULL, NULL);
}
