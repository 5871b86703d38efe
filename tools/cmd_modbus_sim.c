/* cmd_modbus_sim.c: `hexcnc modbus_sim`: simulated Modbus drives on loopback for any Modbus TCP client, commands on stdin. */
#include <errno.h>
#include <math.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#include "hal/hal.h"
#include "hal/drivers/modbus_cfg.h"
#include "sim/modbus_sim.h"
#include "tools/cmd.h"

const char cmd_modbus_sim_usage[] =
    "modbus_sim [--ini MACHINE.ini [--lockstep] | --drives N --base-port P ...] [--start MM,...]\n"
    "             [--seconds S]: simulated Modbus TCP drives; `hexcnc modbus_sim --help` for more";

static const char modbus_sim_help[] =
    "usage: hexcnc modbus_sim [OPTIONS]\n"
    "\n"
    "Simulated Modbus TCP position drives, one port per drive, for hexcnc or any Modbus client\n"
    "(docs/modbus.md has the register map). The drives move on wall time whether or not a\n"
    "client stays connected.\n"
    "\n"
    "  --ini FILE            take ports, register map, word order, COUNTS_PER_MM and TIMEOUT\n"
    "                        from FILE's [MODBUS] / [MODBUS_DRIVE_n], TAU and MAX_VELOCITY from\n"
    "                        [MODBUS_SIM], and start at the leg lengths of [KINS] HOME\n"
    "  --lockstep            (with --ini) advance one SETPOINT_PERIOD per read request instead\n"
    "                        of wall time: for `hexcnc run` on the simulated clock\n"
    "  --drives N            without --ini: N drives (default 6, at most 64)\n"
    "  --base-port P         drive n listens on P + n (default 15020)\n"
    "  --host ADDR           listening IPv4 address (default 127.0.0.1)\n"
    "  --word-order high-first|low-first   32-bit values (default high-first)\n"
    "  --counts-per-mm C     drive counts per mm, for --start and `position` (default 1000)\n"
    "  --tau S               first-order lag of the drives, s (default 0.002)\n"
    "  --vmax COUNTS_PER_S   velocity limit, counts/s (default none)\n"
    "  --start L0,L1,...     start positions (leg lengths), mm: one per drive, or one for all\n"
    "  --seconds S           stop after S seconds (default: at quit, end of input or a signal)\n"
    "  -h, --help            this text\n"
    "\n"
    "Commands on stdin, each acted on as soon as its line arrives:\n"
    "  fault N none|no-answer|exception CODE|delay US|disconnect|drive\n"
    "  position N MM         put drive N at MM (target and actual)\n"
    "  state                 every drive's target, position, words and counters\n"
    "  quit\n";

/* Command-line settings. */
struct modbus_sim_args {
    int drives;                   /* number of drives (without --ini) */
    int base_port;                /* drive n listens on base_port + n */
    const char *host;             /* listening address (loopback by default) */
    double seconds;               /* stop after this long; 0 = until quit, EOF or a signal */
    const char *ini;              /* --ini: the machine's INI, or NULL */
    bool lockstep;                /* --lockstep: model time per read request */
    double counts_per_mm;         /* without --ini: scaling of --start and `position` */
    const char *start;            /* --start: comma-separated positions, mm, or NULL */
    bool explicit_drive_opts;     /* an option that --ini replaces was given */
    struct modbus_sim_opts opts;
};

/* The running simulator and what the stdin commands need. */
struct modbus_sim_run {
    struct modbus_sim *s;         /* the drives */
    struct hal *h;                /* with --ini: the runtime that owns s; else NULL */
    double counts_per_mm[64];     /* per drive */
    enum modbus_word_order order; /* drive 0's word order, for the banner */
    char buf[1024];               /* stdin bytes not yet ending in a newline */
    size_t len;
};

