/* test_stepgen_hal.c: HAL-graph test: commands streamed through `loadrt stepgen` on a thread. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"
#include "tests/test_hal_util.h"
#include "sim/stepgen.h"

#define PERIOD_NS 1000000L

/* Runs HAL command lines, failing the test with the runtime's message on an error. */
static void cmd(struct hal *h, const char *line)
{
    int st = hal_cmd(h, line, "test", 0, stdout);
    ck_assert_msg(st == HAL_OK, "'%s': %s", line, hal_last_error(h));
}

/* Two channels on a 1 kHz simulated thread; channel 0 at 400 steps/mm, 1 at 1000. */
static struct hal *make_graph(void)
{
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    hal_set_sim_clock(h, true);
    cmd(h, "newthread servo-thread 1000000");
    cmd(h, "loadrt stepgen count=2");
    cmd(h, "setp stepgen.0.position-scale 400");
    cmd(h, "setp stepgen.0.maxvel 50");
    cmd(h, "setp stepgen.0.maxaccel 500");
    cmd(h, "setp stepgen.1.position-scale 1000");
    cmd(h, "setp stepgen.1.maxvel 5");
    cmd(h, "setp stepgen.1.maxaccel 100");
    cmd(h, "net cmd0 => stepgen.0.position-cmd");
    cmd(h, "net cmd1 => stepgen.1.position-cmd");
    cmd(h, "net en => stepgen.0.enable stepgen.1.enable");
    cmd(h, "addf stepgen.update servo-thread");
    cmd(h, "sets en 1");
    ck_assert_int_eq(hal_start(h), HAL_OK);
    /* One period at 0: the channels power up where the command is (homed), then follow. */
    ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
    return h;
}

/* The HAL component gives what the pure controller gives, period by period, and its
 * feedback is whole steps: counts / scale. */
START_TEST(test_hal_matches_core)
{
    struct hal *h = make_graph();
    double *fb0 = test_pin(h, "stepgen.0.position-fb", HAL_FLOAT);
    int32_t *counts0 = test_pin(h, "stepgen.0.counts", HAL_S32);
    double *vel0 = test_pin(h, "stepgen.0.velocity-fb", HAL_FLOAT);
    struct stepgen_limits lim = { 400.0, 50.0, 500.0 };
    struct stepgen_state ref;
    stepgen_state_init(&ref, 0.0);
    stepgen_step(&ref, &lim, 0.0, true, 1e-3);
    char line[64];
    for (int i = 0; i < 1500; i++) {
        double c = 20.0 * sin(i * 0.002) + (i > 700 ? 3.0 : 0.0);  /* a jump at 0.7 s */
        snprintf(line, sizeof line, "sets cmd0 %.17g", c);
        cmd(h, line);
        ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
        stepgen_step(&ref, &lim, c, true, 1e-3);
        ck_assert_int_eq(*counts0, (int32_t)ref.counts);
        ck_assert(*fb0 == (double)*counts0 / 400.0);
        ck_assert(fabs(*vel0) <= 50.0 + 1e-9);
    }
    hal_destroy(h);
}
END_TEST

/* A 10 mm step on channel 1 (5 mm/s, 100 mm/s^2): the analytic trapezoid, 2.05 s; the
 * velocity never exceeds maxvel and changes by at most maxaccel * period. */
START_TEST(test_hal_step_limits)
{
    struct hal *h = make_graph();
    double *vel1 = test_pin(h, "stepgen.1.velocity-fb", HAL_FLOAT);
    int32_t *counts1 = test_pin(h, "stepgen.1.counts", HAL_S32);
    cmd(h, "sets cmd1 10");
    double v_prev = 0.0;
    int arrived = -1;
    for (int i = 0; i < 3000; i++) {
        ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
        ck_assert(*vel1 <= 5.0 + 1e-9);
        ck_assert(fabs(*vel1 - v_prev) <= 100.0 * 1e-3 + 1e-9);
        v_prev = *vel1;
        ck_assert_int_le(*counts1, 10000);
        if (arrived < 0 && *counts1 == 10000)
            arrived = i + 1;
    }
    ck_assert_msg(abs(arrived - 2050) <= 5, "arrived after %d periods, analytic 2050", arrived);
    hal_destroy(h);
}
END_TEST

/* Disabled channels make no steps; a bad loadrt argument is refused with a message. */
START_TEST(test_hal_enable_and_args)
{
    struct hal *h = make_graph();
    int32_t *counts0 = test_pin(h, "stepgen.0.counts", HAL_S32);
    cmd(h, "sets cmd0 1");
    ck_assert_int_eq(hal_sim_advance(h, 500 * PERIOD_NS), HAL_OK);
    ck_assert_int_eq(*counts0, 400);
    cmd(h, "sets en 0");
    cmd(h, "sets cmd0 2");
    ck_assert_int_eq(hal_sim_advance(h, 500 * PERIOD_NS), HAL_OK);
    ck_assert_int_eq(*counts0, 400);
    cmd(h, "sets en 1");
    ck_assert_int_eq(hal_sim_advance(h, 500 * PERIOD_NS), HAL_OK);
    ck_assert_int_eq(*counts0, 800);
    hal_destroy(h);

    h = hal_create();
    ck_assert_int_ne(hal_cmd(h, "loadrt stepgen count=99", "x.hal", 3, stdout), HAL_OK);
    ck_assert_ptr_nonnull(strstr(hal_last_error(h), "count"));
    hal_destroy(h);
}
END_TEST

/* `ctrl_type=p,v`: channel 1 follows velocity-cmd; channel 0 stays in position mode. */
START_TEST(test_hal_ctrl_type)
{
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    hal_set_sim_clock(h, true);
    cmd(h, "newthread servo-thread 1000000");
    cmd(h, "loadrt stepgen ctrl_type=p,v");
    cmd(h, "setp stepgen.1.position-scale 1000");
    cmd(h, "setp stepgen.1.maxvel 5");
    cmd(h, "setp stepgen.1.maxaccel 100");
    cmd(h, "setp stepgen.1.enable 1");
    cmd(h, "setp stepgen.1.velocity-cmd 2");
    cmd(h, "setp stepgen.1.position-cmd 99");  /* ignored in velocity mode */
    cmd(h, "addf stepgen.update servo-thread");
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 1000 * PERIOD_NS), HAL_OK);
    /* 0.02 s ramp to 2 mm/s (0.02 mm), then 0.98 s at 2 mm/s (1.96 mm): 1.98 mm */
    int32_t *counts1 = test_pin(h, "stepgen.1.counts", HAL_S32);
    ck_assert_msg(abs(*counts1 - 1980) <= 2, "counts %d, expected about 1980", *counts1);
    ck_assert(fabs(*(double *)test_pin(h, "stepgen.1.velocity-fb", HAL_FLOAT) - 2.0) < 1e-9);
    hal_destroy(h);
    h = hal_create();
    ck_assert_int_ne(hal_cmd(h, "loadrt stepgen ctrl_type=p,x", "y.hal", 1, stdout), HAL_OK);
    ck_assert_ptr_nonnull(strstr(hal_last_error(h), "ctrl_type"));
    hal_destroy(h);
}
END_TEST

static Suite *stepgen_hal_suite(void)
{
    Suite *s = suite_create("stepgen-hal");
    TCase *tc = tcase_create("graph");
    tcase_add_test(tc, test_hal_matches_core);
    tcase_add_test(tc, test_hal_step_limits);
    tcase_add_test(tc, test_hal_enable_and_args);
    tcase_add_test(tc, test_hal_ctrl_type);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(stepgen_hal_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
