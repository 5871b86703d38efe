/* test_can_hal.c: HAL-graph test: cia402 + cia402-sim, six drives following a trajectory. */
#include <check.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "hal/drivers/canopen_master.h"
#include "hal/drivers/cia402_hal.h"
#include "hal/hal.h"

#define PERIOD_NS 1000000L   /* 1 kHz servo thread; SYNC every 2 ms */
#define NDRIVES 6

/* Six drives, SYNC 2 ms, 1 um per count, legs 600..650 mm at power-on. */
static const char ini_text[] =
    "[KINS]\nJOINTS = 6\n"
    "[EMCMOT]\nSERVO_PERIOD = 1000000\n"
    "[CAN]\nINTERFACE = sim\nBITRATE = 1000000\nSYNC_PERIOD = 2000000\n"
    "HEARTBEAT_PERIOD = 20\nHEARTBEAT_TIMEOUT = 100\n"
    "[CAN_NODE_0]\nNODE_ID = 1\nCOUNTS_PER_MM = 1000\nOFFSET = 600\nSIM_START = 600\n"
    "[CAN_NODE_1]\nNODE_ID = 2\nCOUNTS_PER_MM = 1000\nOFFSET = 600\nSIM_START = 610\n"
    "[CAN_NODE_2]\nNODE_ID = 3\nCOUNTS_PER_MM = 1000\nOFFSET = 600\nSIM_START = 620\n"
    "[CAN_NODE_3]\nNODE_ID = 4\nCOUNTS_PER_MM = -1000\nOFFSET = 600\nSIM_START = 630\n"
    "[CAN_NODE_4]\nNODE_ID = 5\nCOUNTS_PER_MM = 1000\nOFFSET = 600\nSIM_START = 640\n"
    "[CAN_NODE_5]\nNODE_ID = 6\nCOUNTS_PER_MM = 1000\nOFFSET = 600\nSIM_START = 650\n";

