/*
 * tool_common.c - what every subcommand of cdsp_tool shares: the option
 * table (parsing, range checks and the OPTIONS section of --help from the
 * same place), frame lists, progress on a terminal, the geometry of the
 * paper's simulated scene, and the reading of JSON records (export, plot,
 * compare).
 */
#define _POSIX_C_SOURCE 200809L
#include "tool_internal.h"

#include <dirent.h>
#include <errno.h>
#include <json-c/json.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

/* ---- messages ------------------------------------------------------------ */

int tool_usage_error(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "cdsp_tool %s: ", cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
    return TOOL_EXIT_USAGE;
}

void tool_warn(const char *cmd, const char *fmt, ...)
{
    va_list ap;
    fprintf(stderr, "cdsp_tool %s: ", cmd);
    va_start(ap, fmt);
    vfprintf(stderr, fmt, ap);
    va_end(ap);
    fputc('\n', stderr);
}

double tool_now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec * 1e6 + (double)ts.tv_nsec * 1e-3;
}

/* One level: an existing directory is fine, an existing file is ENOTDIR. */
static int mkdir_one(const char *path)
{
    struct stat st;
    if (mkdir(path, 0777) == 0)
        return 0;
    if (errno == EEXIST && stat(path, &st) == 0 && S_ISDIR(st.st_mode))
        return 0;
    if (errno == EEXIST)
        errno = ENOTDIR;
    return -1;
}

int tool_mkdir(const char *path)
{
    char buf[4096];
    size_t n = strlen(path), i;
    if (n == 0 || n >= sizeof buf) {
        errno = n ? ENAMETOOLONG : ENOENT;
        return -1;
    }
    memcpy(buf, path, n + 1);
    /* each parent in turn, as mkdir -p does ("a//b" and a trailing '/' too) */
    for (i = 1; i < n; i++) {
        if (buf[i] != '/' || buf[i - 1] == '/')
            continue;
        buf[i] = 0;
        if (mkdir_one(buf) != 0)
            return -1;
        buf[i] = '/';
    }
    return mkdir_one(buf);
}

/* ---- option values ------------------------------------------------------- */

static int parse_real(const char *s, double *out)
{
    char *end;
    double v;
    if (!*s)
        return -1;
    errno = 0;
    v = strtod(s, &end);
    if (*end || errno == ERANGE || !isfinite(v))
        return -1;
    *out = v;
    return 0;
}

/* "a,b,c" -> up to max reals; the count read, -1 on a bad element. */
static int parse_reals(const char *s, double *out, int max)
{
    char buf[1024], *tok, *save = NULL;
    int n = 0;
    if (strlen(s) >= sizeof buf)
        return -1;
    strcpy(buf, s);
    for (tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
        if (n >= max || parse_real(tok, &out[n]) != 0)
            return -1;
        n++;
    }
    return n;
}

