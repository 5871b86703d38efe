/* cmd_can_sim.c: `hexcnc can_sim`: the simulated CiA 402 drives of a config, served on a unix socket. */
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdbool.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <time.h>
#include <unistd.h>

#include "hal/drivers/can_bus.h"
#include "hal/hal.h"
#include "sim/cia402_sim.h"
#include "sim/cia402_sim_hal.h"
#include "tools/cmd.h"

/*
 * The server side of `[CAN] INTERFACE = unix:PATH`: listens on an AF_UNIX SOCK_SEQPACKET
 * socket at PATH, takes one connection (the master), and runs one simulated drive per
 * [CAN_NODE_n] of the INI (as `loadrt cia402-sim` would) on the wall clock: every frame
 * from the master goes to every drive, answers go back at once, heartbeats and boot-up
 * messages at their times. It ends when the master closes the connection, on SIGINT or
 * SIGTERM, or after --seconds.
 */

const char cmd_can_sim_usage[] =
    "can_sim CONFIG.ini --listen unix:PATH [--seconds S]: the config's simulated CiA 402\n"
    "             drives ([CAN_NODE_n]) as a separate process, for [CAN]INTERFACE = unix:PATH;\n"
    "             serves one connection, ends when it closes, on SIGINT/SIGTERM or after S s";

#define CAN_SIM_MAX 16

/* The drives and the connection. */
struct can_sim {
    struct cia402_sim node[CAN_SIM_MAX];
    int count;
    int listen_fd, fd, sfd;       /* listening socket, the master's connection, signals */
    bool bound;                   /* the socket file at PATH is ours (removed at the end) */
    struct timespec t0;           /* the drives' clock starts here */
};

/* Nanoseconds since t0 (CLOCK_MONOTONIC). */
static int64_t can_sim_now_ns(const struct can_sim *s)
{
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (int64_t)(t.tv_sec - s->t0.tv_sec) * 1000000000LL + (t.tv_nsec - s->t0.tv_nsec);
}

/* Reads [KINS]JOINTS drives from the INI; prints why not and returns 1. */
static int can_sim_load(struct can_sim *s, const char *ini)
{
    struct hal *h = hal_create();
    long joints = 6;
    int rc = 1;
    if (!h) {
        fprintf(stderr, "hexcnc can_sim: out of memory\n");
        return 1;
    }
    if (hal_load_ini(h, ini) != HAL_OK ||
        hal_ini_int(h, "KINS", "JOINTS", 6, &joints) == HAL_ERR_SYNTAX)
        goto fail;
    if (joints < 1 || joints > CAN_SIM_MAX) {
        fprintf(stderr, "hexcnc can_sim: %s: [KINS]JOINTS = %ld: 1 to %d drives\n", ini, joints,
                CAN_SIM_MAX);
        goto done;
    }
    for (int i = 0; i < joints; i++) {
        struct cia402_sim_cfg sc = { 0 };
        if (cia402_sim_cfg_read(h, i, &sc) != HAL_OK)
            goto fail;
        cia402_sim_init(&s->node[i], &sc);
    }
    s->count = (int)joints;
    rc = 0;
    goto done;
fail:
    fprintf(stderr, "hexcnc can_sim: %s: %s\n", ini, hal_last_error(h));
done:
    hal_destroy(h);
    return rc;
}

/* Listens on PATH; refuses to replace anything that is not a stale socket. */
static int can_sim_listen(struct can_sim *s, const char *path)
{
    struct sockaddr_un sa = { .sun_family = AF_UNIX };
    struct stat st;
    if (!path[0] || strlen(path) >= sizeof sa.sun_path) {
        fprintf(stderr, "hexcnc can_sim: socket path '%s' is empty or too long\n", path);
        return 1;
    }
    if (lstat(path, &st) == 0) {
        if (!S_ISSOCK(st.st_mode)) {
            fprintf(stderr, "hexcnc can_sim: %s exists and is not a socket: not replacing "
                    "it\n", path);
            return 1;
        }
        unlink(path);  /* a socket left by an earlier run */
    }
    memcpy(sa.sun_path, path, strlen(path) + 1);
    s->listen_fd = socket(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0);
    if (s->listen_fd >= 0 && bind(s->listen_fd, (struct sockaddr *)&sa, sizeof sa) == 0)
        s->bound = true;
    if (!s->bound || listen(s->listen_fd, 1) < 0) {
        fprintf(stderr, "hexcnc can_sim: cannot listen on %s: %s\n", path, strerror(errno));
        return 1;
    }
    return 0;
}

