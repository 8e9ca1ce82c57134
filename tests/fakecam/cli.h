/*
 * cli.h - the command-line plumbing cdsp_fakecam and arv_probe share: the
 * host library's option table (host/options.h, cdspd's too) with a usage
 * printer, and a range-checked number parser (usage errors exit with
 * status 2).
 */
#ifndef FAKECAM_CLI_H
#define FAKECAM_CLI_H

#include <stddef.h>
#include <stdio.h>

#include "options.h" /* host/options.h */

/* head (usage and purpose lines), then one line per option. */
void cli_usage(FILE *f, const char *head, const cdsp_host_option *t, size_t n, int width);
/* s as a number in [lo, hi], or "PROG: --OPT 'S': expected ..." and exit 2. */
double cli_number(const char *prog, const char *opt, const char *s, double lo, double hi);

#endif