/* Runs a HAL command, failing the test with the runtime's message. */
static void cmd(struct hal *h, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void cmd(struct hal *h, const char *fmt, ...)
{
    char line[200];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(line, sizeof line, fmt, ap);
    va_end(ap);
    int st = hal_cmd(h, line, "test", 0, stdout);
    ck_assert_msg(st == HAL_OK, "'%s': %s", line, hal_last_error(h));
}

/* A pin's data, type-checked. */
static void *pin(struct hal *h, enum hal_type want, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
static void *pin(struct hal *h, enum hal_type want, const char *fmt, ...)
{
    char name[80];
    enum hal_type t;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(name, sizeof name, fmt, ap);
    va_end(ap);
    void *p = hal_data_ptr(h, name, &t);
    ck_assert_msg(p != NULL, "no pin %s", name);
    ck_assert_int_eq(t, want);
    return p;
}

/* The graph: master and simulated drives on one simulated-clock thread. */
static struct hal *make_graph(char *ini_path)
{
    int fd = mkstemp(ini_path);
    ck_assert_int_ge(fd, 0);
    ck_assert_int_eq(write(fd, ini_text, sizeof ini_text - 1), (ssize_t)(sizeof ini_text - 1));
    close(fd);
    struct hal *h = hal_create();
    ck_assert_ptr_nonnull(h);
    ck_assert_int_eq(hal_load_ini(h, ini_path), HAL_OK);
    hal_set_sim_clock(h, true);
    cmd(h, "newthread servo-thread [EMCMOT]SERVO_PERIOD");
    cmd(h, "loadrt cia402");
    cmd(h, "loadrt cia402-sim");
    cmd(h, "addf cia402.update servo-thread");
    cmd(h, "addf cia402-sim.update servo-thread");
    ck_assert_int_eq(hal_start(h), HAL_OK);
    return h;
}

/* Advances the simulated clock by ms milliseconds. */
static void run_ms(struct hal *h, int ms)
{
    ck_assert_int_eq(hal_sim_advance(h, ms * PERIOD_NS), HAL_OK);
}

/* Startup, enable, a trajectory followed by all six drives, then standstill on target. */
START_TEST(test_six_drives_follow)
{
    char path[] = "/tmp/test_can_hal_XXXXXX";
    struct hal *h = make_graph(path);
    double *cmdp[NDRIVES], *fb[NDRIVES];
    bool *en[NDRIVES];
    int32_t *state[NDRIVES];
    for (int i = 0; i < NDRIVES; i++) {
        cmdp[i] = pin(h, HAL_FLOAT, "cia402.%d.position-cmd", i);
        fb[i] = pin(h, HAL_FLOAT, "cia402.%d.position-fb", i);
        en[i] = pin(h, HAL_BIT, "cia402.%d.enable", i);
        state[i] = pin(h, HAL_S32, "cia402.%d.state", i);
    }
    bool *all = pin(h, HAL_BIT, "cia402.all-enabled");
    *cmdp[0] = 650.0;  /* before the drive has reported, the feedback echoes the command */
    run_ms(h, 1);
    ck_assert_double_eq(*fb[0], 650.0);
    run_ms(h, 149);
    for (int i = 0; i < NDRIVES; i++) {
        ck_assert_int_eq(*state[i], CIA402_SWITCH_ON_DISABLED);
        ck_assert_double_eq_tol(*fb[i], 600.0 + 10.0 * i, 1e-9);
        *cmdp[i] = *fb[i];  /* motion tracks feedback while disabled */
        *en[i] = true;
    }
    run_ms(h, 30);
    ck_assert(*all);
    double start[NDRIVES], lo[NDRIVES], hi[NDRIVES], worst = 0;
    for (int i = 0; i < NDRIVES; i++)
        start[i] = lo[i] = hi[i] = *fb[i];
    for (int t = 1; t <= 1000; t++) {  /* 1 s: each leg a 5 mm, 1 Hz sine, phases apart */
        for (int i = 0; i < NDRIVES; i++)
            *cmdp[i] = start[i] + 5.0 * (sin(2 * M_PI * t * 1e-3 + i) - sin(i));
        run_ms(h, 1);
        for (int i = 0; i < NDRIVES; i++) {
            worst = fmax(worst, fabs(*fb[i] - *cmdp[i]));
            lo[i] = fmin(lo[i], *fb[i]);
            hi[i] = fmax(hi[i], *fb[i]);
        }
    }
    /* 31.4 mm/s peak: a lag of at most 3 SYNC periods (6 ms) is 0.19 mm */
    ck_assert_msg(worst < 0.19, "worst following distance %g mm", worst);
    run_ms(h, 20);  /* standstill: every drive ends on its command to the count */
    for (int i = 0; i < NDRIVES; i++) {
        ck_assert_msg(hi[i] - lo[i] > 9.9, "drive %d moved only %g mm", i, hi[i] - lo[i]);
        ck_assert_double_eq_tol(*fb[i], *cmdp[i], 0.0005);
    }
    int32_t *counts3 = pin(h, HAL_S32, "cia402-sim.%d.position-counts", 3);
    ck_assert_int_eq(*counts3, (int32_t)lround((*cmdp[3] - 600.0) * -1000.0));  /* sign */
    hal_destroy(h);
    unlink(path);
}
END_TEST

/* A drive fault raised from the simulated drive reaches the fault pins with its EMCY code,
 * the others stay enabled, and a fault reset brings it back to Operation enabled. */
START_TEST(test_fault_pins_and_reset)
{
    char path[] = "/tmp/test_can_hal_XXXXXX";
    struct hal *h = make_graph(path);
    for (int i = 0; i < NDRIVES; i++) {
        double *fbp = pin(h, HAL_FLOAT, "cia402.%d.position-fb", i);
        double *cp = pin(h, HAL_FLOAT, "cia402.%d.position-cmd", i);
        bool *e = pin(h, HAL_BIT, "cia402.%d.enable", i);
        run_ms(h, i == 0 ? 150 : 0);
        *cp = *fbp;
        *e = true;
    }
    run_ms(h, 30);
    bool *fault3 = pin(h, HAL_BIT, "cia402.%d.fault", 3);
    bool *any = pin(h, HAL_BIT, "cia402.fault-any");
    uint32_t *emcy3 = pin(h, HAL_U32, "cia402.%d.emcy-code", 3);
    int32_t *state3 = pin(h, HAL_S32, "cia402.%d.state", 3);
    int32_t *state0 = pin(h, HAL_S32, "cia402.%d.state", 0);
    bool *reset3 = pin(h, HAL_BIT, "cia402.%d.fault-reset", 3);
    ck_assert(!*any);
    cmd(h, "setp cia402-sim.3.fault-code 0x4310");
    cmd(h, "setp cia402-sim.3.inject-fault 1");
    run_ms(h, 10);
    ck_assert(*fault3 && *any);
    ck_assert_uint_eq(*emcy3, 0x4310);
    ck_assert_int_eq(*state3, CIA402_FAULT);
    ck_assert_int_eq(*state0, CIA402_OP_ENABLED);
    struct canopen_master *m = hal_get_object(h, CIA402_OBJ_MASTER);
    ck_assert_ptr_nonnull(m);
    ck_assert_ptr_nonnull(strstr(m->node[3].message, "CAN node 4 (joint 3)"));
    ck_assert_ptr_nonnull(strstr(m->node[3].message, "0x4310"));
    cmd(h, "setp cia402-sim.3.inject-fault 0");
    *reset3 = true;
    run_ms(h, 30);
    ck_assert(!*fault3 && !*any);
    ck_assert_int_eq(*state3, CIA402_OP_ENABLED);
    ck_assert_uint_eq(*emcy3, 0);
    /* heartbeat stops: the fault comes 100 ms after the last one (sent 0..20 ms ago) */
    cmd(h, "setp cia402-sim.1.heartbeat-stop 1");
    bool *fault1 = pin(h, HAL_BIT, "cia402.%d.fault", 1);
    run_ms(h, 79);
    ck_assert(!*fault1);
    run_ms(h, 24);
    ck_assert(*fault1 && *any);
    ck_assert_ptr_nonnull(strstr(m->node[1].message, "no heartbeat"));
    hal_destroy(h);
    unlink(path);
}
END_TEST

/* The suite. */
static Suite *can_hal_suite(void)
{
    Suite *s = suite_create("can_hal");
    TCase *tc = tcase_create("graph");
    tcase_add_test(tc, test_six_drives_follow);
    tcase_add_test(tc, test_fault_pins_and_reset);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(can_hal_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