static int set_value(const tool_doc *doc, const tool_opt *o, const char *v)
{
    double d, vec[TOOL_LIST_MAX];
    int n;
    switch (o->kind) {
    case OPT_FLAG:
        *(int *)o->target = 1;
        return 0;
    case OPT_INT:
        if (parse_real(v, &d) != 0 || d != floor(d))
            return tool_usage_error(doc->name, "--%s: expected an integer, got '%s'", o->name, v);
        if (d < o->min || d > o->max)
            return tool_usage_error(doc->name, "--%s: %s is outside %.0f..%.0f", o->name, v,
                                    o->min, o->max);
        *(int *)o->target = (int)d;
        return 0;
    case OPT_U64: {
        char *end;
        unsigned long long u;
        errno = 0;
        u = strtoull(v, &end, 0);
        if (!*v || *end || errno || v[0] == '-')
            return tool_usage_error(doc->name, "--%s: expected a non-negative integer, got '%s'",
                                    o->name, v);
        *(uint64_t *)o->target = (uint64_t)u;
        return 0;
    }
    case OPT_REAL:
        if (parse_real(v, &d) != 0)
            return tool_usage_error(doc->name, "--%s: expected a number, got '%s'", o->name, v);
        if (d < o->min || d > o->max)
            return tool_usage_error(doc->name, "--%s: %s is outside %g..%g", o->name, v, o->min,
                                    o->max);
        *(double *)o->target = d;
        return 0;
    case OPT_STR:
        *(const char **)o->target = v;
        return 0;
    case OPT_VEC3:
        if (parse_reals(v, vec, 3) != 3)
            return tool_usage_error(doc->name, "--%s: expected three numbers x,y,z, got '%s'",
                                    o->name, v);
        memcpy(o->target, vec, sizeof(double) * 3);
        return 0;
    case OPT_ROI: {
        cdsp_roi *r = o->target;
        n = parse_reals(v, vec, 4);
        if (n != 4 || vec[0] != floor(vec[0]) || vec[1] != floor(vec[1]) ||
            vec[2] != floor(vec[2]) || vec[3] != floor(vec[3]) || vec[0] < 0 || vec[1] < 0 ||
            vec[2] < 1 || vec[3] < 1 || vec[0] + vec[2] > CDSP_HOST_MAX_DIM ||
            vec[1] + vec[3] > CDSP_HOST_MAX_DIM)
            return tool_usage_error(doc->name,
                                    "--%s: expected X,Y,W,H (pixels, W and H >= 1), got '%s'",
                                    o->name, v);
        r->x = (int)vec[0];
        r->y = (int)vec[1];
        r->w = (int)vec[2];
        r->h = (int)vec[3];
        return 0;
    }
    case OPT_CHOICE: {
        const char *c = o->choices;
        size_t len = strlen(v);
        int idx = 0;
        while (c) {
            const char *bar = strchr(c, '|');
            size_t cl = bar ? (size_t)(bar - c) : strlen(c);
            if (cl == len && strncmp(c, v, len) == 0) {
                *(int *)o->target = idx;
                return 0;
            }
            c = bar ? bar + 1 : NULL;
            idx++;
        }
        return tool_usage_error(doc->name, "--%s: expected one of %s, got '%s'", o->name,
                                o->choices, v);
    }
    case OPT_LIST: {
        tool_list *l = o->target;
        n = parse_reals(v, vec, TOOL_LIST_MAX);
        if (n < 1)
            return tool_usage_error(doc->name, "--%s: expected a list of numbers a,b,..., got '%s'",
                                    o->name, v);
        for (l->n = 0; l->n < n; l->n++) {
            if (vec[l->n] < o->min || vec[l->n] > o->max)
                return tool_usage_error(doc->name, "--%s: %g is outside %g..%g", o->name,
                                        vec[l->n], o->min, o->max);
            l->v[l->n] = vec[l->n];
        }
        return 0;
    }
    }
    return TOOL_EXIT_USAGE;
}

int tool_parse_alloc(const char *cmd, const tool_doc *doc, const tool_opt *opts, int argc,
                     char **argv, char ***pos, int *npos)
{
    int rc;
    *pos = calloc((size_t)argc + 1, sizeof **pos);
    if (!*pos)
        return tool_usage_error(cmd, "out of memory") + 1;
    rc = tool_parse(doc, opts, argc, argv, *pos, npos);
    if (rc) {
        free(*pos);
        *pos = NULL;
    }
    return rc;
}

int tool_parse(const tool_doc *doc, const tool_opt *opts, int argc, char **argv, char **pos,
               int *npos)
{
    int i, only_pos = 0;
    *npos = 0;
    for (i = 1; i < argc; i++) {
        const char *a = argv[i], *val = NULL;
        const tool_opt *o = NULL;
        char name[64];
        if (only_pos || a[0] != '-' || a[1] == 0) {
            pos[(*npos)++] = argv[i];
            continue;
        }
        if (strcmp(a, "--") == 0) {
            only_pos = 1;
            continue;
        }
        if (strcmp(a, "--help") == 0 || strcmp(a, "-h") == 0) {
            tool_help(doc, opts);
            return 1;
        }
        if (a[1] == '-') {
            const char *eq = strchr(a + 2, '=');
            size_t len = eq ? (size_t)(eq - a - 2) : strlen(a + 2);
            if (len >= sizeof name)
                return tool_usage_error(doc->name, "unknown option '%s' (see --help)", a) + 1;
            memcpy(name, a + 2, len);
            name[len] = 0;
            if (eq)
                val = eq + 1;
            for (o = opts; o->name; o++)
                if (strcmp(o->name, name) == 0)
                    break;
        } else {
            if (a[2] != 0)
                val = a + 2;
            for (o = opts; o->name; o++)
                if (o->short_name && o->short_name == a[1])
                    break;
            snprintf(name, sizeof name, "%c", a[1]);
        }
        if (!o || !o->name)
            return tool_usage_error(doc->name, "unknown option '%s' (see --help)", a) + 1;
        if (o->kind == OPT_FLAG) {
            if (val)
                return tool_usage_error(doc->name, "--%s takes no value", o->name) + 1;
        } else if (!val) {
            if (i + 1 >= argc)
                return tool_usage_error(doc->name, "--%s needs a value (%s)", o->name,
                                        o->arg ? o->arg : "VALUE") + 1;
            val = argv[++i];
        }
        if (set_value(doc, o, val) != 0)
            return TOOL_EXIT_USAGE + 1;
    }
    return 0;
}

