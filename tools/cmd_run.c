/* cmd_run.c: `hexcnc run`: starts the machine from its INI file and runs a program on it. */
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "hal/hal.h"
#include "task/runner.h"
#include "tools/cmd.h"

const char cmd_run_usage[] =
    "run [--sim-clock|--realtime] [--quiet] CONFIG.ini [PROGRAM]   run a program on the machine";

/* Exit statuses: 0 done, 1 refused before any motion, 2 usage, 3 fault while moving,
 * 130 stopped by Ctrl-C (as a shell reports SIGINT). */
enum { RUN_EXIT_OK = 0, RUN_EXIT_REFUSED = 1, RUN_EXIT_USAGE = 2, RUN_EXIT_FAULT = 3,
       RUN_EXIT_INTERRUPT = 130 };

/* Set by the SIGINT/SIGTERM handler. A signal handler can only reach static storage: this
 * flag is the one piece of process-wide state, and only the handler writes it. */
static volatile sig_atomic_t run_stop_requested;

/* Ctrl-C: ask for the controlled stop; a second Ctrl-C changes nothing (the stop is on). */
static void run_on_signal(int sig)
{
    (void)sig;
    run_stop_requested = 1;
}

/* Command-line options. */
struct run_args {
    enum runner_clock clock;
    int quiet;
    const char *ini;
    const char *program;
};

/* The progress display's state. A line (or, on a terminal, an update of the one line) is
 * due at each further 10 % of the program, after every `every_s` of machine time and after
 * every second of wall time (a terminal: a tenth of a second), whichever comes first, and
 * whenever the machine's state changes (running, paused, done, ...). */
struct run_display {
    int tty;                  /* stdout is a terminal: one updating line */
    int quiet;                /* no progress at all */
    double every_s;           /* a line at least every this much machine time */
    double next_s;            /* machine time of the next line */
    double next_percent;      /* the next 10 % mark */
    double wall_every_s;      /* a line at least every this much wall time */
    double last_wall_s;       /* wall time of the last line */
    int last_state;           /* enum motion_state of the last line, -1 before the first */
    int shown;                /* a terminal line is on screen (needs a newline) */
};

/* Wall-clock seconds (monotonic). */
static double run_wall_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Whether a progress line is due now (see struct run_display). */
static int run_progress_due(const struct run_display *d, const struct runner_progress *p,
                            double now_wall_s)
{
    return (int)p->state != d->last_state || p->percent >= d->next_percent ||
           p->elapsed_s >= d->next_s || now_wall_s - d->last_wall_s >= d->wall_every_s;
}

/* Prints progress: an updating line on a terminal, else one line each time one is due. */
static void run_progress(void *ctx, const struct runner_progress *p)
{
    struct run_display *d = ctx;
    double now = run_wall_s();
    if (d->quiet || !run_progress_due(d, p, now))
        return;
    d->last_wall_s = now;
    d->last_state = (int)p->state;
    d->next_s = p->elapsed_s + d->every_s;
    while (d->next_percent <= p->percent)
        d->next_percent += 10.0;
    if (d->tty) {
        printf("\r  line %-5d %5.1f %%  elapsed %8.3f s  remaining %8.3f s  %-9s", p->line,
               p->percent, p->elapsed_s, p->remaining_s, motion_state_name(p->state));
        d->shown = 1;
    } else
        printf("  line %d: %.1f %%, elapsed %.3f s, remaining %.3f s\n", p->line, p->percent,
               p->elapsed_s, p->remaining_s);
    fflush(stdout);
}

/* Parses the command line; returns 0 or prints usage and returns RUN_EXIT_USAGE. */
static int run_parse(int argc, char **argv, struct run_args *a)
{
    memset(a, 0, sizeof *a);
    int i = 1;
    for (; i < argc && argv[i][0] == '-'; i++) {
        if (!strcmp(argv[i], "--sim-clock"))
            a->clock = RUNNER_CLOCK_SIM;
        else if (!strcmp(argv[i], "--realtime"))
            a->clock = RUNNER_CLOCK_REALTIME;
        else if (!strcmp(argv[i], "--quiet"))
            a->quiet = 1;
        else
            break;
    }
    if (argc - i < 1 || argc - i > 2) {
        fprintf(stderr, "usage: hexcnc %s\n", cmd_run_usage);
        return RUN_EXIT_USAGE;
    }
    a->ini = argv[i];
    a->program = argc - i == 2 ? argv[i + 1] : NULL;
    return 0;
}

/* Prints the summary of a run. */
static void run_print_summary(struct runner *r, const char *program, double wall_s)
{
    struct runner_summary s;
    runner_summary(r, &s);
    printf("summary of %s:\n", program);
    printf("  machine time   %.3f s (planned %.3f s)", s.machine_time_s, s.planned_time_s);
    if (runner_sim_clock(r) && wall_s > 0.0)
        printf(", simulated in %.3f s (%.0fx real time)", wall_s, s.machine_time_s / wall_s);
    printf("\n  path distance  %.3f mm\n", s.distance_mm);
    printf("  leg            peak rate mm/s  max following error mm  length range mm\n");
    for (int i = 0; i < s.njoints; i++)
        printf("  %d ([JOINT_%d])  %14.3f  %22.5f  %.3f .. %.3f\n", i + 1, i,
               s.peak_rate_mm_s[i], s.max_ferror_mm[i], s.leg_min_mm[i], s.leg_max_mm[i]);
    const double *c = s.final_cmd_pose;
    printf("  commanded end  X %.6f  Y %.6f  Z %.6f  A %.4f  B %.4f  C %.4f\n", c[0], c[1],
           c[2], c[3], c[4], c[5]);
    if (s.final_pose_ok) {
        const double *p = s.final_pose;
        double d_mm = sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                           (p[2] - c[2]) * (p[2] - c[2]));
        printf("  final pose     X %.6f  Y %.6f  Z %.6f  A %.4f  B %.4f  C %.4f\n"
               "                 (forward kinematics of the legs' steps: %.4f mm from the "
               "commanded end)\n", p[0], p[1], p[2], p[3], p[4], p[5], d_mm);
    } else
        printf("  final pose     unknown: the forward kinematics of the leg feedback failed\n");
    printf("  final legs mm ");
    for (int i = 0; i < s.njoints; i++)
        printf(" %.4f", s.final_legs_mm[i]);
    printf("\n");
}

