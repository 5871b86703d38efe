/* test_run_faults.c: a drive fault in the middle of a program stops the runner, and its
 * error names the drive and the cause (the component's message, not just "e-stop"). */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hal/hal.h"
#include "task/runner.h"

/* What the progress callback needs to inject the fault once, partway through. */
struct inject {
    struct runner *r;
    double at_s;            /* machine time to inject at */
    int done;               /* injected */
    int messages;           /* fault messages handed to the shell */
    char last_source[32];
};

/* Progress callback: once the program is well under way, the simulated drive of joint 2
 * goes into Fault and sends an EMCY. */
static void inject_fault(void *ctx, const struct runner_progress *p)
{
    struct inject *in = ctx;
    if (!in->done && p->elapsed_s >= in->at_s) {
        ck_assert_int_eq(hal_setp(runner_hal(in->r), "cia402-sim.2.inject-fault", "1"), HAL_OK);
        in->done = 1;
    }
}

/* Message callback: counts the faults the shell would print. */
static void count_message(void *ctx, const struct hal_msg *m)
{
    struct inject *in = ctx;
    if (m->severity == HAL_MSG_FAULT) {
        in->messages++;
        snprintf(in->last_source, sizeof in->last_source, "%s", m->source);
    }
}

START_TEST(drive_fault_names_its_cause)
{
    char ini[1024], prog[1024], err[1024];
    const char *root = getenv("HEXCNC_ROOT") ? getenv("HEXCNC_ROOT") : ".";
    snprintf(ini, sizeof ini, "%s/configs/can-sim/tmu-hexapod-can.ini", root);
    snprintf(prog, sizeof prog, "%s/examples/paper/prog10_g141_d20.ngc", root);
    struct runner_opts o = { ini, RUNNER_CLOCK_SIM };
    struct runner *r;
    ck_assert_msg(runner_create(&o, &r, err, sizeof err) == RUNNER_OK, "%s", err);
    struct inject in = { .r = r, .at_s = 1.5 };
    runner_set_message_fn(r, count_message, &in);
    ck_assert_msg(runner_load_program(r, prog, err, sizeof err) == RUNNER_OK, "%s", err);
    ck_assert_msg(runner_start(r, err, sizeof err) == RUNNER_OK, "%s", err);
    int st = runner_run(r, NULL, inject_fault, &in, err, sizeof err);
    ck_assert_int_eq(in.done, 1);
    ck_assert_int_eq(st, RUNNER_ERR_FAULT);
    ck_assert_msg(strstr(err, "cause: cia402.2: ") != NULL, "error without its cause: %s", err);
    ck_assert_msg(strstr(err, "CAN node 3 (joint 2)") != NULL, "cause without the node: %s", err);
    ck_assert_int_eq(in.messages, 1);
    ck_assert_str_eq(in.last_source, "cia402.2");
    struct runner_summary s;
    runner_summary(r, &s);
    ck_assert(s.machine_time_s < s.planned_time_s);  /* it stopped before the end */
    runner_destroy(r);
}
END_TEST

/* The suite. */
static Suite *run_faults_suite(void)
{
    Suite *s = suite_create("run_faults");
    TCase *tc = tcase_create("drive");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, drive_fault_names_its_cause);
    suite_add_tcase(s, tc);
    return s;
}

int main(void)
{
    SRunner *sr = srunner_create(run_faults_suite());
    srunner_run_all(sr, CK_NORMAL);
    int failed = srunner_ntests_failed(sr);
    srunner_free(sr);
    return failed ? EXIT_FAILURE : EXIT_SUCCESS;
}