/* ---- help ------------------------------------------------------------------ */

/* Words of text wrapped to `width` columns, each line indented by `indent`. */
static void wrap(FILE *f, const char *text, int indent, int width)
{
    int col = 0;
    const char *p = text;
    while (*p) {
        const char *w = p;
        int len;
        while (*p && *p != ' ' && *p != '\n')
            p++;
        len = (int)(p - w);
        if (len > 0) {
            if (col > 0 && col + 1 + len > width) {
                fputc('\n', f);
                col = 0;
            }
            if (col == 0) {
                fprintf(f, "%*s", indent, "");
                col = indent;
            } else {
                fputc(' ', f);
                col++;
            }
            fwrite(w, 1, (size_t)len, f);
            col += len;
        }
        while (*p == ' ' || *p == '\n')
            p++;
    }
    if (col > 0)
        fputc('\n', f);
}

static void print_default(char *buf, size_t cap, const tool_opt *o)
{
    buf[0] = 0;
    if (o->no_default)
        return;
    switch (o->kind) {
    case OPT_INT:
        snprintf(buf, cap, "%d", *(const int *)o->target);
        break;
    case OPT_U64:
        snprintf(buf, cap, "%llu", (unsigned long long)*(const uint64_t *)o->target);
        break;
    case OPT_REAL:
        snprintf(buf, cap, "%g", *(const double *)o->target);
        break;
    case OPT_STR:
        if (*(const char *const *)o->target)
            snprintf(buf, cap, "%s", *(const char *const *)o->target);
        break;
    case OPT_VEC3: {
        const double *v = o->target;
        snprintf(buf, cap, "%g,%g,%g", v[0], v[1], v[2]);
        break;
    }
    case OPT_ROI: {
        const cdsp_roi *r = o->target;
        if (r->w > 0 && r->h > 0)
            snprintf(buf, cap, "%d,%d,%d,%d", r->x, r->y, r->w, r->h);
        else
            snprintf(buf, cap, "the whole frame");
        break;
    }
    case OPT_CHOICE: {
        const char *c = o->choices, *bar;
        int idx = *(const int *)o->target;
        while (idx-- > 0 && c)
            c = strchr(c, '|') ? strchr(c, '|') + 1 : NULL;
        if (c) {
            bar = strchr(c, '|');
            snprintf(buf, cap, "%.*s", bar ? (int)(bar - c) : (int)strlen(c), c);
        }
        break;
    }
    case OPT_LIST: {
        const tool_list *l = o->target;
        size_t k = 0;
        int i;
        for (i = 0; i < l->n && k + 24 < cap; i++)
            k += (size_t)snprintf(buf + k, cap - k, i ? ",%g" : "%g", l->v[i]);
        break;
    }
    case OPT_FLAG:
        break;
    }
}

