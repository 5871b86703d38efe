/* bench_jerk.c: what jerk limiting costs in machining time, and the peak leg speed,
 * acceleration and jerk against their limits, trapezoidal beside jerk-limited, on the paper's
 * programs, the TMU demo, long exact-stop moves and the dense five-axis hour, through `hexcnc check`'s servo pass
 * (the legs differenced every servo period). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bench/bench_dense.h"
#include "check/check.h"
#include "check/check_priv.h"

#define LEG_JERK 50000.0       /* mm/s^3, [JOINT_n] MAX_JERK */
#define LIN_JERK 50000.0       /* mm/s^3, [TRAJ] MAX_LINEAR_JERK */
#define ANG_JERK 30000.0       /* deg/s^3, [TRAJ] MAX_ANGULAR_JERK */
#define FULL_WINDOW (-1.0)     /* (check_one's window: the full one, every acceleration) */

/* One check of prog on ini, trapezoidal (scale 0) or with the jerk limits above times
 * scale, and [TRAJ] JERK_WINDOW window (s; 0: none, the default window; FULL_WINDOW: the
 * full one); the window motion used into *window_s. */
static int check_one(const char *ini, const char *prog, double jerk, double window,
                     struct check_result *r, double *window_s)
{
    char err[1024];
    struct check_machine *mc;
    if (check_machine_open(ini, &mc, err, sizeof err) != CHECK_OK) {
        fprintf(stderr, "bench_jerk: %s\n", err);
        return -1;
    }
    if (jerk) {       /* the same machine with jerk limits: a new motion on the same limits */
        mc->mcfg.max_lin_jerk_mm_s3 = jerk * LIN_JERK;
        mc->mcfg.max_ang_jerk_deg_s3 = jerk * ANG_JERK;
        for (int i = 0; i < mc->mcfg.njoints; i++)
            mc->mcfg.joint[i].max_jerk_mm_s3 = jerk * LEG_JERK;
        mc->mcfg.jerk_window_s = window == FULL_WINDOW ? motion_jerk_full_window_s(&mc->mcfg)
                                                       : window;
        motion_destroy(mc->motion);
        mc->motion = NULL;
        if (motion_create(&mc->mcfg, mc->kins, &mc->motion, err, sizeof err) != MOTION_OK) {
            fprintf(stderr, "bench_jerk: %s\n", err);
            check_machine_close(mc);
            return -1;
        }
    }
    *window_s = motion_jerk_window_s(&mc->mcfg);
    check_result_init(r);
    int st = check_program(mc, prog, NULL, r);
    if (st != CHECK_OK || r->nproblems)
        fprintf(stderr, "bench_jerk: %s: %s\n", prog,
                r->nproblems ? r->problems[0].message : "the check did not run");
    check_machine_close(mc);
    return st == CHECK_OK && !r->nproblems ? 0 : -1;
}

/* The largest ratio to its limit over the legs: speed, acceleration, jerk (to jerk_mm_s3). */
static void peaks(const struct check_result *r, double jerk_mm_s3, double out[3])
{
    out[0] = out[1] = out[2] = 0;
    for (int i = 0; i < r->njoints; i++) {
        const struct check_leg *l = &r->leg[i];
        out[0] = fmax(out[0], l->peak_vel_mm_s / l->limit_vel_mm_s);
        out[1] = fmax(out[1], l->peak_acc_mm_s2 / l->limit_acc_mm_s2);
        out[2] = fmax(out[2], l->peak_jerk_mm_s3 / jerk_mm_s3);
    }
}

/* Both checks of one program (the jerk limits times scale, [TRAJ] JERK_WINDOW window as
 * check_one takes it), one row. */
static int row(const char *label, const char *ini, const char *prog, double scale,
               double window)
{
    struct check_result t, j;
    double w0, w1, pt[3], pj[3];
    if (check_one(ini, prog, 0, 0, &t, &w0) || check_one(ini, prog, scale, window, &j, &w1))
        return -1;
    peaks(&t, scale * LEG_JERK, pt);
    peaks(&j, scale * LEG_JERK, pj);
    printf("%-22s %9.3f s %9.3f s %6.3fx %4.0f ms   %4.2f %4.2f %7.2f   %4.2f %4.2f %5.2f\n",
           label, t.machining_time_s, j.machining_time_s,
           j.machining_time_s / t.machining_time_s, w1 * 1e3, pt[0], pt[1], pt[2], pj[0], pj[1],
           pj[2]);
    check_result_free(&t);
    check_result_free(&j);
    return 0;
}

/* Long exact-stop moves on the TMU, where the legs' acceleration counts most: rapids and
 * feeds of 80 to 160 mm in X Y, Z ramps of 100 mm, turns of A B C in place. */
static const char LONG_MOVES[] =
    "G21 G90 G61\nG0 X0 Y0 Z645\nG0 X80\nG0 Y80\nG0 X-80\nG0 Y-80 Z660\nG1 X80 F6000\n"
    "G1 Y0 Z640\nG0 X0 Y0 Z645\nG1 X60 A5 F3000\nG0 X0 A0\nG0 Z700\nG0 Z600\n"
    "G1 Z700 F6000\nG1 Z600\nG0 Z645\nG0 A10\nG0 A-10\nG0 B10\nG0 C20\nG0 A0 B0 C0\nM2\n";

