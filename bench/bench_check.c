/* bench_check.c: hexcnc check on an hour of generated five-axis machining, beside its baselines. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "check/check.h"

#define TARGET_S 3600.0      /* machining time the generated program aims at, s */
#define SHORT_S 360.0        /* the exhaustive baseline runs on a tenth of that (it is slow) */
#define FEED_MM_S 10.0       /* its feed: F600 (mm/min, as the TMU INI reads F) = 10 mm/s */

/* Wall and process CPU clocks, s (the machine is shared: CPU time is the fair figure). */
static double clock_s(clockid_t id)
{
    struct timespec ts;
    clock_gettime(id, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* A small deterministic generator (no global state: the caller holds the seed). */
static double uniform(unsigned long long *s, double lo, double hi)
{
    *s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
    return lo + (hi - lo) * (double)(*s >> 11) / 9007199254740992.0;
}

/* v limited to [lo, hi]. */
static double clampd(double v, double lo, double hi) { return v < lo ? lo : v > hi ? hi : v; }

/* A random walk of G1 X Y Z A B C moves inside the TMU working region (X, Y +-100 mm,
 * Z 625..665 mm, |A|, |B| <= 8 deg, |C| <= 12 deg), about target_s long at FEED_MM_S. */
static char *generate(double target_s, size_t *len, int *moves)
{
    size_t cap = 1 << 20, n = 0;
    char *t = malloc(cap);
    unsigned long long seed = 12345;
    double p[6] = { 0, 0, 645, 0, 0, 0 }, time_s = 0;
    if (!t)
        return NULL;
    n += (size_t)snprintf(t + n, cap - n, "G21 G90 G64 P0.01\nG1 X0 Y0 Z645 A0 B0 C0 F%.3f\n",
                          FEED_MM_S * 60);
    for (*moves = 0; time_s < target_s; ++*moves) {
        double q[6];
        do {
            q[0] = p[0] + uniform(&seed, -10, 10), q[1] = p[1] + uniform(&seed, -10, 10);
            q[2] = p[2] + uniform(&seed, -3, 3);
        } while (fabs(q[0]) > 100 || fabs(q[1]) > 100 || q[2] < 625 || q[2] > 665);
        q[3] = clampd(p[3] + uniform(&seed, -1, 1), -8, 8);
        q[4] = clampd(p[4] + uniform(&seed, -1, 1), -8, 8);
        q[5] = clampd(p[5] + uniform(&seed, -1.5, 1.5), -12, 12);
        time_s += sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                       (q[2] - p[2]) * (q[2] - p[2])) / FEED_MM_S;
        memcpy(p, q, sizeof p);
        if (cap - n < 256) {
            char *nt = realloc(t, cap *= 2);
            if (!nt)
                return free(t), NULL;
            t = nt;
        }
        n += (size_t)snprintf(t + n, cap - n, "G1 X%.3f Y%.3f Z%.3f A%.3f B%.3f C%.3f\n", p[0],
                              p[1], p[2], p[3], p[4], p[5]);
    }
    n += (size_t)snprintf(t + n, cap - n, "M2\n");
    *len = n;
    return t;
}

/* One timed check of the program with the given schedule; prints a row. */
static int timed_check(struct check_machine *mc, const struct canon_prog *prog,
                       const char *what, double dev_s, double cond_s, int cold,
                       double *cpu_out)
{
    struct check_opts o;
    struct check_result r;
    check_opts_default(&o);
    o.deviation_every_s = dev_s, o.condition_every_s = cond_s, o.cold_forward = cold;
    check_result_init(&r);
    double w0 = clock_s(CLOCK_MONOTONIC), c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    int st = check_canon(mc, prog, &o, &r);
    double cpu = clock_s(CLOCK_PROCESS_CPUTIME_ID) - c0, wall = clock_s(CLOCK_MONOTONIC) - w0;
    printf("%-44s %9.1f s %8.3f s %8.3f s %8.0fx %8.3f um %7ld %7ld\n", what,
           r.machining_time_s, cpu, wall, r.machining_time_s / cpu, r.max_deviation_mm * 1e3,
           r.deviation_evals, r.condition_evals);
    *cpu_out = cpu;
    check_result_free(&r);
    return st;
}

/* The floor: motion_step alone over the same program, no measures. */
static double motion_alone(struct check_machine *mc, const struct canon_prog *prog)
{
    struct motion *m = check_machine_motion(mc);
    struct motion_out out;
    char err[400];
    double T = check_machine_motion_config(mc)->servo_period_s;
    double c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    if (motion_load(m, prog, err, sizeof err) != MOTION_OK || motion_start(m) != MOTION_OK) {
        fprintf(stderr, "bench_check: %s\n", err);
        return -1;
    }
    do
        motion_step(m, T, &out);
    while (out.state == MOTION_RUNNING);
    double cpu = clock_s(CLOCK_PROCESS_CPUTIME_ID) - c0;
    printf("%-44s %9.1f s %8.3f s %10s %8.0fx\n", "motion_load + motion_step alone (floor)",
           out.time_elapsed_s, cpu, "", out.time_elapsed_s / cpu);
    return cpu;
}

/* Generates and interprets a program of about target_s seconds into prog. */
static int make_program(struct check_machine *mc, double target_s, struct canon_prog *prog,
                        char **text)
{
    size_t len = 0;
    int moves = 0;
    struct check_problem p;
    *text = generate(target_s, &len, &moves);
    double c0 = clock_s(CLOCK_PROCESS_CPUTIME_ID);
    if (!*text || check_machine_interpret_text(mc, "generated.ngc", *text, len, prog, &p)) {
        fprintf(stderr, "bench_check: %s\n", *text ? p.message : "out of memory");
        return -1;
    }
    printf("\ngenerated program: %d G1 X Y Z A B C moves at %.0f mm/s in the TMU working region;"
           " interpreted in %.3f s CPU\n", moves, FEED_MM_S,
           clock_s(CLOCK_PROCESS_CPUTIME_ID) - c0);
    printf("%-44s %11s %10s %10s %9s %11s %7s %7s\n", "check (TMU, 1 kHz servo)", "machining",
           "CPU", "wall", "ratio", "max dev", "fwd", "svd");
    return 0;
}

/* The hour with its baselines, then the exhaustive baseline on a tenth of it. */
int main(void)
{
    char err[1024];
    struct check_machine *mc;
    if (check_machine_open("configs/sim/tmu-hexapod.ini", &mc, err, sizeof err) != CHECK_OK) {
        fprintf(stderr, "bench_check: %s (run from the source tree: make bench)\n", err);
        return 1;
    }
    struct canon_prog prog, shorter;
    char *text = NULL, *text2 = NULL;
    canon_prog_init(&prog);
    canon_prog_init(&shorter);
    double fast, cold, fast2, every;
    int st = 1;
    if (make_program(mc, TARGET_S, &prog, &text))
        goto out;
    st = timed_check(mc, &prog, "optimised: dev 50 ms, cond 500 ms, warm fwd", 0.050, 0.500, 0,
                     &fast);
    timed_check(mc, &prog, "baseline: cold-started forward, same schedule", 0.050, 0.500, 1,
                &cold);
    motion_alone(mc, &prog);
    printf("warm over cold-started forward kinematics: %.2fx\n", cold / fast);
    if (make_program(mc, SHORT_S, &shorter, &text2))
        goto out;
    timed_check(mc, &shorter, "optimised: dev 50 ms, cond 500 ms, warm fwd", 0.050, 0.500, 0,
                &fast2);
    timed_check(mc, &shorter, "baseline: dev + cond every servo period", 0, 0, 0, &every);
    printf("the schedule over measuring at every servo period: %.1fx\n", every / fast2);
out:
    canon_prog_free(&prog);
    canon_prog_free(&shorter);
    free(text);
    free(text2);
    check_machine_close(mc);
    return st == CHECK_OK ? 0 : 1;
}
