/* bench_motion.c: kinematic deviation with and without the bound, motion_step cost, load time,
 * corner blending against G61, set-point chords on blend arcs. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "tests/test_motion_util.h"

/* Monotonic time, s. */
static double now_s(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Measured deviation of S -> E at 500 mm/s programmed, set points every T s. */
static int deviation(const double *S, const double *E, double T, double tol_mm, struct tm_dev *d)
{
    struct tk_cfg *c = tm_fast_hexapod_cfg(T, tol_mm);
    struct tm_machine mc;
    if (!c || tm_open(&mc, c, &kins_hexapod_ops))
        return -1;
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, S, 6 * sizeof *S);
    tm_add(&p, CANON_FEED, 1, E, 30000, 0);
    char err[512];
    int st = motion_load(mc.m, &p, err, sizeof err) || motion_start(mc.m) ||
             tm_deviation(mc.m, mc.kins, S, E, T, d);
    canon_prog_free(&p);
    tm_close(&mc);
    return st ? -1 : 0;
}

/* A long program of short five-axis moves (a raster with tilts), n blocks, G64. With tf,
 * the same raster is the tool tip's under G43.4 (tool length 60 mm, the tip 80 mm above
 * the TMU platform instead of the platform at 640 mm). */
static void long_program_tcp(struct canon_prog *p, int n, const struct kins_tool_frame *tf)
{
    canon_prog_init(p);
    double s[6] = {-50, -50, tf ? 80 : 640, 0, 0, 0};
    if (tf)
        kins_tcp_to_pose(tf, 60, s, p->start);
    else
        memcpy(p->start, s, sizeof s);
    struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 1, .file = "long.ngc", .value = 0.01};
    canon_prog_sink(p, &pm);
    for (int i = 0; i < n; i++) {
        double e[6], t = i * 0.01;
        e[0] = -50 + fmod(i * 0.5, 100.0);
        e[1] = -50 + (double)((i / 200) % 100);
        e[2] = (tf ? 80 : 640) + 2 * sin(t);
        e[3] = 3 * sin(0.7 * t), e[4] = 3 * cos(0.5 * t), e[5] = 5 * sin(0.3 * t);
        tm_add(p, CANON_FEED, i + 2, e, 3000, 0);
        if (tf) {
            p->cmds[p->count - 1].tcp = 1;
            p->cmds[p->count - 1].tool_len_mm = 60;
        }
    }
}

static void long_program(struct canon_prog *p, int n)
{
    long_program_tcp(p, n, NULL);
}

/* Tool centre point control's cost: load and motion_step per servo period on the raster as
 * platform poses and as the tool tip's (G43.4), in one run. */
static int tcp_figures(void)
{
    double load_s[2], step_ns[2];
    size_t samples[2];
    for (int k = 0; k < 2; k++) {
        struct tm_machine mc;
        if (tm_open(&mc, tm_hexapod_cfg(), &kins_hexapod_ops))
            return 1;
        struct kins_tool_frame tf;
        if (kins_get_tool_frame(mc.kins, &tf) != KINS_OK)
            return 1;
        struct canon_prog p;
        long_program_tcp(&p, 50000, k ? &tf : NULL);
        char err[512];
        double t0 = now_s();
        if (motion_load(mc.m, &p, err, sizeof err)) {
            fprintf(stderr, "bench_motion: %s\n", err);
            return 1;
        }
        load_s[k] = now_s() - t0;
        struct motion_plan_info info;
        motion_plan_info(mc.m, &info);
        samples[k] = info.samples;
        motion_start(mc.m);
        struct motion_out o;
        int steps = 200000;
        t0 = now_s();
        for (int i = 0; i < steps; i++)
            motion_step(mc.m, 0.001, &o);
        step_ns[k] = 1e9 * (now_s() - t0) / steps;
        canon_prog_free(&p);
        tm_close(&mc);
    }
    printf("tool centre point control (G43.4), 50000 short five-axis blocks on the TMU hexapod:\n"
           "  motion_step per servo period: platform poses %.0f ns, tool tip %.0f ns: ratio %.2f\n"
           "  load (plan): platform poses %.3f s (%zu samples), tool tip %.3f s (%zu samples): "
           "ratio %.2f\n", step_ns[0], step_ns[1], step_ns[1] / step_ns[0], load_s[0], samples[0],
           load_s[1], samples[1], load_s[1] / load_s[0]);
    return 0;
}

/* Simulated run time (1 kHz) of the polyline pts[0..n-1] at feed_mm_min on the TMU hexapod,
 * in G61 (tol_mm 0) or G64 P tol_mm; the slowest speed after the first and before the last
 * 5 % of the time into *vmin. -1 on failure. */
