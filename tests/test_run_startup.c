/* test_run_startup.c: the runner waits for the drives' own start-up (CAN boot-up and SDO
 * configuration, Modbus first exchange) and reports a drive that fails to start by its
 * drive, node and cause, not as an e-stop chain problem. */
#include <check.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "hal/hal.h"
#include "sim/modbus_sim.h"
#include "tests/test_net_util.h"
#include "task/runner.h"

#define NLEGS 6

/* A copy of a configuration's INI in a fresh directory: HALFILE and ../sim/ paths made
 * absolute, `insert` added after every line that starts with `after` (if given), lines
 * starting with `drop` left out (if given), `tail` appended. Returns the INI's path. */
static void config_copy(const char *rel_ini, const char *after, const char *insert,
                        const char *drop, const char *tail, char *out, size_t len)
{
    const char *root = getenv("HEXCNC_ROOT") ? getenv("HEXCNC_ROOT") : ".";
    char src_path[1024], dir[64] = "/tmp/test_run_startup_XXXXXX", cfgdir[1024];
    snprintf(src_path, sizeof src_path, "%s/%s", root, rel_ini);
    snprintf(cfgdir, sizeof cfgdir, "%s/%s", root, rel_ini);
    *strrchr(cfgdir, '/') = '\0';
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(out, len, "%s/machine.ini", dir);
    FILE *src = fopen(src_path, "r"), *dst = fopen(out, "w");
    ck_assert_ptr_nonnull(src);
    ck_assert_ptr_nonnull(dst);
    char line[1024];
    while (fgets(line, sizeof line, src)) {
        if (drop && strncmp(line, drop, strlen(drop)) == 0)
            continue;
        if (strncmp(line, "HALFILE = ../", 13) == 0)
            fprintf(dst, "HALFILE = %s/%s", cfgdir, line + 10);
        else if (strncmp(line, "HALFILE = ", 10) == 0 && line[10] != '/')
            fprintf(dst, "HALFILE = %s/%s", cfgdir, line + 10);
        else if (strncmp(line, "TOOL_TABLE = ../", 16) == 0)
            fprintf(dst, "TOOL_TABLE = %s/%s", cfgdir, line + 13);
        else
            fputs(line, dst);
        if (after && strncmp(line, after, strlen(after)) == 0)
            fputs(insert, dst);
    }
    if (tail)
        fputs(tail, dst);
    fclose(src);
    fclose(dst);
}

/* Removes the copy made by config_copy (the INI and its directory; extra files by name). */
static void config_remove(const char *ini, const char *extra)
{
    char dir[1024];
    snprintf(dir, sizeof dir, "%s", ini);
    *strrchr(dir, '/') = '\0';
    unlink(ini);
    if (extra)
        unlink(extra);
    rmdir(dir);
}

/* What a run came to: status, error text and the machine time it took. */
struct outcome {
    int status;
    char err[1024];
    double waited_ms;      /* monitor periods run, as ms */
    double machine_s;      /* time the program was moving */
};