void tool_help(const tool_doc *doc, const tool_opt *opts)
{
    const tool_opt *o;
    FILE *f = stdout;
    fprintf(f, "NAME\n    cdsp_tool %s - %s\n\n", doc->name, doc->summary);
    fprintf(f, "SYNOPSIS\n    cdsp_tool %s %s\n\n", doc->name, doc->synopsis);
    {
        /* paragraphs, then exactly one blank line */
        size_t n = strlen(doc->description);
        while (n > 0 && doc->description[n - 1] == '\n')
            n--;
        fprintf(f, "DESCRIPTION\n%.*s\n\n", (int)n, doc->description);
    }
    fprintf(f, "OPTIONS\n");
    for (o = opts; o->name; o++) {
        char def[256], text[1400];
        if (o->short_name)
            fprintf(f, "    -%c, --%s", o->short_name, o->name);
        else
            fprintf(f, "    --%s", o->name);
        if (o->kind == OPT_CHOICE)
            fprintf(f, " %s\n", o->choices);
        else if (o->arg)
            fprintf(f, " %s\n", o->arg);
        else
            fputc('\n', f);
        print_default(def, sizeof def, o);
        if (def[0])
            snprintf(text, sizeof text, "%s Default: %s.", o->help, def);
        else
            snprintf(text, sizeof text, "%s", o->help);
        wrap(f, text, 8, 79);
    }
    fprintf(f, "    -h, --help\n        Print this help and exit.\n\n");
    if (doc->after)
        fprintf(f, "%s\n", doc->after);
    fprintf(f, "EXIT STATUS\n%s", doc->exit_status);
}

/* ---- growing arrays ------------------------------------------------------- */

void *tool_grow(void *p, size_t *cap, size_t n, size_t elem, size_t first)
{
    size_t c;
    void *np;
    if (n < *cap)
        return p;
    c = *cap ? 2 * *cap : first;
    if (c < *cap || c > (size_t)-1 / elem) /* the doubling or the bytes overflow */
        return NULL;
    np = realloc(p, c * elem);
    if (np)
        *cap = c;
    return np;
}

/* ---- frame lists ------------------------------------------------------------ */

static int frames_push(tool_frames *f, const char *path)
{
    char *copy;
    char **np = tool_grow(f->path, &f->cap, f->n, sizeof *np, 64);
    if (!np)
        return -1;
    f->path = np;
    copy = malloc(strlen(path) + 1);
    if (!copy)
        return -1;
    strcpy(copy, path);
    f->path[f->n++] = copy;
    return 0;
}

/* A frame file by its extension (any case): .pgm .png .jpg .jpeg .tif .tiff */
static int is_frame_name(const char *name)
{
    static const char *const ext[] = {".pgm", ".png", ".jpg", ".jpeg", ".tif", ".tiff"};
    size_t n = strlen(name), i, k, e;
    if (name[0] == '.')
        return 0;
    for (e = 0; e < sizeof ext / sizeof ext[0]; e++) {
        k = strlen(ext[e]);
        if (n <= k)
            continue;
        for (i = 0; i < k; i++) {
            char c = name[n - k + i];
            if ((c >= 'A' && c <= 'Z' ? (char)(c - 'A' + 'a') : c) != ext[e][i])
                break;
        }
        if (i == k)
            return 1;
    }
    return 0;
}

static int cmp_str(const void *a, const void *b)
{
    return strcmp(*(char *const *)a, *(char *const *)b);
}

int tool_frames_add(tool_frames *f, const char *cmd, const char *arg)
{
    struct stat st;
    DIR *d;
    struct dirent *e;
    size_t first;
    if (stat(arg, &st) != 0 || !S_ISDIR(st.st_mode))
        return frames_push(f, arg) == 0 ? 0 : tool_usage_error(cmd, "out of memory");
    d = opendir(arg);
    if (!d)
        return tool_usage_error(cmd, "%s: cannot list the directory: %s", arg, strerror(errno));
    first = f->n;
    while ((e = readdir(d)) != NULL) {
        char path[4096];
        if (!is_frame_name(e->d_name))
            continue;
        if ((size_t)snprintf(path, sizeof path, "%s%s%s", arg,
                             arg[strlen(arg) - 1] == '/' ? "" : "/", e->d_name) >= sizeof path)
            continue;
        if (frames_push(f, path) != 0) {
            closedir(d);
            return tool_usage_error(cmd, "out of memory");
        }
    }
    closedir(d);
    if (f->n == first)
        tool_warn(cmd, "%s: no frame files (.pgm .png .jpg .tif) in this directory", arg);
    qsort(f->path + first, f->n - first, sizeof *f->path, cmp_str);
    return 0;
}

