/*
 * log.h - cdspd's log: one line per message on stderr, a level per
 * category (config keys log.level and log.<category>), safe from any
 * thread. Under systemd (JOURNAL_STREAM set) each line starts with the
 * syslog priority "<N>" so the journal files it at the right level.
 */
#ifndef CDSPD_LOG_H
#define CDSPD_LOG_H

typedef enum {
    CDSPD_LOG_ERROR = 0,
    CDSPD_LOG_WARN = 1,
    CDSPD_LOG_INFO = 2,
    CDSPD_LOG_DEBUG = 3
} cdspd_log_level;

typedef enum {
    CDSPD_LOGC_MAIN = 0, /* start, stop, signals, reload */
    CDSPD_LOGC_CONFIG,   /* configuration */
    CDSPD_LOGC_SOURCE,   /* cameras and other frame sources */
    CDSPD_LOGC_PROC,     /* the processing thread */
    CDSPD_LOGC_NET,      /* the UDP sender */
    CDSPD_LOGC_STATS,    /* periodic statistics */
    CDSPD_LOGC_RECORD,   /* --record */
    CDSPD_LOGC_MAVLINK,  /* the MAVLink links */
    CDSPD_LOGC_COUNT
} cdspd_log_cat;

/* "main", "config", ...; NULL out of range. */
const char *cdspd_log_cat_name(int cat);
/* "error", "warn", "info", "debug"; index of a name or -1. */
const char *cdspd_log_level_name(int level);
int cdspd_log_level_parse(const char *s);

void cdspd_log_set_level(cdspd_log_cat cat, cdspd_log_level level);
int cdspd_log_enabled(cdspd_log_cat cat, cdspd_log_level level);

#if defined(__GNUC__)
#define CDSPD_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define CDSPD_PRINTF(a, b)
#endif

void cdspd_log(cdspd_log_cat cat, cdspd_log_level level, const char *fmt, ...) CDSPD_PRINTF(3, 4);

#define LOG_E(cat, ...) cdspd_log(CDSPD_LOGC_##cat, CDSPD_LOG_ERROR, __VA_ARGS__)
#define LOG_W(cat, ...) cdspd_log(CDSPD_LOGC_##cat, CDSPD_LOG_WARN, __VA_ARGS__)
#define LOG_I(cat, ...) cdspd_log(CDSPD_LOGC_##cat, CDSPD_LOG_INFO, __VA_ARGS__)
#define LOG_D(cat, ...) cdspd_log(CDSPD_LOGC_##cat, CDSPD_LOG_DEBUG, __VA_ARGS__)

#endif
