/* cmd_modbus_sim.c: `hexcnc modbus_sim`: simulated Modbus drives on loopback, with faults set from stdin. */
#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#include "sim/modbus_sim.h"
#include "tools/cmd.h"

const char cmd_modbus_sim_usage[] =
    "modbus_sim [--drives N] [--base-port P] [--host ADDR] [--word-order high-first|low-first]\n"
    "             [--tau S] [--vmax COUNTS_PER_S] [--seconds S]: simulated Modbus drives;\n"
    "             stdin: `fault N none|no-answer|exception CODE|delay US|disconnect|drive`, "
    "`state`, `quit`";

/* Command-line settings. */
struct modbus_sim_args {
    int drives;             /* number of drives */
    int base_port;          /* drive n listens on base_port + n */
    const char *host;       /* listening address (loopback by default) */
    double seconds;         /* stop after this long; 0 = until quit, EOF or a signal */
    struct modbus_sim_opts opts;
};

/* Parses the options; returns 0 or prints why and returns 2. */
static int modbus_sim_parse(int argc, char **argv, struct modbus_sim_args *a)
{
    a->drives = 6;
    a->base_port = 15020;
    a->host = "127.0.0.1";
    a->seconds = 0.0;
    modbus_sim_opts_default(&a->opts);
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
        if (!v) {
            fprintf(stderr, "hexcnc modbus_sim: %s needs a value\n", o);
            return 2;
        }
        i++;
        if (!strcmp(o, "--drives"))
            a->drives = atoi(v);
        else if (!strcmp(o, "--base-port"))
            a->base_port = atoi(v);
        else if (!strcmp(o, "--host"))
            a->host = v;
        else if (!strcmp(o, "--tau"))
            a->opts.tau_s = atof(v);
        else if (!strcmp(o, "--vmax"))
            a->opts.vmax_counts_s = atof(v);
        else if (!strcmp(o, "--seconds"))
            a->seconds = atof(v);
        else if (!strcmp(o, "--word-order") && (!strcmp(v, "high-first") || !strcmp(v, "low-first")))
            a->opts.map.order = !strcmp(v, "low-first") ? MODBUS_WORDS_LOW_FIRST
                                                        : MODBUS_WORDS_HIGH_FIRST;
        else {
            fprintf(stderr, "hexcnc modbus_sim: unknown option or value '%s %s'\nusage: hexcnc %s\n",
                    o, v, cmd_modbus_sim_usage);
            return 2;
        }
    }
    if (a->drives < 1 || a->drives > 64 || a->base_port < 1 || a->base_port + a->drives > 65536) {
        fprintf(stderr, "hexcnc modbus_sim: --drives must be 1..64 and the ports fit in 1..65535\n");
        return 2;
    }
    return 0;
}

/* One line from stdin: fault N KIND [ARG] | state | quit. Returns false on quit. */
static bool modbus_sim_command(struct modbus_sim *s, char *line)
{
    char word[32] = "", kind[32] = "";
    int drive = -1;
    long arg = 0;
    int n = sscanf(line, "%31s %d %31s %ld", word, &drive, kind, &arg);
    if (n < 1)
        return true;
    if (!strcmp(word, "quit"))
        return false;
    if (!strcmp(word, "state")) {
        for (int i = 0; i < modbus_sim_count(s); i++) {
            struct modbus_sim_drive_state st;
            modbus_sim_state(s, i, &st);
            printf("drive %d port %d: target %d actual %.1f counts, control 0x%04x status 0x%04x,"
                   " %u requests, %u connections\n", i, modbus_sim_port(s, i), st.target_counts,
                   st.actual_counts, st.control_word, st.status_word, st.requests,
                   st.connections);
        }
    } else if (!strcmp(word, "fault") && n >= 3 && modbus_sim_fault_parse(kind) >= 0) {
        int rc = modbus_sim_inject(s, drive, (enum modbus_sim_fault)modbus_sim_fault_parse(kind),
                                   arg);
        if (rc)
            printf("fault: %s\n", modbus_sim_strerror(rc));
        else
            printf("drive %d: %s\n", drive, kind);
    } else {
        printf("commands: fault N none|no-answer|exception CODE|delay US|disconnect|drive; "
               "state; quit\n");
    }
    fflush(stdout);
    return true;
}

/* Serves until quit, EOF, SIGINT/SIGTERM or --seconds. */
static void modbus_sim_loop(struct modbus_sim *s, int sfd, double seconds)
{
    struct timespec t0, now;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    struct pollfd p[2] = { { .fd = sfd, .events = POLLIN }, { .fd = 0, .events = POLLIN } };
    int nfds = 2;
    char line[256];
    for (;;) {
        if (poll(p, (nfds_t)nfds, 100) > 0) {
            if (p[0].revents)
                return;
            if (nfds == 2 && p[1].revents) {
                if (!fgets(line, sizeof(line), stdin))
                    nfds = seconds > 0.0 ? 1 : 0;   /* EOF: keep serving if timed */
                else if (!modbus_sim_command(s, line))
                    return;
                if (nfds == 0)
                    return;
            }
        }
        clock_gettime(CLOCK_MONOTONIC, &now);
        double el = (double)(now.tv_sec - t0.tv_sec) + (now.tv_nsec - t0.tv_nsec) * 1e-9;
        if (seconds > 0.0 && el >= seconds)
            return;
    }
}

/* Entry point of `hexcnc modbus_sim`. */
int cmd_modbus_sim(int argc, char **argv)
{
    struct modbus_sim_args a;
    int rc = modbus_sim_parse(argc, argv, &a);
    if (rc)
        return rc;
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    sigprocmask(SIG_BLOCK, &mask, NULL);
    int sfd = signalfd(-1, &mask, SFD_CLOEXEC);
    struct modbus_sim *s = NULL;
    if ((rc = modbus_sim_create(&s, a.drives, &a.opts)) ||
        (rc = modbus_sim_start_tcp(s, a.host, a.base_port))) {
        fprintf(stderr, "hexcnc modbus_sim: drives on %s:%d..%d: %s\n", a.host, a.base_port,
                a.base_port + a.drives - 1, modbus_sim_strerror(rc));
        modbus_sim_destroy(s);
        close(sfd);
        return 1;
    }
    printf("modbus_sim: %d drives on %s:%d..%d (%s word first)\n", a.drives, a.host, a.base_port,
           a.base_port + a.drives - 1,
           a.opts.map.order == MODBUS_WORDS_HIGH_FIRST ? "high" : "low");
    fflush(stdout);
    modbus_sim_loop(s, sfd, a.seconds);
    modbus_sim_destroy(s);
    close(sfd);
    return 0;
}
