/* test_modbus_faults.c: Modbus drive faults (timeout, exception, disconnect, delay, drive fault), reset and reconnection, RTU over a pty. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hal/drivers/modbus_link.h"
#include "sim/modbus_sim.h"

/* A simulator of n drives on ephemeral loopback ports, lockstep 1 ms per cycle. */
static struct modbus_sim *sim_n(int n)
{
    struct modbus_sim_opts o;
    modbus_sim_opts_default(&o);
    o.step_ns = 1000000;
    o.tau_s = 0.0;
    struct modbus_sim *s;
    ck_assert_int_eq(modbus_sim_create(&s, n, &o), MODBUS_SIM_OK);
    ck_assert_int_eq(modbus_sim_start_tcp(s, "127.0.0.1", 0), MODBUS_SIM_OK);
    return s;
}

/* A link to drive i with the given timeout, not started (cycles run by the test). These are
 * wall-clock timeouts: 200 ms, so a loaded machine never times out a healthy drive. */
static void link_to(struct modbus_link *l, struct modbus_sim *s, int i, long timeout_us)
{
    struct modbus_drive_cfg c;
    modbus_drive_cfg_default(&c, i);
    c.port = modbus_sim_port(s, i);
    c.timeout_us = timeout_us;
    c.counts_per_mm = 1000.0;
    ck_assert_int_eq(modbus_link_init(l, &c), MODBUS_DRIVE_OK);
    modbus_link_command(l, 0.0, false);
}

/* The expected "modbus drive N (127.0.0.1:PORT): " prefix. */
static void expect_msg(struct modbus_link *l, struct modbus_sim *s, int i, const char *cause)
{
    char want[200];
    snprintf(want, sizeof(want), "modbus drive %d (127.0.0.1:%d): %s", i, modbus_sim_port(s, i),
             cause);
    ck_assert_msg(strstr(modbus_link_fault_message(l), want) != NULL, "got '%s', want '%s'",
                  modbus_link_fault_message(l), want);
}

/* A healthy link: one good cycle, no fault. */
static void good_cycle(struct modbus_link *l)
{
    ck_assert_msg(modbus_link_cycle(l) == MODBUS_DRIVE_OK, "%s", modbus_link_fault_message(l));
    struct modbus_feedback fb;
    modbus_link_feedback(l, &fb);
    ck_assert(!fb.fault);
    ck_assert(fb.connected);
}

START_TEST(test_timeout_faults_names_drive)
{
    struct modbus_sim *s = sim_n(4);
    struct modbus_link l;
    link_to(&l, s, 3, 200000);
    good_cycle(&l);
    modbus_sim_inject(s, 3, MODBUS_SIM_FAULT_NO_ANSWER, 0);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_TIMEOUT);
    expect_msg(&l, s, 3, "no answer within 200 ms");
    struct modbus_feedback fb;
    modbus_link_feedback(&l, &fb);
    ck_assert(fb.fault);
    ck_assert_uint_eq(fb.errors, 1);
    ck_assert_uint_eq(fb.fault_seq, 1);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

START_TEST(test_injected_exception)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_link l;
    link_to(&l, s, 0, 200000);
    good_cycle(&l);
    modbus_sim_inject(s, 0, MODBUS_SIM_FAULT_EXCEPTION, 4);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_EXCEPTION);
    expect_msg(&l, s, 0, "exception 4 server device failure at register 0");
    ck_assert_int_eq(l.drive.last_exception, 4);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

/* A register map beyond the drive's registers: libmodbus's own "illegal data address". */
START_TEST(test_real_exception_illegal_address)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_drive_cfg c;
    modbus_drive_cfg_default(&c, 0);
    c.port = modbus_sim_port(s, 0);
    c.map.control = 100;
    c.map.target = 101;
    struct modbus_link l;
    ck_assert_int_eq(modbus_link_init(&l, &c), MODBUS_DRIVE_OK);
    /* Before the first command a cycle only reads: the feedback is the drive's position and
     * nothing is written (the target the drive was parked at stays). */
    modbus_sim_set_position(s, 0, 1234);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_OK);
    struct modbus_sim_drive_state st;
    modbus_sim_state(s, 0, &st);
    ck_assert_uint_eq(st.requests, 1);
    ck_assert_int_eq(st.target_counts, 1234);
    struct modbus_feedback fb;
    modbus_link_feedback(&l, &fb);
    ck_assert_double_eq(fb.pos_mm, 1.234);
    modbus_link_command(&l, 0.0, false);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_EXCEPTION);
    expect_msg(&l, s, 0, "exception 2 illegal data address at register 100");
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

