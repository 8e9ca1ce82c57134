/*
 * tool_test.h - helpers shared by the tests of the host library (host/) and cdsp_tool:
 * a scratch directory per suite, writing byte buffers to files, and
 * substring checks on error messages.
 */
#ifndef TOOL_TEST_H
#define TOOL_TEST_H

#include <stdarg.h>
#include <stddef.h>
#include <setjmp.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>
#include <cmocka.h>

/* A fresh scratch directory (mkdtemp under $TMPDIR or /tmp). */
static inline const char *tt_tmpdir(void)
{
    static char dir[512];
    if (!dir[0]) {
        const char *base = getenv("TMPDIR");
        snprintf(dir, sizeof dir, "%s/cdsp_tool_test.XXXXXX", base && *base ? base : "/tmp");
        if (!mkdtemp(dir)) {
            perror("mkdtemp");
            exit(1);
        }
    }
    return dir;
}

/* dir/name in a rotating set of static buffers. */
static inline const char *tt_path(const char *name)
{
    static char bufs[8][768];
    static int k;
    char *b = bufs[k++ & 7];
    snprintf(b, sizeof bufs[0], "%s/%s", tt_tmpdir(), name);
    return b;
}

static inline void tt_write(const char *path, const void *data, size_t len)
{
    FILE *f = fopen(path, "wb");
    assert_non_null(f);
    if (len)
        assert_int_equal(fwrite(data, 1, len, f), len);
    assert_int_equal(fclose(f), 0);
}

static inline void tt_write_str(const char *path, const char *s)
{
    tt_write(path, s, strlen(s));
}

#define tt_assert_contains(hay, needle)                                                   \
    do {                                                                                  \
        const char *h_ = (hay), *n_ = (needle);                                           \
        if (!strstr(h_, n_))                                                              \
            fail_msg("expected \"%s\" in \"%s\"", n_, h_);                                \
    } while (0)

#endif
