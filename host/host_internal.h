/*
 * host_internal.h - private helpers of libcdsp_host (not installed).
 */
#ifndef CDSP_HOST_INTERNAL_H
#define CDSP_HOST_INTERNAL_H

#include "cdsp_host.h"

/* Fill err (when not NULL) with "NAME: message" and return rc. */
int cdsp_host__fail(cdsp_host_err *err, int rc, const char *name, const char *fmt, ...)
#if defined(__GNUC__)
    __attribute__((format(printf, 4, 5)))
#endif
    ;

#endif