/* Parses a number in [lo, hi]; prints why not and returns false. */
static bool modbus_sim_num(const char *opt, const char *v, double lo, double hi, double *out)
{
    char *end;
    errno = 0;
    double x = strtod(v, &end);
    if (end == v || *end || errno || !(x >= lo && x <= hi)) {
        fprintf(stderr, "hexcnc modbus_sim: %s %s: expected a number in %g..%g\n", opt, v, lo, hi);
        return false;
    }
    *out = x;
    return true;
}

/* Numeric options and their ranges. */
static const struct modbus_sim_numopt {
    const char *name;
    double lo, hi;
    bool integer;
} modbus_sim_numopts[] = {
    { "--drives", 1, 64, true },            { "--base-port", 1, 65535, true },
    { "--tau", 0, 1e3, false },             { "--vmax", 1e-9, 1e12, false },
    { "--counts-per-mm", -1e9, 1e9, false }, { "--seconds", 0, 1e9, false },
};

/* Takes one option with its value; false (after printing why) when bad. */
static bool modbus_sim_option(struct modbus_sim_args *a, const char *o, const char *v)
{
    double x = 0.0;
    for (size_t k = 0; k < sizeof(modbus_sim_numopts) / sizeof(modbus_sim_numopts[0]); k++) {
        const struct modbus_sim_numopt *n = &modbus_sim_numopts[k];
        if (strcmp(o, n->name))
            continue;
        if (!modbus_sim_num(o, v, n->lo, n->hi, &x))
            return false;
        if ((n->integer && x != floor(x)) || (!strcmp(o, "--counts-per-mm") && x == 0.0)) {
            fprintf(stderr, "hexcnc modbus_sim: %s %s: expected %s\n", o, v,
                    n->integer ? "a whole number" : "a non-zero number");
            return false;
        }
    }
    if (!strcmp(o, "--seconds"))
        a->seconds = x;
    else if (!strcmp(o, "--ini"))
        a->ini = v;
    else if (!strcmp(o, "--start"))
        a->start = v;
    else {
        if (!strcmp(o, "--drives"))
            a->drives = (int)x;
        else if (!strcmp(o, "--base-port"))
            a->base_port = (int)x;
        else if (!strcmp(o, "--tau"))
            a->opts.tau_s = x;
        else if (!strcmp(o, "--vmax"))
            a->opts.vmax_counts_s = x;
        else if (!strcmp(o, "--counts-per-mm"))
            a->counts_per_mm = x;
        else if (!strcmp(o, "--host"))
            a->host = v;
        else if (!strcmp(o, "--word-order") && (!strcmp(v, "high-first") || !strcmp(v, "low-first")))
            a->opts.map.order = !strcmp(v, "low-first") ? MODBUS_WORDS_LOW_FIRST
                                                        : MODBUS_WORDS_HIGH_FIRST;
        else {
            fprintf(stderr, "hexcnc modbus_sim: bad option or value '%s %s' (hexcnc modbus_sim "
                    "--help)\n", o, v);
            return false;
        }
        a->explicit_drive_opts = true;      /* --ini takes these from the INI */
    }
    return true;
}

/* Parses the command line; returns -1 to go on, else the exit status (0 after --help). */
static int modbus_sim_parse(int argc, char **argv, struct modbus_sim_args *a)
{
    memset(a, 0, sizeof(*a));
    a->drives = 6;
    a->base_port = 15020;
    a->host = "127.0.0.1";
    a->counts_per_mm = 1000.0;
    modbus_sim_opts_default(&a->opts);
    for (int i = 1; i < argc; i++) {
        const char *o = argv[i];
        if (!strcmp(o, "-h") || !strcmp(o, "--help")) {
            fputs(modbus_sim_help, stdout);
            return 0;
        }
        if (!strcmp(o, "--lockstep")) {
            a->lockstep = true;
            continue;
        }
        if (i + 1 >= argc) {
            fprintf(stderr, "hexcnc modbus_sim: %s needs a value (hexcnc modbus_sim --help)\n", o);
            return 2;
        }
        if (!modbus_sim_option(a, o, argv[++i]))
            return 2;
    }
    if (a->ini && a->explicit_drive_opts) {
        fprintf(stderr, "hexcnc modbus_sim: with --ini the drives, ports, host, word order, "
                "scaling and model come from the INI\n");
        return 2;
    }
    if (a->lockstep && !a->ini) {
        fprintf(stderr, "hexcnc modbus_sim: --lockstep needs --ini (for SETPOINT_PERIOD)\n");
        return 2;
    }
    if (!a->ini && a->base_port + a->drives - 1 > 65535) {
        fprintf(stderr, "hexcnc modbus_sim: ports %d..%d do not fit in 1..65535\n", a->base_port,
                a->base_port + a->drives - 1);
        return 2;
    }
    return -1;
}