/* Prints what the planner made of the program. */
static void run_print_plan(struct runner *r)
{
    struct motion_plan_info pi;
    if (runner_plan_info(r, &pi) != RUNNER_OK)
        return;
    printf("planned: %zu segments, %.3f mm of path, %.3f s\n", pi.segments, pi.length_mm,
           pi.time_s);
}

/* Installs the Ctrl-C / TERM handler (no SA_RESTART: sleeps end early, which is fine). */
static void run_catch_signals(void)
{
    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = run_on_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);
}

/* A component's message as it arrives: faults and warnings on stderr, the rest on stdout. */
static void run_on_message(void *ctx, const struct hal_msg *m)
{
    const int *quiet = ctx;
    if (*quiet && m->severity == HAL_MSG_INFO)
        return;
    FILE *f = m->severity == HAL_MSG_INFO ? stdout : stderr;
    fprintf(f, "hexcnc run: %s: %s: %s\n", hal_msg_severity_name(m->severity), m->source,
            m->text);
}

/* Loads, plans, runs and reports; returns the exit status. */
static int run_machine(struct runner *r, const char *program, int quiet)
{
    char err[1024];
    if (!quiet) {
        printf("program %s\n", program);
        fflush(stdout);  /* shown before a long load, also when stdout is a file */
    }
    runner_set_cancel(r, &run_stop_requested);  /* Ctrl-C while reading or planning */
    int st = runner_load_program(r, program, err, sizeof err);
    if (st != RUNNER_OK) {
        fprintf(stderr, "hexcnc run: %s%s\nhexcnc run: the program was not started; "
                "the machine did not move\n", st == RUNNER_ERR_ABORTED ? "interrupted: " : "",
                err);
        return st == RUNNER_ERR_ABORTED ? RUN_EXIT_INTERRUPT : RUN_EXIT_REFUSED;
    }
    if (!quiet)
        run_print_plan(r);
    int tty = isatty(STDOUT_FILENO);
    struct run_display d = { .tty = tty, .quiet = quiet, .every_s = 5.0, .next_s = 5.0,
                             .next_percent = 10.0, .wall_every_s = tty ? 0.1 : 1.0,
                             .last_wall_s = run_wall_s(), .last_state = -1 };
    long every = 5;
    if (hal_ini_int(runner_hal(r), "TASK", "PROGRESS_INTERVAL", 5, &every) == HAL_OK &&
        every > 0)
        d.every_s = d.next_s = (double)every;
    runner_set_message_fn(r, run_on_message, &quiet);
    double t0 = run_wall_s();
    if (runner_start(r, err, sizeof err) != RUNNER_OK) {
        fprintf(stderr, "hexcnc run: %s\n", err);
        return RUN_EXIT_REFUSED;
    }
    st = runner_run(r, &run_stop_requested, run_progress, &d, err, sizeof err);
    double wall_s = run_wall_s() - t0;
    if (d.shown)
        printf("\n");
    run_print_summary(r, program, wall_s);
    if (st == RUNNER_ERR_ABORTED) {
        fprintf(stderr, "hexcnc run: interrupted: %s\n", err);
        return RUN_EXIT_INTERRUPT;
    }
    if (st != RUNNER_OK) {
        fprintf(stderr, "hexcnc run: %s: %s\n", runner_strerror(st), err);
        return RUN_EXIT_FAULT;
    }
    if (!quiet)
        printf("program finished\n");
    return RUN_EXIT_OK;
}

/* `hexcnc run`: the machine startup without the shell around it. */
int cmd_run(int argc, char **argv)
{
    struct run_args a;
    int rc = run_parse(argc, argv, &a);
    if (rc)
        return rc;
    run_catch_signals();
    struct runner_opts opts = { .ini_path = a.ini, .clock = a.clock };
    struct runner *r;
    char err[1024];
    if (runner_create(&opts, &r, err, sizeof err) != RUNNER_OK) {
        fprintf(stderr, "hexcnc run: %s\n", err);
        return RUN_EXIT_REFUSED;
    }
    const char *program = a.program ? a.program : runner_default_program(r);
    if (!program) {
        fprintf(stderr, "hexcnc run: no program given and no [DISPLAY] OPEN_FILE in %s\n",
                a.ini);
        runner_destroy(r);
        return RUN_EXIT_USAGE;
    }
    if (!a.quiet)
        printf("hexcnc run: machine %s, %s clock\n", a.ini,
               runner_sim_clock(r) ? "simulated" : "real-time");
    rc = run_machine(r, program, a.quiet);
    runner_destroy(r);
    return rc;
}
