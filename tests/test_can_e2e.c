/* test_can_e2e.c: the paper's program (10) on configs/can-sim: interp -> motion -> CAN -> drives. */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/drivers/canopen_master.h"
#include "hal/drivers/cia402_hal.h"
#include "hal/hal.h"
#include "tests/test_hal_util.h"
#include "interp/canon.h"
#include "interp/interp.h"
#include "motion/motion_hal.h"

#define PERIOD_NS 1000000L
#define NLEGS 6

/* The machine of configs/can-sim with the paper's program (10) planned and the e-stop
 * latch reset; the servo thread is started on the simulated clock. */
static struct hal *machine_with_program(void)
{
    char ini[512], hal_file[512], prog_path[512];
    test_root_path(ini, sizeof ini, "configs/can-sim/tmu-hexapod-can.ini");
    test_root_path(hal_file, sizeof hal_file, "configs/can-sim/tmu-hexapod-can.hal");
    test_root_path(prog_path, sizeof prog_path, "examples/paper/prog10_g141_d20.ngc");
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    ck_assert_msg(hal_load_ini(h, ini) == HAL_OK, "%s", hal_last_error(h));
    hal_set_sim_clock(h, true);
    ck_assert_msg(hal_source(h, hal_file) == HAL_OK, "%s", hal_last_error(h));
    struct interp *in = interp_create();
    double factor, home[6];
    const char *units = hal_ini_get(h, "RS274NGC", "FEED_UNITS");
    ck_assert_int_eq(interp_feed_units_parse(units, &factor), 0);
    interp_set_feed_factor(in, factor);
    ck_assert_int_eq(sscanf(hal_ini_get(h, "KINS", "HOME"), "%lf %lf %lf %lf %lf %lf", &home[0],
                            &home[1], &home[2], &home[3], &home[4], &home[5]), 6);
    interp_set_start(in, home);
    struct canon_prog prog;
    canon_prog_init(&prog);
    memcpy(prog.start, home, sizeof prog.start);  /* the machine stands at HOME */
    ck_assert_int_eq(interp_run_file(in, prog_path, canon_prog_sink, &prog), INTERP_OK);
    char err[300];
    ck_assert_msg(motion_hal_load(h, &prog, err, sizeof err) == 0, "%s", err);
    canon_prog_free(&prog);
    interp_destroy(in);
    ck_assert_int_eq(hal_setp(h, "estop-latch.0.reset", "1"), HAL_OK);
    ck_assert_int_eq(hal_start(h), HAL_OK);
    return h;
}

/* The program runs to its end on the CAN drives: no fault, following error within
 * MIN_FERROR once motion runs (before, the drives are still reporting in), and the platform ends where the paper's compensated path ends. */
START_TEST(test_paper_program_on_can)
{
    struct hal *h = machine_with_program();
    double worst_ferror = 0;
    char name[64];
    int ms = 0;
    for (; ms < 60000 && test_pin_value(h, "motion.done") == 0.0; ms++) {
        ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
        ck_assert_msg(test_pin_value(h, "motion.fault") == 0.0, "motion fault at %d ms: %s", ms,
                      motion_hal_fault(h));
        ck_assert_msg(test_pin_value(h, "cia402.fault-any") == 0.0, "drive fault at %d ms", ms);
        for (int i = 0; i < NLEGS && test_pin_value(h, "motion.enable") != 0.0; i++) {
            snprintf(name, sizeof name, "motion.ferror-%d", i);
            worst_ferror = fmax(worst_ferror, fabs(test_pin_value(h, name)));
        }
    }
    ck_assert_msg(test_pin_value(h, "motion.done") != 0.0, "program not done after %d ms", ms);
    ck_assert_double_lt(worst_ferror, 0.1);  /* [JOINT_n]MIN_FERROR */
    ck_assert_int_eq(hal_sim_advance(h, 20 * PERIOD_NS), HAL_OK);
    /* docs/compensation.md: the compensated path ends at X59.975641 Y-20 Z630.697565 */
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-x"), 59.975641, 0.002);
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-y"), -20.0, 0.002);
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-z"), 630.697565, 0.002);
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-b"), -4.0, 0.001);
    const struct canopen_master *m = hal_get_object(h, CIA402_OBJ_MASTER);
    ck_assert(canopen_master_all_enabled(m));
    printf("paper program (10) on CAN: %d ms machine time, %u SYNCs, worst following error "
           "%.4f mm\n", ms, m->sync_count, worst_ferror);
    hal_destroy(h);
}
END_TEST

/* A drive fault in the middle of the program: the latch trips, motion stops with a fault,
 * every other drive is quick-stopped and holds, and the message names the drive. */
