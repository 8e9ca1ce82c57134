/*
 * yaml_load.c - see host_yaml.h: a bounded pre-pass with libyaml's event
 * parser, then yaml_parser_load() on text known to be within the bounds.
 */
#define _POSIX_C_SOURCE 200809L
#include "host_yaml.h"

#include "host_internal.h"

static int syntax_error(yaml_parser_t *p, const char *name, cdsp_host_err *err)
{
    return cdsp_host__fail(err, CDSP_HOST_E_FORMAT, name, "YAML error at line %lu, column %lu: %s",
                           (unsigned long)p->problem_mark.line + 1,
                           (unsigned long)p->problem_mark.column + 1,
                           p->problem ? p->problem : "unknown");
}

/* The event pass: depth and aliases within bounds, syntax valid. */
static int check_bounds(const char *text, size_t len, const char *name, cdsp_host_err *err)
{
    yaml_parser_t p;
    yaml_event_t ev;
    int depth = 0, aliases = 0, rc = CDSP_HOST_OK, done = 0;
    if (!yaml_parser_initialize(&p))
        return cdsp_host__fail(err, CDSP_HOST_E_NOMEM, name, "out of memory (YAML parser)");
    yaml_parser_set_input_string(&p, (const unsigned char *)text, len);
    while (!done && rc == CDSP_HOST_OK) {
        if (!yaml_parser_parse(&p, &ev)) {
            rc = syntax_error(&p, name, err);
            break;
        }
        switch (ev.type) {
        case YAML_SEQUENCE_START_EVENT:
        case YAML_MAPPING_START_EVENT:
            if (++depth > CDSP_HOST_YAML_MAX_DEPTH)
                rc = cdsp_host__fail(err, CDSP_HOST_E_LIMIT, name,
                                     "YAML nested deeper than %d levels at line %lu, column %lu",
                                     CDSP_HOST_YAML_MAX_DEPTH,
                                     (unsigned long)ev.start_mark.line + 1,
                                     (unsigned long)ev.start_mark.column + 1);
            break;
        case YAML_SEQUENCE_END_EVENT:
        case YAML_MAPPING_END_EVENT:
            depth--;
            break;
        case YAML_ALIAS_EVENT:
            if (++aliases > CDSP_HOST_YAML_MAX_ALIASES)
                rc = cdsp_host__fail(err, CDSP_HOST_E_LIMIT, name,
                                     "more than %d YAML aliases, at line %lu, column %lu",
                                     CDSP_HOST_YAML_MAX_ALIASES,
                                     (unsigned long)ev.start_mark.line + 1,
                                     (unsigned long)ev.start_mark.column + 1);
            break;
        case YAML_STREAM_END_EVENT:
            done = 1;
            break;
        default:
            break;
        }
        yaml_event_delete(&ev);
    }
    yaml_parser_delete(&p);
    return rc;
}

int cdsp_host_yaml_load(const char *text, size_t len, const char *name, yaml_document_t *doc,
                        cdsp_host_err *err)
{
    yaml_parser_t p;
    int rc;
    if (len > CDSP_HOST_YAML_MAX_BYTES)
        return cdsp_host__fail(err, CDSP_HOST_E_LIMIT, name, "larger than %d bytes",
                               CDSP_HOST_YAML_MAX_BYTES);
    rc = check_bounds(text, len, name, err);
    if (rc)
        return rc;
    if (!yaml_parser_initialize(&p))
        return cdsp_host__fail(err, CDSP_HOST_E_NOMEM, name, "out of memory (YAML parser)");
    yaml_parser_set_input_string(&p, (const unsigned char *)text, len);
    rc = CDSP_HOST_OK;
    if (!yaml_parser_load(&p, doc))
        rc = syntax_error(&p, name, err);
    yaml_parser_delete(&p);
    return rc;
}
