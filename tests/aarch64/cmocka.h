/*
 * tests/aarch64/cmocka.h - the part of cmocka's API the library's unit
 * tests use (tests/lib/test_*.c), for the AArch64 cross build: Debian ships
 * libcmocka for arm64 only through multiarch (dpkg --add-architecture),
 * which the cross toolchain packages do not need. Same behaviour where the
 * tests rely on it: a failed assertion prints where and why and ends that
 * test (longjmp), the others still run, and cmocka_run_group_tests returns
 * the number failed; the "[  PASSED  ] N test(s)" / "[  FAILED  ]" and
 * "test(s) run." lines tests/run.sh counts are printed as cmocka does.
 * Only tests/aarch64/aarch64.mk puts this directory on the include path.
 */
#ifndef CDSP_TESTS_CMOCKA_SHIM_H
#define CDSP_TESTS_CMOCKA_SHIM_H

#include <setjmp.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <string.h>

#if defined(__GNUC__)
#define CMS__UNUSED __attribute__((unused))
#define CMS__PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define CMS__UNUSED
#define CMS__PRINTF(a, b)
#endif

typedef void (*CMUnitTestFunction)(void **state);
typedef int (*CMFixtureFunction)(void **state);

struct CMUnitTest {
    const char *name;
    CMUnitTestFunction test_func;
    CMFixtureFunction setup_func;
    CMFixtureFunction teardown_func;
    void *initial_state;
};

static jmp_buf cms__env;

static void cms__fail(const char *file, int line, const char *fmt, ...) CMS__PRINTF(3, 4) CMS__UNUSED;
static void cms__fail(const char *file, int line, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "ERROR: ");
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fprintf(stderr, "\n%s:%d: error: Failure!\n", file, line);
    longjmp(cms__env, 1);
}

#define print_message(...) printf(__VA_ARGS__)
#define fail_msg(...) cms__fail(__FILE__, __LINE__, __VA_ARGS__)
#define assert_true(c) ((c) ? (void)0 : cms__fail(__FILE__, __LINE__, "%s", #c))
#define assert_false(c) (!(c) ? (void)0 : cms__fail(__FILE__, __LINE__, "!(%s)", #c))
#define assert_non_null(p) ((p) != NULL ? (void)0 : cms__fail(__FILE__, __LINE__, "%s is NULL", #p))
/* cmocka compares integers as its largest unsigned type */
#define assert_int_equal(a, b)                                                                       \
    do {                                                                                             \
        uintmax_t cms__a = (uintmax_t)(a), cms__b = (uintmax_t)(b);                                  \
        if (cms__a != cms__b)                                                                        \
            cms__fail(__FILE__, __LINE__, "%ju (%#jx) != %ju (%#jx)", cms__a, cms__a, cms__b, cms__b); \
    } while (0)
#define assert_int_not_equal(a, b)                                                                   \
    do {                                                                                             \
        uintmax_t cms__a = (uintmax_t)(a), cms__b = (uintmax_t)(b);                                  \
        if (cms__a == cms__b)                                                                        \
            cms__fail(__FILE__, __LINE__, "%ju == %ju", cms__a, cms__b);                             \
    } while (0)
#define assert_memory_equal(a, b, n)                                                                 \
    (memcmp((a), (b), (n)) == 0 ? (void)0 : cms__fail(__FILE__, __LINE__, "%s and %s differ", #a, #b))
#define assert_string_equal(a, b)                                                                    \
    (strcmp((a), (b)) == 0 ? (void)0 : cms__fail(__FILE__, __LINE__, "\"%s\" != \"%s\"", (a), (b)))
#define assert_string_not_equal(a, b)                                                                \
    (strcmp((a), (b)) != 0 ? (void)0 : cms__fail(__FILE__, __LINE__, "\"%s\" == \"%s\"", (a), (b)))

#define cmocka_unit_test(f) {#f, f, NULL, NULL, NULL}

static int cms__run(const char *group, const struct CMUnitTest *t, size_t n, CMFixtureFunction setup,
                    CMFixtureFunction teardown) CMS__UNUSED;
static int cms__run(const char *group, const struct CMUnitTest *t, size_t n, CMFixtureFunction setup,
                    CMFixtureFunction teardown)
{
    size_t i, failed = 0;
    void *gstate = NULL;
    /* volatile: read after a longjmp back into this frame */
    volatile size_t nfail = 0;
    printf("[==========] %s: Running %zu test(s).\n", group, n);
    if (setup && setup(&gstate) != 0) {
        printf("[  ERROR   ] %s: group setup failed\n", group);
        return (int)n;
    }
    for (i = 0; i < n; i++) {
        void *state = t[i].initial_state ? t[i].initial_state : gstate;
        printf("[ RUN      ] %s\n", t[i].name);
        fflush(stdout);
        if (setjmp(cms__env) == 0) {
            t[i].test_func(&state);
            printf("[       OK ] %s\n", t[i].name);
        } else {
            printf("[  FAILED  ] %s\n", t[i].name);
            nfail = nfail + 1;
        }
    }
    failed = nfail;
    if (teardown)
        teardown(&gstate);
    printf("[==========] %s: %zu test(s) run.\n", group, n);
    printf("[  PASSED  ] %zu test(s).\n", n - failed);
    if (failed)
        printf("[  FAILED  ] %zu test(s), listed above.\n", failed);
    return (int)failed;
}

#define cmocka_run_group_tests_name(name, tests, setup, teardown)                                    \
    cms__run((name), (tests), sizeof(tests) / sizeof((tests)[0]), (setup), (teardown))
#define cmocka_run_group_tests(tests, setup, teardown)                                               \
    cms__run(#tests, (tests), sizeof(tests) / sizeof((tests)[0]), (setup), (teardown))

#endif
