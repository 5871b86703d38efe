/* bench_servo.c: cost of one servo period of the simulated TMU hexapod, and the simulated
 * clock's speed-up over real time on the paper's programs. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "hal/hal.h"
#include "task/runner.h"

#define BARE_PERIODS 2000000L   /* periods of the empty-thread baseline */
#define FWD_SOLVES 20000        /* forward solves per cold/warm measurement */

/* The paper's programs (10) and (11) with G141 and G142 (F2 = 2 m/min), as printed but for
 * a positioning move to 20 mm before each G142 contour's start on its compensation side
 * (-X), as the experiment's programs have: the interpreter refuses a G142 start that would
 * approach the wall across the contour (the gouge check, docs/compensation.md). */
static const char *const bench_programs[] = {
    "G141 X50 Y-80 Z630 A0 B-4 W10 F2\nG141 X50 Y-20 Z630 A0 B-4\nM2\n",
    "G141 X50 Y-30 Z630 A0 B-4 W5 F2\nG141 X50 Y20 Z630 A0 B-4\nM2\n",
    "G1 X30 Y-100 Z630 A0 B-4 F2\n"
    "G142 X50 Y-80 Z630 A0 B-4 W10 F2\nG142 X50 Y-20 Z630 A0 B-4\nM2\n",
    "G1 X30 Y-50 Z630 A0 B-4 F2\n"
    "G142 X50 Y-30 Z630 A0 B-4 W5 F2\nG142 X50 Y20 Z630 A0 B-4\nM2\n",
};
#define NPROG (sizeof bench_programs / sizeof bench_programs[0])

/* CPU seconds of this thread: unlike wall time, not inflated when other processes share
 * the cores (the simulated clock runs on this one thread). */
static double cpu_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Leg feedback of a run, kept for the forward-kinematics measurement. */
struct legs_log {
    double (*legs)[KINS_MAX_JOINTS];
    int n, cap, njoints;
};

/* Monotonic wall-clock seconds. */
static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

/* Observer: every 50th period's leg feedback. */
static void log_legs(void *ctx, const struct runner_sample *s)
{
    struct legs_log *l = ctx;
    if (l->n >= l->cap || (s->time_ns / 1000000) % 50)
        return;
    l->njoints = s->njoints;
    memcpy(l->legs[l->n++], s->joint_fb_mm, (size_t)s->njoints * sizeof(double));
}

/* Runs the paper's programs on a fresh machine; returns wall seconds, machine seconds and
 * periods through the pointers. with_monitor = 0 takes the runner's monitor off the thread
 * (the config's own functs only). */
