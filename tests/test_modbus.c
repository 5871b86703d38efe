/* test_modbus.c: the Modbus drive core against simulated drives on loopback: packing, scaling, exchange, faults. */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "hal/drivers/modbus_cfg.h"
#include "hal/drivers/modbus_drive.h"
#include "sim/modbus_sim.h"

/* A client config for simulated drive i of s (FC23; a 200 ms wall-clock timeout, so a
 * loaded machine never times out a healthy drive). */
static void client_cfg(struct modbus_drive_cfg *c, struct modbus_sim *s, int i)
{
    modbus_drive_cfg_default(c, i);
    c->port = modbus_sim_port(s, i);
    c->counts_per_mm = 1000.0;
    c->timeout_us = 200000;
}

/* One simulated drive on an ephemeral port with a lockstep model of 1 ms per cycle. */
static struct modbus_sim *sim_one(enum modbus_word_order order, double tau_s)
{
    struct modbus_sim_opts o;
    modbus_sim_opts_default(&o);
    o.map.order = order;
    o.step_ns = 1000000;
    o.tau_s = tau_s;
    struct modbus_sim *s;
    ck_assert_int_eq(modbus_sim_create(&s, 1, &o), MODBUS_SIM_OK);
    ck_assert_int_eq(modbus_sim_start_tcp(s, "127.0.0.1", 0), MODBUS_SIM_OK);
    return s;
}

START_TEST(test_words_both_orders)
{
    uint16_t r[2];
    modbus_words_pack(0x12345678, MODBUS_WORDS_HIGH_FIRST, r);
    ck_assert_uint_eq(r[0], 0x1234);
    ck_assert_uint_eq(r[1], 0x5678);
    ck_assert_int_eq(modbus_words_unpack(r, MODBUS_WORDS_HIGH_FIRST), 0x12345678);
    ck_assert_int_ne(modbus_words_unpack(r, MODBUS_WORDS_LOW_FIRST), 0x12345678);
    modbus_words_pack(0x12345678, MODBUS_WORDS_LOW_FIRST, r);
    ck_assert_uint_eq(r[0], 0x5678);
    ck_assert_uint_eq(r[1], 0x1234);
    ck_assert_int_eq(modbus_words_unpack(r, MODBUS_WORDS_LOW_FIRST), 0x12345678);
    modbus_words_pack(-2, MODBUS_WORDS_LOW_FIRST, r);
    ck_assert_uint_eq(r[0], 0xfffe);
    ck_assert_uint_eq(r[1], 0xffff);
    ck_assert_int_eq(modbus_words_unpack(r, MODBUS_WORDS_LOW_FIRST), -2);
}
END_TEST