int tool_frames_add_list(tool_frames *f, const char *cmd, const char *listfile)
{
    FILE *in = strcmp(listfile, "-") == 0 ? stdin : fopen(listfile, "r");
    char line[4096];
    if (!in)
        return tool_usage_error(cmd, "%s: cannot open: %s", listfile, strerror(errno));
    while (fgets(line, sizeof line, in)) {
        size_t n = strlen(line);
        while (n && (line[n - 1] == '\n' || line[n - 1] == '\r'))
            line[--n] = 0;
        if (n == 0)
            continue;
        if (frames_push(f, line) != 0) {
            if (in != stdin)
                fclose(in);
            return tool_usage_error(cmd, "out of memory");
        }
    }
    if (in != stdin)
        fclose(in);
    return 0;
}

void tool_frames_free(tool_frames *f)
{
    size_t i;
    for (i = 0; i < f->n; i++)
        free(f->path[i]);
    free(f->path);
    f->path = NULL;
    f->n = f->cap = 0;
}

/* ---- progress ----------------------------------------------------------- */

/* A run shorter than this shows no progress: the line would only flash. */
#define PROGRESS_AFTER_US 2e6

void tool_progress_start(tool_progress *p, const char *what, size_t total, int quiet)
{
    p->what = what;
    p->total = total;
    p->enabled = !quiet && total >= 2 && isatty(STDERR_FILENO);
    p->shown = 0;
    p->t0 = p->last = tool_now_us();
}

void tool_progress_update(tool_progress *p, size_t done)
{
    double now;
    if (!p->enabled)
        return;
    now = tool_now_us();
    if (now - p->t0 < PROGRESS_AFTER_US || (now - p->last < 200e3 && done < p->total))
        return;
    p->shown = 1;
    p->last = now;
    fprintf(stderr, "\r%s: %zu/%zu frames, %.1f frames/s   ", p->what, done, p->total,
            now > p->t0 ? (double)done * 1e6 / (now - p->t0) : 0.0);
    fflush(stderr);
}

void tool_progress_end(tool_progress *p)
{
    if (!p->enabled || !p->shown)
        return;
    fprintf(stderr, "\r%*s\r", 60, "");
    fflush(stderr);
}

/* ---- the paper's scene --------------------------------------------------- */

void tool_paper_camera(cdsp_camera *cam)
{
    cdsp_render_paper_camera(cam); /* defined once, in libcdsp (lib/render.c) */
}

static void cross3(const double a[3], const double b[3], double o[3])
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}

static double dot3(const double a[3], const double b[3])
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

void tool_paper_pipe(int k, double point[3], double dir[3], double *half_length)
{
    cdsp_render_paper_pipe(k, point, dir, half_length); /* lib/render.c */
}

void tool_axis_truth(const double point[3], const double dir[3], double foot[3],
                     double unit[3], double *distance)
{
    cdsp_host_axis_truth(point, dir, foot, unit, distance); /* defined once, shared with cdspd */
}

double tool_line_distance(const double X[3], const double q[3], const double v[3])
{
    double d[3] = {X[0] - q[0], X[1] - q[1], X[2] - q[2]}, c[3];
    cross3(d, v, c);
    return sqrt(dot3(c, c)) / sqrt(dot3(v, v));
}

double tool_segment_rmse(const double a[3], const double b[3], const double q[3],
                         const double v[3], int samples)
{
    double sum = 0;
    int i, j;
    for (i = 0; i < samples; i++) {
        double f = samples > 1 ? (double)i / (samples - 1) : 0.5, X[3], d;
        for (j = 0; j < 3; j++)
            X[j] = a[j] + f * (b[j] - a[j]);
        d = tool_line_distance(X, q, v);
        sum += d * d;
    }
    return samples > 0 ? sqrt(sum / samples) : NAN;
}

/* ---- JSON records read back ----------------------------------------------- */

/* Records files up to 1 GiB (a day of 30 Hz records is about 100 MiB). */
#define TOOL_INPUT_MAX_BYTES ((size_t)1 << 30)

int tool_read_input(const char *cmd, const char *path, void **buf, size_t *len,
                    const char **name)
{
    cdsp_host_err err;
    int std_in = strcmp(path, "-") == 0;
    *name = std_in ? "(stdin)" : path;
    if (cdsp_host_read_file(std_in ? "/dev/stdin" : path, TOOL_INPUT_MAX_BYTES, buf, len, &err) != 0)
        return tool_usage_error(cmd, "%s", err.msg);
    return 0;
}

