/*
 * tool_records.c - reading back what `solve` (JSON Lines or CSV) and
 * `cdspd --format json` wrote, and what `sim` wrote as truth.json, for
 * `cdsp_tool plot` and `cdsp_tool compare`. JSON through json-c, CSV
 * through libcsv (RFC 4180 quoting), columns found by their header names,
 * so the reader follows the field list rather than column positions. Input
 * that is not such a record says so with the file and line, as export does.
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <csv.h>
#include <json-c/json.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static int push(tool_records *rs, tool_record **r)
{
    tool_record *nr = tool_grow(rs->r, &rs->cap, rs->n, sizeof *nr, 256);
    if (!nr)
        return -1;
    rs->r = nr;
    *r = &rs->r[rs->n++];
    memset(*r, 0, sizeof **r);
    (*r)->t_us = (*r)->distance = (*r)->sigma_distance = (*r)->confidence = NAN;
    {
        int i;
        for (i = 0; i < 3; i++)
            (*r)->sigma_point[i] = (*r)->sigma_direction[i] = NAN;
    }
    return 0;
}

void tool_records_free(tool_records *rs)
{
    size_t i;
    for (i = 0; i < rs->n; i++)
        free(rs->r[i].frame);
    free(rs->r);
    rs->r = NULL;
    rs->n = rs->cap = 0;
}

static char *dup_str(const char *s)
{
    char *d = malloc(strlen(s) + 1);
    if (d)
        strcpy(d, s);
    return d;
}

/* ---- JSON (the lines read by tool_jsonl_read, tool_common.c) ------------------ */

/* One record object; TOOL_JSONL_OK, or NOT_RECORD with the reason it is
 * not one. */
static int from_json(json_object *o, size_t line, void *ctx, const char **why)
{
    tool_records *rs = ctx;
    tool_record *r;
    json_object *st, *fr, *sig, *seg;
    const char *status;
    (void)line;
    if (push(rs, &r) != 0) {
        *why = "out of memory";
        return TOOL_JSONL_BAD;
    }
    if (!json_object_object_get_ex(o, "status", &st) || !json_object_is_type(st, json_type_string)) {
        *why = "no \"status\"";
        return TOOL_JSONL_NOT_RECORD;
    }
    status = json_object_get_string(st);
    /* the frame's file when the record names one (solve: "file"), else
     * its number ("frame") */
    if (json_object_object_get_ex(o, "file", &fr) || json_object_object_get_ex(o, "frame", &fr)) {
        r->frame = dup_str(json_object_get_string(fr));
        if (!r->frame) {
            *why = "out of memory";
            return TOOL_JSONL_BAD;
        }
    }
    if (tool_json_num(o, "t_camera_us", &r->t_us) != 0 && tool_json_num(o, "t_host_us", &r->t_us) != 0)
        r->t_us = NAN;
    if (strcmp(status, "ok") != 0) {
        json_object *e;
        snprintf(r->error, sizeof r->error, "%s",
                 json_object_object_get_ex(o, "error", &e) ? json_object_get_string(e) : status);
        return TOOL_JSONL_OK;
    }
    if (tool_json_vec(o, "point", r->point, 3) || tool_json_vec(o, "direction", r->direction, 3) ||
        tool_json_num(o, "distance", &r->distance)) {
        *why = "an \"ok\" record without point, direction and distance";
        return TOOL_JSONL_NOT_RECORD;
    }
    r->ok = 1;
    if (json_object_object_get_ex(o, "sigma", &sig)) {
        if (tool_json_vec(sig, "point", r->sigma_point, 3))
            r->sigma_point[0] = r->sigma_point[1] = r->sigma_point[2] = NAN;
        if (tool_json_vec(sig, "direction", r->sigma_direction, 3))
            r->sigma_direction[0] = r->sigma_direction[1] = r->sigma_direction[2] = NAN;
        if (tool_json_num(sig, "distance", &r->sigma_distance))
            r->sigma_distance = NAN;
    }
    if (json_object_object_get_ex(o, "segment", &seg) && json_object_is_type(seg, json_type_array) &&
        json_object_array_length(seg) == 2)
        r->have_segment = tool_json_array(json_object_array_get_idx(seg, 0), r->segment[0], 3) == 0 &&
                          tool_json_array(json_object_array_get_idx(seg, 1), r->segment[1], 3) == 0;
    if (tool_json_num(o, "confidence", &r->confidence))
        r->confidence = NAN;
    return TOOL_JSONL_OK;
}

