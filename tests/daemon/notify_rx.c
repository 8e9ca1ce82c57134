/*
 * notify_rx - stands in for systemd's notification socket in the daemon's
 * test: binds a unix datagram socket at PATH and prints every message it
 * receives ("READY=1", "WATCHDOG=1", ...), one line per field with the
 * milliseconds since start, for SECONDS seconds or until SIGTERM.
 * Usage: notify_rx PATH SECONDS. Exit status 0, 2 usage or socket error.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "cdsp_host.h"

int main(int argc, char **argv)
{
    struct sockaddr_un sa;
    double t0, seconds;
    int fd;
    if (argc != 3 || strlen(argv[1]) >= sizeof sa.sun_path) {
        fprintf(stderr, "usage: notify_rx PATH SECONDS\n");
        return 2;
    }
    seconds = atof(argv[2]);
    memset(&sa, 0, sizeof sa);
    sa.sun_family = AF_UNIX;
    strcpy(sa.sun_path, argv[1]);
    unlink(argv[1]);
    fd = socket(AF_UNIX, SOCK_DGRAM, 0);
    if (fd < 0 || bind(fd, (struct sockaddr *)&sa, sizeof sa)) {
        fprintf(stderr, "notify_rx: %s: %s\n", argv[1], strerror(errno));
        return 2;
    }
    cdsp_host_stop_on_signals();
    t0 = cdsp_host_now_s();
    while (!cdsp_host_stop_requested() && cdsp_host_now_s() - t0 < seconds) {
        struct pollfd p = {fd, POLLIN, 0};
        char buf[4096], *line, *save;
        ssize_t n;
        if (poll(&p, 1, 100) <= 0)
            continue;
        n = recv(fd, buf, sizeof buf - 1, 0);
        if (n <= 0)
            continue;
        buf[n] = 0;
        for (line = strtok_r(buf, "\n", &save); line; line = strtok_r(NULL, "\n", &save))
            printf("%.0f %s\n", 1e3 * (cdsp_host_now_s() - t0), line);
        fflush(stdout);
    }
    close(fd);
    unlink(argv[1]);
    return 0;
}
