/* test_modbus_hal.c: HAL-graph tests: six simulated Modbus drives driven through `loadrt modbus` on the simulated clock. */
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
#include "sim/modbus_sim.h"
#include "tests/test_net_util.h"

#define NDRIVES 6
#define PERIOD_NS 1000000L          /* servo period */
#define SETPOINT_NS 4000000L        /* set-point period: every 4th servo period */
#define CPM 1000.0                  /* counts per mm */

/* Runs one HAL command line; fails the test with the runtime's message. */
static void cmd(struct hal *h, const char *line)
{
    int st = hal_cmd(h, line, "test", 0, stdout);
    ck_assert_msg(st == HAL_OK, "'%s': %s", line, hal_last_error(h));
}

/* Writes an INI with [MODBUS] and a PORT per drive; returns its path in buf. */
static void write_ini(char *buf, size_t len, const int *ports, const char *extra)
{
    snprintf(buf, len, "/tmp/test_modbus_hal_XXXXXX");
    int fd = mkstemp(buf);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    fprintf(f, "[MODBUS]\nDRIVES = %d\nHOST = 127.0.0.1\nSETPOINT_PERIOD = %ld\n"
            "COUNTS_PER_MM = %g\nTIMEOUT = 20\nWORD_ORDER = low-first\n%s\n", NDRIVES,
            SETPOINT_NS, CPM, extra);
    for (int i = 0; i < NDRIVES; i++)
        fprintf(f, "[MODBUS_DRIVE_%d]\nPORT = %d\n", i, ports[i]);
    fclose(f);
}

/* Six free loopback ports (test_net_util.h). */
static void free_ports(int *ports)
{
    ck_assert_int_eq(tn_free_ports(ports, NDRIVES), 0);
}

/* The leg command of drive i at servo period k: a 2 Hz sine of 5 mm around 600 + 10 i. */
static double leg_cmd(int i, int k)
{
    return 600.0 + 10.0 * i + 5.0 * sin(2.0 * M_PI * 2.0 * k * 1e-3);
}

/* The legs' commands, one row per servo period, for the streamer; path in buf. */
static void write_rows(char *buf, size_t len, int nrows)
{
    snprintf(buf, len, "/tmp/test_modbus_rows_XXXXXX");
    int fd = mkstemp(buf);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    for (int k = 0; k < nrows; k++)
        for (int i = 0; i < NDRIVES; i++)
            fprintf(f, "%.17g%c", leg_cmd(i, k), i + 1 < NDRIVES ? ' ' : '\n');
    fclose(f);
}

/* A graph on a simulated 1 kHz thread, loaded from `ini`:
 *   streamer (leg commands) -> modbus.N.position-cmd, modbus.fault-any -> estop-latch,
 *   estop-latch ok-out -> modbus.N.enable, one reset signal for the latch and the drives. */
static struct hal *make_graph(const char *ini, bool with_server)
{
    char rows[64], line[160];
    write_rows(rows, sizeof(rows), 1200);
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    hal_set_sim_clock(h, true);
    ck_assert_msg(hal_load_ini(h, ini) == HAL_OK, "%s", hal_last_error(h));
    cmd(h, "newthread servo-thread 1000000");
    if (with_server)
        cmd(h, "loadrt modbus-sim-server");
    cmd(h, "loadrt modbus");
    snprintf(line, sizeof(line), "loadrt streamer cfg=ffffff file=%s", rows);
    cmd(h, line);
    unlink(rows);
    for (int i = 0; i < NDRIVES; i++) {
        snprintf(line, sizeof(line), "net leg-%d-cmd streamer.0.pin.%d => modbus.%d.position-cmd",
                 i, i, i);
        cmd(h, line);
    }
    cmd(h, "loadrt estop-latch");
    cmd(h, "setp estop-latch.0.ok-in 1");
    cmd(h, "net drive-fault modbus.fault-any => estop-latch.0.fault-in");
    cmd(h, "net machine-reset => estop-latch.0.reset modbus.0.fault-reset modbus.1.fault-reset "
           "modbus.2.fault-reset modbus.3.fault-reset modbus.4.fault-reset modbus.5.fault-reset");
    cmd(h, "net machine-ok estop-latch.0.ok-out => modbus.0.enable modbus.1.enable "
           "modbus.2.enable modbus.3.enable modbus.4.enable modbus.5.enable");
    cmd(h, "addf streamer.0 servo-thread");
    cmd(h, "addf modbus.update servo-thread");
    cmd(h, "addf estop-latch.0 servo-thread");
    ck_assert_int_eq(hal_start(h), HAL_OK);
    return h;
}

/* One servo period; the streamer puts out row k (the legs at period k). */
static void step(struct hal *h, int k)
{
    ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
    ck_assert_int_eq(*(int32_t *)test_pin(h, "streamer.0.row", HAL_S32), k + 1);
}

