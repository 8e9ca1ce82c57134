/*
 * log.c - see log.h. Each message is formatted into a stack buffer and
 * written with one write(2), so lines from different threads never mix.
 * Levels are plain ints read without a lock: a reload that changes them
 * while another thread logs may let one line through at the old level,
 * which is harmless.
 */
#define _POSIX_C_SOURCE 200809L
#include "log.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

static volatile int levels[CDSPD_LOGC_COUNT] = {2, 2, 2, 2, 2, 2, 2, 2};

static const char *const cat_names[CDSPD_LOGC_COUNT] = {"main", "config", "source", "proc",
                                                         "net", "stats", "record",
                                                         "mavlink"};
static const char *const level_names[] = {"error", "warn", "info", "debug"};

const char *cdspd_log_cat_name(int cat)
{
    return cat >= 0 && cat < CDSPD_LOGC_COUNT ? cat_names[cat] : NULL;
}

const char *cdspd_log_level_name(int level)
{
    return level >= 0 && level <= CDSPD_LOG_DEBUG ? level_names[level] : NULL;
}

int cdspd_log_level_parse(const char *s)
{
    int i;
    for (i = 0; i <= CDSPD_LOG_DEBUG; i++)
        if (!strcmp(s, level_names[i]))
            return i;
    if (!strcmp(s, "warning"))
        return CDSPD_LOG_WARN;
    return -1;
}

void cdspd_log_set_level(cdspd_log_cat cat, cdspd_log_level level)
{
    if ((int)cat >= 0 && cat < CDSPD_LOGC_COUNT)
        levels[cat] = (int)level;
}

int cdspd_log_enabled(cdspd_log_cat cat, cdspd_log_level level)
{
    return (int)cat >= 0 && cat < CDSPD_LOGC_COUNT && (int)level <= levels[cat];
}

void cdspd_log(cdspd_log_cat cat, cdspd_log_level level, const char *fmt, ...)
{
    /* syslog priorities: err 3, warning 4, info 6, debug 7 */
    static const int prio[] = {3, 4, 6, 7};
    static const char *const tag[] = {"error: ", "warning: ", "", ""};
    char line[1024];
    size_t n = 0;
    int k;
    va_list ap;

    if (!cdspd_log_enabled(cat, level))
        return;
    if (getenv("JOURNAL_STREAM"))
        n = (size_t)snprintf(line, sizeof line, "<%d>", prio[level]);
    k = snprintf(line + n, sizeof line - n, "cdspd: %s: %s", cat_names[cat], tag[level]);
    if (k > 0)
        n += (size_t)k;
    if (n < sizeof line) {
        va_start(ap, fmt);
        k = vsnprintf(line + n, sizeof line - n, fmt, ap);
        va_end(ap);
        if (k > 0)
            n += (size_t)k;
    }
    if (n > sizeof line - 2)
        n = sizeof line - 2; /* truncated: keep the newline */
    line[n++] = '\n';
    if (write(STDERR_FILENO, line, n) < 0) {
        /* nowhere left to report it */
    }
}