START_TEST(test_drive_fault_stops_machine)
{
    struct hal *h = machine_with_program();
    ck_assert_int_eq(hal_sim_advance(h, 1500 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "motion.done") == 0.0);
    ck_assert(test_pin_value(h, "motion.path-vel") > 1.0);  /* moving */
    ck_assert_int_eq(hal_setp(h, "cia402-sim.2.inject-fault", "1"), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 10 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "cia402.2.fault") != 0.0);
    ck_assert(test_pin_value(h, "estop-latch.0.ok-out") == 0.0);
    ck_assert(test_pin_value(h, "motion.fault") != 0.0);
    const struct canopen_master *m = hal_get_object(h, CIA402_OBJ_MASTER);
    ck_assert_ptr_nonnull(strstr(m->node[2].message, "CAN node 3 (joint 2)"));
    ck_assert_ptr_nonnull(strstr(m->node[2].message, "error code 0x2310"));
    /* the same words reach the shell through the runtime's message queue, once */
    struct hal_msg msg;
    int faults = 0;
    while (hal_msg_take(h, &msg)) {
        if (msg.severity != HAL_MSG_FAULT)
            continue;
        faults++;
        ck_assert_str_eq(msg.source, "cia402.2");
        ck_assert_ptr_nonnull(strstr(msg.text, "CAN node 3 (joint 2)"));
    }
    ck_assert_int_eq(faults, 1);
    double held[NLEGS];
    for (int i = 0; i < NLEGS; i++)
        held[i] = m->node[i].position_fb_mm;
    ck_assert_int_eq(hal_sim_advance(h, 20 * PERIOD_NS), HAL_OK);
    for (int i = 0; i < NLEGS; i++)  /* standing still since the stop */
        ck_assert_double_eq(m->node[i].position_fb_mm, held[i]);
    for (int i = 0; i < NLEGS; i++)  /* the others quick-stopped and holding; one in Fault */
        ck_assert_int_eq(m->node[i].state, i == 2 ? CIA402_FAULT : CIA402_QUICK_STOP);
    /* and still so 200 ms later: quick stop option 6 keeps them under power (the CiA 402
     * default would have dropped them to Switch on disabled after the ramp) */
    ck_assert_int_eq(hal_sim_advance(h, 200 * PERIOD_NS), HAL_OK);
    for (int i = 0; i < NLEGS; i++) {
        ck_assert_int_eq(m->node[i].state, i == 2 ? CIA402_FAULT : CIA402_QUICK_STOP);
        ck_assert_uint_eq(m->node[i].controlword, i == 2 ? CIA402_CW_DISABLE_VOLTAGE
                                                         : CIA402_CW_QUICK_STOP);
        ck_assert_double_eq(m->node[i].position_fb_mm, held[i]);
    }
    /* reset: drives first, then the latch; all six come back to Operation enabled */
    ck_assert_int_eq(hal_sets(h, "drive-reset", "1"), HAL_OK);
    ck_assert_int_eq(hal_setp(h, "estop-latch.0.reset", "0"), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 20 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "cia402.fault-any") == 0.0);
    ck_assert_int_eq(hal_setp(h, "estop-latch.0.reset", "1"), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 30 * PERIOD_NS), HAL_OK);
    ck_assert(canopen_master_all_enabled(m));
    hal_destroy(h);
}
END_TEST

/* Position feedback of one drive stops in the middle of the program (its heartbeat goes on):
 * the first fault is the lost feedback, naming the node and the time, not a following
 * error; the machine stops. */
START_TEST(test_feedback_loss_named)
{
    struct hal *h = machine_with_program();
    ck_assert_int_eq(hal_sim_advance(h, 1500 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "motion.path-vel") > 1.0);  /* moving */
    struct hal_msg msg;
    while (hal_msg_take(h, &msg))
        ;
    ck_assert_int_eq(hal_setp(h, "cia402-sim.2.tpdo-stop", "1"), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, 20 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "motion.fault") != 0.0);
    bool first = true;
    while (hal_msg_take(h, &msg)) {
        if (msg.severity != HAL_MSG_FAULT || !first)
            continue;
        first = false;
        ck_assert_str_eq(msg.source, "cia402.2");
        ck_assert_msg(strstr(msg.text, "no position feedback (TPDO1) from node 3 for 7 ms") !=
                      NULL, "%s", msg.text);
    }
    ck_assert(!first);
    ck_assert_msg(strstr(motion_hal_fault(h), "following error") == NULL, "%s",
                  motion_hal_fault(h));
    hal_destroy(h);
}
END_TEST

/* The suite. */
static Suite *can_e2e_suite(void)
{
    Suite *s = suite_create("can_e2e");
    TCase *tc = tcase_create("machine");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_paper_program_on_can);
    tcase_add_test(tc, test_drive_fault_stops_machine);
    tcase_add_test(tc, test_feedback_loss_named);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(can_e2e_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
