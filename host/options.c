/*
 * options.c - see options.h.
 */
#define _POSIX_C_SOURCE 200809L
#include "options.h"

#include <string.h>

void cdsp_host_options_usage(FILE *f, const cdsp_host_option *t, size_t n, int width)
{
    size_t i;
    for (i = 0; i < n; i++) {
        const struct option *o = &t[i].opt;
        const char *sp = t[i].arg ? " " : "", *arg = t[i].arg ? t[i].arg : "";
        char left[64];
        if (o->val < 256)
            snprintf(left, sizeof left, "-%c, --%s%s%s", o->val, o->name, sp, arg);
        else
            snprintf(left, sizeof left, "    --%s%s%s", o->name, sp, arg);
        fprintf(f, "  %-*s %s\n", width, left, t[i].help);
    }
}

void cdsp_host_options_getopt(const cdsp_host_option *t, size_t n, struct option *out)
{
    size_t i;
    for (i = 0; i < n; i++)
        out[i] = t[i].opt;
    memset(&out[n], 0, sizeof out[n]);
}