/* Presses and releases the machine reset (one period each). */
static void press_reset(struct hal *h, int *k)
{
    cmd(h, "sets machine-reset 1");
    step(h, (*k)++);
    cmd(h, "sets machine-reset 0");
    step(h, (*k)++);
}

/* Six drives follow a motion; one exchange per 4 servo periods; feedback within the lag. */
static void follow_motion(struct hal *h, struct modbus_sim *s, const int *ticks)
{
    double *fb[NDRIVES];
    char name[64];
    for (int i = 0; i < NDRIVES; i++) {
        snprintf(name, sizeof(name), "modbus.%d.position-fb", i);
        fb[i] = test_pin(h, name, HAL_FLOAT);
    }
    int k = 0;
    press_reset(h, &k);                             /* leave the start-up e-stop */
    ck_assert(*(bool *)test_pin(h, "estop-latch.0.ok-out", HAL_BIT));
    struct modbus_sim_drive_state st0[NDRIVES];
    for (int i = 0; i < NDRIVES; i++)
        modbus_sim_state(s, i, &st0[i]);
    double worst_mm = 0.0;
    for (int n = 0; n < 1000; n++, k++) {
        step(h, k);
        for (int i = 0; n > 20 && i < NDRIVES; i++)
            worst_mm = fmax(worst_mm, fabs(*fb[i] - leg_cmd(i, k)));
    }
    /* Lag of a 4 ms set point, one period of transport and a 4 ms drive time constant at
     * up to 62.8 mm/s: well under 1 mm; a stuck or unscaled drive would be 5..600 mm off. */
    ck_assert_double_lt(worst_mm, 1.0);
    ck_assert_double_gt(worst_mm, 0.01);
    for (int i = 0; i < NDRIVES; i++) {
        struct modbus_sim_drive_state st;
        modbus_sim_state(s, i, &st);
        ck_assert_uint_eq(st.requests - st0[i].requests, 1000 / ticks[i]);
        /* Exchanges fall on every ticks-th call of modbus.update (calls 0, 4, 8, ...):
         * the command of the last one is the drive's target. */
        int last = (k - 1) / ticks[i] * ticks[i];
        ck_assert(lround(leg_cmd(i, last) * CPM) != lround(leg_cmd(i, k - 1) * CPM));
        ck_assert_int_eq(st.target_counts, (int32_t)lround(leg_cmd(i, last) * CPM));
        ck_assert_double_eq(*fb[i], lround(st.actual_counts) / CPM);
        snprintf(name, sizeof(name), "modbus.%d.status-word", i);
        ck_assert_uint_eq(*(uint32_t *)test_pin(h, name, HAL_U32) & MODBUS_STAT_ENABLED,
                          MODBUS_STAT_ENABLED);
        snprintf(name, sizeof(name), "modbus.%d.rtt-us", i);
        ck_assert_double_gt(*(double *)test_pin(h, name, HAL_FLOAT), 0.0);
        snprintf(name, sizeof(name), "modbus.%d.errors", i);
        ck_assert_uint_eq(*(uint32_t *)test_pin(h, name, HAL_U32), 0);
    }
}

/* Simulated drives started through the API, ports passed to the INI. */
static struct modbus_sim *api_sim(int *ports)
{
    struct modbus_sim_opts o;
    modbus_sim_opts_default(&o);
    o.map.order = MODBUS_WORDS_LOW_FIRST;
    o.step_ns = SETPOINT_NS;
    o.tau_s = 0.004;
    struct modbus_sim *s;
    ck_assert_int_eq(modbus_sim_create(&s, NDRIVES, &o), MODBUS_SIM_OK);
    ck_assert_int_eq(modbus_sim_start_tcp(s, "127.0.0.1", 0), MODBUS_SIM_OK);
    for (int i = 0; i < NDRIVES; i++) {
        ports[i] = modbus_sim_port(s, i);
        modbus_sim_set_position(s, i, (int32_t)lround(leg_cmd(i, 0) * CPM));
    }
    return s;
}

START_TEST(test_six_drives_follow_slower_setpoints)
{
    int ports[NDRIVES];
    struct modbus_sim *s = api_sim(ports);
    char ini[64];
    /* Drive 5 takes set points every 2 ms, the others every 4 ms. */
    write_ini(ini, sizeof(ini), ports, "[MODBUS_DRIVE_5]\nSETPOINT_PERIOD = 2000000\n");
    struct hal *h = make_graph(ini, false);
    const int ticks[NDRIVES] = { 4, 4, 4, 4, 4, 2 };
    follow_motion(h, s, ticks);
    hal_destroy(h);
    modbus_sim_destroy(s);
    unlink(ini);
}
END_TEST