START_TEST(test_scaling_and_range)
{
    int32_t c;
    ck_assert_int_eq(modbus_mm_to_counts(12.3456, 1000.0, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(c, 12346);
    ck_assert_int_eq(modbus_mm_to_counts(-0.0004, 10000.0, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(c, -4);
    ck_assert_int_eq(modbus_mm_to_counts(650.0, -2000.0, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(c, -1300000);
    ck_assert_double_eq_tol(modbus_counts_to_mm(-1300000, -2000.0), 650.0, 1e-12);
    ck_assert_int_eq(modbus_mm_to_counts(1e6, 1e4, &c), MODBUS_DRIVE_ERR_RANGE);
    ck_assert_int_eq(c, INT32_MAX);
    ck_assert_int_eq(modbus_mm_to_counts(-1e6, 1e4, &c), MODBUS_DRIVE_ERR_RANGE);
    ck_assert_int_eq(c, INT32_MIN);
}
END_TEST

START_TEST(test_config_rejects_bad_maps)
{
    struct modbus_drive_cfg c;
    struct modbus_drive d;
    modbus_drive_cfg_default(&c, 2);
    c.map.control = 5;
    c.map.target = 1;            /* control not adjacent: FC23 impossible */
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_ERR_CONFIG);
    ck_assert_ptr_nonnull(strstr(modbus_drive_message(&d), "modbus drive 2 (127.0.0.1:502)"));
    ck_assert_ptr_nonnull(strstr(modbus_drive_message(&d), "EXCHANGE = separate"));
    c.exchange = MODBUS_EXCHANGE_SEPARATE;
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_OK);
    ck_assert(d.plan.write_split);
    modbus_drive_close(&d);
    modbus_drive_cfg_default(&c, 0);
    c.map.status = 12;           /* overlaps actual 11..12 */
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_ERR_CONFIG);
    modbus_drive_cfg_default(&c, 0);
    c.counts_per_mm = 0.0;
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_ERR_CONFIG);
}
END_TEST

/* Exchanges `n` cycles and returns the last actual position. */
static int32_t run_cycles(struct modbus_drive *d, int32_t target, uint16_t ctl, int n,
                          uint16_t *status)
{
    int32_t act = 0;
    for (int k = 0; k < n; k++)
        ck_assert_msg(modbus_drive_exchange(d, target, ctl, &act, status) == MODBUS_DRIVE_OK,
                      "%s", modbus_drive_message(d));
    return act;
}

/* Round trip in one word order: target arrives intact, actual follows, status bits. */
static void exchange_in_order(enum modbus_word_order order, enum modbus_exchange ex)
{
    struct modbus_sim *s = sim_one(order, 0.0);
    struct modbus_drive_cfg c;
    client_cfg(&c, s, 0);
    c.map.order = order;
    c.exchange = ex;
    struct modbus_drive d;
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(modbus_drive_connect(&d), MODBUS_DRIVE_OK);
    int32_t target;
    ck_assert_int_eq(modbus_mm_to_counts(-123.4567, c.counts_per_mm, &target), MODBUS_DRIVE_OK);
    uint16_t st;
    run_cycles(&d, target, MODBUS_CTRL_ENABLE, 1, &st);
    /* FC23 reads the status the drive had before this write; FC16 + FC3 reads after it. */
    ck_assert_uint_eq(st & MODBUS_STAT_ENABLED, ex == MODBUS_EXCHANGE_FC23 ? 0 : MODBUS_STAT_ENABLED);
    int32_t act = run_cycles(&d, target, MODBUS_CTRL_ENABLE, 2, &st);
    struct modbus_sim_drive_state ss;
    modbus_sim_state(s, 0, &ss);
    ck_assert_int_eq(ss.target_counts, -123457);
    ck_assert_int_eq(act, -123457);                      /* tau 0: reaches it in one step */
    ck_assert_uint_eq(st & (MODBUS_STAT_READY | MODBUS_STAT_ENABLED | MODBUS_STAT_AT_TARGET),
                      MODBUS_STAT_READY | MODBUS_STAT_ENABLED | MODBUS_STAT_AT_TARGET);
    ck_assert_double_eq_tol(modbus_counts_to_mm(act, c.counts_per_mm), -123.457, 1e-9);
    ck_assert_uint_eq(ss.requests, ex == MODBUS_EXCHANGE_FC23 ? 3u : 6u);
    ck_assert_uint_eq(d.requests, ss.requests);
    modbus_drive_close(&d);
    modbus_sim_destroy(s);
}

START_TEST(test_exchange_high_first_fc23) { exchange_in_order(MODBUS_WORDS_HIGH_FIRST, MODBUS_EXCHANGE_FC23); }
END_TEST
START_TEST(test_exchange_low_first_fc23) { exchange_in_order(MODBUS_WORDS_LOW_FIRST, MODBUS_EXCHANGE_FC23); }
END_TEST
START_TEST(test_exchange_low_first_separate) { exchange_in_order(MODBUS_WORDS_LOW_FIRST, MODBUS_EXCHANGE_SEPARATE); }
END_TEST

START_TEST(test_word_order_mismatch_garbles)
{
    struct modbus_sim *s = sim_one(MODBUS_WORDS_LOW_FIRST, 0.0);
    struct modbus_drive_cfg c;
    client_cfg(&c, s, 0);       /* client high first, drive low first */
    struct modbus_drive d;
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(modbus_drive_connect(&d), MODBUS_DRIVE_OK);
    uint16_t st;
    run_cycles(&d, 100000, MODBUS_CTRL_ENABLE, 2, &st);
    struct modbus_sim_drive_state ss;
    modbus_sim_state(s, 0, &ss);
    ck_assert_int_eq(ss.target_counts, (int32_t)0x86a00001);   /* 0x000186a0 swapped */
    modbus_drive_close(&d);
    modbus_sim_destroy(s);
}
END_TEST

/* The lag model: after one 1 ms step with tau 2 ms, 1 - e^-0.5 of the way. */
START_TEST(test_drive_model_lag)
{
    struct modbus_sim *s = sim_one(MODBUS_WORDS_HIGH_FIRST, 0.002);
    struct modbus_drive_cfg c;
    client_cfg(&c, s, 0);
    struct modbus_drive d;
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(modbus_drive_connect(&d), MODBUS_DRIVE_OK);
    uint16_t st;
    run_cycles(&d, 100000, MODBUS_CTRL_ENABLE, 1, &st);   /* target and enable land */
    int32_t act = run_cycles(&d, 100000, MODBUS_CTRL_ENABLE, 1, &st);
    ck_assert_int_eq(act, 39347);                          /* 100000 * (1 - e^-0.5) */
    ck_assert_uint_eq(st & MODBUS_STAT_AT_TARGET, 0);
    act = run_cycles(&d, 100000, 0, 1, &st);   /* moves one more step, then disables */
    ck_assert_int_eq(act, 63212);                          /* 100000 * (1 - e^-1) */
    int32_t held = run_cycles(&d, 100000, 0, 3, &st);
    ck_assert_int_eq(held, act);                           /* a disabled drive holds */
    ck_assert_uint_eq(st & MODBUS_STAT_ENABLED, 0);
    modbus_drive_close(&d);
    modbus_sim_destroy(s);
}
END_TEST

/* On wall time the drive moves whether or not a client is connected: a client that connects
 * for each request (as mbpoll does) sees it arrive, and so does a state read. */
START_TEST(test_wall_time_model_moves_between_connections)
{
    struct modbus_sim_opts o;
    modbus_sim_opts_default(&o);
    o.tau_s = 0.002;
    struct modbus_sim *s;
    ck_assert_int_eq(modbus_sim_create(&s, 1, &o), MODBUS_SIM_OK);
    ck_assert_int_eq(modbus_sim_start_tcp(s, "127.0.0.1", 0), MODBUS_SIM_OK);
    modbus_sim_set_position(s, 0, 5000);
    struct modbus_drive_cfg c;
    client_cfg(&c, s, 0);
    struct modbus_drive d;
    ck_assert_int_eq(modbus_drive_open(&d, &c), MODBUS_DRIVE_OK);
    ck_assert_int_eq(modbus_drive_connect(&d), MODBUS_DRIVE_OK);
    uint16_t st;
    ck_assert_int_eq(run_cycles(&d, 15000, MODBUS_CTRL_ENABLE, 1, &st), 5000);
    modbus_drive_disconnect(&d);
    struct timespec nap = { 0, 60000000 };      /* 30 time constants: within one count */
    nanosleep(&nap, NULL);
    struct modbus_sim_drive_state ss;
    modbus_sim_state(s, 0, &ss);
    ck_assert_double_eq_tol(ss.actual_counts, 15000.0, 1.0);
    ck_assert_uint_eq(ss.connections, 1);
    ck_assert_int_eq(modbus_drive_connect(&d), MODBUS_DRIVE_OK);
    int32_t act;
    ck_assert_int_eq(modbus_drive_read(&d, &act, &st), MODBUS_DRIVE_OK);
    ck_assert_int_eq(act, 15000);
    ck_assert_uint_eq(st, MODBUS_STAT_READY | MODBUS_STAT_ENABLED | MODBUS_STAT_AT_TARGET);
    modbus_drive_close(&d);
    modbus_sim_destroy(s);
}
END_TEST

/* A tiny INI: {section, key, value} triples. */
static const char *const ini_table[][3] = {
    { "MODBUS", "BASE_PORT", "15020" },
    { "MODBUS", "COUNTS_PER_MM", "-2000" },
    { "MODBUS", "TIMEOUT", "2.5" },
    { "MODBUS", "WORD_ORDER", "Low-First" },
    { "MODBUS", "SETPOINT_PERIOD", "4000000" },
    { "MODBUS_DRIVE_1", "PORT", "502" },
    { "MODBUS_DRIVE_1", "HOST", "127.0.0.2" },
    { "MODBUS_DRIVE_1", "EXCHANGE", "separate" },
    { "MODBUS_DRIVE_2", "TRANSPORT", "rtu" },
    { "MODBUS_DRIVE_2", "DEVICE", "/dev/ttyUSB0" },
    { "MODBUS_DRIVE_2", "BAUD", "57600" },
    { "MODBUS_DRIVE_2", "PARITY", "E" },
    { "MODBUS_DRIVE_2", "UNIT", "7" },
    { "MODBUS_DRIVE_3", "TIMEOUT", "soon" },
    { "MODBUS_DRIVE_4", "TRANSPORT", "rtu" },
};

static const char *ini_get(void *ctx, const char *section, const char *key)
{
    (void)ctx;
    for (size_t i = 0; i < sizeof(ini_table) / sizeof(ini_table[0]); i++)
        if (!strcmp(ini_table[i][0], section) && !strcmp(ini_table[i][1], key))
            return ini_table[i][2];
    return NULL;
}

START_TEST(test_cfg_from_ini)
{
    struct modbus_drive_cfg c;
    char err[256];
    ck_assert_int_eq(modbus_cfg_read(&c, 0, "MODBUS", ini_get, NULL, "m.ini", err, sizeof(err)),
                     MODBUS_DRIVE_OK);
    ck_assert_int_eq(c.port, 15020);
    ck_assert_double_eq(c.counts_per_mm, -2000.0);
    ck_assert_int_eq(c.timeout_us, 2500);
    ck_assert_int_eq(c.map.order, MODBUS_WORDS_LOW_FIRST);
    ck_assert_int_eq(c.period_ns, 4000000);
    ck_assert_int_eq(c.exchange, MODBUS_EXCHANGE_FC23);
    ck_assert_int_eq(modbus_cfg_read(&c, 5, "MODBUS", ini_get, NULL, "m.ini", err, sizeof(err)),
                     MODBUS_DRIVE_OK);
    ck_assert_int_eq(c.port, 15025);                 /* BASE_PORT + n */
    ck_assert_int_eq(modbus_cfg_read(&c, 1, "MODBUS", ini_get, NULL, "m.ini", err, sizeof(err)),
                     MODBUS_DRIVE_OK);
    ck_assert_int_eq(c.port, 502);                   /* the drive's own PORT wins */
    ck_assert_str_eq(c.host, "127.0.0.2");
    ck_assert_int_eq(c.exchange, MODBUS_EXCHANGE_SEPARATE);
    ck_assert_int_eq(modbus_cfg_read(&c, 2, "MODBUS", ini_get, NULL, "m.ini", err, sizeof(err)),
                     MODBUS_DRIVE_OK);
    ck_assert_int_eq(c.transport, MODBUS_DRIVE_RTU);
    char where[96];
    modbus_drive_cfg_where(&c, where, sizeof(where));
    ck_assert_str_eq(where, "/dev/ttyUSB0@57600,8E1");
    ck_assert_int_eq(c.unit, 7);
    ck_assert_int_eq(modbus_cfg_read(&c, 3, "MODBUS", ini_get, NULL, "m.ini", err, sizeof(err)),
                     MODBUS_DRIVE_ERR_CONFIG);
    ck_assert_str_eq(err, "m.ini: [MODBUS_DRIVE_3] TIMEOUT = soon: expected a number above 0");
    ck_assert_int_eq(modbus_cfg_read(&c, 4, "MODBUS", ini_get, NULL, "m.ini", err, sizeof(err)),
                     MODBUS_DRIVE_ERR_CONFIG);
    ck_assert_ptr_nonnull(strstr(err, "TRANSPORT = rtu needs DEVICE"));
}
END_TEST

static Suite *modbus_suite(void)
{
    Suite *s = suite_create("modbus");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 20);
    tcase_add_test(tc, test_words_both_orders);
    tcase_add_test(tc, test_scaling_and_range);
    tcase_add_test(tc, test_config_rejects_bad_maps);
    tcase_add_test(tc, test_cfg_from_ini);
    tcase_add_test(tc, test_exchange_high_first_fc23);
    tcase_add_test(tc, test_exchange_low_first_fc23);
    tcase_add_test(tc, test_exchange_low_first_separate);
    tcase_add_test(tc, test_word_order_mismatch_garbles);
    tcase_add_test(tc, test_drive_model_lag);
    tcase_add_test(tc, test_wall_time_model_moves_between_connections);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(modbus_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