static double polyline_time(const double (*pts)[6], int n, double tol_mm, double feed_mm_min,
                            double *vmin)
{
    struct tm_machine mc;
    if (tm_open(&mc, tm_hexapod_cfg(), &kins_hexapod_ops))
        return -1;
    struct canon_prog p;
    canon_prog_init(&p);
    memcpy(p.start, pts[0], sizeof p.start);
    struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 1, .file = "bench.ngc",
                           .value = tol_mm, .ivalue = tol_mm > 0 ? 640 : 610};
    canon_prog_sink(&p, &pm);
    for (int i = 1; i < n; i++)
        tm_add(&p, CANON_FEED, i + 1, pts[i], feed_mm_min, 0);
    char err[512];
    double t = -1;
    if (motion_load(mc.m, &p, err, sizeof err) == MOTION_OK && motion_start(mc.m) == MOTION_OK) {
        struct motion_plan_info info;
        motion_plan_info(mc.m, &info);
        struct motion_out o;
        *vmin = HUGE_VAL;
        for (int k = 0; k < 10000000; k++) {
            motion_step(mc.m, 0.001, &o);
            if (o.state == MOTION_DONE)
                break;
            if (o.time_elapsed_s > 0.05 * info.time_s && o.time_elapsed_s < 0.95 * info.time_s)
                *vmin = fmin(*vmin, o.path_vel);
        }
        t = o.time_elapsed_s;
    }
    canon_prog_free(&p);
    tm_close(&mc);
    return t;
}

/* G64 P0.05 against G61 on three paths: a square wave (90 degree corners), a 72-sided polygon
 * (5 degree corners, as CAM output approximates a circle), a five-axis zigzag whose A B C
 * reverse at every corner. */
static int blend_figures(void)
{
    double sq[21][6], pg[73][6], zz[11][6];
    memset(sq, 0, sizeof sq), memset(pg, 0, sizeof pg), memset(zz, 0, sizeof zz);
    for (int i = 0; i < 21; i++)
        sq[i][0] = -50 + 5 * ((i + 1) / 2), sq[i][1] = (i / 2) % 2 ? 10 : -10, sq[i][2] = 645;
    for (int i = 0; i < 73; i++)
        pg[i][0] = 40 * cos(i * M_PI / 36), pg[i][1] = 40 * sin(i * M_PI / 36), pg[i][2] = 645;
    for (int i = 0; i < 11; i++) {
        zz[i][0] = -50 + 10 * i, zz[i][1] = i % 2 ? 20 : -20, zz[i][2] = 640 + (i % 2) * 5;
        zz[i][3] = i % 2 ? 4 : -4, zz[i][4] = i % 2 ? -3 : 3;
    }
    static const char *names[3] = {"square wave, 5 x 20 mm steps", "72-gon, radius 40 mm",
                                   "five-axis zigzag, A B C reversing"};
    const double (*paths[3])[6] = {sq, pg, zz};
    const int counts[3] = {21, 73, 11};
    const double feeds[2] = {1200, 3000};
    printf("G64 P0.05 corner blending against G61 (TMU hexapod, its own limits, 1 kHz):\n");
    for (int k = 0; k < 3; k++)
        for (int f = 0; f < 2; f++) {
            double v64, v61, t64 = polyline_time(paths[k], counts[k], 0.05, feeds[f], &v64);
            double t61 = polyline_time(paths[k], counts[k], 0, feeds[f], &v61);
            if (t64 < 0 || t61 < 0)
                return -1;
            printf("  %s, F%.0f: G64 %.3f s (slowest %.2f mm/s), G61 %.3f s (slowest %.2f "
                   "mm/s): ratio %.2f\n", names[k], feeds[f], t64, v64, t61, v61, t61 / t64);
        }
    return 0;
}

/* The five-axis zigzag of test_motion_blend.c with G64 P0.05 at 500 mm/s and 100 Hz set
 * points (2000 mm/s^2): measured largest distance of the tool from the blended path against
 * KINEMATIC_TOLERANCE, and its time against G61 measured in the same run; G61's distance
 * from the zigzag (its corners held for a set point), also for every phase of the drive. */