/* Waits for the master; false on a signal or the time limit. */
static bool can_sim_accept(struct can_sim *s, double seconds)
{
    struct pollfd p[2] = { { .fd = s->listen_fd, .events = POLLIN },
                           { .fd = s->sfd, .events = POLLIN } };
    int timeout_ms = seconds > 0 ? (int)(seconds * 1000) : -1;
    if (poll(p, 2, timeout_ms) <= 0 || p[1].revents || !(p[0].revents & POLLIN))
        return false;
    s->fd = accept4(s->listen_fd, NULL, NULL, SOCK_NONBLOCK | SOCK_CLOEXEC);
    return s->fd >= 0;
}

/* Sends answers; a full queue drops them as a congested bus would. */
static void can_sim_send(struct can_sim *s, const struct can_frame *f, int n)
{
    for (int i = 0; i < n; i++)
        (void)can_fd_write(s->fd, &f[i]);
}

/* Serves until the master closes, a signal or the time limit. Returns why it ended. */
static const char *can_sim_serve(struct can_sim *s, double seconds)
{
    struct can_frame in, out[CIA402_SIM_MAX_OUT];
    struct pollfd p[2] = { { .fd = s->fd, .events = POLLIN }, { .fd = s->sfd, .events = POLLIN } };
    for (;;) {
        poll(p, 2, 1);  /* at least every millisecond for heartbeats and boot-up times */
        if (p[1].revents)
            return "signal";
        int64_t now = can_sim_now_ns(s);
        int r;
        while ((r = can_fd_read(s->fd, &in)) == 1)
            for (int i = 0; i < s->count; i++)
                can_sim_send(s, out, cia402_sim_rx(&s->node[i], &in, now, out,
                                                   CIA402_SIM_MAX_OUT));
        if (r < 0 && errno != EMSGSIZE)
            return "the master closed the connection";
        for (int i = 0; i < s->count; i++)
            can_sim_send(s, out, cia402_sim_step(&s->node[i], now, out, CIA402_SIM_MAX_OUT));
        if (seconds > 0 && (double)now * 1e-9 >= seconds)
            return "time limit";
    }
}

/* Entry point of `hexcnc can_sim`. */
int cmd_can_sim(int argc, char **argv)
{
    const char *ini = NULL, *listen_on = NULL;
    double seconds = 0;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--help") || !strcmp(argv[i], "-h")) {
            printf("usage: hexcnc %s\n", cmd_can_sim_usage);
            return 0;
        } else if (!strcmp(argv[i], "--listen") && i + 1 < argc) {
            listen_on = argv[++i];
        } else if (!strcmp(argv[i], "--seconds") && i + 1 < argc) {
            seconds = atof(argv[++i]);
        } else if (argv[i][0] != '-' && !ini) {
            ini = argv[i];
        } else {
            fprintf(stderr, "hexcnc can_sim: unexpected '%s'\nusage: hexcnc %s\n", argv[i],
                    cmd_can_sim_usage);
            return 2;
        }
    }
    if (!ini || !listen_on || strncmp(listen_on, CAN_BUS_UNIX, strlen(CAN_BUS_UNIX)) != 0) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_can_sim_usage);
        return 2;
    }
    const char *path = listen_on + strlen(CAN_BUS_UNIX);
    struct can_sim *s = calloc(1, sizeof *s);
    if (!s)
        return 1;
    s->listen_fd = s->fd = -1;
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    sigprocmask(SIG_BLOCK, &mask, NULL);
    s->sfd = signalfd(-1, &mask, SFD_CLOEXEC);
    int rc = 1;
    if (can_sim_load(s, ini) || can_sim_listen(s, path))
        goto done;
    printf("can_sim: %d drives of %s listening on unix:%s\n", s->count, ini, path);
    fflush(stdout);
    clock_gettime(CLOCK_MONOTONIC, &s->t0);
    if (!can_sim_accept(s, seconds)) {
        rc = 0;
        goto done;
    }
    clock_gettime(CLOCK_MONOTONIC, &s->t0);  /* power-on: the drives boot from here */
    printf("can_sim: master connected; ended: %s\n", can_sim_serve(s, seconds));
    rc = 0;
done:
    if (s->fd >= 0)
        close(s->fd);
    if (s->listen_fd >= 0)
        close(s->listen_fd);
    if (s->bound)
        unlink(path);
    if (s->sfd >= 0)
        close(s->sfd);
    free(s);
    return rc;
}