/* Runs the paper's program (10) on the simulated clock; `pin`, if given, is set first. */
static struct outcome run_program(const char *ini, const char *pin)
{
    const char *root = getenv("HEXCNC_ROOT") ? getenv("HEXCNC_ROOT") : ".";
    char prog[1024];
    snprintf(prog, sizeof prog, "%s/examples/paper/prog10_g141_d20.ngc", root);
    struct outcome o = { 0 };
    struct runner_opts opts = { ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    ck_assert_msg(runner_create(&opts, &r, o.err, sizeof o.err) == RUNNER_OK, "%s", o.err);
    if (pin)
        ck_assert_int_eq(hal_setp(runner_hal(r), pin, "1"), HAL_OK);
    ck_assert_msg(runner_load_program(r, prog, o.err, sizeof o.err) == RUNNER_OK, "%s", o.err);
    ck_assert_msg(runner_start(r, o.err, sizeof o.err) == RUNNER_OK, "%s", o.err);
    o.status = runner_run(r, NULL, NULL, NULL, o.err, sizeof o.err);
    struct runner_summary s;
    runner_summary(r, &s);
    o.waited_ms = (double)s.periods;  /* 1 ms servo period in both configurations */
    o.machine_s = s.machine_time_s;
    runner_destroy(r);
    return o;
}

/* Drives that take 150 ms to boot after NMT reset: the runner waits for them (the fixed
 * 100-period wait gave up at 100 ms with an e-stop message) and the program runs to its end. */
START_TEST(can_boot_150ms_runs)
{
    char ini[1024];
    config_copy("configs/can-sim/tmu-hexapod-can.ini", "[CAN_NODE_", "SIM_BOOT_DELAY = 150\n",
                NULL, NULL, ini, sizeof ini);
    struct outcome o = run_program(ini, NULL);
    config_remove(ini, NULL);
    ck_assert_msg(o.status == RUNNER_OK, "%s", o.err);
    ck_assert_double_gt(o.machine_s, 4.9);          /* the whole program, 4.963 s planned */
    ck_assert_double_gt(o.waited_ms - o.machine_s * 1000.0, 150.0);  /* it did wait */
}
END_TEST

/* A node that never boots: reported with its node, joint and cause once BOOT_TIMEOUT
 * (1000 ms) has passed, not as an e-stop problem. */
START_TEST(can_node_never_boots)
{
    char ini[1024];
    config_copy("configs/can-sim/tmu-hexapod-can.ini", NULL, NULL, NULL, NULL, ini, sizeof ini);
    struct outcome o = run_program(ini, "cia402-sim.3.silent");
    config_remove(ini, NULL);
    ck_assert_int_eq(o.status, RUNNER_ERR_FAULT);
    ck_assert_msg(strstr(o.err, "a drive faulted before motion") != NULL, "%s", o.err);
    ck_assert_msg(strstr(o.err, "cia402.3: CAN node 4 (joint 3): no boot-up message within "
                                "1000 ms") != NULL, "%s", o.err);
    ck_assert_msg(strstr(o.err, "e-stop") == NULL, "%s", o.err);
    ck_assert_double_ge(o.waited_ms, 1000.0);
    ck_assert_double_lt(o.waited_ms, 1100.0);
    ck_assert_double_eq(o.machine_s, 0.0);
}
END_TEST

/* A node that never answers an SDO: the first configuration write times out after
 * SDO_TIMEOUT (100 ms) and is reported. */
START_TEST(can_node_sdo_mute)
{
    char ini[1024];
    config_copy("configs/can-sim/tmu-hexapod-can.ini", NULL, NULL, NULL, NULL, ini, sizeof ini);
    struct outcome o = run_program(ini, "cia402-sim.1.sdo-mute");
    config_remove(ini, NULL);
    ck_assert_int_eq(o.status, RUNNER_ERR_FAULT);
    ck_assert_msg(strstr(o.err, "CAN node 2 (joint 1): no answer within 100 ms to writing "
                                "0x1017:00") != NULL, "%s", o.err);
    ck_assert_double_lt(o.waited_ms, 200.0);
}
END_TEST

/* Ready drives and an e-stop chain that is never reset (no [TASK] HALFILE): the e-stop
 * message, once the drives are up, not before. */
START_TEST(can_ready_but_estop)
{
    char ini[1024];
    config_copy("configs/can-sim/tmu-hexapod-can.ini", NULL, NULL, "HALFILE = tmu-hexapod-can-task",
                NULL, ini, sizeof ini);
    struct outcome o = run_program(ini, NULL);
    config_remove(ini, NULL);
    ck_assert_int_eq(o.status, RUNNER_ERR_STATE);
    ck_assert_msg(strstr(o.err, "did not come out of e-stop") != NULL, "%s", o.err);
    ck_assert_double_ge(o.waited_ms, 100.0);
    ck_assert_double_lt(o.waited_ms, 300.0);
}
END_TEST

/* A Modbus drive that does not answer at start: six simulated drives in this process (the
 * HAL file's own simulator left out), drive 2 reads requests and never answers. The run
 * stops before motion with the drive, its address, unit and the cause. */
START_TEST(modbus_no_answer_at_start)
{
    const char *root = getenv("HEXCNC_ROOT") ? getenv("HEXCNC_ROOT") : ".";
    struct modbus_sim_opts so;
    modbus_sim_opts_default(&so);
    struct modbus_sim *sim;
    ck_assert_int_eq(modbus_sim_create(&sim, NLEGS, &so), MODBUS_SIM_OK);
    char tail[512] = "", item[64], ini[1024], hal_copy[1100], hal_src[1024], line[1024];
    int ports[NLEGS];
    ck_assert_int_eq(tn_free_ports(ports, NLEGS), 0);
    for (int i = 0; i < NLEGS; i++) {
        int port = ports[i];
        ck_assert_int_eq(modbus_sim_start_tcp_port(sim, i, "127.0.0.1", port), MODBUS_SIM_OK);
        snprintf(item, sizeof item, "\n[MODBUS_DRIVE_%d]\nPORT = %d\n", i, port);
        strcat(tail, item);
    }
    ck_assert_int_eq(modbus_sim_inject(sim, 2, MODBUS_SIM_FAULT_NO_ANSWER, 0), MODBUS_SIM_OK);
    config_copy("configs/modbus-sim/tmu-hexapod-modbus.ini", "[HAL]", "HALFILE = machine.hal\n",
                "HALFILE = tmu-hexapod-modbus.hal", tail, ini, sizeof ini);
    /* the HAL file without its simulator, next to the copy */
    snprintf(hal_copy, sizeof hal_copy, "%s", ini);
    strcpy(strrchr(hal_copy, '/'), "/machine.hal");
    snprintf(hal_src, sizeof hal_src, "%s/configs/modbus-sim/tmu-hexapod-modbus.hal", root);
    FILE *src = fopen(hal_src, "r"), *dst = fopen(hal_copy, "w");
    ck_assert_ptr_nonnull(src);
    ck_assert_ptr_nonnull(dst);
    while (fgets(line, sizeof line, src)) {
        if (strncmp(line, "loadrt modbus-sim-server", 24) == 0)
            continue;
        if (strncmp(line, "source ", 7) == 0) /* sourced files stay in the config's folder */
            fprintf(dst, "source %s/configs/modbus-sim/%s", root, line + 7);
        else
            fputs(line, dst);
    }
    fclose(src);
    fclose(dst);
    struct outcome o = run_program(ini, NULL);
    config_remove(ini, hal_copy);
    modbus_sim_destroy(sim);
    ck_assert_int_eq(o.status, RUNNER_ERR_FAULT);
    ck_assert_msg(strstr(o.err, "a drive faulted before motion") != NULL, "%s", o.err);
    ck_assert_msg(strstr(o.err, "modbus.2: modbus drive 2 (127.0.0.1:") != NULL, "%s", o.err);
    ck_assert_msg(strstr(o.err, "no answer within 20 ms (unit 1; at start-up") != NULL, "%s",
                  o.err);
    ck_assert_msg(strstr(o.err, "e-stop") == NULL, "%s", o.err);
    ck_assert_double_eq(o.machine_s, 0.0);
}
END_TEST

/* The suite. */
static Suite *run_startup_suite(void)
{
    Suite *s = suite_create("run_startup");
    TCase *tc = tcase_create("drives");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, can_boot_150ms_runs);
    tcase_add_test(tc, can_node_never_boots);
    tcase_add_test(tc, can_node_sdo_mute);
    tcase_add_test(tc, can_ready_but_estop);
    tcase_add_test(tc, modbus_no_answer_at_start);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(run_startup_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
