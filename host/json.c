/*
 * json.c - a small JSON writer into a caller buffer, and the pose record
 * that cdsp_tool and cdspd both emit. Written by hand because the daemon
 * must not allocate per frame; it is kept simple enough to be obviously
 * right (every string escaped, UTF-8 validated, non-finite numbers as null)
 * and the tests read its output back with json-c.
 * Numbers are formatted with snprintf, so the C locale is assumed (the
 * programs never call setlocale()).
 */
#include "cdsp_host.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

void cdsp_host_json_init(cdsp_host_json *j, char *buf, size_t cap)
{
    j->buf = buf;
    j->cap = cap;
    j->len = 0;
    j->overflow = cap == 0;
    j->depth = 0;
    j->count[0] = 0;
    j->after_key = 0;
    if (cap)
        buf[0] = 0;
}

static void put(cdsp_host_json *j, const char *s, size_t n)
{
    if (j->overflow)
        return;
    if (j->len + n + 1 > j->cap) {
        j->overflow = 1;
        return;
    }
    memcpy(j->buf + j->len, s, n);
    j->len += n;
    j->buf[j->len] = 0;
}

static void puts_(cdsp_host_json *j, const char *s)
{
    put(j, s, strlen(s));
}

/* Before a value (or a key): the comma between siblings. */
static void sep(cdsp_host_json *j)
{
    if (j->after_key) {
        j->after_key = 0;
        return;
    }
    if (j->count[j->depth])
        put(j, ",", 1);
    if (j->count[j->depth] < 255)
        j->count[j->depth]++;
}

static void open_(cdsp_host_json *j, const char *ch)
{
    sep(j);
    put(j, ch, 1);
    if (j->depth + 1 >= CDSP_HOST_JSON_DEPTH) {
        j->overflow = 1;
        return;
    }
    j->depth++;
    j->count[j->depth] = 0;
}

static void close_(cdsp_host_json *j, const char *ch)
{
    if (j->depth == 0 || j->after_key) {
        j->overflow = 1;
        return;
    }
    put(j, ch, 1);
    j->depth--;
}

void cdsp_host_json_begin_object(cdsp_host_json *j) { open_(j, "{"); }
void cdsp_host_json_end_object(cdsp_host_json *j) { close_(j, "}"); }
void cdsp_host_json_begin_array(cdsp_host_json *j) { open_(j, "["); }
void cdsp_host_json_end_array(cdsp_host_json *j) { close_(j, "]"); }

/* Length of the valid UTF-8 sequence at s (RFC 3629: no overlong forms, no
 * surrogates, nothing above U+10FFFF), or 0 if it is not one. */
static size_t utf8_len(const unsigned char *s)
{
    unsigned c = s[0];
    if (c < 0x80)
        return 1;
    if (c >= 0xc2 && c <= 0xdf)
        return (s[1] & 0xc0) == 0x80 ? 2 : 0;
    if (c >= 0xe0 && c <= 0xef) {
        unsigned lo = c == 0xe0 ? 0xa0 : 0x80, hi = c == 0xed ? 0x9f : 0xbf;
        if (s[1] < lo || s[1] > hi || (s[2] & 0xc0) != 0x80)
            return 0;
        return 3;
    }
    if (c >= 0xf0 && c <= 0xf4) {
        unsigned lo = c == 0xf0 ? 0x90 : 0x80, hi = c == 0xf4 ? 0x8f : 0xbf;
        if (s[1] < lo || s[1] > hi || (s[2] & 0xc0) != 0x80 || (s[3] & 0xc0) != 0x80)
            return 0;
        return 4;
    }
    return 0;
}