/* The INI lookup modbus_cfg_read wants. */
static const char *modbus_sim_ini_get(void *ctx, const char *section, const char *key)
{
    return hal_ini_get(ctx, section, key);
}

/* --ini: the same component `hexcnc run` loads in-process (modbus-sim-server), after the
 * kinematics so that it parks the drives at [KINS] HOME. */
static int modbus_sim_from_ini(struct modbus_sim_run *r, const struct modbus_sim_args *a)
{
    char err[320];
    r->h = hal_create();
    if (!r->h) {
        fprintf(stderr, "hexcnc modbus_sim: out of memory\n");
        return 1;
    }
    hal_set_sim_clock(r->h, a->lockstep);
    if (hal_load_ini(r->h, a->ini) ||
        (hal_ini_get(r->h, "KINS", "KINEMATICS") &&
         hal_cmd(r->h, "loadrt [KINS]KINEMATICS", a->ini, 0, stdout)) ||
        hal_cmd(r->h, "loadrt modbus-sim-server", a->ini, 0, stdout)) {
        fprintf(stderr, "hexcnc modbus_sim: %s\n", hal_last_error(r->h));
        return 1;
    }
    r->s = hal_get_object(r->h, "modbus-sim");
    for (int i = 0; i < modbus_sim_count(r->s); i++) {
        struct modbus_drive_cfg cfg;
        if (modbus_cfg_read(&cfg, i, "MODBUS", modbus_sim_ini_get, r->h, a->ini, err,
                            sizeof(err))) {
            fprintf(stderr, "hexcnc modbus_sim: %s\n", err);
            return 1;
        }
        r->counts_per_mm[i] = cfg.counts_per_mm;
        if (i == 0)
            r->order = cfg.map.order;
    }
    return 0;
}

/* Without --ini: n drives on base_port.. from the options. */
static int modbus_sim_from_args(struct modbus_sim_run *r, const struct modbus_sim_args *a)
{
    int rc;
    if ((rc = modbus_sim_create(&r->s, a->drives, &a->opts)) ||
        (rc = modbus_sim_start_tcp(r->s, a->host, a->base_port))) {
        fprintf(stderr, "hexcnc modbus_sim: drives on %s:%d..%d: %s\n", a->host, a->base_port,
                a->base_port + a->drives - 1, modbus_sim_strerror(rc));
        return 1;
    }
    for (int i = 0; i < a->drives; i++)
        r->counts_per_mm[i] = a->counts_per_mm;
    r->order = a->opts.map.order;
    return 0;
}

/* Puts drive i at pos_mm; prints why not and returns false. */
static bool modbus_sim_put(struct modbus_sim_run *r, int i, double pos_mm, const char *who)
{
    int32_t counts;
    if (i < 0 || i >= modbus_sim_count(r->s)) {
        printf("%s: no drive %d (drives 0..%d)\n", who, i, modbus_sim_count(r->s) - 1);
        return false;
    }
    if (modbus_mm_to_counts(pos_mm, r->counts_per_mm[i], &counts)) {
        printf("%s: %g mm is beyond drive %d's 32-bit count range at %g counts/mm\n", who,
               pos_mm, i, r->counts_per_mm[i]);
        return false;
    }
    modbus_sim_set_position(r->s, i, counts);
    return true;
}