/* The server component reads the same INI and serves every drive in-process. */
START_TEST(test_server_component_end_to_end)
{
    int ports[NDRIVES];
    free_ports(ports);
    char ini[64];
    write_ini(ini, sizeof(ini), ports, "[MODBUS_SIM]\nTAU = 0.004\n");
    struct hal *h = make_graph(ini, true);
    struct modbus_sim *s = hal_get_object(h, "modbus-sim");
    ck_assert_ptr_nonnull(s);
    for (int i = 0; i < NDRIVES; i++)
        modbus_sim_set_position(s, i, (int32_t)lround(leg_cmd(i, 0) * CPM));
    const int ticks[NDRIVES] = { 4, 4, 4, 4, 4, 4 };
    follow_motion(h, s, ticks);
    hal_destroy(h);                 /* stops the client links, then the servers */
    unlink(ini);
}
END_TEST

/* A drive that stops answering trips the e-stop chain; a reset reconnects and clears it. */
START_TEST(test_drive_fault_trips_estop_and_resets)
{
    int ports[NDRIVES];
    struct modbus_sim *s = api_sim(ports);
    char ini[64];
    write_ini(ini, sizeof(ini), ports, "");
    struct hal *h = make_graph(ini, false);
    bool *ok = test_pin(h, "estop-latch.0.ok-out", HAL_BIT);
    bool *fault3 = test_pin(h, "modbus.3.fault", HAL_BIT), *fault2 = test_pin(h, "modbus.2.fault", HAL_BIT);
    int k = 0;
    press_reset(h, &k);
    for (int n = 0; n < 20; n++)
        step(h, k++);
    ck_assert(*ok && !*fault3);
    modbus_sim_inject(s, 3, MODBUS_SIM_FAULT_DISCONNECT, 0);
    for (int n = 0; n < 8; n++)
        step(h, k++);
    ck_assert(*fault3);
    ck_assert(!*fault2);
    ck_assert(*(bool *)test_pin(h, "modbus.fault-any", HAL_BIT));
    ck_assert(!*ok);                                /* e-stop: motion loses enable */
    ck_assert(!*(bool *)test_pin(h, "modbus.3.connected", HAL_BIT));
    ck_assert_uint_eq(*(uint32_t *)test_pin(h, "modbus.3.errors", HAL_U32), 1);
    press_reset(h, &k);
    ck_assert(*ok);                                 /* the chain resets in the same press */
    for (int n = 0; n < 8; n++)
        step(h, k++);
    ck_assert(!*fault3 && *ok);
    ck_assert(*(bool *)test_pin(h, "modbus.3.connected", HAL_BIT));
    struct modbus_sim_drive_state st;
    modbus_sim_state(s, 3, &st);
    ck_assert_uint_eq(st.connections, 2);
    /* A drive still silent at the reset faults again at its next set point. */
    modbus_sim_inject(s, 1, MODBUS_SIM_FAULT_NO_ANSWER, 0);
    for (int n = 0; n < 8; n++)
        step(h, k++);
    ck_assert(!*ok);
    press_reset(h, &k);
    for (int n = 0; n < 8; n++)
        step(h, k++);
    ck_assert(*(bool *)test_pin(h, "modbus.1.fault", HAL_BIT));
    ck_assert(!*ok);
    hal_destroy(h);
    modbus_sim_destroy(s);
    unlink(ini);
}
END_TEST

/* On the simulated clock an injected delay is simulated time: the in-process drives read the
 * same TIMEOUT (20 ms), answer a 19 ms delay at once and leave a 21 ms one unanswered, so the
 * outcome never depends on how busy the computer is. */
START_TEST(test_simclock_delay_is_simulated_time)
{
    int ports[NDRIVES];
    free_ports(ports);
    char ini[64];
    write_ini(ini, sizeof(ini), ports, "");
    struct hal *h = make_graph(ini, true);
    struct modbus_sim *s = hal_get_object(h, "modbus-sim");
    ck_assert_ptr_nonnull(s);
    bool *fault2 = test_pin(h, "modbus.2.fault", HAL_BIT);
    int k = 0;
    press_reset(h, &k);
    ck_assert_int_eq(modbus_sim_inject(s, 2, MODBUS_SIM_FAULT_DELAY, 19000), MODBUS_SIM_OK);
    for (int n = 0; n < 40; n++)
        step(h, k++);
    ck_assert(!*fault2);
    struct modbus_sim_drive_state st;
    modbus_sim_state(s, 2, &st);
    ck_assert_uint_ge(st.requests, 10);
    ck_assert_int_eq(modbus_sim_inject(s, 2, MODBUS_SIM_FAULT_DELAY, 21000), MODBUS_SIM_OK);
    for (int n = 0; n < 8; n++)
        step(h, k++);
    ck_assert(*fault2);
    ck_assert(!*(bool *)test_pin(h, "modbus.1.fault", HAL_BIT));
    hal_destroy(h);
    unlink(ini);
}
END_TEST