/* plot and compare: JSON Lines only (a pretty-printed record is not what
 * solve or cdspd write), CSV read by read_csv below, so no CSV hint. */
static const tool_jsonl records_jsonl = {from_json, 0, NULL};

/* ---- CSV ------------------------------------------------------------------------ */

/* The columns used, by their header names (solve --csv). */
enum {
    C_FILE, C_FRAME, C_STATUS, C_ERROR, C_PX, C_PY, C_PZ, C_DX, C_DY, C_DZ, C_DIST,
    C_S0X, C_S0Y, C_S0Z, C_S1X, C_S1Y, C_S1Z, C_SPX, C_SPY, C_SPZ, C_SDX, C_SDY, C_SDZ, C_SDIST,
    C_CONF, C_TCAM, C_THOST, C_N
};
static const char *const col_name[C_N][2] = {
    {"file", NULL}, {"frame", NULL}, {"status", NULL}, {"error", NULL},
    {"point_x", NULL}, {"point_y", NULL}, {"point_z", NULL},
    {"direction_x", NULL}, {"direction_y", NULL}, {"direction_z", NULL}, {"distance", NULL},
    /* segment ends: either numbering of the field list */
    {"segment_0_x", "segment_1_x"}, {"segment_0_y", "segment_1_y"}, {"segment_0_z", "segment_1_z"},
    {"segment_1_x", "segment_2_x"}, {"segment_1_y", "segment_2_y"}, {"segment_1_z", "segment_2_z"},
    {"sigma_point_x", NULL}, {"sigma_point_y", NULL}, {"sigma_point_z", NULL},
    {"sigma_direction_x", NULL}, {"sigma_direction_y", NULL}, {"sigma_direction_z", NULL},
    {"sigma_distance", NULL}, {"confidence", NULL}, {"t_camera_us", NULL}, {"t_host_us", NULL},
};

typedef struct {
    const char *cmd, *name;
    tool_records *rs;
    int col[C_N];        /* column index of each, -1 if absent */
    int have_header, failed, ncols;
    size_t row;          /* 1-based line of the row being read */
    char *field[128];    /* this row's fields */
    int nfield;
} csv_state;

static void csv_field(void *s, size_t len, void *data)
{
    csv_state *c = data;
    char *f;
    if (c->failed || c->nfield >= 128)
        return;
    f = malloc(len + 1);
    if (!f) {
        c->failed = 1;
        return;
    }
    memcpy(f, s, len);
    f[len] = 0;
    c->field[c->nfield++] = f;
}

static double csv_num(const csv_state *c, int which)
{
    char *end;
    double v;
    int k = c->col[which];
    if (k < 0 || k >= c->nfield || !c->field[k][0])
        return NAN;
    v = strtod(c->field[k], &end);
    return *end ? NAN : v;
}

