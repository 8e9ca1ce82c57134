/*
 * listen_main.c - build/cdsp_listen: `cdsp_tool listen` as a program of its
 * own, for the daemon's tests and `make demo` until cdsp_tool offers it.
 */
#include "listen.h"

int main(int argc, char **argv)
{
    return cdsp_tool_listen(argc, argv);
}
