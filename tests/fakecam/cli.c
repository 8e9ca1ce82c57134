/*
 * cli.c - see cli.h.
 */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

void cli_usage(FILE *f, const char *head, const cdsp_host_option *t, size_t n, int width)
{
    fputs(head, f);
    cdsp_host_options_usage(f, t, n, width);
}

double cli_number(const char *prog, const char *opt, const char *s, double lo, double hi)
{
    char *end;
    double v;
    errno = 0;
    v = strtod(s, &end);
    if (end == s || *end || errno || !(v >= lo && v <= hi)) {
        fprintf(stderr, "%s: --%s '%s': expected a number in [%g, %g]\n", prog, opt, s, lo, hi);
        exit(2);
    }
    return v;
}
