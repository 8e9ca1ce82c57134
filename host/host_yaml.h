/*
 * host_yaml.h - libyaml documents loaded with bounds (part of
 * libcdsp_host; for the calibration reader and cdspd's config reader,
 * which include <yaml.h> themselves).
 *
 * libyaml's scanner keeps a simple-key entry per open flow level and
 * revisits them for every token, so a file of nested '[' costs the square
 * of its depth (a 120 KB one took 15 s, a 1 MiB one ~20 min) inside
 * yaml_parser_load(), and aliases can make one node reachable many times.
 * cdsp_host_yaml_load() first runs the event parser over the text and stops
 * at the first event beyond CDSP_HOST_YAML_MAX_DEPTH nested collections or
 * CDSP_HOST_YAML_MAX_ALIASES aliases, so a hostile file costs time linear
 * in its length (the scanner never holds more than MAX_DEPTH flow levels),
 * and only then builds the document.
 */
#ifndef CDSP_HOST_YAML_H
#define CDSP_HOST_YAML_H

#include <stddef.h>
#include <yaml.h>

#include "cdsp_host.h"

/* Nested mappings/sequences: a camera_info file and cdspd's config need 3
 * (root, section or matrix, list); the scanner's cost per token grows
 * with the depth, so the bound is kept near what is needed. */
#ifndef CDSP_HOST_YAML_MAX_DEPTH
#define CDSP_HOST_YAML_MAX_DEPTH 8
#endif

/* Aliases (*name) in one document: neither file format needs any. */
#ifndef CDSP_HOST_YAML_MAX_ALIASES
#define CDSP_HOST_YAML_MAX_ALIASES 64
#endif

/* Load text (len bytes, at most CDSP_HOST_YAML_MAX_BYTES) into *doc (free
 * it with yaml_document_delete). 0, or a negative cdsp_host_rc with err
 * "NAME: YAML error at line L, column C: ..." (CDSP_HOST_E_FORMAT), or
 * "NAME: YAML nested deeper than N levels at line L, column C" / "more
 * than N YAML aliases, ..." (CDSP_HOST_E_LIMIT); *doc is then untouched. */
int cdsp_host_yaml_load(const char *text, size_t len, const char *name, yaml_document_t *doc,
                        cdsp_host_err *err);

#endif
