#define _POSIX_C_SOURCE 200809L
#include "tool_test.h"
static void placeholder(void **state) { (void)state; }
int main(void)
{
    const struct CMUnitTest tests[] = {cmocka_unit_test(placeholder)};
    return cmocka_run_group_tests_name("tool_cli", tests, NULL, NULL);
}
