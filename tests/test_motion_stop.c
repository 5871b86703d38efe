/* test_motion_stop.c: stops where the path changes direction are held for one set-point period. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "tests/test_motion_util.h"

#define DT 0.001                 /* servo period, s */

/* Set-point periods: 100 Hz, 250 Hz (Modbus), 500 Hz (CAN), 1 kHz (the servo period). */
static const double SP_S[4] = {0.01, 0.004, 0.002, 0.001};

/* The trivial machine (1000 mm/s^2, 900 deg/s^2) with drives taking a set point every sp_s;
 * lin_acc_mm_s2 > 0 and tol_mm >= 0 replace the acceleration and KINEMATIC_TOLERANCE. */
static void open_machine(struct tm_machine *mc, double sp_s, double lin_acc_mm_s2, double tol_mm)
{
    struct tk_cfg *c = tm_trivial_cfg();
    tk_setf(c, "TRAJ", "SETPOINT_PERIOD", sp_s * 1e9);
    if (lin_acc_mm_s2 > 0) {
        tk_setf(c, "TRAJ", "MAX_LINEAR_ACCELERATION", lin_acc_mm_s2);
        tk_set(c, "TRAJ", "MAX_ANGULAR_ACCELERATION", "300");
    }
    if (tol_mm >= 0)
        tk_setf(c, "TRAJ", "KINEMATIC_TOLERANCE", tol_mm);
    ck_assert_int_eq(tm_open(mc, c, &kins_trivial_ops), 0);
}

/* A program from the origin through pts[0..n-1]: G0 for the first move when rapid_first,
 * G1 at feed_mm_min otherwise; a dwell of dwell_s (> 0) or an M0 (dwell_s < 0) after the
 * first move. G61 (stated: a program that says nothing runs in G64). */
static void prog(struct canon_prog *p, const double (*pts)[6], int n, double feed_mm_min,
                 int rapid_first, double dwell_s)
{
    canon_prog_init(p);
    p->start_path_mode = 610;
    for (int i = 0; i < n; i++) {
        tm_add(p, i == 0 && rapid_first ? CANON_TRAVERSE : CANON_FEED, 10 + i, pts[i],
               feed_mm_min, 0);
        if (i == 0 && dwell_s > 0)
            tm_add(p, CANON_DWELL, 20, NULL, 0, dwell_s);
        if (i == 0 && dwell_s < 0)
            tm_add(p, CANON_PAUSE, 20, NULL, 0, 0);
    }
    tm_add(p, CANON_PROGRAM_END, 30, NULL, 0, 0);
}

/* Plans p on mc: the planned time and the stops held. */
static double plan(struct tm_machine *mc, const struct canon_prog *p, size_t *held)
{
    char err[512] = "";
    ck_assert_msg(motion_load(mc->m, p, err, sizeof err) == MOTION_OK, "load: %s", err);
    struct motion_plan_info info;
    motion_plan_info(mc->m, &info);
    *held = info.stops_held;
    return info.time_s;
}

static const double LINE1[1][6] = {{100, 0, 0, 0, 0, 0}};
static const double STRAIGHT[2][6] = {{10, 0, 0, 0, 0, 0}, {20, 0, 0, 0, 0, 0}};
static const double CORNER[2][6] = {{10, 0, 0, 0, 0, 0}, {10, 10, 0, 0, 0, 0}};
static const double REVERSE[2][6] = {{10, 0, 0, 0, 0, 0}, {0, 0, 0, 0, 0, 0}};
static const double ROTARY[2][6] = {{0, 0, 0, 10, 0, 0}, {0, 0, 0, 10, 10, 0}};

/* Single moves and collinear G61 lines keep their times at every set-point rate: one 100 mm
 * move at 50 mm/s takes its trapezoid's 2.05 s; X0 -> X10 -> X20 stops at X10 without
 * turning, so nothing is held there and it takes twice one 10 mm move. */
START_TEST(test_straight_unchanged)
{
    for (int k = 0; k < 4; k++) {
        struct tm_machine mc;
        struct canon_prog p;
        size_t held;
        open_machine(&mc, SP_S[k], 0, -1);
        prog(&p, LINE1, 1, 3000, 0, 0);
        ck_assert_double_eq_tol(plan(&mc, &p, &held), 2.05, 1e-9);
        ck_assert_int_eq(held, 0);
        canon_prog_free(&p);
        prog(&p, STRAIGHT, 1, 1200, 0, 0);
        double one = plan(&mc, &p, &held);
        canon_prog_free(&p);
        prog(&p, STRAIGHT, 2, 1200, 0, 0);
        ck_assert_double_eq_tol(plan(&mc, &p, &held), 2 * one, 1e-9);
        ck_assert_int_eq(held, 0);
        canon_prog_free(&p);
        tm_close(&mc);
    }
}
END_TEST

/* Runs the loaded program at override `ovr` (servo period DT); the longest run of
 * consecutive servo periods whose command is exactly at `corner` (X Y Z A B C), and the
 * run time into *t_s. */
static int periods_at(struct motion *m, const double *corner, double ovr, double *t_s)
{
    struct motion_out o;
    int run = 0, best = 0;
    ck_assert_int_eq(motion_set_feed_override(m, ovr), MOTION_OK);
    ck_assert_int_eq(motion_start(m), MOTION_OK);
    for (int k = 0; k < 1000000; k++) {
        motion_step(m, DT, &o);
        double e = 0;
        for (int i = 0; i < 6; i++)
            e = fmax(e, fabs(o.pose[i] - corner[i]));
        run = e <= 1e-12 ? run + 1 : 0;
        best = run > best ? run : best;
        if (o.state != MOTION_RUNNING)
            break;
    }
    ck_assert_int_eq(o.state, MOTION_DONE);
    *t_s = o.time_elapsed_s;
    return best;
}

