/*
 * options.h - the option table of cdspd and the test peers (cdsp_fakecam,
 * arv_probe): getopt_long's entry, the value's name and one line of help,
 * from which both the getopt_long table and the OPTIONS lines of --help are
 * made, so the two never disagree. (cdsp_tool's subcommands use their own
 * typed table, tools/tool_internal.h, which also checks ranges.) Part of
 * libcdsp_host (host/options.c).
 */
#ifndef CDSP_HOST_OPTIONS_H
#define CDSP_HOST_OPTIONS_H

#include <getopt.h>
#include <stddef.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct {
    struct option opt;
    const char *arg;  /* the value's name in --help ("FILE"), NULL for a flag */
    const char *help; /* one line */
} cdsp_host_option;

/* One line per option: "  -c, --config FILE   help" (a short name when
 * opt.val < 256), the option column width characters wide. */
void cdsp_host_options_usage(FILE *f, const cdsp_host_option *t, size_t n, int width);

/* The getopt_long table: the n entries and the terminating zero entry
 * (out has n + 1 places). */
void cdsp_host_options_getopt(const cdsp_host_option *t, size_t n, struct option *out);

#ifdef __cplusplus
}
#endif

#endif
