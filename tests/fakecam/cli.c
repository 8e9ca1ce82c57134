/*
 * cli.c - see cli.h.
 */
#define _POSIX_C_SOURCE 200809L
#include "cli.h"

#include <errno.h>
#include <stdlib.h>
#include <string.h>

void cli_usage(FILE *f, const char *head, const cli_option *t, size_t n, int width)
{
    size_t i;
    fputs(head, f);
    for (i = 0; i < n; i++) {
        const struct option *o = &t[i].opt;
        char left[64];
        if (o->val < 256)
            snprintf(left, sizeof left, "-%c, --%s%s%s", o->val, o->name, t[i].arg ? " " : "",
                     t[i].arg ? t[i].arg : "");
        else
            snprintf(left, sizeof left, "    --%s %s", o->name, t[i].arg ? t[i].arg : "");
        fprintf(f, "  %-*s %s\n", width, left, t[i].help);
    }
}

void cli_longopts(const cli_option *t, size_t n, struct option *out)
{
    size_t i;
    for (i = 0; i < n; i++)
        out[i] = t[i].opt;
    memset(&out[n], 0, sizeof out[n]);
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
