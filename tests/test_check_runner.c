/* test_check_runner.c: hexcnc check and hexcnc run (HAL graph, stepgens) agree on the same program. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "check/check.h"
#include "task/runner.h"
#include "tests/test_check_util.h"

/* The check on the library path, the run on the machine's HAL graph: the same motion, so the
 * same machining time, leg ranges and peak leg rates. */
static void compare(const char *ini_rel, const char *prog_rel)
{
    char ini[1024], prog[1024], err[1024];
    tc_path(ini_rel, ini, sizeof ini);
    tc_path(prog_rel, prog, sizeof prog);
    struct check_machine *mc;
    struct check_result c;
    ck_assert_msg(check_machine_open(ini, &mc, err, sizeof err) == 0, "%s", err);
    check_result_init(&c);
    ck_assert_int_eq(check_program(mc, prog, NULL, &c), CHECK_OK);
    check_machine_close(mc);

    struct runner_opts o = { ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    struct runner_summary s;
    ck_assert_msg(runner_create(&o, &r, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_load_program(r, prog, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_start(r, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_run(r, NULL, NULL, NULL, err, sizeof err) == RUNNER_OK, "%s", err);
    runner_summary(r, &s);
    runner_destroy(r);

    ck_assert_msg(fabs(s.machine_time_s - c.machining_time_s) <= 2 * c.servo_period_s,
                  "run %.4f s, check %.4f s", s.machine_time_s, c.machining_time_s);
    ck_assert(fabs(s.planned_time_s - c.planned_time_s) < 1e-9);
    for (int i = 0; i < 6; i++) {
        /* the run's rates are motion's commanded (Jacobian) rates, the check's come from
         * successive set points: equal to within the change of rate over one period */
        ck_assert_msg(fabs(s.peak_rate_mm_s[i] - c.leg[i].peak_vel_mm_s) < 0.01 *
                      c.leg[i].peak_vel_mm_s, "leg %d: run %.4f, check %.4f", i + 1,
                      s.peak_rate_mm_s[i], c.leg[i].peak_vel_mm_s);
        ck_assert(fabs(s.leg_min_mm[i] - c.leg[i].min_mm) < 1e-6);
        ck_assert(fabs(s.leg_max_mm[i] - c.leg[i].max_mm) < 1e-6);
    }
    check_result_free(&c);
}

START_TEST(test_check_agrees_with_run)
{
    compare("configs/sim/tmu-hexapod.ini", "examples/paper/path1_tooltable.ngc");
    compare("examples/paper/experiment/tmu-path2.ini", "examples/paper/experiment/run4_g141.ngc");
}
END_TEST

/* The test case. */
static Suite *suite(void)
{
    Suite *s = suite_create("check_runner");
    TCase *tc = tcase_create("check_runner");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_check_agrees_with_run);
    suite_add_tcase(s, tc);
    return s;
}

/* Runs the suite; non-zero when a test failed. */
int main(void)
{
    SRunner *sr = srunner_create(suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