static int chord_figures(void)
{
    static const double zig[6][6] = {
        {-30, -20, 640, -4, 3, -5}, {-15, 20, 645, 4, -3, 5}, {0, -20, 650, -4, 3, -5},
        {15, 20, 645, 4, -3, 5}, {30, -20, 640, -4, 3, -5}, {30, 20, 635, 0, 0, 0},
    };
    struct tm_chord d[2];
    double worst61 = 0;
    for (int g = 0; g < 2; g++) {
        struct canon_prog p;
        canon_prog_init(&p);
        memcpy(p.start, zig[0], sizeof p.start);
        struct canon_cmd pm = {.type = CANON_PATH_MODE, .line = 1, .file = "zig.ngc",
                               .value = g ? 0 : 0.05, .ivalue = g ? 610 : 640};
        canon_prog_sink(&p, &pm);
        for (int i = 1; i < 6; i++)
            tm_add(&p, CANON_FEED, i + 1, zig[i], 30000, 0);
        int st = tm_chord_deviation(&p, 0.01, 0.001, &d[g]);
        for (int phase = 0; g == 1 && !st && phase < 10; phase++) {
            struct tm_chord e;        /* G61: 1 ms servo, the drive in each of its phases */
            st = tm_chord_deviation_at(&p, 0.01, 0.001, phase, 0.001, &e);
            worst61 = fmax(worst61, e.path_mm);
        }
        canon_prog_free(&p);
        if (st)
            return -1;
    }
    printf("five-axis zigzag G64 P0.05, 500 mm/s, 100 Hz set points, 2000 mm/s^2: %.6f mm off the "
           "blended path, KINEMATIC_TOLERANCE 0.001 mm: ratio %.2f; %.3f s, G61 %.3f s: ratio "
           "%.2f\n", d[0].path_mm, d[0].path_mm / 0.001, d[0].time_s, d[1].time_s,
           d[0].time_s / d[1].time_s);
    printf("same in G61, %zu corners held one set-point period: %.6f mm off the zigzag, worst of "
           "the 10 drive phases on a 1 kHz servo %.6f mm, KINEMATIC_TOLERANCE 0.001 mm: ratio "
           "%.2f\n", d[1].stops_held, d[1].path_mm, worst61, worst61 / 0.001);
    return 0;
}

/* Ascending doubles, for percentiles. */
static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* The TMU hexapod, with jerk limits (50,000 mm/s^3 on the path and the legs, 30,000 deg/s^3
 * angular: a 40 ms moving average) or without. */
static struct tk_cfg *density_cfg(int jerk)
{
    struct tk_cfg *c = tm_hexapod_cfg();
    if (!c || !jerk)
        return c;
    tk_setf(c, "TRAJ", "MAX_LINEAR_JERK", 50000);
    tk_setf(c, "TRAJ", "MAX_ANGULAR_JERK", 30000);
    for (int j = 0; j < 6; j++) {
        char sec[24];
        snprintf(sec, sizeof sec, "JOINT_%d", j);
        tk_setf(c, sec, "MAX_JERK", 50000);
    }
    return c;
}

/* The servo step's cost at every segment density: a wandering five-axis path (its direction
 * turns 0.02 rad per mm, A B C in slow waves) cut into blocks of 0.01 to 2 mm (1,600 mm: 160,000
 * blocks of 0.01 mm), G64 P0.01 at 2 m/min, trapezoidal and jerk-limited; every period of the
 * first 20 s timed alone. The mean and percentiles; the worst period includes the preemptions
 * of a shared, non-real-time machine. */
static int density_figures(void)
{
    static const double step_mm[] = { 0.01, 0.05, 0.1, 0.5, 2.0 };
    enum { PERIODS = 20000 };
    static double cost[PERIODS];
    printf("motion_step per 1 ms servo period against segment length (G64 P0.01, F2000, five "
           "axes, %d periods each):\n", PERIODS);
    for (size_t d = 0; d < 2 * sizeof step_mm / sizeof step_mm[0]; d++) {
        int jerk = d >= sizeof step_mm / sizeof step_mm[0];
        double step = step_mm[d % (sizeof step_mm / sizeof step_mm[0])];
        struct tm_machine mc;
        if (tm_open(&mc, density_cfg(jerk), &kins_hexapod_ops))
            return 1;
        struct canon_prog p;
        canon_prog_init(&p);
        double e[6] = { 0, 0, 640, 0, 0, 0 }, ang = 0;
        memcpy(p.start, e, sizeof e);
        struct canon_cmd pm = { .type = CANON_PATH_MODE, .line = 1, .file = "dense.ngc",
                                .value = 0.01 };
        canon_prog_sink(&p, &pm);
        int n = (int)(1600.0 / step);                /* longer than 20 s at 33 mm/s */
        for (int i = 0; i < n; i++) {
            double u = i * step;
            ang += 0.02 * step * (1 + sin(0.05 * u));
            e[0] += step * cos(ang), e[1] += step * sin(ang);
            e[2] = 640 + 2 * sin(0.01 * u);
            e[3] = 3 * sin(0.007 * u), e[4] = 3 * cos(0.005 * u), e[5] = 5 * sin(0.003 * u);
            tm_add(&p, CANON_FEED, i + 2, e, 2000, 0);
        }
        char err[512];
        if (motion_load(mc.m, &p, err, sizeof err) || motion_start(mc.m)) {
            fprintf(stderr, "bench_motion: %s\n", err);
            return 1;
        }
        struct motion_out o;
        double sum = 0;
        for (int k = 0; k < PERIODS; k++) {
            double t0 = now_s();
            motion_step(mc.m, 0.001, &o);
            cost[k] = now_s() - t0;
            sum += cost[k];
        }
        double v = o.path_vel;
        qsort(cost, PERIODS, sizeof cost[0], cmp_double);
        printf("  %-12s %5.2f mm blocks: mean %4.0f ns, 99th percentile %5.0f ns, 99.9th %6.0f "
               "ns, worst %8.0f ns (budget 5000 ns); %4.1f mm/s at 20 s\n",
               jerk ? "jerk-limited" : "trapezoidal", step,
               1e9 * sum / PERIODS, 1e9 * cost[PERIODS - 1 - PERIODS / 100],
               1e9 * cost[PERIODS - 1 - PERIODS / 1000], 1e9 * cost[PERIODS - 1], v);
        canon_prog_free(&p);
        tm_close(&mc);
    }
    return 0;
}

