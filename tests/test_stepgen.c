/* test_stepgen.c: the step generator's controller: quantisation, limits, tracking. */
#include <check.h>
#include <math.h>
#include <stdlib.h>

#include "sim/stepgen.h"

#define DT_S 0.001   /* 1 kHz servo period */

/* Starts a channel at pos_mm and enables it (the first enabled period primes it). */
static void start_at(struct stepgen_state *s, const struct stepgen_limits *lim, double pos_mm)
{
    stepgen_state_init(s, 0.0);
    stepgen_step(s, lim, pos_mm, true, DT_S);
}

/* Whole steps: feedback is the nearest step, never more than half a step off. */
START_TEST(test_quantisation)
{
    struct stepgen_limits lim = { 200.0, 50.0, 1000.0 };  /* 5 um steps */
    struct stepgen_state s;
    start_at(&s, &lim, 0.0);
    const double targets[] = { 1.2345, -0.0012, 0.0026, 3.0 };
    for (size_t t = 0; t < sizeof targets / sizeof targets[0]; t++) {
        for (int i = 0; i < 2000; i++)
            stepgen_step(&s, &lim, targets[t], true, DT_S);
        ck_assert_int_eq(s.counts, llround(targets[t] * 200.0));
        ck_assert(fabs((double)s.counts / 200.0 - targets[t]) <= 0.5 / 200.0 + 1e-12);
    }
}
END_TEST

/* A 10 mm step command: the motor accelerates, cruises at maxvel, brakes, and arrives
 * without overshoot, in the time of the analytic trapezoid (within a few periods). */
START_TEST(test_step_response_limits)
{
    struct stepgen_limits lim = { 1000.0, 5.0, 100.0 };
    struct stepgen_state s;
    start_at(&s, &lim, 0.0);
    double v_prev = 0.0, peak_v = 0.0, max_pos = 0.0;
    int arrived = -1;
    for (int i = 0; i < 4000; i++) {
        stepgen_step(&s, &lim, 10.0, true, DT_S);
        ck_assert(fabs(s.vel_mm_s) <= 5.0 + 1e-9);
        ck_assert(fabs(s.vel_mm_s - v_prev) <= 100.0 * DT_S + 1e-9);
        v_prev = s.vel_mm_s;
        peak_v = fmax(peak_v, s.vel_mm_s);
        max_pos = fmax(max_pos, s.pos_mm);
        if (arrived < 0 && s.counts == 10000)
            arrived = i + 1;
    }
    /* trapezoid: 0.05 s up, 0.05 s down (0.125 mm each), (10 - 0.25) / 5 = 1.95 s cruise */
    double t_analytic_s = 0.05 + 1.95 + 0.05;
    ck_assert_int_ge(arrived, 0);
    ck_assert_msg(fabs(arrived * DT_S - t_analytic_s) <= 5 * DT_S,
                  "arrived after %d periods, analytic %.3f s", arrived, t_analytic_s);
    ck_assert(peak_v > 5.0 - 1e-9);
    ck_assert(max_pos <= 10.0 + 0.5 / 1000.0);
    ck_assert_int_eq(s.counts, 10000);
    ck_assert(fabs(s.vel_mm_s) < 1e-9);
}
END_TEST

/* A command within the limits (a smooth ramp, as the planner makes) is tracked to the
 * nearest step at every period: following error at most half a step. */
START_TEST(test_tracks_planned_motion)
{
    struct stepgen_limits lim = { 400.0, 20.0, 500.0 };
    struct stepgen_state s;
    double p0 = 612.5;   /* a leg's working length, mm */
    start_at(&s, &lim, p0);
    double worst = 0.0;
    for (int i = 0; i <= 3000; i++) {
        /* S-shaped move of 8 mm over 3 s: peak 5.3 mm/s, peak accel 5.6 mm/s^2 */
        double t = i * DT_S, cmd = p0 + 8.0 * (t / 3.0 - sin(2.0 * M_PI * t / 3.0) / (2 * M_PI));
        stepgen_step(&s, &lim, cmd, true, DT_S);
        worst = fmax(worst, fabs(cmd - (double)s.counts / lim.scale));
    }
    ck_assert_msg(worst <= 0.5 / 400.0 + 1e-9, "worst following error %g mm", worst);
    ck_assert_int_eq(s.counts, llround((p0 + 8.0) * 400.0));
}
END_TEST

