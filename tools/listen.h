/*
 * listen.h - `cdsp_tool listen [ADDR:PORT]`: receive cdspd's datagrams
 * (binary or JSON, docs/protocol.md), decode and print them, one line
 * each. Built from tools/listen.c and host/proto.c (link json-c).
 */
#ifndef CDSP_TOOL_LISTEN_H
#define CDSP_TOOL_LISTEN_H

#include <stddef.h>
#include <stdint.h>

/* argv[0] is the command's name ("listen"). Exit status: 0 done (count or
 * duration reached, or SIGINT/SIGTERM), 1 some datagram could not be
 * decoded, 2 usage error or the address cannot be bound. */
int cdsp_tool_listen(int argc, char **argv);

/* One datagram -> the line listen prints (no newline): decoded
 * (host/proto.c), then formatted from the record: the readable line, or
 * with json the record encoded again. 0, or -1 with *why when the datagram
 * cannot be decoded (out is then ""). *seq receives the record's sequence
 * number. */
int cdsp_tool_listen_format(const uint8_t *buf, size_t len, int json, char *out, size_t cap,
                            uint32_t *seq, const char **why);

#endif
