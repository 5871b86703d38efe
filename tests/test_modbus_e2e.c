/* test_modbus_e2e.c: the paper's program (10) on configs/modbus-sim: interp -> motion -> Modbus TCP -> six simulated drives. */
#include <check.h>
#include <math.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "hal/hal.h"
#include "tests/test_hal_util.h"
#include "interp/canon.h"
#include "interp/interp.h"
#include "motion/motion_hal.h"
#include "sim/modbus_sim.h"
#include "tests/test_net_util.h"

#define PERIOD_NS 1000000L
#define NLEGS 6

/* The configuration's INI with a free port per drive appended ([MODBUS_DRIVE_n] PORT wins
 * over [MODBUS] BASE_PORT), so parallel test runs never share the example's ports. */
static void ini_with_free_ports(const char *ini, char *out, size_t len)
{
    snprintf(out, len, "/tmp/test_modbus_e2e_XXXXXX");
    int fd = mkstemp(out);
    ck_assert_int_ge(fd, 0);
    FILE *dst = fdopen(fd, "w"), *src = fopen(ini, "r");
    ck_assert_ptr_nonnull(src);
    char line[512];
    while (fgets(line, sizeof line, src))
        fputs(line, dst);
    fclose(src);
    int ports[NLEGS];
    ck_assert_int_eq(tn_free_ports(ports, NLEGS), 0);
    for (int i = 0; i < NLEGS; i++)
        fprintf(dst, "\n[MODBUS_DRIVE_%d]\nPORT = %d\n", i, ports[i]);
    fclose(dst);
}

/* The machine of configs/modbus-sim with the paper's program (10) planned and the e-stop
 * latch reset; the servo thread is started on the simulated clock. */