START_TEST(test_bad_ini_value_names_key)
{
    int ports[NDRIVES] = { 1, 2, 3, 4, 5, 6 };
    char ini[64];
    write_ini(ini, sizeof(ini), ports, "[MODBUS_DRIVE_4]\nWORD_ORDER = middle\n");
    struct hal *h = hal_create();
    ck_assert_int_eq(hal_load_ini(h, ini), HAL_OK);
    ck_assert_int_ne(hal_cmd(h, "loadrt modbus", "test.hal", 3, stdout), HAL_OK);
    ck_assert_msg(strstr(hal_last_error(h), "[MODBUS_DRIVE_4] WORD_ORDER = middle: expected "
                         "high-first or low-first") != NULL, "%s", hal_last_error(h));
    ck_assert_ptr_nonnull(strstr(hal_last_error(h), ini));
    hal_destroy(h);
    unlink(ini);
}
END_TEST

/* One drive over Modbus RTU: the INI's TRANSPORT = rtu and DEVICE reach libmodbus's RTU
 * backend; the simulated drive answers on the other side of a pseudo-terminal. */
START_TEST(test_rtu_drive_through_hal)
{
    struct modbus_sim_opts o;
    modbus_sim_opts_default(&o);
    o.step_ns = SETPOINT_NS;
    o.tau_s = 0.0;
    o.unit = 3;
    struct modbus_sim *s;
    ck_assert_int_eq(modbus_sim_create(&s, 1, &o), MODBUS_SIM_OK);
    char dev[64], ini[64];
    ck_assert_int_eq(modbus_sim_start_rtu_pty(s, 0, dev, sizeof(dev)), MODBUS_SIM_OK);
    snprintf(ini, sizeof(ini), "/tmp/test_modbus_rtu_XXXXXX");
    int fd = mkstemp(ini);
    ck_assert_int_ge(fd, 0);
    FILE *f = fdopen(fd, "w");
    fprintf(f, "[MODBUS]\nDRIVES = 1\nTRANSPORT = rtu\nDEVICE = %s\nBAUD = 115200\n"
            "PARITY = E\nUNIT = 3\nSETPOINT_PERIOD = %ld\nCOUNTS_PER_MM = 500\nTIMEOUT = 50\n",
            dev, SETPOINT_NS);
    fclose(f);
    struct hal *h = hal_create();
    hal_set_sim_clock(h, true);
    ck_assert_msg(hal_load_ini(h, ini) == HAL_OK, "%s", hal_last_error(h));
    unlink(ini);
    cmd(h, "newthread servo-thread 1000000");
    modbus_sim_set_position(s, 0, -1000);
    cmd(h, "loadrt modbus");
    /* Loading reads the drive once: the feedback is its position before any command. */
    ck_assert_double_eq(*(double *)test_pin(h, "modbus.0.position-fb", HAL_FLOAT), -2.0);
    cmd(h, "addf modbus.update servo-thread");
    cmd(h, "setp modbus.0.enable 1");
    cmd(h, "setp modbus.0.position-cmd 612.346");
    ck_assert_int_eq(hal_start(h), HAL_OK);
    for (int k = 0; k < 12; k++)
        ck_assert_int_eq(hal_sim_advance(h, PERIOD_NS), HAL_OK);
    ck_assert(!*(bool *)test_pin(h, "modbus.0.fault", HAL_BIT));
    ck_assert_double_eq(*(double *)test_pin(h, "modbus.0.position-fb", HAL_FLOAT), 612.346);
    struct modbus_sim_drive_state st;
    modbus_sim_state(s, 0, &st);
    ck_assert_int_eq(st.target_counts, 306173);
    ck_assert_uint_eq(st.requests, 1 + 3);   /* a read at load, then one exchange per 4 periods */
    hal_destroy(h);
    modbus_sim_destroy(s);
}
END_TEST

static Suite *modbus_hal_suite(void)
{
    Suite *s = suite_create("modbus_hal");
    TCase *tc = tcase_create("graph");
    tcase_set_timeout(tc, 30);
    tcase_add_test(tc, test_six_drives_follow_slower_setpoints);
    tcase_add_test(tc, test_server_component_end_to_end);
    tcase_add_test(tc, test_drive_fault_trips_estop_and_resets);
    tcase_add_test(tc, test_simclock_delay_is_simulated_time);
    tcase_add_test(tc, test_bad_ini_value_names_key);
    tcase_add_test(tc, test_rtu_drive_through_hal);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(modbus_hal_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
