/*
 * err.c - the one-line error messages of libcdsp_host: the file (or the
 * name given for an in-memory buffer) first, then the problem.
 */
#define _POSIX_C_SOURCE 200809L
#include "host_internal.h"

#include <stdarg.h>
#include <stdio.h>

int cdsp_host__fail(cdsp_host_err *err, int rc, const char *name, const char *fmt, ...)
{
    if (err) {
        va_list ap;
        int k = snprintf(err->msg, sizeof err->msg, "%s: ", name);
        if (k < 0 || (size_t)k >= sizeof err->msg)
            k = 0;
        va_start(ap, fmt);
        vsnprintf(err->msg + k, sizeof err->msg - (size_t)k, fmt, ap);
        va_end(ap);
    }
    return rc;
}