static void csv_row(int term, void *data)
{
    csv_state *c = data;
    int i;
    (void)term;
    c->row++;
    if (c->failed)
        goto out;
    if (!c->have_header) {
        int j;
        for (j = 0; j < C_N; j++) {
            c->col[j] = -1;
            for (i = 0; i < c->nfield && c->col[j] < 0; i++)
                if (strcmp(c->field[i], col_name[j][0]) == 0 ||
                    (col_name[j][1] && strcmp(c->field[i], col_name[j][1]) == 0 &&
                     j >= C_S0X && j <= C_S0Z))
                    c->col[j] = i;
        }
        /* segment ends numbered 1 and 2: the second end is segment_2_* */
        if (c->col[C_S0X] >= 0 && strcmp(c->field[c->col[C_S0X]], "segment_1_x") == 0)
            for (j = C_S1X; j <= C_S1Z; j++)
                for (c->col[j] = -1, i = 0; i < c->nfield; i++)
                    if (strcmp(c->field[i], col_name[j][1]) == 0)
                        c->col[j] = i;
        if (c->col[C_STATUS] < 0 || c->col[C_PX] < 0 || c->col[C_DIST] < 0) {
            tool_usage_error(c->cmd, "%s: not a cdsp_tool CSV record file (line 1): no "
                             "status, point_x or distance column", c->name);
            c->failed = 2;
            goto out;
        }
        c->have_header = 1;
        c->ncols = c->nfield;
    } else {
        tool_record *r;
        const char *status;
        if (c->nfield != c->ncols) {
            tool_usage_error(c->cmd, "%s: not a cdsp_tool CSV record (line %zu): %d fields, "
                             "the header has %d", c->name, c->row, c->nfield, c->ncols);
            c->failed = 2;
            goto out;
        }
        if (push(c->rs, &r) != 0) {
            c->failed = 1;
            goto out;
        }
        if (c->col[C_FILE] >= 0 || c->col[C_FRAME] >= 0) /* the file, else the number */
            r->frame = dup_str(c->field[c->col[c->col[C_FILE] >= 0 ? C_FILE : C_FRAME]]);
        status = c->field[c->col[C_STATUS]];
        r->t_us = csv_num(c, C_TCAM);
        if (isnan(r->t_us))
            r->t_us = csv_num(c, C_THOST);
        if (strcmp(status, "ok") != 0) {
            snprintf(r->error, sizeof r->error, "%s",
                     c->col[C_ERROR] >= 0 ? c->field[c->col[C_ERROR]] : status);
            goto out;
        }
        for (i = 0; i < 3; i++) {
            r->point[i] = csv_num(c, C_PX + i);
            r->direction[i] = csv_num(c, C_DX + i);
            r->sigma_point[i] = csv_num(c, C_SPX + i);
            r->sigma_direction[i] = csv_num(c, C_SDX + i);
            r->segment[0][i] = csv_num(c, C_S0X + i);
            r->segment[1][i] = csv_num(c, C_S1X + i);
        }
        r->distance = csv_num(c, C_DIST);
        r->sigma_distance = csv_num(c, C_SDIST);
        r->confidence = csv_num(c, C_CONF);
        r->have_segment = 1;
        for (i = 0; i < 3; i++)
            r->have_segment &= isfinite(r->segment[0][i]) && isfinite(r->segment[1][i]);
        r->ok = isfinite(r->point[0]) && isfinite(r->point[1]) && isfinite(r->point[2]) &&
                isfinite(r->direction[0]) && isfinite(r->direction[1]) &&
                isfinite(r->direction[2]) && isfinite(r->distance);
        if (!r->ok) {
            tool_usage_error(c->cmd, "%s: not a cdsp_tool CSV record (line %zu): an \"ok\" row "
                             "without point, direction and distance", c->name, c->row);
            c->failed = 2;
        }
    }
out:
    for (i = 0; i < c->nfield; i++)
        free(c->field[i]);
    c->nfield = 0;
}

static int read_csv(const char *cmd, const char *name, const char *text, size_t len,
                    tool_records *rs)
{
    struct csv_parser p;
    csv_state c;
    memset(&c, 0, sizeof c);
    c.cmd = cmd;
    c.name = name;
    c.rs = rs;
    if (csv_init(&p, CSV_STRICT | CSV_STRICT_FINI | CSV_APPEND_NULL) != 0)
        return tool_usage_error(cmd, "out of memory");
    if (csv_parse(&p, text, len, csv_field, csv_row, &c) != len ||
        csv_fini(&p, csv_field, csv_row, &c) != 0) {
        if (!c.failed)
            tool_usage_error(cmd, "%s: not a cdsp_tool CSV record (line %zu): %s", name,
                             c.row + 1, csv_strerror(csv_error(&p)));
        c.failed = c.failed ? c.failed : 2;
    }
    csv_free(&p);
    {
        int i;
        for (i = 0; i < c.nfield; i++)
            free(c.field[i]);
    }
    if (c.failed == 1)
        return tool_usage_error(cmd, "out of memory");
    return c.failed ? TOOL_EXIT_USAGE : 0;
}

/* ---- either --------------------------------------------------------------------- */

int tool_records_read(const char *cmd, const char *path, tool_records *rs)
{
    void *buf;
    size_t len;
    const char *name;
    char *text;
    size_t lead;
    int rc;
    memset(rs, 0, sizeof *rs);
    if (tool_read_input(cmd, path, &buf, &len, &name) != 0)
        return TOOL_EXIT_USAGE;
    text = buf;
    lead = strspn(text, " \t\r\n");
    if (text[lead] == '{')
        rc = tool_jsonl_read(cmd, name, text, len, &records_jsonl, rs);
    else if (strncmp(text + lead, "frame,", 6) == 0 || strstr(text, ",status,"))
        rc = read_csv(cmd, name, text, len, rs);
    else if (lead == len)
        rc = tool_usage_error(cmd, "%s: no records (empty file)", name);
    else
        rc = tool_usage_error(cmd, "%s: not a cdsp_tool JSON record (line 1): neither JSON "
                              "Lines nor solve's CSV", name);
    free(buf);
    if (rc)
        tool_records_free(rs);
    return rc;
}