static int run_paper(const char *ini, int with_monitor, struct legs_log *log, double *wall_s,
                     double *cpu_used_s, double *machine_s, long *periods)
{
    struct runner_opts o = { ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    char err[1024], path[256];
    if (runner_create(&o, &r, err, sizeof err) != RUNNER_OK) {
        fprintf(stderr, "bench_servo: %s\n", err);
        return -1;
    }
    if (!with_monitor)
        hal_delf(runner_hal(r), "runner.monitor", NULL);
    if (log)
        runner_set_observer(r, log_legs, log);
    *wall_s = *cpu_used_s = *machine_s = 0.0;
    *periods = 0;
    for (size_t i = 0; i < NPROG; i++) {
        snprintf(path, sizeof path, "/tmp/bench_servo_%d_%zu.ngc", (int)getpid(), i);
        FILE *f = fopen(path, "w");
        if (!f)
            return -1;
        fputs(bench_programs[i], f);
        fclose(f);
        int st = runner_load_program(r, path, err, sizeof err);
        remove(path);
        struct motion_plan_info pi;
        if (st || runner_plan_info(r, &pi) || runner_start(r, err, sizeof err)) {
            fprintf(stderr, "bench_servo: %s\n", err);
            runner_destroy(r);
            return -1;
        }
        /* Exactly the planned time plus a few periods, so both variants run the same
         * number of periods (runner_finished needs the monitor). */
        long n = (long)(pi.time_s * 1000.0) + 5;
        double t0 = now_s(), c0 = cpu_s();
        runner_advance(r, (double)n * 1e-3);
        *wall_s += now_s() - t0;
        *cpu_used_s += cpu_s() - c0;
        *machine_s += (double)n * 1e-3;
        *periods += n;
    }
    runner_destroy(r);
    return 0;
}

/* Per-funct cost: a time stamp funct between every two functs of the servo thread. */
#define MAX_FUNCTS 16
struct stamps {
    double last_s;                    /* time of the previous stamp */
    double acc_s[MAX_FUNCTS];         /* time spent in funct i, summed over the run */
    char name[MAX_FUNCTS][64];        /* funct i's name */
    int n;                            /* functs on the thread */
};
struct stamp_slot {
    struct stamps *s;
    int idx;                          /* the funct this stamp ends (-1: the first stamp) */
};

/* A stamp: charges the time since the previous stamp to the funct before it. */
static void stamp(void *arg, long period_ns)
{
    struct stamp_slot *slot = arg;
    double t = now_s();
    if (slot->idx >= 0)
        slot->s->acc_s[slot->idx] += t - slot->s->last_s;
    slot->s->last_s = now_s();  /* the stamp's own cost is not charged to the next funct */
}

/* The names of the functs on servo-thread, in order, from `show thread`. */
static int thread_functs(struct hal *h, struct stamps *st)
{
    char *buf = NULL;
    size_t len = 0;
    FILE *f = open_memstream(&buf, &len);
    if (!f)
        return -1;
    hal_cmd(h, "show thread servo-thread", NULL, 0, f);
    fclose(f);
    st->n = 0;
    for (char *line = strtok(buf, "\n"); line; line = strtok(NULL, "\n")) {
        int k;
        char name[64];
        if (!strchr(line, '(') && sscanf(line, " %d %63s", &k, name) == 2 &&
            st->n < MAX_FUNCTS)
            snprintf(st->name[st->n++], sizeof st->name[0], "%s", name);
    }
    free(buf);
    return st->n > 0 ? 0 : -1;
}

/* Runs program (10) with a stamp after every funct and prints each funct's mean cost. */
static void bench_functs(const char *ini)
{
    struct runner_opts o = { ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    char err[1024], path[256];
    static struct stamps st;
    static struct stamp_slot slots[MAX_FUNCTS + 1];
    if (runner_create(&o, &r, err, sizeof err) != RUNNER_OK)
        return;
    struct hal *h = runner_hal(r);
    if (thread_functs(h, &st)) {
        runner_destroy(r);
        return;
    }
    for (int i = 0; i <= st.n; i++) {
        slots[i] = (struct stamp_slot){ &st, i - 1 };
        hal_export_functf(h, stamp, &slots[i], "bench.stamp-%d", i);
        char name[32];
        snprintf(name, sizeof name, "bench.stamp-%d", i);
        hal_addf(h, name, "servo-thread", 2 * i + 1);  /* before funct i (1-based 2i+2) */
    }
    snprintf(path, sizeof path, "/tmp/bench_servo_%d.ngc", (int)getpid());
    FILE *f = fopen(path, "w");
    if (!f)
        return;
    fputs(bench_programs[0], f);
    fclose(f);
    struct motion_plan_info pi;
    int bad = runner_load_program(r, path, err, sizeof err) || runner_plan_info(r, &pi) ||
              runner_start(r, err, sizeof err);
    remove(path);
    if (!bad) {
        long n = (long)(pi.time_s * 1000.0);
        runner_advance(r, (double)n * 1e-3);
        printf("per funct, program (10), %ld periods (time stamps between functs):\n", n);
        for (int i = 0; i < st.n; i++)
            printf("  %-16s %.3f us\n", st.name[i], st.acc_s[i] * 1e6 / (double)n);
    }
    runner_destroy(r);
}

/* The bare thread: the same periods with no functs at all (the runtime's own cost). */
static double bare_thread_us(void)
{
    struct hal *h = hal_create();
    hal_set_sim_clock(h, true);
    if (!h || hal_thread_new(h, "servo-thread", 1000000) || hal_start(h))
        return -1.0;
    double t0 = now_s();
    for (long i = 0; i < BARE_PERIODS / 1000; i++)
        hal_sim_advance(h, 1000L * 1000000L);
    double us = (now_s() - t0) * 1e6 / (double)BARE_PERIODS;
    hal_destroy(h);
    return us;
}

/* Forward kinematics of the logged legs: cold start (home pose) vs warm start (the previous
 * solution, as the kins funct does inside the period). */
static void bench_forward(const char *ini, const struct legs_log *log)
{
    struct runner_opts o = { ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    char err[1024];
    if (log->n < 2 || runner_create(&o, &r, err, sizeof err) != RUNNER_OK)
        return;
    struct kins *k = runner_kins(r);
    double pose[KINS_POSE_DIM];
    int fails = 0;
    double t0 = now_s();
    for (int i = 0; i < FWD_SOLVES; i++) {
        memcpy(pose, k->home, sizeof pose);
        fails += kins_forward(k, log->legs[i % log->n], pose, NULL) != KINS_OK;
    }
    double cold_us = (now_s() - t0) * 1e6 / FWD_SOLVES;
    memcpy(pose, k->home, sizeof pose);
    t0 = now_s();
    for (int i = 0; i < FWD_SOLVES; i++)
        fails += kins_forward(k, log->legs[i % log->n], pose, NULL) != KINS_OK;
    double warm_us = (now_s() - t0) * 1e6 / FWD_SOLVES;
    printf("forward kinematics per solve: cold start %.3f us, warm start %.3f us "
           "(warm/cold %.2f)%s\n", cold_us, warm_us, warm_us / cold_us,
           fails ? " (some solves failed)" : "");
    runner_destroy(r);
}

/* The fastest of REPEATS runs of one variant (the machine is shared: the minimum is the
 * figure least disturbed by other processes). */
#define REPEATS 5
static int best_of(const char *ini, int with_monitor, struct legs_log *log, double *wall_s,
                   double *cpu_used_s, double *machine_s, long *periods)
{
    double best_wall = 1e30, best_cpu = 1e30;
    for (int i = 0; i < REPEATS; i++) {
        if (run_paper(ini, with_monitor, i == 0 ? log : NULL, wall_s, cpu_used_s, machine_s,
                      periods))
            return -1;
        best_wall = *wall_s < best_wall ? *wall_s : best_wall;
        best_cpu = *cpu_used_s < best_cpu ? *cpu_used_s : best_cpu;
    }
    *wall_s = best_wall;
    *cpu_used_s = best_cpu;
    return 0;
}

/* Runs every measurement and prints each beside its baseline. */
int main(void)
{
    static char ini[1024];
    const char *root = getenv("HEXCNC_ROOT");
    /* the paper's machine for path 1: its programs' F2 is 2 m/min there */
    snprintf(ini, sizeof ini, "%s/examples/paper/experiment/tmu-path1.ini", root ? root : ".");
    static double legs[4096][KINS_MAX_JOINTS];
    struct legs_log log = { legs, 0, 4096, 0 };
    double wall_s, cpu1_s, machine_s, wall2_s, cpu2_s, machine2_s;
    long periods, periods2;
    if (best_of(ini, 1, &log, &wall_s, &cpu1_s, &machine_s, &periods) ||
        best_of(ini, 0, NULL, &wall2_s, &cpu2_s, &machine2_s, &periods2))
        return 1;
    double bare_us = bare_thread_us();
    double p1 = (double)periods, p2 = (double)periods2;
    printf("paper programs (10) and (11), G141 and G142: %ld servo periods of 1 ms, "
           "best of %d runs; us per period, wall clock / CPU time of the thread\n",
           periods, REPEATS);
    printf("  sim config (e-stop + motion + stepgen + kins.forward): %.3f / %.3f us "
           "(target <= 5 us)\n", wall2_s * 1e6 / p2, cpu2_s * 1e6 / p2);
    printf("  the same with the run monitor of hexcnc run:          %.3f / %.3f us\n",
           wall_s * 1e6 / p1, cpu1_s * 1e6 / p1);
    printf("  bare thread, no functs (baseline, wall):              %.3f us "
           "(config / bare %.0fx)\n", bare_us, wall2_s * 1e6 / p2 / bare_us);
    printf("simulated clock, as hexcnc run: %.3f s of machine time in %.4f s wall "
           "(%.4f s CPU): %.0fx real time (%.0fx per CPU second; target >= 1000x)\n",
           machine_s, wall_s, cpu1_s, machine_s / wall_s, machine_s / cpu1_s);
    bench_forward(ini, &log);
    bench_functs(ini);
    return 0;
}