static int json_number(json_object *e, double *v)
{
    if (!json_object_is_type(e, json_type_double) && !json_object_is_type(e, json_type_int))
        return -1;
    *v = json_object_get_double(e);
    return isfinite(*v) ? 0 : -1;
}

int tool_json_num(json_object *o, const char *key, double *v)
{
    json_object *e;
    if (!o || !json_object_object_get_ex(o, key, &e))
        return -1;
    return json_number(e, v);
}

int tool_json_array(json_object *a, double *v, int n)
{
    int i;
    if (!a || !json_object_is_type(a, json_type_array) || (int)json_object_array_length(a) != n)
        return -1;
    for (i = 0; i < n; i++)
        if (json_number(json_object_array_get_idx(a, (size_t)i), &v[i]) != 0)
            return -1;
    return 0;
}

int tool_json_vec(json_object *o, const char *key, double *v, int n)
{
    json_object *a;
    if (!o || !json_object_object_get_ex(o, key, &a))
        return -1;
    return tool_json_array(a, v, n);
}

#define NOT_A_RECORD "not a cdsp_tool JSON record"

/* The message of a refused record (line 0: the whole document). */
static int refused(const char *cmd, const char *name, size_t line, int kind, const char *why)
{
    if (kind == TOOL_JSONL_NOT_RECORD)
        return tool_usage_error(cmd, "%s: " NOT_A_RECORD " (line %zu): %s", name, line ? line : 1,
                                why);
    if (line)
        return tool_usage_error(cmd, "%s:%zu: %s", name, line, why);
    return tool_usage_error(cmd, "%s: %s", name, why);
}

/* The whole text one JSON object, nothing but white space after it: that
 * object (the caller's to put), else NULL. */
static json_object *whole_document(json_tokener *tok, const char *text, size_t len)
{
    json_object *o = json_tokener_parse_ex(tok, text, (int)(len < 0x7fffffff ? len : 0));
    if (o && json_tokener_get_error(tok) == json_tokener_success &&
        json_object_is_type(o, json_type_object)) {
        size_t end = (size_t)json_tokener_get_parse_end(tok);
        end += strspn(text + end, " \t\r\n");
        if (end == len)
            return o;
    }
    if (o)
        json_object_put(o);
    json_tokener_reset(tok);
    return NULL;
}

int tool_jsonl_read(const char *cmd, const char *name, char *text, size_t len,
                    const tool_jsonl *how, void *ctx)
{
    json_tokener *tok = json_tokener_new();
    char *line, *next;
    size_t lineno = 0;
    const char *why = "";
    int kind;
    if (!tok)
        return tool_usage_error(cmd, "out of memory");
    if (how->whole_document) {
        json_object *o = whole_document(tok, text, len);
        if (o) {
            kind = how->record(o, 0, ctx, &why);
            json_object_put(o);
            json_tokener_free(tok);
            return kind ? refused(cmd, name, 0, kind, why) : 0;
        }
    }
    for (line = text; line && *line; line = next) {
        json_object *o;
        next = strchr(line, '\n');
        if (next)
            *next++ = 0;
        lineno++;
        if (strspn(line, " \t\r") == strlen(line))
            continue;
        json_tokener_reset(tok);
        o = json_tokener_parse_ex(tok, line, (int)strlen(line));
        if (!o || json_tokener_get_error(tok) != json_tokener_success ||
            !json_object_is_type(o, json_type_object)) {
            enum json_tokener_error e = json_tokener_get_error(tok);
            /* what the line is instead, in words: JSON cut short (json-c
             * says "continue"), a CSV header or row, another JSON value */
            const char *msg = e == json_tokener_continue ? "the JSON text ends mid-value"
                              : e != json_tokener_success && how->csv_hint && strchr(line, ',') &&
                                        line[strspn(line, " \t")] != '{'
                                  ? how->csv_hint
                              : e != json_tokener_success ? json_tokener_error_desc(e)
                                                          : "a JSON value that is not an object";
            if (o)
                json_object_put(o);
            json_tokener_free(tok);
            return refused(cmd, name, lineno, TOOL_JSONL_NOT_RECORD, msg);
        }
        kind = how->record(o, lineno, ctx, &why);
        json_object_put(o);
        if (kind) {
            json_tokener_free(tok);
            return refused(cmd, name, lineno, kind, why);
        }
    }
    json_tokener_free(tok);
    return 0;
}
