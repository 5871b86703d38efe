/* test_motion_hal.c: HAL-graph test: `loadrt motion` in the simulated TMU machine's HAL file. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"
#include "tests/test_hal_util.h"
#include "motion/motion_hal.h"
#include "tests/test_motion_util.h"

#define PERIOD_NS 1000000L

static const double HOME[6] = {0, 0, 645, 0, 0, 0};
static const double GOAL[6] = {20, -10, 650, 2, -2, 5};

/* The machine of configs/sim (INI + HAL file) on the simulated clock, with a program
 * HOME -> GOAL -> HOME handed to motion, started. */
static struct hal *make_machine(struct canon_prog *p)
{
    char ini[1024], halfile[1024];
    tk_tree_path(ini, sizeof ini, "configs/sim/tmu-hexapod.ini");
    tk_tree_path(halfile, sizeof halfile, "configs/sim/tmu-hexapod.hal");
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    hal_set_sim_clock(h, true);
    ck_assert_msg(hal_load_ini(h, ini) == HAL_OK, "%s", hal_last_error(h));
    ck_assert_msg(hal_source(h, halfile) == HAL_OK, "%s", hal_last_error(h));
    ck_assert_ptr_nonnull(motion_hal_get(h));
    canon_prog_init(p);
    memcpy(p->start, HOME, sizeof HOME);
    tm_add(p, CANON_FEED, 3, GOAL, 1200, 0);
    tm_add(p, CANON_FEED, 4, HOME, 1200, 0);
    char err[512] = "";
    ck_assert_msg(motion_hal_load(h, p, err, sizeof err) == MOTION_OK, "%s", err);
    ck_assert_int_eq(hal_start(h), HAL_OK);
    /* the machine comes up in e-stop: a reset edge on the latch enables it */
    ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
    ck_assert(!*(bool *)test_pin(h, "motion.enable", HAL_BIT));
    ck_assert_int_eq(*(int32_t *)test_pin(h, "motion.state", HAL_S32), MOTION_IDLE);
    ck_assert_int_eq(hal_setp(h, "estop-latch.0.reset", "1"), HAL_OK);
    return h;
}

/* Runs up to n periods or until motion.done / motion.fault. */
static int advance(struct hal *h, int n)
{
    bool *done = test_pin(h, "motion.done", HAL_BIT), *fault = test_pin(h, "motion.fault", HAL_BIT);
    int k = 0;
    for (; k < n && !*done && !*fault; k++)
        ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
    return k;
}

/* The program runs through motion -> stepgens -> forward kinematics: done without a fault,
 * the legs' following error within a few steps, the platform back home. */
START_TEST(test_hal_run)
{
    struct canon_prog p;
    struct hal *h = make_machine(&p);
    double *fe[6], worst = 0;
    char name[64];
    for (int i = 0; i < 6; i++) {
        snprintf(name, sizeof name, "motion.ferror-%d", i);
        fe[i] = test_pin(h, name, HAL_FLOAT);
    }
    int32_t *line = test_pin(h, "motion.program-line", HAL_S32);
    double *px = test_pin(h, "motion.pose-cmd-x", HAL_FLOAT), *rem = test_pin(h, "motion.time-remaining", HAL_FLOAT);
    int seen3 = 0, seen_goal = 0;
    for (int k = 0; k < 20000 && !*(bool *)test_pin(h, "motion.done", HAL_BIT); k++) {
        ck_assert(!*(bool *)test_pin(h, "motion.fault", HAL_BIT));
        advance(h, 1);
        seen3 |= *line == 3;
        seen_goal |= fabs(*px - 20) < 1e-3;
        for (int i = 0; i < 6; i++)
            worst = fmax(worst, fabs(*fe[i]));
    }
    ck_assert_msg(*(bool *)test_pin(h, "motion.done", HAL_BIT), "%s", motion_hal_fault(h));
    ck_assert(seen3 && seen_goal);
    ck_assert_int_eq(*line, 4);
    ck_assert_double_eq_tol(*rem, 0, 1e-9);
    ck_assert_msg(worst < 0.01, "following error %.4f mm", worst);
    ck_assert_double_eq_tol(*(double *)test_pin(h, "kins.pose-fb-z", HAL_FLOAT), 645, 0.01);
    ck_assert_double_eq_tol(*(double *)test_pin(h, "kins.pose-fb-x", HAL_FLOAT), 0, 0.01);
    hal_destroy(h);
    canon_prog_free(&p);
}
END_TEST

/* motion.estop mid-move: motion.fault at once, amp-enable drops, the text says why. */
START_TEST(test_hal_estop)
{
    struct canon_prog p;
    struct hal *h = make_machine(&p);
    advance(h, 500);
    double *px = test_pin(h, "motion.pose-cmd-x", HAL_FLOAT);
    ck_assert(*px > 0.1);
    ck_assert_int_eq(hal_setp(h, "motion.estop", "1"), HAL_OK);
    advance(h, 1);
    double held = *px;
    ck_assert(*(bool *)test_pin(h, "motion.fault", HAL_BIT));
    ck_assert(!*(bool *)test_pin(h, "motion.amp-enable", HAL_BIT));
    ck_assert_int_eq(*(int32_t *)test_pin(h, "motion.state", HAL_S32), MOTION_FAULT);
    advance(h, 100);
    ck_assert_double_eq(*px, held);
    ck_assert_msg(strstr(motion_hal_fault(h), "emergency stop"), "%s", motion_hal_fault(h));
    hal_destroy(h);
    canon_prog_free(&p);
}
END_TEST