START_TEST(test_disconnect_then_reset_reconnects)
{
    struct modbus_sim *s = sim_n(2);
    struct modbus_link l;
    link_to(&l, s, 1, 200000);
    good_cycle(&l);
    modbus_sim_inject(s, 1, MODBUS_SIM_FAULT_DISCONNECT, 0);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_CLOSED);
    expect_msg(&l, s, 1, "connection closed");
    struct modbus_sim_drive_state st;
    modbus_sim_state(s, 1, &st);
    uint32_t req = st.requests;
    /* Latched: further cycles send nothing. */
    for (int k = 0; k < 3; k++)
        ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_OK);
    modbus_sim_state(s, 1, &st);
    ck_assert_uint_eq(st.requests, req);
    struct modbus_feedback fb;
    modbus_link_feedback(&l, &fb);
    ck_assert(fb.fault && !fb.connected);
    modbus_link_reset(&l);
    good_cycle(&l);
    modbus_sim_state(s, 1, &st);
    ck_assert_uint_eq(st.connections, 2);
    ck_assert_uint_eq(st.requests, req + 1);
    /* The first exchange after a reset carries FAULT_RESET, the next one does not. */
    ck_assert_uint_eq(st.control_word & MODBUS_CTRL_FAULT_RESET, MODBUS_CTRL_FAULT_RESET);
    good_cycle(&l);
    modbus_sim_state(s, 1, &st);
    ck_assert_uint_eq(st.control_word & MODBUS_CTRL_FAULT_RESET, 0);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

START_TEST(test_reset_while_still_failing_faults_again)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_link l;
    link_to(&l, s, 0, 200000);
    modbus_sim_inject(s, 0, MODBUS_SIM_FAULT_NO_ANSWER, 0);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_TIMEOUT);
    modbus_link_reset(&l);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_TIMEOUT);
    struct modbus_feedback fb;
    modbus_link_feedback(&l, &fb);
    ck_assert(fb.fault);
    ck_assert_uint_eq(fb.errors, 2);
    ck_assert_uint_eq(fb.fault_seq, 2);
    modbus_sim_inject(s, 0, MODBUS_SIM_FAULT_NONE, 0);
    modbus_link_reset(&l);
    good_cycle(&l);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

START_TEST(test_delay_within_timeout_is_fine)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_link l;
    link_to(&l, s, 0, 200000);
    modbus_sim_inject(s, 0, MODBUS_SIM_FAULT_DELAY, 5000);
    good_cycle(&l);
    good_cycle(&l);
    struct modbus_feedback fb;
    modbus_link_feedback(&l, &fb);
    ck_assert_uint_eq(fb.exchanges, 2);
    ck_assert_uint_eq(fb.errors, 0);
    /* The 5 ms the drive waited are inside the measured round trip. */
    ck_assert_double_ge(fb.rtt_us, 5000.0);
    ck_assert_double_ge(fb.rtt_max_us, fb.rtt_us);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

START_TEST(test_delay_over_timeout_faults)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_link l;
    link_to(&l, s, 0, 200000);
    good_cycle(&l);
    modbus_sim_inject(s, 0, MODBUS_SIM_FAULT_DELAY, 400000);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_TIMEOUT);
    expect_msg(&l, s, 0, "no answer within 200 ms");
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

START_TEST(test_connect_refused)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_drive_cfg c;
    modbus_drive_cfg_default(&c, 5);
    c.port = modbus_sim_port(s, 0);
    modbus_sim_destroy(s);                  /* nobody listens there now */
    struct modbus_link l;
    ck_assert_int_eq(modbus_link_init(&l, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_CONNECT);
    ck_assert_ptr_nonnull(strstr(modbus_link_fault_message(&l), "cannot connect"));
    modbus_link_fini(&l);
}
END_TEST

START_TEST(test_drive_fault_bit_and_reset)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_link l;
    link_to(&l, s, 0, 200000);
    modbus_link_command(&l, 1.0, true);
    good_cycle(&l);
    modbus_sim_inject(s, 0, MODBUS_SIM_FAULT_DRIVE, 0);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_FAULT);
    expect_msg(&l, s, 0, "drive reports a fault (status word 0x");
    modbus_link_reset(&l);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_OK);   /* carries FAULT_RESET */
    good_cycle(&l);
    struct modbus_feedback fb;
    modbus_link_feedback(&l, &fb);
    ck_assert_uint_eq(fb.status_word & MODBUS_STAT_FAULT, 0);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

START_TEST(test_range_fault)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_link l;
    link_to(&l, s, 0, 200000);
    modbus_link_command(&l, 3e6, true);     /* 3e9 counts at 1000 counts/mm */
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_RANGE);
    expect_msg(&l, s, 0, "position command 3000000.000 mm is beyond");
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

/* The I/O thread: feedback converges to the command without the test calling cycles, and
 * a disconnect raises the fault from the thread. Loops are bounded (2 s). */
