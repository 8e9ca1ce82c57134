/*
 * fuzz_calib.c - the ROS camera_info YAML reader (host/calib.c,
 * through the bounded loader of host/yaml_load.c). A calibration
 * it accepts must pass the library's cdsp_camera_check, and is written back
 * and read again: the same camera.
 */
#define _GNU_SOURCE
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "cdsp_host.h"

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    cdsp_camera cam, back;
    cdsp_host_err err;
    char path[64];
    if (cdsp_host_calib_parse((const char *)data, size, "fuzz.yaml", &cam, &err) != CDSP_HOST_OK)
        return 0;
    if (cdsp_camera_check(&cam) != CDSP_OK)
        abort();
    snprintf(path, sizeof path, "/tmp/cdsp-fuzz-calib-%ld.yaml", (long)getpid());
    if (cdsp_host_calib_write(path, &cam, "fuzz", &err) == CDSP_HOST_OK) {
        if (cdsp_host_calib_read(path, &back, &err) != CDSP_HOST_OK ||
            back.width != cam.width || back.height != cam.height || back.fx != cam.fx ||
            back.k1 != cam.k1)
            abort(); /* what the writer wrote, the reader must read back */
    }
    unlink(path);
    return 0;
}