/* --start L0,L1,...: one position per drive, or one for all. */
static int modbus_sim_start_positions(struct modbus_sim_run *r, const char *list)
{
    int n = modbus_sim_count(r->s), k = 0;
    double v[64];
    const char *p = list;
    while (*p && k < 64) {
        char *end;
        v[k] = strtod(p, &end);
        if (end == p || (*end && *end != ',') || !isfinite(v[k]))
            break;
        k++;
        p = *end ? end + 1 : end;
    }
    if (*p || (k != n && k != 1)) {
        fprintf(stderr, "hexcnc modbus_sim: --start %s: expected %d positions in mm separated "
                "by commas (or one for every drive)\n", list, n);
        return 2;
    }
    for (int i = 0; i < n; i++)
        if (!modbus_sim_put(r, i, v[k == 1 ? 0 : i], "hexcnc modbus_sim: --start"))
            return 2;
    return 0;
}

/* `state`: one line per drive. */
static void modbus_sim_print_state(struct modbus_sim_run *r)
{
    for (int i = 0; i < modbus_sim_count(r->s); i++) {
        struct modbus_sim_drive_state st;
        modbus_sim_state(r->s, i, &st);
        printf("drive %d port %d: target %d actual %.1f counts (%.4f mm), control 0x%04x "
               "status 0x%04x, %u requests, %u connections\n", i, modbus_sim_port(r->s, i),
               st.target_counts, st.actual_counts, st.actual_counts / r->counts_per_mm[i],
               st.control_word, st.status_word, st.requests, st.connections);
    }
}

/* One line from stdin. Returns false on quit. */
static bool modbus_sim_command(struct modbus_sim_run *r, const char *line)
{
    char word[32] = "", kind[32] = "";
    int drive = -1;
    long arg = 0;
    double pos_mm;
    int n = sscanf(line, "%31s %d %31s %ld", word, &drive, kind, &arg);
    if (n < 1)
        return true;
    if (!strcmp(word, "quit"))
        return false;
    if (!strcmp(word, "state")) {
        modbus_sim_print_state(r);
    } else if (!strcmp(word, "position") && sscanf(line, "%*s %d %lf", &drive, &pos_mm) == 2) {
        if (modbus_sim_put(r, drive, pos_mm, "position"))
            printf("drive %d: at %.4f mm\n", drive, pos_mm);
    } else if (!strcmp(word, "fault") && n >= 3 && modbus_sim_fault_parse(kind) >= 0) {
        int rc = modbus_sim_inject(r->s, drive,
                                   (enum modbus_sim_fault)modbus_sim_fault_parse(kind), arg);
        if (rc)
            printf("fault: %s\n", modbus_sim_strerror(rc));
        else
            printf("drive %d: %s\n", drive, kind);
    } else {
        printf("commands: fault N none|no-answer|exception CODE|delay US|disconnect|drive; "
               "position N MM; state; quit\n");
    }
    fflush(stdout);
    return true;
}

/* Reads what stdin has (never more than is there, so no line waits in a stdio buffer) and
 * runs every complete line. Returns 0 to go on, 1 on quit, -1 at end of input. */
static int modbus_sim_read_stdin(struct modbus_sim_run *r)
{
    ssize_t k = read(0, r->buf + r->len, sizeof(r->buf) - 1 - r->len);
    if (k < 0 && (errno == EINTR || errno == EAGAIN))
        return 0;
    bool eof = k <= 0;
    if (!eof)
        r->len += (size_t)k;
    r->buf[r->len] = '\0';
    char *line = r->buf, *nl;
    while ((nl = strchr(line, '\n'))) {
        *nl = '\0';
        if (!modbus_sim_command(r, line))
            return 1;
        line = nl + 1;
    }
    r->len = strlen(line);
    memmove(r->buf, line, r->len + 1);
    if ((eof || r->len == sizeof(r->buf) - 1) && r->len) {   /* a last or overlong line */
        r->len = 0;
        if (!modbus_sim_command(r, r->buf))
            return 1;
    }
    return eof ? -1 : 0;
}