/* A G61 corner, a reversal, a G0 -> G1 entry and a rotary-only corner each add exactly one
 * set-point period to the plan; the command then rests on the corner for at least T / DT
 * consecutive servo periods, so a drive sampling every T, in any phase, gets a set point on
 * it; the run takes the planned time, and an override does not shorten the rest. */
START_TEST(test_corner_held)
{
    for (int k = 0; k < 4; k++) {
        struct tm_machine mc;
        struct canon_prog p;
        size_t held;
        double t_run;
        int every = (int)lround(SP_S[k] / DT);
        open_machine(&mc, SP_S[k], 0, -1);
        prog(&p, STRAIGHT, 2, 1200, 0, 0);
        double straight = plan(&mc, &p, &held);
        canon_prog_free(&p);
        for (int v = 0; v < 3; v++) {
            prog(&p, v == 0 ? CORNER : REVERSE, 2, 1200, v == 2, 0);
            double t = plan(&mc, &p, &held);
            ck_assert_int_eq(held, 1);
            if (v < 2)
                ck_assert_double_eq_tol(t, straight + SP_S[k], 1e-9);
            int at = periods_at(mc.m, CORNER[0], 1, &t_run);
            ck_assert_msg(at >= every, "%.0f Hz: %d periods on the corner", 1 / SP_S[k], at);
            ck_assert_msg(fabs(t_run - t) <= DT + 1e-9, "ran %.4f s, planned %.4f s", t_run, t);
            if (v == 0) {
                plan(&mc, &p, &held);
                at = periods_at(mc.m, CORNER[0], 1.5, &t_run);
                ck_assert_msg(at >= every, "override 1.5: %d periods on the corner", at);
                printf("corner, %.0f Hz set points: +%.3f s planned, %d servo periods on the "
                       "corner\n", 1 / SP_S[k], t - straight, at);
            }
            canon_prog_free(&p);
        }
        prog(&p, ROTARY, 2, 1200, 0, 0);
        plan(&mc, &p, &held);
        ck_assert_int_eq(held, 1);
        ck_assert_int_ge(periods_at(mc.m, ROTARY[0], 1, &t_run), every);
        canon_prog_free(&p);
        tm_close(&mc);
    }
}
END_TEST

/* A dwell already rests: one shorter than T gets the rest of T, a longer one nothing more; an
 * M0 waits for the operator, so nothing is added there. */
START_TEST(test_dwell_and_pause)
{
    struct tm_machine mc;
    struct canon_prog p;
    size_t held;
    open_machine(&mc, 0.01, 0, -1);
    prog(&p, CORNER, 2, 1200, 0, 0);
    double corner = plan(&mc, &p, &held);
    canon_prog_free(&p);
    prog(&p, CORNER, 2, 1200, 0, 0.004);
    ck_assert_double_eq_tol(plan(&mc, &p, &held), corner, 1e-9);
    ck_assert_int_eq(held, 1);
    canon_prog_free(&p);
    prog(&p, CORNER, 2, 1200, 0, 0.5);
    ck_assert_double_eq_tol(plan(&mc, &p, &held), corner - 0.01 + 0.5, 1e-9);
    ck_assert_int_eq(held, 0);
    canon_prog_free(&p);
    prog(&p, CORNER, 2, 1200, 0, -1);
    ck_assert_double_eq_tol(plan(&mc, &p, &held), corner - 0.01, 1e-9);
    ck_assert_int_eq(held, 0);
    canon_prog_free(&p);
    tm_close(&mc);
}
END_TEST

/* The rule: held when a T^2 / 8 (the cut a stop between set points can make) exceeds a tenth
 * of KINEMATIC_TOLERANCE. At 1 kHz with 1000 mm/s^2: 0.000125 mm, held; with 500 mm/s^2:
 * 0.0000625 mm, not held and the time is that of the straight program. With the bound off
 * (KINEMATIC_TOLERANCE 0) nothing is held. */
START_TEST(test_rule)
{
    struct tm_machine mc;
    struct canon_prog p, s;
    size_t held;
    prog(&p, CORNER, 2, 1200, 0, 0);
    prog(&s, STRAIGHT, 2, 1200, 0, 0);
    open_machine(&mc, 0.001, 500, -1);
    double straight = plan(&mc, &s, &held);
    ck_assert_double_eq_tol(plan(&mc, &p, &held), straight, 1e-9);
    ck_assert_int_eq(held, 0);
    tm_close(&mc);
    open_machine(&mc, 0.01, 0, 0);
    straight = plan(&mc, &s, &held);
    ck_assert_double_eq_tol(plan(&mc, &p, &held), straight, 1e-9);
    ck_assert_int_eq(held, 0);
    tm_close(&mc);
    open_machine(&mc, 0.001, 0, -1);
    plan(&mc, &p, &held);
    ck_assert_int_eq(held, 1);
    tm_close(&mc);
    canon_prog_free(&p);
    canon_prog_free(&s);
}
END_TEST

static Suite *stop_suite(void)
{
    Suite *s = suite_create("motion_stop");
    TCase *tc = tcase_create("stop");
    tcase_set_timeout(tc, 30);
    tcase_add_test(tc, test_straight_unchanged);
    tcase_add_test(tc, test_corner_held);
    tcase_add_test(tc, test_dwell_and_pause);
    tcase_add_test(tc, test_rule);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(stop_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
