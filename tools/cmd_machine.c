/* cmd_machine.c: `hexcnc machine`: the machine session, commanded over its Unix socket. */
#include <signal.h>
#include <stdio.h>
#include <string.h>

#include "task/session.h"
#include "tools/cmd.h"

const char cmd_machine_usage[] =
    "machine [--sim-clock|--realtime] [--socket PATH] [--quiet] CONFIG.ini   start the "
    "machine session (docs/api.md)";

/* Set by SIGINT/SIGTERM: the session stops the machine in a controlled way and exits. */
static volatile sig_atomic_t machine_stop;

static void machine_on_signal(int sig)
{
    (void)sig;
    machine_stop = 1;
}

int cmd_machine(int argc, char **argv)
{
    struct session_opts o = { 0 };
    o.clock = RUNNER_CLOCK_INI;
    for (int i = 1; i < argc; i++) {
        if (!strcmp(argv[i], "--sim-clock"))
            o.clock = RUNNER_CLOCK_SIM;
        else if (!strcmp(argv[i], "--realtime"))
            o.clock = RUNNER_CLOCK_REALTIME;
        else if (!strcmp(argv[i], "--quiet"))
            o.quiet = 1;
        else if (!strcmp(argv[i], "--socket") && i + 1 < argc)
            o.socket_path = argv[++i];
        else if (argv[i][0] == '-' || o.ini_path) {
            fprintf(stderr, "usage: hexcnc %s\n", cmd_machine_usage);
            return 2;
        } else
            o.ini_path = argv[i];
    }
    if (!o.ini_path) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_machine_usage);
        return 2;
    }
    char err[1024];
    struct session *s;
    if (session_create(&o, &s, err, sizeof err) != 0) {
        fprintf(stderr, "hexcnc machine: %s\n", err);
        return 1;
    }
    struct sigaction sa = { .sa_handler = machine_on_signal };
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
    signal(SIGPIPE, SIG_IGN);
    if (!o.quiet)
        fprintf(stderr, "hexcnc machine: %s: listening on %s\n", o.ini_path,
                session_socket_path(s));
    int rc = session_run(s, &machine_stop);
    session_destroy(s);
    if (!o.quiet)
        fprintf(stderr, "hexcnc machine: session ended\n");
    return rc;
}