static void string_(cdsp_host_json *j, const char *str)
{
    const unsigned char *s = (const unsigned char *)(str ? str : "");
    put(j, "\"", 1);
    while (*s) {
        size_t n;
        char esc[8];
        switch (*s) {
        case '"': put(j, "\\\"", 2); s++; continue;
        case '\\': put(j, "\\\\", 2); s++; continue;
        case '\n': put(j, "\\n", 2); s++; continue;
        case '\r': put(j, "\\r", 2); s++; continue;
        case '\t': put(j, "\\t", 2); s++; continue;
        case '\b': put(j, "\\b", 2); s++; continue;
        case '\f': put(j, "\\f", 2); s++; continue;
        default: break;
        }
        if (*s < 0x20) {
            snprintf(esc, sizeof esc, "\\u%04x", *s);
            put(j, esc, 6);
            s++;
            continue;
        }
        /* a string ends at its NUL, so a truncated sequence fails the
         * continuation test before reading past it */
        n = utf8_len(s);
        if (n == 0) {
            put(j, "\\ufffd", 6);
            s++;
        } else {
            put(j, (const char *)s, n);
            s += n;
        }
    }
    put(j, "\"", 1);
}

void cdsp_host_json_key(cdsp_host_json *j, const char *key)
{
    if (j->after_key || j->depth == 0) {
        j->overflow = 1;
        return;
    }
    sep(j);
    string_(j, key);
    put(j, ":", 1);
    j->after_key = 1;
}

void cdsp_host_json_string(cdsp_host_json *j, const char *s)
{
    sep(j);
    string_(j, s);
}

const char *cdsp_host_fmt_real(char buf[32], double v)
{
    if (!isfinite(v)) {
        strcpy(buf, "null");
        return buf;
    }
    snprintf(buf, 32, "%.15g", v);
    if (strtod(buf, NULL) != v)
        snprintf(buf, 32, "%.17g", v);
    return buf;
}

void cdsp_host_json_number(cdsp_host_json *j, double v)
{
    char b[32];
    sep(j);
    puts_(j, cdsp_host_fmt_real(b, v));
}

void cdsp_host_json_int(cdsp_host_json *j, long long v)
{
    char b[32];
    sep(j);
    snprintf(b, sizeof b, "%lld", v);
    puts_(j, b);
}

void cdsp_host_json_bool(cdsp_host_json *j, int v)
{
    sep(j);
    puts_(j, v ? "true" : "false");
}

void cdsp_host_json_null(cdsp_host_json *j)
{
    sep(j);
    puts_(j, "null");
}

void cdsp_host_json_reals(cdsp_host_json *j, const cdsp_real *v, int n)
{
    int i;
    cdsp_host_json_begin_array(j);
    for (i = 0; i < n; i++)
        cdsp_host_json_number(j, (double)v[i]);
    cdsp_host_json_end_array(j);
}

const char *cdsp_host_json_finish(cdsp_host_json *j)
{
    if (j->overflow || j->depth != 0 || j->after_key)
        return NULL;
    return j->buf;
}

/* The rows f[0..n) of r as keys of the open object (a "group.key" row
 * inside the object "group"); skip: a row name left out. */