static struct hal *machine_with_program(void)
{
    char ini0[512], ini[64], hal_file[512], prog_path[512];
    test_root_path(ini0, sizeof ini0, "configs/modbus-sim/tmu-hexapod-modbus.ini");
    test_root_path(hal_file, sizeof hal_file, "configs/modbus-sim/tmu-hexapod-modbus.hal");
    test_root_path(prog_path, sizeof prog_path, "examples/paper/prog10_g141_d20.ngc");
    ini_with_free_ports(ini0, ini, sizeof ini);
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    ck_assert_msg(hal_load_ini(h, ini) == HAL_OK, "%s", hal_last_error(h));
    unlink(ini);
    hal_set_sim_clock(h, true);
    ck_assert_msg(hal_source(h, hal_file) == HAL_OK, "%s", hal_last_error(h));
    struct interp *in = interp_create();
    double factor, home[6];
    ck_assert_int_eq(interp_feed_units_parse(hal_ini_get(h, "RS274NGC", "FEED_UNITS"), &factor), 0);
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
    ck_assert_int_eq(hal_start(h), HAL_OK);
    ck_assert_int_eq(hal_sets(h, "estop-reset", "1"), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
    ck_assert_int_eq(hal_sets(h, "estop-reset", "0"), HAL_OK);
    return h;
}

/* The program runs to its end over Modbus: no fault, small following error, one exchange
 * per drive every 4 ms, and the platform ends where the paper's compensated path ends. */
START_TEST(test_paper_program_on_modbus)
{
    struct hal *h = machine_with_program();
    struct modbus_sim *s = hal_get_object(h, "modbus-sim");
    ck_assert_ptr_nonnull(s);
    struct modbus_sim_drive_state st0;
    modbus_sim_state(s, 0, &st0);
    double worst_ferror = 0;
    char name[64];
    int ms = 0;
    for (; ms < 60000 && test_pin_value(h, "motion.done") == 0.0; ms++) {
        ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
        ck_assert_msg(test_pin_value(h, "motion.fault") == 0.0, "motion fault at %d ms: %s", ms,
                      motion_hal_fault(h));
        ck_assert_msg(test_pin_value(h, "modbus.fault-any") == 0.0, "drive fault at %d ms", ms);
        for (int i = 0; i < NLEGS; i++) {
            snprintf(name, sizeof name, "motion.ferror-%d", i);
            worst_ferror = fmax(worst_ferror, fabs(test_pin_value(h, name)));
        }
    }
    ck_assert_msg(test_pin_value(h, "motion.done") != 0.0, "program not done after %d ms", ms);
    /* One 4 ms set point and the 1 ms drive lag at up to 21.6 mm/s of leg rate: 0.11 mm,
     * plus the lockstep phase; a lost or unscaled drive would be far beyond. */
    ck_assert_double_lt(worst_ferror, 0.2);
    ck_assert_int_eq(hal_sim_advance(h, 40 * PERIOD_NS), HAL_OK);
    /* docs/compensation.md: the compensated path ends at X59.975641 Y-20 Z630.697565 */
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-x"), 59.975641, 0.002);
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-y"), -20.0, 0.002);
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-z"), 630.697565, 0.002);
    ck_assert_double_eq_tol(test_pin_value(h, "kins.pose-fb-b"), -4.0, 0.001);
    struct modbus_sim_drive_state st;
    modbus_sim_state(s, 0, &st);
    uint32_t exchanges = st.requests - st0.requests;
    /* Calls 1 .. ms + 40 of modbus.update since st0; every 4th exchanges (call 0 did). */
    ck_assert_uint_eq(exchanges, (uint32_t)(ms + 40) / 4);
    printf("paper program (10) on Modbus TCP: %d ms machine time, %u exchanges per drive, "
           "worst following error %.4f mm, last round trip %.0f us\n", ms, exchanges,
           worst_ferror, test_pin_value(h, "modbus.0.rtt-us"));
    hal_destroy(h);
}
END_TEST

/* A drive that stops answering in the middle of the program: the latch trips, motion stops
 * with a fault, the other drives stay enabled and hold; one reset reconnects it. */
START_TEST(test_drive_timeout_stops_machine)
{
    struct hal *h = machine_with_program();
    struct modbus_sim *s = hal_get_object(h, "modbus-sim");
    ck_assert_int_eq(hal_sim_advance(h, 1500 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "motion.done") == 0.0);
    ck_assert(test_pin_value(h, "motion.path-vel") > 1.0);  /* moving */
    ck_assert_int_eq(modbus_sim_inject(s, 2, MODBUS_SIM_FAULT_NO_ANSWER, 0), MODBUS_SIM_OK);
    ck_assert_int_eq(hal_sim_advance(h, 10 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "modbus.2.fault") != 0.0);
    ck_assert(test_pin_value(h, "modbus.1.fault") == 0.0);
    ck_assert(test_pin_value(h, "estop-latch.0.ok-out") == 0.0);
    ck_assert(test_pin_value(h, "motion.fault") != 0.0);
    ck_assert(test_pin_value(h, "motion.amp-enable") == 0.0);
    ck_assert_int_eq(hal_sim_advance(h, 10 * PERIOD_NS), HAL_OK);
    /* the healthy drives keep ENABLE (modbus.N.hold from the latch's fault-out) with their
     * targets frozen: they hold the platform under power */
    struct modbus_sim_drive_state held[NLEGS];
    for (int i = 0; i < NLEGS; i++)
        modbus_sim_state(s, i, &held[i]);
    ck_assert_int_eq(hal_sim_advance(h, 100 * PERIOD_NS), HAL_OK);
    for (int i = 0; i < NLEGS; i++) {
        struct modbus_sim_drive_state st;
        modbus_sim_state(s, i, &st);
        if (i == 2)
            continue;
        ck_assert_uint_eq(st.control_word & MODBUS_CTRL_ENABLE, MODBUS_CTRL_ENABLE);
        ck_assert_int_eq(st.target_counts, held[i].target_counts);
        ck_assert(st.requests > held[i].requests);          /* still exchanging */
        ck_assert_double_eq_tol(st.actual_counts, (double)st.target_counts, 1.0);
    }
    modbus_sim_inject(s, 2, MODBUS_SIM_FAULT_NONE, 0);
    ck_assert_int_eq(hal_sets(h, "estop-reset", "1"), HAL_OK);
    ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "estop-latch.0.ok-out") != 0.0);
    ck_assert_int_eq(hal_sim_advance(h, 10 * PERIOD_NS), HAL_OK);
    ck_assert(test_pin_value(h, "modbus.fault-any") == 0.0);
    ck_assert(test_pin_value(h, "modbus.2.connected") != 0.0);
    ck_assert_uint_eq(test_pin_value(h, "modbus.2.errors"), 1);
    hal_destroy(h);
}
END_TEST

static Suite *modbus_e2e_suite(void)
{
    Suite *s = suite_create("modbus_e2e");
    TCase *tc = tcase_create("machine");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_paper_program_on_modbus);
    tcase_add_test(tc, test_drive_timeout_stops_machine);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(modbus_e2e_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