/* Monotonic time, s. */
static double modbus_sim_now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + ts.tv_nsec * 1e-9;
}

/* Serves until quit, end of input (unless --seconds), SIGINT/SIGTERM or --seconds. The
 * drives are served by their own threads; this loop waits on stdin and the signals only. */
static void modbus_sim_loop(struct modbus_sim_run *r, int sfd, double seconds)
{
    double t_end = modbus_sim_now_s() + seconds;
    struct pollfd p[2] = { { .fd = sfd, .events = POLLIN }, { .fd = 0, .events = POLLIN } };
    nfds_t nfds = 2;
    for (;;) {
        int wait_ms = -1;
        if (seconds > 0.0) {
            double left_s = t_end - modbus_sim_now_s();
            if (left_s <= 0.0)
                return;
            wait_ms = (int)ceil(left_s * 1000.0);
        } else if (nfds == 1) {
            return;                         /* end of input and no time limit */
        }
        if (poll(p, nfds, wait_ms) < 0 && errno != EINTR)
            return;
        if (p[0].revents)
            return;
        if (nfds == 2 && p[1].revents) {
            int rc = modbus_sim_read_stdin(r);
            if (rc > 0)
                return;
            if (rc < 0)
                nfds = 1;
        }
    }
}

/* Tells where the drives are and how they move. */
static void modbus_sim_banner(struct modbus_sim_run *r, const struct modbus_sim_args *a)
{
    int n = modbus_sim_count(r->s);
    const char *host = a->host;
    if (r->h)
        host = hal_ini_get(r->h, "MODBUS", "HOST") ? hal_ini_get(r->h, "MODBUS", "HOST")
                                                    : "127.0.0.1";
    printf("modbus_sim: %d drives on %s:%d..%d (%s word first, %s)\n", n, host,
           modbus_sim_port(r->s, 0), modbus_sim_port(r->s, n - 1),
           r->order == MODBUS_WORDS_HIGH_FIRST ? "high" : "low",
           a->lockstep ? "one set-point period per read request" : "moving on wall time");
    printf("modbus_sim: positions mm:");
    for (int i = 0; i < n; i++) {
        struct modbus_sim_drive_state st;
        modbus_sim_state(r->s, i, &st);
        printf(" %.4f", st.actual_counts / r->counts_per_mm[i]);
    }
    printf("\n");
    fflush(stdout);
}

/* Entry point of `hexcnc modbus_sim`. */
int cmd_modbus_sim(int argc, char **argv)
{
    struct modbus_sim_args a;
    int rc = modbus_sim_parse(argc, argv, &a);
    if (rc >= 0)
        return rc;
    sigset_t mask;
    sigemptyset(&mask);
    sigaddset(&mask, SIGINT);
    sigaddset(&mask, SIGTERM);
    sigprocmask(SIG_BLOCK, &mask, NULL);
    int sfd = signalfd(-1, &mask, SFD_CLOEXEC);
    struct modbus_sim_run *r = calloc(1, sizeof(*r));
    if (!r || sfd < 0) {
        fprintf(stderr, "hexcnc modbus_sim: %s\n", strerror(errno));
        rc = 1;
        goto out;
    }
    rc = a.ini ? modbus_sim_from_ini(r, &a) : modbus_sim_from_args(r, &a);
    if (!rc && a.start)
        rc = modbus_sim_start_positions(r, a.start);
    if (rc)
        goto out;
    modbus_sim_banner(r, &a);
    modbus_sim_loop(r, sfd, a.seconds);
out:
    if (r && r->h)
        hal_destroy(r->h);          /* stops and frees the drives too */
    else if (r)
        modbus_sim_destroy(r->s);
    free(r);
    if (sfd >= 0)
        close(sfd);
    return rc;
}