START_TEST(test_io_thread_follows_and_faults)
{
    struct modbus_sim *s = sim_n(1);
    struct modbus_link l;
    link_to(&l, s, 0, 200000);
    l.drive.cfg.period_ns = 2000000;
    modbus_link_command(&l, 42.5, true);
    ck_assert_int_eq(modbus_link_start(&l), MODBUS_DRIVE_OK);
    struct modbus_feedback fb = { 0 };
    struct timespec nap = { 0, 2000000 };
    for (int k = 0; k < 1000 && !(fb.pos_mm == 42.5 && fb.exchanges > 3); k++) {
        nanosleep(&nap, NULL);
        modbus_link_feedback(&l, &fb);
    }
    ck_assert_double_eq(fb.pos_mm, 42.5);
    ck_assert(!fb.fault);
    modbus_sim_inject(s, 0, MODBUS_SIM_FAULT_DISCONNECT, 0);
    for (int k = 0; k < 1000 && !fb.fault; k++) {
        nanosleep(&nap, NULL);
        modbus_link_feedback(&l, &fb);
    }
    ck_assert(fb.fault);
    expect_msg(&l, s, 0, "connection closed");
    modbus_link_reset(&l);
    for (int k = 0; k < 1000 && (fb.fault || !fb.connected); k++) {
        nanosleep(&nap, NULL);
        modbus_link_feedback(&l, &fb);
    }
    ck_assert(!fb.fault && fb.connected);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

/* RTU: the simulated drive serves the master side of a pseudo-terminal; the client opens
 * the slave side as its serial device. A wrong unit id is ignored by the drive: timeout. */
START_TEST(test_rtu_over_pty)
{
    struct modbus_sim_opts o;
    modbus_sim_opts_default(&o);
    o.step_ns = 1000000;
    o.tau_s = 0.0;
    struct modbus_sim *s;
    ck_assert_int_eq(modbus_sim_create(&s, 2, &o), MODBUS_SIM_OK);
    char dev[64];
    ck_assert_int_eq(modbus_sim_start_rtu_pty(s, 1, dev, sizeof(dev)), MODBUS_SIM_OK);
    struct modbus_drive_cfg c;
    modbus_drive_cfg_default(&c, 1);
    c.transport = MODBUS_DRIVE_RTU;
    snprintf(c.device, sizeof(c.device), "%s", dev);
    c.map.order = MODBUS_WORDS_HIGH_FIRST;
    c.timeout_us = 100000;
    struct modbus_link l;
    ck_assert_int_eq(modbus_link_init(&l, &c), MODBUS_DRIVE_OK);
    modbus_link_command(&l, -7.25, true);
    good_cycle(&l);
    good_cycle(&l);
    struct modbus_feedback fb;
    modbus_link_feedback(&l, &fb);
    ck_assert_double_eq(fb.pos_mm, -7.25);
    ck_assert_uint_eq(fb.status_word & MODBUS_STAT_ENABLED, MODBUS_STAT_ENABLED);
    modbus_link_fini(&l);
    c.unit = 9;
    c.timeout_us = 20000;
    ck_assert_int_eq(modbus_link_init(&l, &c), MODBUS_DRIVE_OK);
    modbus_link_command(&l, 0.0, false);
    ck_assert_int_eq(modbus_link_cycle(&l), MODBUS_DRIVE_ERR_TIMEOUT);
    char want[128];
    snprintf(want, sizeof(want), "modbus drive 1 (%s@115200,8N1): no answer within 20 ms", dev);
    ck_assert_str_eq(modbus_link_fault_message(&l), want);
    modbus_link_fini(&l);
    modbus_sim_destroy(s);
}
END_TEST

static Suite *modbus_faults_suite(void)
{
    Suite *s = suite_create("modbus_faults");
    TCase *tc = tcase_create("faults");
    tcase_set_timeout(tc, 20);
    tcase_add_test(tc, test_timeout_faults_names_drive);
    tcase_add_test(tc, test_injected_exception);
    tcase_add_test(tc, test_real_exception_illegal_address);
    tcase_add_test(tc, test_disconnect_then_reset_reconnects);
    tcase_add_test(tc, test_reset_while_still_failing_faults_again);
    tcase_add_test(tc, test_delay_within_timeout_is_fine);
    tcase_add_test(tc, test_delay_over_timeout_faults);
    tcase_add_test(tc, test_connect_refused);
    tcase_add_test(tc, test_drive_fault_bit_and_reset);
    tcase_add_test(tc, test_range_fault);
    tcase_add_test(tc, test_io_thread_follows_and_faults);
    tcase_add_test(tc, test_rtu_over_pty);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(modbus_faults_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
