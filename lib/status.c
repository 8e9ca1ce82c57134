/*
 * status.c - the one status enum, in words and in tokens.
 * Tokens are stable: the tools' JSON and the UDP protocol carry them.
 */
#include "cdsp.h"

const char *cdsp_strerror(cdsp_status s)
{
    switch (s) {
    case CDSP_OK: return "ok";
    case CDSP_E_ARG: return "invalid argument";
    case CDSP_E_NONFINITE: return "NaN or Inf in input";
    case CDSP_E_NOCONVERGE: return "iteration did not converge";
    case CDSP_E_CAPACITY: return "more data than the fixed buffers hold";
    case CDSP_E_FEW_POINTS: return "too few edge points";
    case CDSP_E_NO_PIPE: return "no pipe found";
    case CDSP_E_DEGENERATE: return "degenerate geometry";
    case CDSP_E_FORMAT: return "unsupported image format";
    }
    return "unknown status";
}

const char *cdsp_status_token(cdsp_status s)
{
    switch (s) {
    case CDSP_OK: return "ok";
    case CDSP_E_ARG: return "bad-argument";
    case CDSP_E_NONFINITE: return "non-finite";
    case CDSP_E_NOCONVERGE: return "no-convergence";
    case CDSP_E_CAPACITY: return "capacity";
    case CDSP_E_FEW_POINTS: return "few-points";
    case CDSP_E_NO_PIPE: return "no-pipe";
    case CDSP_E_DEGENERATE: return "degenerate";
    case CDSP_E_FORMAT: return "bad-format";
    }
    return "unknown";
}
