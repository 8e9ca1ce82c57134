/*
 * listen.h - `cdsp_tool listen [ADDR:PORT]`: receive cdspd's datagrams
 * (binary or JSON, docs/protocol.md), decode and print them, one line
 * each. Built from tools/listen.c and daemon/proto.c (link json-c).
 */
#ifndef CDSP_TOOL_LISTEN_H
#define CDSP_TOOL_LISTEN_H

/* argv[0] is the command's name ("listen"). Exit status: 0 done (count or
 * duration reached, or SIGINT/SIGTERM), 1 some datagram could not be
 * decoded, 2 usage error or the address cannot be bound. */
int cdsp_tool_listen(int argc, char **argv);

#endif