/* ---- truth.json ------------------------------------------------------------------ */

void tool_truth_free(tool_truth *t)
{
    size_t i;
    for (i = 0; i < t->n; i++)
        free(t->f[i].frame);
    free(t->f);
    t->f = NULL;
    t->n = 0;
}

int tool_truth_read(const char *cmd, const char *path, tool_truth *t)
{
    void *buf;
    size_t len, i;
    const char *what;
    json_object *o, *frames;
    memset(t, 0, sizeof *t);
    if (tool_read_input(cmd, path, &buf, &len, &what) != 0)
        return TOOL_EXIT_USAGE;
    o = json_tokener_parse(buf);
    free(buf);
    if (!o || !json_object_object_get_ex(o, "frames", &frames) ||
        !json_object_is_type(frames, json_type_array)) {
        if (o)
            json_object_put(o);
        return tool_usage_error(cmd, "%s: not a truth.json of cdsp_tool sim (no \"frames\" list)",
                                what);
    }
    if (tool_json_num(o, "radius", &t->radius))
        t->radius = NAN;
    t->n = json_object_array_length(frames);
    t->f = calloc(t->n ? t->n : 1, sizeof *t->f);
    if (!t->f) {
        json_object_put(o);
        return tool_usage_error(cmd, "out of memory");
    }
    for (i = 0; i < t->n; i++) {
        json_object *f = json_object_array_get_idx(frames, i), *name;
        tool_truth_frame *tf = &t->f[i];
        /* the frame's file name ("file"; "frame" in truth files before the
         * field list had "file"), matched to the records' */
        if ((json_object_object_get_ex(f, "file", &name) ||
             json_object_object_get_ex(f, "frame", &name)) &&
            json_object_is_type(name, json_type_string))
            tf->frame = dup_str(json_object_get_string(name));
        if (tool_json_vec(f, "point", tf->point, 3) || tool_json_vec(f, "direction", tf->direction, 3) ||
            tool_json_num(f, "distance", &tf->distance)) {
            json_object_put(o);
            tool_truth_free(t);
            return tool_usage_error(cmd, "%s: frame %zu of \"frames\" has no point, direction "
                                    "and distance", what, i);
        }
        if (tool_json_num(f, "half_length", &tf->half_length))
            tf->half_length = 0;
    }
    json_object_put(o);
    return 0;
}

static const char *base_name(const char *p)
{
    const char *s = p ? strrchr(p, '/') : NULL;
    return s ? s + 1 : p ? p : "";
}

const tool_truth_frame *tool_truth_match(const tool_truth *t, const tool_record *r, size_t index)
{
    size_t i;
    /* by file name (solve's records name the frame as given, truth.json
     * by its name in the directory), else by position */
    if (r->frame)
        for (i = 0; i < t->n; i++)
            if (t->f[i].frame && strcmp(base_name(r->frame), t->f[i].frame) == 0)
                return &t->f[i];
    return index < t->n ? &t->f[index] : NULL;
}

/* ---- errors against the truth ---------------------------------------------------- */

void tool_record_errors(const tool_record *r, const tool_truth_frame *tf, int samples,
                        double *rmse, double *angle_deg, double *ddist)
{
    double a[3], b[3], c;
    int i;
    for (i = 0; i < 3; i++) {
        a[i] = r->segment[0][i];
        b[i] = r->segment[1][i];
    }
    if (!r->have_segment ||
        hypot(hypot(b[0] - a[0], b[1] - a[1]), b[2] - a[2]) < 1e-9 * (1 + r->distance)) {
        /* no visible extent: the true half length, else the point only */
        double h = tf->half_length > 0 ? tf->half_length : 0;
        for (i = 0; i < 3; i++) {
            a[i] = r->point[i] - h * r->direction[i];
            b[i] = r->point[i] + h * r->direction[i];
        }
    }
    *rmse = tool_segment_rmse(a, b, tf->point, tf->direction, samples);
    c = fabs(r->direction[0] * tf->direction[0] + r->direction[1] * tf->direction[1] +
             r->direction[2] * tf->direction[2]) /
        (sqrt(r->direction[0] * r->direction[0] + r->direction[1] * r->direction[1] +
              r->direction[2] * r->direction[2]) *
         sqrt(tf->direction[0] * tf->direction[0] + tf->direction[1] * tf->direction[1] +
              tf->direction[2] * tf->direction[2]));
    *angle_deg = acos(c > 1 ? 1 : c) * 180.0 / 3.14159265358979323846;
    *ddist = r->distance - tf->distance;
}
