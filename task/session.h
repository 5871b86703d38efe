/* session.h: the machine session: a persistent controller commanded over a Unix socket. */
#ifndef HEXCNC_TASK_SESSION_H
#define HEXCNC_TASK_SESSION_H

#include <signal.h>
#include <stddef.h>

#include "task/runner.h"

/*
 * `hexcnc machine CONFIG.ini`: the machine's HAL runtime and servo thread (the runner's),
 * a state machine as LinuxCNC's task (e-stop, on/off, modes, homing, jog, MDI, programs),
 * and the JSON-RPC API of docs/api.md on a Unix socket. One thread runs the session loop:
 * it serves the socket, commands motion (manual moves through motion's command queue,
 * programs through the runner) and, on the simulated clock, advances the machine: as fast
 * as the CPU allows while anything moves, paced on the wall clock while at rest.
 */

struct session_opts {
    const char *ini_path;
    enum runner_clock clock;
    const char *socket_path;     /* NULL: [API] SOCKET, else the default (docs/api.md) */
    int quiet;                   /* no messages on stderr */
};

struct session;

int session_create(const struct session_opts *opts, struct session **out, char *err,
                   size_t errlen);
/* Runs until machine.shutdown or *stop (a signal handler's flag). 0 on a clean end. */
int session_run(struct session *s, const volatile sig_atomic_t *stop);
void session_destroy(struct session *s);
/* The socket path in use. */
const char *session_socket_path(const struct session *s);

#endif