/* Writes text into a new file named from tmpl (its XXXXXX.ngc replaced); 0 or -1. */
static int write_temp(char *tmpl, const char *text)
{
    int fd = mkstemps(tmpl, 4);
    if (fd < 0)
        return -1;
    FILE *f = fdopen(fd, "w");
    if (!f) {
        close(fd);
        return -1;
    }
    int ok = fputs(text, f) >= 0;
    return fclose(f) == 0 && ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    int blocks = argc > 1 ? atoi(argv[1]) : 240000;
    static const struct { const char *label, *ini, *prog; } progs[] = {
        { "paper run 1 (G141)", "examples/paper/experiment/tmu-path1.ini",
          "examples/paper/experiment/run1_g141.ngc" },
        { "paper run 1 (G142)", "examples/paper/experiment/tmu-path1.ini",
          "examples/paper/experiment/run1_g142.ngc" },
        { "paper run 2 (G141)", "examples/paper/experiment/tmu-path1.ini",
          "examples/paper/experiment/run2_g141.ngc" },
        { "paper run 3 (G141)", "examples/paper/experiment/tmu-path2.ini",
          "examples/paper/experiment/run3_g141.ngc" },
        { "paper run 4 (G141)", "examples/paper/experiment/tmu-path2.ini",
          "examples/paper/experiment/run4_g141.ngc" },
        { "TMU demo", "configs/sim/tmu-hexapod.ini", "configs/sim/tmu-hexapod-demo.ngc" },
    };
    char dense[] = "/tmp/hexcnc-bench-jerk-XXXXXX.ngc";
    char longm[] = "/tmp/hexcnc-bench-long-XXXXXX.ngc";
    if (write_temp(longm, LONG_MOVES) != 0) {
        fprintf(stderr, "bench_jerk: cannot write %s\n", longm);
        return 1;
    }
    int fd = mkstemps(dense, 4);
    if (fd < 0 || close(fd) != 0 || bench_dense_write(dense, blocks) != 0) {
        fprintf(stderr, "bench_jerk: cannot write %s\n", dense);
        unlink(longm);
        return 1;
    }
    printf("jerk limiting: [JOINT_n] MAX_JERK %.0f mm/s^3, [TRAJ] MAX_LINEAR_JERK %.0f mm/s^3, "
           "MAX_ANGULAR_JERK %.0f deg/s^3 on the TMU's limits, the default window (the "
           "path's 2 x 500 / 50000 = 20 ms on the TMU, its legs' acceleration lowered to 500 "
           "mm/s^2, their own 2 x 1000 / 50000 being 40 ms);\n"
           "peaks: the largest over the legs, differenced every servo period, as a ratio to "
           "the leg's limit (jerk: to %.0f mm/s^3 in both columns)\n\n", LEG_JERK, LIN_JERK,
           ANG_JERK, LEG_JERK);
    printf("%-22s %11s %11s %7s %7s   %-16s   %-16s\n", "program", "trapezoidal",
           "jerk-limited", "ratio", "window", "trap. v a j", "jerk-lim. v a j");
    int fail = 0;
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; i++)
        fail |= row(progs[i].label, progs[i].ini, progs[i].prog, 1, 0);
    fail |= row("long G61 moves", "configs/sim/tmu-hexapod.ini", longm, 1, 0);
    char label[64];
    snprintf(label, sizeof label, "dense, %d blocks", blocks);
    fail |= row(label, "configs/sim/tmu-hexapod.ini", dense, 1, 0);
    printf("\nthe same jerk limits with [TRAJ] JERK_WINDOW the full window (every acceleration "
           "in full: on the TMU the legs' 40 ms):\n");
    for (size_t i = 0; i < sizeof progs / sizeof progs[0]; i++)
        fail |= row(progs[i].label, progs[i].ini, progs[i].prog, 1, FULL_WINDOW);
    fail |= row("long G61 moves", "configs/sim/tmu-hexapod.ini", longm, 1, FULL_WINDOW);
    fail |= row(label, "configs/sim/tmu-hexapod.ini", dense, 1, FULL_WINDOW);
    printf("\nthe same with 4 x the jerk limits (the default window, here the full 10 ms; "
           "jerk to 200000 mm/s^3):\n");
    fail |= row("TMU demo", "configs/sim/tmu-hexapod.ini", "configs/sim/tmu-hexapod-demo.ngc",
                4, 0);
    fail |= row(label, "configs/sim/tmu-hexapod.ini", dense, 4, 0);
    printf("\nthe same with 4 x the jerk limits and [TRAJ] JERK_WINDOW = 0.005 (the path's "
           "own window, half the full one: the default shortens no window below 20 ms):\n");
    fail |= row("TMU demo", "configs/sim/tmu-hexapod.ini", "configs/sim/tmu-hexapod-demo.ngc",
                4, 0.005);
    fail |= row(label, "configs/sim/tmu-hexapod.ini", dense, 4, 0.005);
    unlink(dense);
    unlink(longm);
    return fail ? 1 : 0;
}