static void json_fields(cdsp_host_json *j, const cdsp_result *r, const cdsp_host_field *f, size_t n,
                        const char *skip)
{
    size_t i;
    const char *group = NULL; /* the nested object open now, e.g. "sigma" */
    size_t group_len = 0;
    for (i = 0; i < n; i++) {
        const char *dot = strchr(f[i].name, '.'), *key = dot ? dot + 1 : f[i].name;
        const char *base = (const char *)r + f[i].offset;
        const cdsp_real *v = (const cdsp_real *)(const void *)base;
        const uint32_t *u = (const uint32_t *)(const void *)base;
        if (skip && strcmp(f[i].name, skip) == 0)
            continue;
        if (group && (!dot || (size_t)(dot - f[i].name) != group_len ||
                      strncmp(f[i].name, group, group_len))) {
            cdsp_host_json_end_object(j);
            group = NULL;
        }
        if (dot && !group) {
            char g[64];
            group = f[i].name;
            group_len = (size_t)(dot - f[i].name);
            snprintf(g, sizeof g, "%.*s", (int)group_len, group);
            cdsp_host_json_key(j, g);
            cdsp_host_json_begin_object(j);
        }
        cdsp_host_json_key(j, key);
        switch (f[i].kind) {
        case CDSP_HOST_FIELD_REAL: cdsp_host_json_number(j, (double)v[0]); break;
        case CDSP_HOST_FIELD_VEC3: cdsp_host_json_reals(j, v, 3); break;
        case CDSP_HOST_FIELD_PAIR: cdsp_host_json_reals(j, v, 2); break;
        case CDSP_HOST_FIELD_COUNT: cdsp_host_json_int(j, u[0]); break;
        case CDSP_HOST_FIELD_COUNT2:
            cdsp_host_json_begin_array(j);
            cdsp_host_json_int(j, u[0]);
            cdsp_host_json_int(j, u[1]);
            cdsp_host_json_end_array(j);
            break;
        case CDSP_HOST_FIELD_LINES:
        case CDSP_HOST_FIELD_POINTS:
            cdsp_host_json_begin_array(j);
            cdsp_host_json_reals(j, v, 3);
            cdsp_host_json_reals(j, v + 3, 3);
            cdsp_host_json_end_array(j);
            break;
        case CDSP_HOST_FIELD_FLAG: cdsp_host_json_bool(j, (u[0] & f[i].mask) != 0); break;
        }
    }
    if (group)
        cdsp_host_json_end_object(j);
}

void cdsp_host_json_pose(cdsp_host_json *j, cdsp_status st, const char *error_token,
                         const cdsp_result *r, cdsp_real radius)
{
    const cdsp_host_field *f;
    size_t n;

    cdsp_host_json_key(j, "status");
    if (st != CDSP_OK || !r) {
        cdsp_host_json_string(j, "error");
        cdsp_host_json_key(j, "error");
        cdsp_host_json_string(j, error_token ? error_token : cdsp_status_token(st));
    } else {
        cdsp_host_json_string(j, "ok");
    }
    cdsp_host_json_key(j, "radius");
    cdsp_host_json_number(j, (double)radius);
    if (st != CDSP_OK || !r)
        return;
    f = cdsp_host_pose_fields(&n);
    json_fields(j, r, f, n, NULL);
}

void cdsp_host_json_pipes(cdsp_host_json *j, const cdsp_result *pipes, size_t n, int tracking)
{
    const cdsp_host_field *f;
    size_t nf, a, b;
    f = cdsp_host_pipe_fields(&nf);
    cdsp_host_json_key(j, "pipes");
    cdsp_host_json_begin_array(j);
    for (a = 0; a < n; a++) {
        cdsp_host_json_begin_object(j);
        json_fields(j, &pipes[a], f, nf, tracking ? NULL : "track_id");
        cdsp_host_json_end_object(j);
    }
    cdsp_host_json_end_array(j);
    cdsp_host_json_key(j, "pairs");
    cdsp_host_json_begin_array(j);
    for (a = 0; a < n; a++)
        for (b = a + 1; b < n; b++) {
            double ang, dist, rms;
            if (cdsp_host_pipe_pair(&pipes[a], &pipes[b], &ang, &dist, &rms) != 0)
                continue;
            cdsp_host_json_begin_object(j);
            cdsp_host_json_key(j, "i");
            cdsp_host_json_int(j, (long long)a);
            cdsp_host_json_key(j, "j");
            cdsp_host_json_int(j, (long long)b);
            cdsp_host_json_key(j, "angle_deg");
            cdsp_host_json_number(j, ang);
            cdsp_host_json_key(j, "axis_distance");
            cdsp_host_json_number(j, dist);
            cdsp_host_json_key(j, "axis_distance_rms");
            cdsp_host_json_number(j, rms);
            cdsp_host_json_end_object(j);
        }
    cdsp_host_json_end_array(j);
}
