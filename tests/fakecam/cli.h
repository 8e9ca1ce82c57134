/*
 * cli.h - the command-line plumbing cdsp_fakecam and arv_probe share: an
 * option table with help text, its usage printer and a range-checked
 * number parser (usage errors exit with status 2).
 */
#ifndef FAKECAM_CLI_H
#define FAKECAM_CLI_H

#include <getopt.h>
#include <stddef.h>
#include <stdio.h>

typedef struct {
    struct option opt;
    const char *arg, *help; /* arg: the value's name, NULL for a flag */
} cli_option;

/* head (usage and purpose lines), then one line per option. */
void cli_usage(FILE *f, const char *head, const cli_option *t, size_t n, int width);
/* The getopt_long table: n entries and the terminating zero entry. */
void cli_longopts(const cli_option *t, size_t n, struct option *out);
/* s as a number in [lo, hi], or "PROG: --OPT 'S': expected ..." and exit 2. */
double cli_number(const char *prog, const char *opt, const char *s, double lo, double hi);

#endif