/* The runner's calls: the last output, the pose, start after a plain motion_load, abort. */
START_TEST(test_hal_runner_calls)
{
    struct canon_prog p;
    struct hal *h = make_machine(&p);
    advance(h, 500);
    struct motion_out o;
    ck_assert_int_eq(motion_hal_out(h, &o), MOTION_OK);
    ck_assert_int_eq(o.state, MOTION_RUNNING);
    double pose[6];
    ck_assert_int_eq(motion_hal_pose(h, pose), MOTION_OK);
    ck_assert_double_eq(pose[0], *(double *)test_pin(h, "motion.pose-cmd-x", HAL_FLOAT));
    ck_assert_int_eq(motion_hal_start(h), MOTION_ERR_STATE);      /* already running */
    ck_assert_int_eq(motion_hal_abort(h), MOTION_OK);
    advance(h, 1000);
    ck_assert_int_eq(*(int32_t *)test_pin(h, "motion.state", HAL_S32), MOTION_IDLE);
    ck_assert_int_eq(motion_hal_start(h), MOTION_ERR_STATE);      /* program dropped */
    /* a new program from where it stopped, loaded on the core, started through HAL */
    canon_prog_free(&p);
    canon_prog_init(&p);
    motion_hal_pose(h, p.start);
    tm_add(&p, CANON_FEED, 7, HOME, 1200, 0);
    char err[256];
    ck_assert_int_eq(motion_load(motion_hal_get(h), &p, err, sizeof err), MOTION_OK);
    ck_assert_int_eq(motion_hal_start(h), MOTION_OK);
    advance(h, 20000);
    ck_assert_int_eq(*(int32_t *)test_pin(h, "motion.state", HAL_S32), MOTION_DONE);
    ck_assert_int_eq(*(int32_t *)test_pin(h, "motion.program-line", HAL_S32), 7);
    hal_destroy(h);
    canon_prog_free(&p);
}
END_TEST

/* Once the servo thread runs, a program planned from somewhere the machine is not is
 * refused at load, naming the leg and the distance (it would jump there in one period); one
 * planned from where the machine is loads. */
START_TEST(test_hal_load_from_elsewhere_refused)
{
    struct canon_prog p;
    struct hal *h = make_machine(&p);
    advance(h, 200000);
    ck_assert_int_eq(*(int32_t *)test_pin(h, "motion.state", HAL_S32), MOTION_DONE);
    canon_prog_free(&p);
    canon_prog_init(&p);
    memcpy(p.start, GOAL, sizeof GOAL);  /* the machine is back at HOME */
    tm_add(&p, CANON_FEED, 9, HOME, 1200, 0);
    char err[512] = "";
    ck_assert_int_eq(motion_hal_load(h, &p, err, sizeof err), MOTION_ERR_STATE);
    ck_assert_msg(strstr(err, "planned from a pose the machine is not at: leg ") &&
                  strstr(err, "mm from the program's start"), "%s", err);
    motion_hal_pose(h, p.start);
    ck_assert_msg(motion_hal_load(h, &p, err, sizeof err) == MOTION_OK, "%s", err);
    hal_destroy(h);
    canon_prog_free(&p);
}
END_TEST

/* motion.pause / motion.resume edges: pauses on the path, resumes, finishes. */
START_TEST(test_hal_pause)
{
    struct canon_prog p;
    struct hal *h = make_machine(&p);
    int32_t *state = test_pin(h, "motion.state", HAL_S32);
    advance(h, 500);
    ck_assert_int_eq(hal_setp(h, "motion.pause", "1"), HAL_OK);
    advance(h, 300);
    ck_assert_int_eq(*state, MOTION_PAUSED);
    double x = *(double *)test_pin(h, "motion.pose-cmd-x", HAL_FLOAT);
    advance(h, 100);
    ck_assert_double_eq(*(double *)test_pin(h, "motion.pose-cmd-x", HAL_FLOAT), x);
    ck_assert_int_eq(hal_setp(h, "motion.resume", "1"), HAL_OK);
    advance(h, 20000);
    ck_assert_int_eq(*state, MOTION_DONE);
    hal_destroy(h);
    canon_prog_free(&p);
}
END_TEST

static Suite *hal_suite(void)
{
    Suite *s = suite_create("motion_hal");
    TCase *tc = tcase_create("hal");
    tcase_add_test(tc, test_hal_run);
    tcase_add_test(tc, test_hal_estop);
    tcase_add_test(tc, test_hal_pause);
    tcase_add_test(tc, test_hal_runner_calls);
    tcase_add_test(tc, test_hal_load_from_elsewhere_refused);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(hal_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
