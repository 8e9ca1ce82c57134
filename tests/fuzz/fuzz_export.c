/*
 * fuzz_export.c - the JSON records `cdsp_tool export` reads (solve's JSON
 * Lines, sim's truth.json), through the command itself: the input is the
 * file, the mesh goes to /dev/null. Exit status 0 or 1 must mean a mesh
 * without a null (non-finite) vertex: written to a memory file and read.
 */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "tool_internal.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static int in_fd = -1, out_fd = -1;
static char in_path[64], out_path[64];

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char *argv[8];
    int rc;
    if (in_fd < 0) {
        in_fd = memfd_create("cdsp-fuzz-export-in", 0);
        out_fd = memfd_create("cdsp-fuzz-export-out", 0);
        if (in_fd < 0 || out_fd < 0)
            abort();
        snprintf(in_path, sizeof in_path, "/proc/self/fd/%d", in_fd);
        snprintf(out_path, sizeof out_path, "/proc/self/fd/%d", out_fd);
    }
    if (ftruncate(in_fd, 0) || pwrite(in_fd, data, size, 0) != (ssize_t)size || ftruncate(out_fd, 0))
        abort();
    argv[0] = "export";
    argv[1] = "--out";
    argv[2] = out_path;
    argv[3] = "--sides";
    argv[4] = "3";
    argv[5] = in_path;
    argv[6] = NULL;
    rc = tool_export_main(6, argv);
    if (rc == 0 || rc == 1) {
        static char mesh[1 << 16];
        ssize_t n = pread(out_fd, mesh, sizeof mesh - 1, 0);
        if (n < 0)
            abort();
        mesh[n] = 0;
        if (strstr(mesh, "null") || strstr(mesh, "nan") || strstr(mesh, "inf"))
            abort(); /* a vertex that is not a number */
    } else if (rc != 2) {
        abort(); /* an undocumented exit status */
    }
    return 0;
}
