/*
 * fuzz_listen.c - what `cdsp_tool listen` does with one datagram
 * (tools/listen.c over host/proto.c): decode, then format as the
 * readable line and as JSON. A line is one line; a JSON line is exactly
 * one JSON object (nothing after it: the injection of issue 16) that
 * decodes again, and encodes to the same JSON from then on.
 */
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include <json-c/json.h>

#include "listen.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static char out[4096], again[4096];
    const char *why;
    uint32_t seq;
    if (cdsp_tool_listen_format(data, size, 0, out, sizeof out, &seq, &why) == 0 &&
        strchr(out, '\n'))
        abort();
    if (cdsp_tool_listen_format(data, size, 1, out, sizeof out, &seq, &why) == 0) {
        json_tokener *tok = json_tokener_new();
        json_object *o = json_tokener_parse_ex(tok, out, (int)strlen(out));
        if (!o || !json_object_is_type(o, json_type_object) ||
            json_tokener_get_parse_end(tok) != strlen(out) || strchr(out, '\n'))
            abort();
        json_object_put(o);
        json_tokener_free(tok);
        /* the re-encoded record is a record, and stable from the next
         * encoding on (the first may still change -0 to 0: json-c reads
         * "-0" as the integer 0) */
        if (cdsp_tool_listen_format((const uint8_t *)out, strlen(out), 1, again, sizeof again, &seq,
                                    &why) != 0 ||
            cdsp_tool_listen_format((const uint8_t *)again, strlen(again), 1, out, sizeof out, &seq,
                                    &why) != 0 ||
            strcmp(out, again) != 0)
            abort();
    }
    return 0;
}