int main(void)
{
    static const double S[6] = {-60, -40, 630, -8, 6, -12}, E[6] = {60, 40, 660, 8, -6, 12};
    struct tm_dev f_on, f_off, s_on, s_off;
    if (deviation(S, E, 0.001, 0.001, &f_on) || deviation(S, E, 0.001, 0, &f_off) ||
        deviation(S, E, 0.01, 0.001, &s_on) || deviation(S, E, 0.01, 0, &s_off)) {
        fprintf(stderr, "bench_motion: cannot build the TMU hexapod (HEXCNC_ROOT?)\n");
        return 1;
    }
    printf("kinematic deviation, five-axis move X-60..60 Y-40..40 Z630..660 A B C +-8..12 deg,\n"
           "500 mm/s programmed, KINEMATIC_TOLERANCE 0.001 mm, forward kinematics of legs\n"
           "interpolated linearly between set points (9 points per interval):\n");
    printf("  1 kHz set points: with bound %.6f mm %.6f deg (%.3f s), without %.6f mm %.6f deg "
           "(%.3f s): ratio %.2f\n", f_on.pos_mm, f_on.ang_deg, f_on.time_s, f_off.pos_mm,
           f_off.ang_deg, f_off.time_s, f_off.pos_mm / f_on.pos_mm);
    printf("  100 Hz set points: with bound %.6f mm %.6f deg (%.3f s), without %.6f mm %.6f deg "
           "(%.3f s): ratio %.2f\n", s_on.pos_mm, s_on.ang_deg, s_on.time_s, s_off.pos_mm,
           s_off.ang_deg, s_off.time_s, s_off.pos_mm / s_on.pos_mm);

    struct tm_machine mc;
    if (tm_open(&mc, tm_hexapod_cfg(), &kins_hexapod_ops))
        return 1;
    int n = 200000;
    struct canon_prog p;
    long_program(&p, n);
    char err[512];
    double t0 = now_s();
    int st = motion_load(mc.m, &p, err, sizeof err);
    double t_load = now_s() - t0;
    if (st) {
        fprintf(stderr, "bench_motion: %s\n", err);
        return 1;
    }
    /* baseline: one inverse kinematics per block end */
    double legs[KINS_MAX_JOINTS], sink = 0;
    t0 = now_s();
    for (size_t i = 0; i < p.count; i++) {
        kins_inverse(mc.kins, p.cmds[i].end, legs);
        sink += legs[0];
    }
    double t_ik_blocks = now_s() - t0;
    struct motion_plan_info info;
    motion_plan_info(mc.m, &info);
    printf("load (plan) of %d short five-axis blocks: %.3f s (%.2f us/block, %zu samples); "
           "one inverse kinematics per block: %.4f s: ratio %.1f\n", n, t_load,
           1e6 * t_load / n, info.samples, t_ik_blocks, t_load / t_ik_blocks);
    motion_start(mc.m);
    struct motion_out o;
    int steps = 200000;
    t0 = now_s();
    for (int k = 0; k < steps; k++)
        motion_step(mc.m, 0.001, &o);
    double t_step = (now_s() - t0) / steps;
    double pose[6] = {10, 5, 645, 1, 2, 3};
    t0 = now_s();
    for (int k = 0; k < steps; k++) {
        pose[0] = 10 + 1e-6 * k;
        kins_inverse(mc.kins, pose, legs);
        sink += legs[1];
    }
    double t_ik = (now_s() - t0) / steps;
    printf("motion_step per servo period: %.0f ns; one inverse kinematics: %.0f ns: ratio %.2f "
           "(%s)\n", 1e9 * t_step, 1e9 * t_ik, t_step / t_ik, sink != 0 ? "ok" : "?");
    canon_prog_free(&p);
    tm_close(&mc);
    return blend_figures() || chord_figures() || tcp_figures() || density_figures() ? 1 : 0;
}