/* Negative scale reverses the count direction; feedback in mm keeps its sign. */
START_TEST(test_negative_scale)
{
    struct stepgen_limits lim = { -100.0, 10.0, 100.0 };
    struct stepgen_state s;
    start_at(&s, &lim, 0.0);
    for (int i = 0; i < 3000; i++)
        stepgen_step(&s, &lim, 2.0, true, DT_S);
    ck_assert_int_eq(s.counts, -200);
    ck_assert(fabs((double)s.counts / lim.scale - 2.0) < 1e-12);
}
END_TEST

/* Disabled: no steps, the motor stands; on enable it catches up within its limits. */
START_TEST(test_enable)
{
    struct stepgen_limits lim = { 100.0, 10.0, 100.0 };
    struct stepgen_state s;
    start_at(&s, &lim, 1.0);
    ck_assert_int_eq(s.counts, 100);
    for (int i = 0; i < 500; i++)
        stepgen_step(&s, &lim, 3.0, false, DT_S);
    ck_assert_int_eq(s.counts, 100);
    ck_assert(s.vel_mm_s == 0.0);
    stepgen_step(&s, &lim, 3.0, true, DT_S);
    ck_assert(s.vel_mm_s <= 100.0 * DT_S + 1e-12);
    for (int i = 0; i < 2000; i++)
        stepgen_step(&s, &lim, 3.0, true, DT_S);
    ck_assert_int_eq(s.counts, 300);
}
END_TEST

/* Before its first enabled period the simulated motor sits at the command (homed). */
START_TEST(test_powers_up_at_command)
{
    struct stepgen_limits lim = { 100.0, 10.0, 100.0 };
    struct stepgen_state s;
    stepgen_state_init(&s, 0.0);
    ck_assert_int_eq(stepgen_step(&s, &lim, 650.004, false, DT_S), 65000);
    ck_assert_int_eq(stepgen_step(&s, &lim, 650.0, true, DT_S), 65000);
    ck_assert(s.vel_mm_s == 0.0);
}
END_TEST

/* Velocity mode: the rate ramps to the command at maxaccel, holds, and counts whole steps
 * of the integrated position; maxvel caps the command. */
START_TEST(test_velocity_mode)
{
    struct stepgen_limits lim = { 100.0, 10.0, 100.0 };
    struct stepgen_state s;
    stepgen_state_init(&s, 0.0);
    for (int i = 0; i < 50; i++)   /* 0.05 s: 100 mm/s^2 gives 5 mm/s */
        stepgen_step_velocity(&s, &lim, 8.0, true, DT_S);
    ck_assert(fabs(s.vel_mm_s - 5.0) < 1e-9);
    for (int i = 0; i < 1000; i++)
        stepgen_step_velocity(&s, &lim, 8.0, true, DT_S);
    ck_assert(fabs(s.vel_mm_s - 8.0) < 1e-9);
    /* 0.08 s ramp (0.32 mm) then 0.97 s at 8 mm/s (7.76 mm): 8.08 mm, to a period's
     * rounding of the ramp */
    ck_assert_msg(fabs(s.pos_mm - 8.08) < 0.01, "%.4f mm", s.pos_mm);
    ck_assert_int_eq(s.counts, llround(s.pos_mm * 100.0));
    for (int i = 0; i < 100; i++)
        stepgen_step_velocity(&s, &lim, 50.0, true, DT_S);
    ck_assert(fabs(s.vel_mm_s - 10.0) < 1e-9);   /* capped at maxvel */
    int64_t held = s.counts;
    stepgen_step_velocity(&s, &lim, 5.0, false, DT_S);
    ck_assert(s.vel_mm_s == 0.0 && s.counts == held);  /* disabled: no steps */
}
END_TEST

static Suite *stepgen_suite(void)
{
    Suite *s = suite_create("stepgen");
    TCase *tc = tcase_create("core");
    tcase_add_test(tc, test_quantisation);
    tcase_add_test(tc, test_step_response_limits);
    tcase_add_test(tc, test_tracks_planned_motion);
    tcase_add_test(tc, test_negative_scale);
    tcase_add_test(tc, test_enable);
    tcase_add_test(tc, test_powers_up_at_command);
    tcase_add_test(tc, test_velocity_mode);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(stepgen_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
