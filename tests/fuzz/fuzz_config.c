/*
 * fuzz_config.c - cdspd's configuration reader (daemon/config.c): the
 * input is loaded as a YAML config file, and each of its lines of the form
 * KEY=VALUE is also given as --set KEY=VALUE, so one input drives both
 * paths. Whatever is accepted must leave solver parameters the library
 * accepts (the load-time check of issue 16) and dump without trouble.
 * cdspd_config_finish is not called: it resolves host names.
 */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>
#include <unistd.h>

#include "config.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

static cdspd_config cfg, defaults;
static int fd = -1;
static char path[64];
static FILE *devnull;

static void check_solver(const cdspd_config *c)
{
    cdsp_params p;
    cdspd_config_params(c, &p);
    if (cdsp_params_check(&p) != CDSP_OK)
        abort(); /* a solver value the library refuses got through */
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    char err[2048], line[4096];
    size_t i = 0;
    if (fd < 0) {
        fd = memfd_create("cdsp-fuzz-config", 0);
        if (fd < 0)
            abort();
        snprintf(path, sizeof path, "/proc/self/fd/%d", fd);
        devnull = fopen("/dev/null", "w");
        /* once: libFuzzer traces every strcmp of the key table's lookups */
        cdspd_config_defaults(&defaults);
    }
    if (ftruncate(fd, 0) || pwrite(fd, data, size, 0) != (ssize_t)size)
        abort();
    cfg = defaults;
    (void)cdspd_config_load_file(&cfg, path, err, sizeof err);
    check_solver(&cfg);
    while (i < size) {
        size_t j = i, l;
        char *eq;
        while (j < size && data[j] != '\n')
            j++;
        l = j - i < sizeof line - 1 ? j - i : sizeof line - 1;
        memcpy(line, data + i, l);
        line[l] = 0;
        i = j + 1;
        eq = memchr(line, '=', l);
        if (!eq || strlen(line) != l)
            continue;
        *eq = 0;
        (void)cdspd_config_set(&cfg, line, eq + 1, "--set", err, sizeof err);
        check_solver(&cfg);
    }
    cdspd_config_dump(&cfg, devnull);
    return 0;
}
